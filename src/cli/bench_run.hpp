// Running the benchmark: each cell (a scene and a variant) built and rendered up to --runs
// times under the cell's time cap (a watchdog stops a run still going at the cap), timed the
// study's way: the mean of the best --best runs.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "cli/bench_catalogue.hpp"
#include "render/render_settings.hpp"
#include "scene/scene.hpp"

namespace tracer::cli {

struct Cell {
  std::string scene, variant;
  bool timed_out = false;
  bool not_traced = false;  // an instanced scene, and a variant that traces no instances: not run
  double load_ms = 0, build_ms = 0, render_ms = 0, total_ms = 0;  // k-best means
  uint64_t rays = 0;
  double mrays = 0;
  size_t triangles = 0;
  std::vector<double> run_ms;
  bool capped(int runs) const { return !timed_out && !not_traced && int(run_ms.size()) < runs; }
};

// The mean of the `best` smallest values.
double kbest_mean(std::vector<double> v, int best);

struct CellJob {
  const Scene& scene;
  CameraSpec camera;
  const Variant& variant;
  int width, height, ao, spp, runs, best, threads;
  Integrator integrator;
  double max_seconds;  // for all the cell's runs together
};

// Builds and renders one cell up to job.runs times; on_run(run) is called before each run.
Cell run_cell(const CellJob& job, const std::function<void(int)>& on_run);

}  // namespace tracer::cli
