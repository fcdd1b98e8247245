// tracer: the command-line front end (render, view, info, bench, compare). Exit codes: 0 ok, 1 bad input, 2 bad usage,
// 130 interrupted.
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <atomic>
#include <chrono>
#include <cinttypes>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <new>
#include <optional>
#include <sstream>

#include "base/errors.hpp"
#include "base/memory_limit.hpp"
#include "base/stopwatch.hpp"
#include "cli/bench.hpp"
#include "frontend/prepare_render.hpp"
#include "frontend/progress.hpp"
#include "frontend/render_args.hpp"
#include "frontend/render_driver.hpp"
#include "frontend/render_options.hpp"
#include "frontend/render_stats.hpp"
#include "frontend/scene_setup.hpp"
#include "frontend/settings_table.hpp"
#include "frontend/signals.hpp"
#include "io/image_compare.hpp"
#include "io/image_io.hpp"
#include "view/view_command.hpp"

namespace tracer::cli {

using namespace frontend;  // the flags, signals and statistics both binaries share

namespace {

int cmd_render(const RenderArgs& args) {
  // main() installed the flag handlers: loading, the build and the render poll the flag.
  const CancelFlag cancel = &stop_requested();
  const PreparedRender setup(args, {.writes_outputs = true, .quiet = args.quiet, .cancel = cancel});
  if (args.threads && ThreadLimit::oversubscribed(*args.threads)) {
    std::cerr << "tracer: warning: --threads " << *args.threads << " is more than this machine's hardware threads; all "
              << *args.threads << " run, sharing them\n";
  }
  if (!setup.lighting_note.empty() && !args.quiet) std::cerr << "tracer: note: " << setup.lighting_note << "\n";
  if (args.focus_distance && setup.camera.lens_radius == 0.0f) {
    std::cerr << "tracer: warning: --focus-distance: the camera is a pinhole (no --aperture), everything is in "
                 "focus: it changes nothing\n";
  }
  const Scene& scene = setup.scene;
  const RenderSettings& settings = setup.settings;
  const Accelerator& accel = setup.accel;

  RenderMonitor control;
  control.cancel = cancel;
  const auto t_render = std::chrono::steady_clock::now();
  ProgressBar progress(!args.quiet, pixel_samples(settings, args.frames), control.pixels_done, control.rays_done,
                       adaptive(settings) ? &control.active_pixels : nullptr,
                       uint64_t(settings.width) * uint64_t(settings.height));
  // Every pass a round of its own: checkpoints, and a complete image after the first on Ctrl-C.
  const auto round = [&](const PassContext& ctx, const std::vector<SampleRange>& passes) {
    return render_round(accel, ctx, passes, setup.sched, control);
  };
  const FrameSequence frames{args.output,       args.frames,    args.orbit,   args.checkpoint, args.exr,
                             args.save_partial, aovs_for(args), args.denoise, args.simd_target};
  const Executor denoiser(setup.sched.strategy, setup.sched.threads);
  const DriveResult r =
      drive_render(scene, setup.camera, settings, frames,
                   {.holds_image = true, .round_per_pass = true, .cancel = cancel, .denoiser = &denoiser}, round,
                   [](const std::string& w) { std::cerr << "tracer: warning: " << w << "\n"; });
  if (r.stopped) {
    progress.stop();
    std::cerr << "tracer: " << stop_signal_name();
    const char* noisy = r.not_denoised ? " (not denoised)" : "";
    if (r.stopped_after_write) {
      std::cerr << " after the render finished; image written to " << r.output << noisy << "\n";
    } else if (r.samples > 0) {
      std::cerr << " after " << r.samples << " of " << settings.spp << " samples per pixel; image written to "
                << r.output << noisy << "\n";
    } else if (r.wrote_partial) {
      std::cerr << "; partial image written to " << r.output << noisy << "\n";
    } else {
      std::cerr << (args.save_partial ? " before any tile finished" : "") << "; no image written\n";
    }
    return exit_code_for_stop();
  }
  const int checkpoints = r.checkpoints;
  progress.stop();
  const double render_ms = ms_since(t_render) - r.denoise_ms;
  const QueryCounts traversal = control.traversal.load();
  nlohmann::json stats =
      render_stats(scene, settings, accel, setup.sched, args, setup.load_ms, render_ms, control.counts.load(),
                   args.scene.scene.empty() && args.scene.view.empty() ? nullptr : &setup.load_phases,
                   settings.count_traversal ? &traversal : nullptr);
  stats["checkpoints_written"] = checkpoints;
  if (args.denoise) stats["denoise_ms"] = r.denoise_ms;
  if (args.stats) print_stats(stats, accel);
  try {
    write_stats_json(args.stats_json, stats);
  } catch (const InputError& e) {
    // The images are written by now: say which output failed and that they are not lost.
    const std::string images =
        args.frames > 1 ? "the " + std::to_string(args.frames) + " frames were" : "the image was";
    throw InputError("--stats-json: " + std::string(e.what()) + " (" + images + " written)");
  }
  return 0;
}

int cmd_info(const SceneArgs& args) {
  const SceneInfo scene = scene_info(args, /*quiet=*/false);
  std::printf("scene       %s\n", scene.source.c_str());
  std::printf("triangles   %" PRIu64 " (%" PRIu64 " degenerate)", scene.triangles, scene.degenerate);
  if (scene.instances > 0) {
    std::printf(", placed by %" PRIu64 " instances of %" PRIu64 " meshes holding %" PRIu64 " unique", scene.instances,
                scene.meshes, scene.unique_triangles);
  }
  std::printf("\n");
  std::printf("vertices    %" PRIu64 "\n", scene.vertices);
  std::printf("geometries  %" PRIu64 "\n", scene.geometries);
  std::printf("materials   %zu:", scene.materials.size());
  for (const std::string& m : scene.materials) std::printf(" %s", m.c_str());
  std::printf("\nlights      %" PRIu64 "\n", uint64_t(scene.lights.size()) + scene.unlisted_area_lights);
  for (const Light& l : scene.lights) {
    if (l.kind == LightKind::Directional) {
      std::printf("  directional along (%g, %g, %g), irradiance (%g, %g, %g)\n", l.normal.x, l.normal.y, l.normal.z,
                  l.power.x, l.power.y, l.power.z);
      continue;
    }
    const char* kind = l.kind == LightKind::Point ? "point" : l.kind == LightKind::Spot ? "spot " : "area ";
    std::printf("  %s at (%g, %g, %g), power (%g, %g, %g)\n", kind, l.position.x, l.position.y, l.position.z, l.power.x,
                l.power.y, l.power.z);
  }
  if (scene.unlisted_area_lights) {
    std::printf("  area: %" PRIu64 " emissive primitives placed by the node tree\n", scene.unlisted_area_lights);
  }
  if (!scene.cameras.empty()) {
    std::printf("cameras     %zu (--camera N)\n", scene.cameras.size());
    for (size_t i = 0; i < scene.cameras.size(); ++i) {
      const CameraSpec& c = scene.cameras[i];
      std::printf("  %zu at (%g, %g, %g), looking at (%g, %g, %g), fov %g\n", i, c.eye.x, c.eye.y, c.eye.z, c.look.x,
                  c.look.y, c.look.z, c.fov_degrees);
    }
  }
  std::printf("bounds      (%g, %g, %g) - (%g, %g, %g)\n", scene.bounds.lo.x, scene.bounds.lo.y, scene.bounds.lo.z,
              scene.bounds.hi.x, scene.bounds.hi.y, scene.bounds.hi.z);
  std::printf(
      "memory      about %s with bvh8's tree (a render adds its image; --max-memory-mib)\n",
      scene.estimated_bytes == UINT64_MAX ? "more than 2^62 bytes" : format_bytes(scene.estimated_bytes).c_str());
  return 0;
}

int cmd_compare(const std::string& a, const std::string& b, std::optional<float> exposure) {
  const ImageDifference d = compare_images(a, b, exposure);
  std::printf("%dx%d, %s", d.width, d.height, d.linear ? "linear radiance" : "display values 0-1");
  if (exposure) std::printf(" at exposure %g", double(*exposure));
  std::printf(": RMSE %.6g, largest difference %.6g", d.rmse, d.max_abs);
  if (!d.linear) std::printf(", PSNR %.2f dB", d.psnr_db);
  std::printf(", means %.6g and %.6g", d.mean_a, d.mean_b);
  if (d.mean_a > 0.0) std::printf(" (%+.2f %%)", 100.0 * (d.mean_b / d.mean_a - 1.0));
  std::printf("\n");
  return 0;
}

}  // namespace
}  // namespace tracer::cli

