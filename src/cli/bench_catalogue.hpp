// The benchmark's catalogue: the study's variants and ours (accelerator, split, builder,
// scheduler), the study's published figures, and the scenes a --scenes list names.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "accel/accelerator.hpp"
#include "cli/bench.hpp"
#include "parallel/parallel_for_tiles.hpp"
#include "scene/views.hpp"

namespace tracer::cli {

struct Variant {
  std::string name;
  AccelKind accel;
  BvhSplit split;
  Strategy build;
  Strategy sched;
  std::string description;
  bool study;
  bool packets = false;                         // primary rays in 4x4 packets (bvh8), AO rays in bundles (bvh, bvh8)
  BuildQuality quality = BuildQuality::Medium;  // bvh8 (Embree's is in its AccelKind)
  bool streams = false;                         // with packets: AO rays in sorted streams per 16x16 pixels
};

// The study's ten columns (its ISPC column is simd-brute, our Highway kernels) and ours.
const std::vector<Variant>& all_variants();

// The study's published milliseconds (4-core i7-7700HQ), for ratio comparison.
const std::map<std::string, std::map<std::string, double>>& study_ms();

// One row of the tables: a view (camera and light from the views file), a scene framed from
// outside its bounds (an OBJ path, or --framed), or the built-in box with its own camera.
struct SceneEntry {
  std::string name, path;    // path empty: the built-in box
  std::optional<View> view;  // the camera and light, when the row is a view
  uint32_t placements = 0;   // > 0: the scene kept once and placed this many times (instanced)
};

// Meshes placed by `--scenes instanced`: the Bunny's 144,046 triangles 100 times (14.4M).
inline constexpr uint32_t kInstancedPlacements = 100;

// The scenes of a --scenes list (view names, OBJ paths, "cornell", "large", "all", "builtin",
// "instanced": the bunny view's scene placed kInstancedPlacements times, framed from outside).
std::vector<SceneEntry> resolve_scenes(const BenchArgs& args);
// The variants of a --variants list (names, "study", "ours", "all").
std::vector<Variant> resolve_variants(const std::string& spec);

}  // namespace tracer::cli
