#include "view/view_command.hpp"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <future>
#include <iostream>
#include <thread>

#include "base/errors.hpp"
#include "frontend/parse.hpp"
#include "frontend/prepare_render.hpp"
#include "frontend/signals.hpp"
#include "view/view_server.hpp"
#include "view/view_session.hpp"

namespace tracer::view {

int run_view(ViewArgs args) {
  using namespace frontend;
  std::signal(SIGPIPE, SIG_IGN);  // a closed tab is a failed write, not the end of the process
  const CancelFlag cancel = &stop_requested();
  RenderArgs& r = args.render;
  if (!args.width_given) r.settings.width = kDefaultViewSide;
  if (!args.height_given) r.settings.height = kDefaultViewSide;
  check_range("--port", args.port, 0, 65535);
  if (args.listen.empty()) throw UsageError("--listen: an empty address (127.0.0.1 keeps the viewer to this machine)");
  // The render flags that make files or sequences mean nothing here (save downloads the image).
  if (r.frames != 1) throw UsageError("--frames: not for tracer view (an image sequence is tracer render's)");
  if (r.orbit != 0.0) throw UsageError("--orbit: not for tracer view (drag to orbit)");
  if (!r.aov.empty()) throw UsageError("--aov: not for tracer view (tracer render writes the layers)");
  if (r.checkpoint) throw UsageError("--checkpoint: not for tracer view (save downloads the image)");
  check_range("--width", r.settings.width, 1, kMaxViewSide);
  check_range("--height", r.settings.height, 1, kMaxViewSide);
  // The first image comes before any gain from a slower build (docs/BENCHMARKS.md section 19);
  // the copied command leaves the quality to tracer render, as the user did.
  RenderArgs built = r;
  if (!built.build_quality) built.build_quality = BuildQuality::Medium;
  const PreparedRender setup(built, {.writes_outputs = false, .quiet = r.quiet, .cancel = cancel});
  if (!setup.lighting_note.empty() && !r.quiet) std::cerr << "tracer: note: " << setup.lighting_note << "\n";
  const Scene& scene = setup.scene;

  ViewSession session(scene, setup.accel, r);
  ViewServer server(session, random_token());
  const int port = server.bind(args.listen, args.port);
  session.start();
  auto listening = std::async(std::launch::async, [&] { server.listen(); });
  const std::string host = args.listen.find(':') != std::string::npos ? "[" + args.listen + "]" : args.listen;
  std::printf("tracer: viewing %s at http://%s:%d/?token=%s (Ctrl-C stops)\n", scene.source.c_str(), host.c_str(), port,
              server.token().c_str());
  std::fflush(stdout);
  if (!is_loopback_address(args.listen)) {
    std::cerr << "tracer: warning: --listen " << args.listen
              << " serves the viewer beyond this machine: anyone who can reach it and sees the URL's token can "
                 "drive the render (plain HTTP, not encrypted)\n";
  }

  while (!is_cancelled(cancel)) {
    if (listening.wait_for(std::chrono::milliseconds(50)) == std::future_status::ready) {
      listening.get();  // the server ended by itself: say why
      throw InputError("the HTTP server stopped unexpectedly");
    }
  }
  session.stop();  // the pass in progress stops within a piece of a tile
  server.stop();
  std::cerr << "tracer: " << stop_signal_name() << std::endl;
  // Idle keep-alive connections of a browser may hold the server's threads for up to a second;
  // nothing is left to write, so the process does not wait for them.
  if (listening.wait_for(std::chrono::milliseconds(300)) != std::future_status::ready) {
    std::_Exit(exit_code_for_stop());
  }
  return exit_code_for_stop();
}

}  // namespace tracer::view
