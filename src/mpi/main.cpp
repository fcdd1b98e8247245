// tracer-mpi: `tracer render` over the ranks of an Open MPI job. Every rank loads the scene and
// builds its own accelerator; the scenes' checksums must agree; each pass's tiles are handed out
// on demand by rank 0 (mpi/tile_server.hpp) to every rank's render threads; rank 0 adds the
// returned tiles into its framebuffer, in the same order of passes as one process would, and
// writes the image, the checkpoints and the statistics. The image is byte-identical to
// `tracer render` with the same flags, for any number of ranks, threads and tile sizes.
// Exit codes as tracer's: 0, 1 bad input (on any rank), 2 bad usage, 128 + signal when stopped.
#include <CLI/CLI.hpp>

#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "frontend/render_args.hpp"
#include "frontend/render_driver.hpp"
#include "frontend/render_options.hpp"
#include "frontend/settings_table.hpp"
#include "frontend/signals.hpp"
#include "mpi/mpi_session.hpp"
#include "mpi/phase_watch.hpp"
#include "mpi/rank_render.hpp"
#include "mpi/setup_agreement.hpp"
#include "mpi/tile_server.hpp"

namespace tracer::mpi {
namespace {

// mpirun answers Ctrl-C, and the death of any rank, by sending SIGTERM to every rank: a rank
// cannot tell which happened, and its peers may already be gone, so each stops at once. Rank 0
// says so in one line; no image is written (a --checkpoint written before stays: it is complete).
constexpr const char* kStopMessage =
    "tracer-mpi: rank 0 stopped by a signal (mpirun sends it on Ctrl-C and when another rank fails: see its "
    "message); no image written\n";

// `parse_error`: this rank's flags did not parse (exit code 2 and the message); it still joins the
// first collective, so rank 0 can name it and end the job instead of waiting for it.
int run(const frontend::RenderArgs& args, MpiSession& session, const std::string& parse_error, double rank_timeout,
        PhaseWatch& watch_phase) {
  frontend::install_immediate_stop_handlers(session.root() ? kStopMessage : nullptr);
  RankSetup setup;  // in place: the accelerator points into the scene
  if (parse_error.empty()) {
    set_up(setup, args, session);
  } else {
    setup.exit_code = 2;
    setup.error = parse_error;
  }
  Agreement agreement = agree_on_setup(setup, args, session);
  watch_phase.disarm();  // start-up is over: every rank answered
  if (agreement.verdict != 0) {
    // The first rank to exit non-zero makes mpirun stop the others with SIGTERM: rank 0 has said
    // what is wrong, so that signal needs no second message.
    frontend::install_immediate_stop_handlers(nullptr);
    return agreement.verdict;
  }
  const frontend::PreparedRender& prepared = *setup.prepared;
  RankRender rank(prepared, args, session, std::move(agreement.threads), rank_timeout, watch_phase);
  // Signals end a rank at once (install_immediate_stop_handlers): no round is ever stopped.
  const frontend::FrameSequence frames{args.output, args.frames, args.orbit,   args.checkpoint, args.exr,
                                       false,       {},          args.denoise, args.simd_target};
  // Rank 0 denoises the gathered film with its own threads.
  const Executor denoiser(prepared.sched.strategy, prepared.sched.threads);
  const frontend::DriveResult driven = frontend::drive_render(
      prepared.scene, prepared.camera, prepared.settings, frames,
      // Adaptive sampling decides between passes, from rank 0's image: a round per pass.
      {.holds_image = session.root(),
       .round_per_pass = args.checkpoint.has_value() || adaptive(prepared.settings),
       .cancel = nullptr,
       .denoiser = &denoiser},
      [&](const PassContext& ctx, const std::vector<SampleRange>& round) { return rank.render_round(ctx, round); },
      [](const std::string& w) { say("tracer-mpi: warning: " + w); });
  rank.report_late_ranks();
  rank.report_ranks(driven.checkpoints);
  return 0;
}

}  // namespace
}  // namespace tracer::mpi

int main(int argc, char** argv) {
  using namespace tracer;
  // Start-up (MPI's, the scene's loading, the agreement on the setup) has a bound of its own from
  // the first instant, MPI_Init included: a rank that never gets there ends the job, named.
  double startup_timeout = 120.0;
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--startup-timeout") startup_timeout = std::atof(argv[i + 1]);
  }
  if (!(startup_timeout >= 0.1 && startup_timeout <= 1e6)) startup_timeout = 120.0;  // CLI11 says what is wrong
  mpi::PhaseWatch watch;
  watch.arm("tracer-mpi: error: rank " + mpi::launcher_rank_text() + ": start-up did not end within " +
                std::to_string(int(startup_timeout)) +
                " s (MPI start-up, loading the scene, agreeing on the setup): a rank stopped or cannot be reached "
                "(--startup-timeout raises it); ending the job",
            startup_timeout);
  std::optional<mpi::MpiSession> session;
  try {
    session.emplace(argc, argv);
  } catch (const std::exception& e) {
    tracer::mpi::say(std::string("tracer-mpi: error: ") + e.what());
    return 1;
  }
  CLI::App app{"tracer-mpi: tracer render over the ranks of an Open MPI job (mpirun -np N tracer-mpi render ...)"};
  app.require_subcommand(1);
  frontend::RenderArgs args;
  CLI::App* render = app.add_subcommand("render", "render a scene to a PNG, PPM or OpenEXR image, on every rank");
  frontend::add_render_options(*render, args);
  frontend::add_output_options(*render, args, " (written by rank 0)",
                               "timings, ray counts and each rank's tiles, rays and idle time");
  double rank_timeout = mpi::StallWatch{}.floor_seconds;
  render
      ->add_option("--rank-timeout", rank_timeout,
                   "seconds a tile may be out with a rank before its tiles go to others (at least; 8x the slowest "
                   "tile so far if more)")
      ->check(CLI::Range(0.1, 1e6))
      ->capture_default_str();
  render
      ->add_option("--startup-timeout", startup_timeout,
                   "seconds every rank may take to start, load the scene and agree on the setup")
      ->check(CLI::Range(0.1, 1e6))
      ->capture_default_str();
  std::string parse_error;
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return session->root() ? app.exit(e) : 0;
    const bool value = dynamic_cast<const CLI::ValidationError*>(&e) != nullptr;  // as tracer's main
    parse_error = frontend::parse_error_text(e.what()) + (value ? "" : " (see tracer-mpi --help)");
  }
  try {
    return mpi::run(args, *session, parse_error, rank_timeout, watch);
  } catch (const std::exception& e) {
    mpi::say("tracer-mpi: error: rank " + std::to_string(session->rank()) + ": " + e.what());
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  return 1;
}
