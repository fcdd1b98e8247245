// `tracer bench`: its flags, and the run over every scene and variant. The catalogue of
// variants and scenes, the timed runs of one cell, and the reports live beside it.
#include "cli/bench.hpp"

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>

#include "base/errors.hpp"
#include "cli/bench_catalogue.hpp"
#include "cli/bench_report.hpp"
#include "cli/bench_run.hpp"
#include "frontend/output_checks.hpp"
#include "frontend/parse.hpp"
#include "frontend/render_args.hpp"
#include "frontend/render_options.hpp"
#include "frontend/scene_setup.hpp"
#include "importers/scene_file.hpp"
#include "io/image_io.hpp"
#include "parallel/thread_count.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"

namespace tracer::cli {

using namespace frontend;  // the flags both binaries share
using Clock = std::chrono::steady_clock;

void add_bench_options(CLI::App& app, BenchArgs& a) {
  app.add_option("--variants", a.variants, "variants: names, or study, ours, all")->capture_default_str();
  app.add_option(
         "--scenes", a.scenes,
         "scenes: view names from --views, or cornell, large, all (views); builtin; instanced (the Bunny placed 100 "
         "times, kept once: bvh8 and embree variants); scene paths (framed from outside)")
      ->capture_default_str();
  app.add_option("--views", a.views,
                 "views file: name, OBJ, camera and light per line (default ../shared/scenes/views.tsv)");
  app.add_flag("--framed", a.framed, "also time each view's scene framed from outside its bounds, as a labelled row");
  app.add_option("--size", a.size, "image size WxH")->capture_default_str();
  app.add_option("--ao", a.ao, "AO rays per hit")->capture_default_str();
  app.add_option("--integrator", a.integrator,
                 "workload: " + names_of<Integrator>(kIntegratorNames) + " (ao: the study's; path: incoherent rays)")
      ->capture_default_str();
  app.add_option("--spp", a.spp, "path: samples per pixel (1-65536)")->capture_default_str();
  app.add_option("--runs", a.runs, "timed runs per cell")->capture_default_str();
  app.add_option("--best", a.best, "mean of the best k runs (the study's k-best rule)")->capture_default_str();
  app.add_option("--threads", a.threads, "threads for the parallel variants (default: all)");
  app.add_option("--build-quality", a.build_quality,
                 "build the variants that have quality levels and none in their name (bvh8, best, embree, "
                 "embree-packets) at this one: " +
                     names_of<BuildQuality>(kBuildQualityNames) + " (their names then say it)");
  app.add_option("--max-seconds", a.max_seconds,
                 "time cap per cell, all its runs together: later runs are skipped, a run at the cap is stopped")
      ->capture_default_str();
  file_option(app.add_option("--json", a.json, "write raw figures as JSON"));
  file_option(app.add_option("--plot", a.plot, "write a grouped bar chart (SVG, log scale)"));
  file_option(app.add_option("--markdown", a.markdown, "also write the tables to this Markdown file"));
  app.add_flag("--list", a.list, "list the variants and exit");
}

int run_bench(const BenchArgs& a) {
  if (a.list) {
    for (const Variant& v : all_variants())
      std::printf("%-24s %s%s\n", v.name.c_str(), v.description.c_str(), v.study ? " (study)" : "");
    return 0;
  }
  const auto [width, height] = parse_size("--size", a.size);
  check_range("--ao", a.ao, 0, 4096);
  check_range("--spp", a.spp, 1, 65536);
  const Integrator integrator = parse_name<Integrator>(kIntegratorNames, a.integrator, "--integrator", "integrator");
  check_range("--runs", a.runs, 1, 1000);
  check_range("--best", a.best, 1, a.runs);
  if (a.threads) check_range("--threads", *a.threads, 1, 1024);
  const int threads = a.threads.value_or(0);
  const ThreadLimit thread_limit(threads);
  check_range_real("--max-seconds", a.max_seconds, 0.0, 1e7, LowEnd::Open);
  std::vector<Variant> variants = resolve_variants(a.variants);
  if (a.build_quality) {
    const BuildQuality q = parse_name<BuildQuality>(kBuildQualityNames, *a.build_quality, "--build-quality", "quality");
    for (Variant& v : variants) {
      if (!has_build_quality(v.accel) || v.accel == AccelKind::EmbreeHigh || v.quality == q) continue;
      if (v.name.find("-high") != std::string::npos) continue;  // a quality of its own
      v.quality = q;
      v.name += "@" + std::string(name_of<BuildQuality>(kBuildQualityNames, q));
    }
  }
  const std::vector<SceneEntry> scenes = resolve_scenes(a);
  const std::pair<const std::string*, const char*> outputs[] = {
      {&a.json, "--json"}, {&a.plot, "--plot"}, {&a.markdown, "--markdown"}};
  // Up front against each other, the scene files (loaded later, one at a time) and the views
  // file (read); after each scene's load against its MTL files and textures, before its cells run.
  for (const auto& [out, flag] : outputs) {
    if (out->empty()) continue;
    check_output(*out, flag);
    for (const auto& [other, other_flag] : outputs) {
      if (other != out && !other->empty() && same_file(*out, *other)) {
        throw UsageError(std::string(flag) + ": '" + *out + "' is also the " + other_flag + " file");
      }
    }
    for (const SceneEntry& se : scenes) {
      if (!se.path.empty() && same_file(*out, se.path)) {
        throw UsageError(std::string(flag) + ": '" + *out + "' is an input of this run (" + se.path + ")");
      }
    }
  }

  CellTable cells;
  const size_t total_cells = variants.size() * scenes.size();
  size_t done_cells = 0;
  const auto bench_start = Clock::now();
  const bool tty = ::isatty(STDERR_FILENO);
  std::fprintf(
      stderr,
      "tracer bench: %zu cells (%zu scenes x %zu variants), up to %d runs each, at most %s s per cell: at most %s\n",
      total_cells, scenes.size(), variants.size(), a.runs, fmt(a.max_seconds, 0).c_str(),
      duration_text(double(total_cells) * a.max_seconds).c_str());
  for (const SceneEntry& se : scenes) {
    const auto t_load = Clock::now();
    Scene scene = se.path.empty() ? make_cornell_box(0) : load_scene_file(se.path, [](const std::string&) {});
    for (const auto& [out, flag] : outputs) {
      if (!out->empty()) check_output(*out, flag);
    }
    if (se.view) apply_view_light(scene, *se.view);
    if (se.placements) scene = place_instances(std::move(scene), grid_placements(scene.bounds, se.placements));
    const double load_ms = std::chrono::duration<double, std::milli>(Clock::now() - t_load).count();
    const CameraSpec cam = se.view ? se.view->camera : scene.camera ? *scene.camera : frame_bounds(scene.bounds);
    for (const Variant& v : variants) {
      if (scene.instanced() && !traces_instances(v.accel)) {  // only bvh8 and Embree trace instances
        Cell& cell = cells[{se.name, v.name}];
        cell.scene = se.name, cell.variant = v.name, cell.not_traced = true;
        cell.triangles = scene.instanced_size();
        ++done_cells;
        continue;
      }
      const auto progress_line = [&](int run) {
        if (!tty && run > 0) return;  // logs get one line per cell
        const double elapsed = std::chrono::duration<double>(Clock::now() - bench_start).count();
        const double frac = (double(done_cells) + double(run) / a.runs) / double(total_cells);
        std::fprintf(stderr, "%scell %zu/%zu %-10s %-24s run %2d/%d  elapsed %6.0fs  ETA %s%s", tty ? "\r" : "",
                     done_cells + 1, total_cells, se.name.c_str(), v.name.c_str(), run + 1, a.runs, elapsed,
                     frac > 0 ? (fmt(elapsed * (1 - frac) / frac, 0) + "s").c_str() : "?", tty ? "   " : "\n");
      };
      Cell cell =
          run_cell({scene, cam, v, width, height, a.ao, a.spp, a.runs, a.best, threads, integrator, a.max_seconds},
                   progress_line);
      cell.scene = se.name;
      cell.load_ms = load_ms;
      cells[{se.name, v.name}] = cell;
      ++done_cells;
    }
  }
  if (tty) std::fprintf(stderr, "\r%100s\r", "");

  const BenchReport report{a, width, height, integrator, threads, scenes, variants, cells};
  const std::string md = markdown_tables(report);
  std::cout << md;
  // Every output once more against every file the run read (MTL files, textures), before any
  // of them is written.
  for (const auto& [out, flag] : outputs) {
    if (!out->empty()) check_output(*out, flag);
  }
  if (!a.markdown.empty()) write_file_atomic(a.markdown, md);
  if (!a.json.empty()) write_file_atomic(a.json, json_report(report));
  if (!a.plot.empty()) write_file_atomic(a.plot, svg_chart(report));
  return 0;
}

}  // namespace tracer::cli
