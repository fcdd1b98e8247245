// The statistics of a render, for --stats (text) and --stats-json: one home for tracer's and
// tracer-mpi's.
#pragma once

#include <nlohmann/json.hpp>

#include "accel/accelerator.hpp"
#include "frontend/render_args.hpp"

namespace tracer::frontend {

nlohmann::json render_stats(const Scene& scene, const RenderSettings& settings, const Accelerator& accel,
                            const SchedOptions& sched, const RenderArgs& args, double load_ms, double render_ms,
                            const RayCounts& rays, const LoadPhases* load_phases = nullptr,
                            const QueryCounts* traversal = nullptr);

// Prints `j` (from render_stats()) as the --stats text.
void print_stats(const nlohmann::json& j, const Accelerator& accel);

// --stats-json: `j` written to `path` (atomically), to standard output for "-", nowhere for "".
void write_stats_json(const std::string& path, const nlohmann::json& j);

}  // namespace tracer::frontend