namespace {
// The stop handlers, installed as the program is loaded: before the shared libraries' constructors
// (TBB's, OpenEXR's, Embree's; tens of milliseconds, docs/RELIABILITY.md), during which a
// background job's SIGINT, ignored since the shell started it, would be discarded by the kernel
// and the viewer never stop.
void install_at_load(int, char**, char**) { tracer::frontend::install_stop_handlers(); }
[[gnu::section(".preinit_array"), gnu::used]] void (*const preinit_stop_handlers)(int, char**,
                                                                                  char**) = install_at_load;
}  // namespace

int main(int argc, char** argv) {
  using namespace tracer;
  using namespace tracer::cli;
  using namespace tracer::frontend;
  CLI::App app{"tracer: a fast parallel CPU ray tracer for OBJ, glTF 2.0 and PLY scenes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "tracer 0.1.0");

  RenderArgs render_args;
  CLI::App* render = app.add_subcommand("render", "render a scene to a PNG, PPM or OpenEXR image");
  add_render_options(*render, render_args);
  add_output_options(*render, render_args, "", "timings, ray counts and Mrays/s");
  render->add_flag("--count", render_args.count,
                   "count the nodes, leaf packs and triangles each ray visits, for --stats and --stats-json "
                   "(8-wide BVH; the same image, rendered slower)");
  render->add_flag("--save-partial", render_args.save_partial,
                   "on Ctrl-C, write the image with unfinished tiles black");

  RenderArgs info_args;
  CLI::App* info = app.add_subcommand("info", "print a scene's triangles, vertices, materials, lights and bounds");
  add_settings(*info, info_args, {SettingGroup::Scene});

  std::string compare_a, compare_b;
  CLI::App* compare = app.add_subcommand(
      "compare", "RMSE between two images: linear radiance for two .exr, display values (and PSNR) for .png/.ppm");
  compare->add_option("a", compare_a, "an image (e.g. the reference)")->required();
  compare->add_option("b", compare_b, "an image of the same size and kind")->required();
  std::optional<float> compare_exposure;
  compare
      ->add_option("--exposure", compare_exposure,
                   "compare two .exr in display values, tone-mapped at this exposure as render's .png (not "
                   "rounded to 8 bits)")
      ->check(CLI::PositiveNumber);

  view::ViewArgs view_args;
  CLI::App* view_cmd = app.add_subcommand(
      "view", "look around a scene in the browser while it renders (prints a URL; every render flag works)");
  add_render_options(*view_cmd, view_args.render);
  view_cmd->add_option("--listen", view_args.listen, "address to serve on (the default keeps it to this machine)")
      ->capture_default_str();
  view_cmd->add_option("--port", view_args.port, "port to serve on, 0 for any free one")->capture_default_str();
  view_cmd->add_flag("-q,--quiet", view_args.render.quiet, "no loader warnings");

  BenchArgs bench_args;
  CLI::App* bench = app.add_subcommand("bench", "time the study's variants and ours on the Cornell scenes and more");
  add_bench_options(*bench, bench_args);

  // CLI11 reports an unknown command as "A subcommand is required"; name it instead.
  if (argc > 1 && argv[1][0] != '-') {
    try {
      app.get_subcommand(argv[1]);
    } catch (const CLI::OptionNotFound&) {
      std::cerr << "tracer: error: unknown command '" << argv[1] << "' (render, view, info, bench, compare)\n";
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);
    // A value refused by its check names the flag and what it takes; CLI11's own errors (an
    // unknown flag, a missing value) point to the help.
    const bool value = dynamic_cast<const CLI::ValidationError*>(&e) != nullptr;
    std::cerr << "tracer: error: " << parse_error_text(e.what()) << (value ? "\n" : " (see tracer --help)\n");
    return 2;
  }
  try {
    if (render->parsed()) return cmd_render(render_args);
    if (view_cmd->parsed()) {
      view_args.width_given = view_cmd->count("--width") > 0;
      view_args.height_given = view_cmd->count("--height") > 0;
      return view::run_view(std::move(view_args));
    }
    // Nothing polls the stop flag in these: a signal ends them at once.
    if (info->parsed() || bench->parsed() || compare->parsed()) install_immediate_stop_handlers(nullptr);
    if (info->parsed()) return cmd_info(info_args.scene);
    if (bench->parsed()) return run_bench(bench_args);
    if (compare->parsed()) return cmd_compare(compare_a, compare_b, compare_exposure);
  } catch (...) {
    const Failure f = failure_of(std::current_exception());
    switch (f.kind) {
      case Failure::Kind::Cancelled:
        std::cerr << "tracer: " << stop_signal_name() << "; no image written\n";
        return exit_code_for_stop();
      case Failure::Kind::Internal:
        std::cerr << "tracer: internal error: " << f.message << "\n";
        return f.exit_code;
      default:
        std::cerr << "tracer: error: " << f.message << "\n";
        return f.exit_code;
    }
  }
  return 0;
}
