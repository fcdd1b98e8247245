// `tracer bench`: the study's variants and ours over a set of scenes, timed the study's way
// (k-best: mean of the best `best` of `runs` runs), with ray counts, Mrays/s and Embree ratios.
#pragma once

#include <CLI/CLI.hpp>

#include <optional>

#include <string>
#include <vector>
#include "render/render_tile.hpp"

namespace tracer::cli {

struct BenchArgs {
  std::string variants = "study";  // comma list of names, or "study", "ours", "all"
  std::string scenes = "cornell";  // comma list of view names or OBJ paths, or "cornell", "large", "all", "builtin"
  std::string views;               // empty: ../shared/scenes/views.tsv
  bool framed = false;             // also each view's scene framed from outside
  std::string size = "256x256";
  int ao = RenderSettings{}.ao_samples;
  std::string integrator{name_of<Integrator>(kIntegratorNames, Integrator::Ao)};  // the study's workload
  int spp = 16;                                                                   // path: samples per pixel
  int runs = 10, best = 3;
  std::optional<int> threads;                // empty: all hardware threads
  std::optional<std::string> build_quality;  // the quality of the variants that build at the default one
  double max_seconds = 10.0;                 // per cell, all runs together
  std::string json, plot, markdown;
  bool list = false;
};

void add_bench_options(CLI::App& app, BenchArgs& args);
int run_bench(const BenchArgs& args);

}  // namespace tracer::cli
