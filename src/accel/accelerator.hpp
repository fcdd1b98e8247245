// The interchangeable accelerators behind one interface: every alternative has
//   bool intersect(const Ray&, Hit&) const;   // closest hit in [tnear, tfar]
//   bool occluded(const Ray&) const;          // any hit in [tnear, tfar]
// Callers dispatch on the variant once (per tile or per batch), never per ray.
#pragma once

#include <concepts>
#include <memory>
#include <optional>
#include <string>
#include <variant>

#include "accel/brute_force.hpp"
#include "accel/bvh/bvh.hpp"
#include "accel/two_level/two_level_bvh.hpp"
#include "accel/wide_bvh/wide_bvh.hpp"
#ifdef TRACER_HAVE_EMBREE
#include "accel/embree_accel.hpp"
#endif

namespace tracer {

template <class A>
concept RayAccelerator = requires(const A& a, const Ray& r, Hit& h) {
  { a.intersect(r, h) } -> std::same_as<bool>;
  { a.occluded(r) } -> std::same_as<bool>;
};

// EmbreeHigh is Embree built at its HIGH quality (spatial splits): the reference at its best.
enum class AccelKind { Brute, BruteSimd, Bvh, Bvh8, Embree, EmbreeHigh };
// The names --accel takes, each the accelerator it says: "brute" the study's scalar brute force,
// "simd-brute" eight triangles per SIMD test (the study's ISPC kernel).
inline constexpr EnumName<AccelKind> kAccelKindNames[] = {
    {AccelKind::Brute, "brute"}, {AccelKind::BruteSimd, "simd-brute"}, {AccelKind::Bvh, "bvh"},
    {AccelKind::Bvh8, "bvh8"},   {AccelKind::Embree, "embree"},        {AccelKind::EmbreeHigh, "embree-high"}};
inline bool is_embree(AccelKind kind) { return kind == AccelKind::Embree || kind == AccelKind::EmbreeHigh; }

// How much a build spends for faster traversal, as Embree's RTC_BUILD_QUALITY_MEDIUM and _HIGH:
// the binned SAH, or the binned SAH with spatial splits adding at most kHighSplitBudget of the
// triangles as extra references (Embree's HIGH allows the same 20 %).
enum class BuildQuality { Medium, High };
inline constexpr EnumName<BuildQuality> kBuildQualityNames[] = {{BuildQuality::Medium, "medium"},
                                                                {BuildQuality::High, "high"}};
inline constexpr float kHighSplitBudget = 0.2f;
// Whether `kind` builds at a quality level: the 8-wide BVH and Embree.
inline bool has_build_quality(AccelKind kind) { return kind == AccelKind::Bvh8 || is_embree(kind); }

// The most a build of `kind` holds per triangle at its peak (the tree, its triangle packs and the
// builder's references), above the scene's own arrays: measured on a 4M-triangle mesh as the
// peak resident set of a render less a load's (docs/RELIABILITY.md, "Memory"), rounded up.
inline uint64_t build_bytes_per_triangle(AccelKind kind, BuildQuality quality) {
  switch (kind) {
    case AccelKind::Brute:
    case AccelKind::BruteSimd:
      return 16;
    case AccelKind::Bvh:
      return 144;
    case AccelKind::Bvh8:
      return quality == BuildQuality::High ? 104 : 96;
    case AccelKind::Embree:
      return quality == BuildQuality::High ? 128 : 120;
    case AccelKind::EmbreeHigh:
      return 128;
  }
  return 144;
}

struct AccelOptions {
  AccelKind kind = AccelKind::Bvh8;             // the fastest (docs/BENCHMARKS.md section 1)
  BuildQuality quality = BuildQuality::Medium;  // Bvh8 and Embree; EmbreeHigh is always High
  BvhBuildOptions bvh;
};

using AccelVariant = std::variant<BruteForce, SimdBruteForce, Bvh, WideBvh, TwoLevelBvh
#ifdef TRACER_HAVE_EMBREE
                                  ,
                                  EmbreeAccel
#endif
                                  >;

struct Accelerator {
  std::unique_ptr<AccelVariant> impl;  // heap: Embree's handle and the BVH must not move mid-render
  AccelKind kind = AccelKind::Bvh;
  double build_ms = 0.0;
  std::string name;

  template <class F>
  decltype(auto) visit(F&& f) const {
    return std::visit(std::forward<F>(f), *impl);
  }
  size_t memory_bytes() const;
  // The two-level tree of an instanced scene.
  bool instanced() const { return instanced_scene; }
  bool instanced_scene = false;
  // The binary BVH's shape (nodes, leaves, depth, SAH cost); empty for the other accelerators.
  std::optional<BvhStats> bvh_stats() const;
};

bool embree_available();

// Whether `kind` has kernels that trace rays together (what --packets turns on): packets of
// primary and shadow rays (bvh8, Embree) and bundles of one hit's AO rays (the binary BVH too).
inline bool traces_rays_together(AccelKind kind) {
  return kind == AccelKind::Bvh || kind == AccelKind::Bvh8 || is_embree(kind);
}

// Whether `kind` traces a sorted stream of occlusion rays at once (render/stream_order.hpp).
inline bool traces_streams(AccelKind kind) { return kind == AccelKind::Bvh8 || is_embree(kind); }

// Whether `kind` traces an instanced scene as instances (a two-level tree); a scene loaded for
// the others has its instances expanded.
inline bool traces_instances(AccelKind kind) { return kind == AccelKind::Bvh8 || is_embree(kind); }

// Builds the accelerator `options` asks for, timing the build: for an instanced scene, its
// two-level form (bvh8; the others throw UsageError naming the ones that trace instances). Throws
// UsageError if it is not compiled in (Embree).
Accelerator build_accelerator(const Scene& scene, const AccelOptions& options);

}  // namespace tracer
