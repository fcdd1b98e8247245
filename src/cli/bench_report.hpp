// The benchmark's reports: the Markdown tables (times, Mrays/s, speedups, the study's ratios,
// Embree ratios), the JSON of every cell and the SVG bar chart.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cli/bench_catalogue.hpp"
#include "cli/bench_run.hpp"

namespace tracer::cli {

using CellTable = std::map<std::pair<std::string, std::string>, Cell>;  // (scene, variant)

// A number with `prec` decimals; a duration as seconds or minutes.
std::string fmt(double v, int prec = 1);
std::string duration_text(double seconds);

struct BenchReport {
  const BenchArgs& args;
  int width, height;
  Integrator integrator;
  int threads;
  const std::vector<SceneEntry>& scenes;
  const std::vector<Variant>& variants;
  const CellTable& cells;
};

std::string markdown_tables(const BenchReport& report);
std::string json_report(const BenchReport& report);
std::string svg_chart(const BenchReport& report);

}  // namespace tracer::cli
