#include "accel/accelerator.hpp"

#include <chrono>

#include "base/errors.hpp"

namespace tracer {

static_assert(RayAccelerator<BruteForce>);
static_assert(RayAccelerator<Bvh>);
static_assert(RayAccelerator<WideBvh>);
static_assert(RayAccelerator<SimdBruteForce>);
static_assert(RayAccelerator<TwoLevelBvh>);

bool embree_available() {
#ifdef TRACER_HAVE_EMBREE
  return true;
#else
  return false;
#endif
}

size_t Accelerator::memory_bytes() const {
  return visit([](const auto& a) { return a.memory_bytes(); });
}

std::optional<BvhStats> Accelerator::bvh_stats() const {
  if (const auto* bvh = std::get_if<Bvh>(impl.get())) return bvh->stats();
  return std::nullopt;
}

Accelerator build_accelerator(const Scene& scene, const AccelOptions& options) {
  Accelerator acc;
  acc.kind = options.kind;
  const auto start = std::chrono::steady_clock::now();
  acc.instanced_scene = scene.instanced();
  if (scene.instanced() && !traces_instances(options.kind)) {
    throw UsageError(std::string("--accel ") + std::string(name_of<AccelKind>(kAccelKindNames, options.kind)) + ": " +
                     scene.source +
                     " places meshes by instances, which only bvh8 and embree trace (load it for this accelerator to "
                     "expand them)");
  }
  switch (options.kind) {
    case AccelKind::Brute:
      acc.impl = std::make_unique<AccelVariant>(std::in_place_type<BruteForce>, scene);
      acc.name = "brute";
      break;
    case AccelKind::BruteSimd:
      acc.impl = std::make_unique<AccelVariant>(std::in_place_type<SimdBruteForce>, scene, options.bvh.simd);
      acc.name = "simd-brute-" + std::get<SimdBruteForce>(*acc.impl).simd().name();
      break;
    case AccelKind::Bvh:
      acc.impl = std::make_unique<AccelVariant>(std::in_place_type<Bvh>, scene, options.bvh);
      acc.name = options.bvh.split == BvhSplit::Sah ? "bvh-sah" : "bvh-median";
      break;
    case AccelKind::Bvh8: {
      BvhBuildOptions bvh = options.bvh;
      const bool high = options.quality == BuildQuality::High;
      bvh.split_budget = high ? kHighSplitBudget : 0.0f;
      std::string simd;
      if (scene.instanced()) {
        acc.impl = std::make_unique<AccelVariant>(std::in_place_type<TwoLevelBvh>, scene, bvh);
        simd = std::get<TwoLevelBvh>(*acc.impl).simd().name();
      } else {
        acc.impl = std::make_unique<AccelVariant>(std::in_place_type<WideBvh>, scene, bvh);
        simd = std::get<WideBvh>(*acc.impl).simd().name();
      }
      acc.name = "bvh8-" + simd + (high ? "-high" : "");
      break;
    }
    case AccelKind::Embree:
    case AccelKind::EmbreeHigh: {
      const bool high = options.kind == AccelKind::EmbreeHigh || options.quality == BuildQuality::High;
#ifdef TRACER_HAVE_EMBREE
      acc.impl = std::make_unique<AccelVariant>(std::in_place_type<EmbreeAccel>, scene, options.bvh.cancel, nullptr,
                                                high ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM);
      acc.name = high ? "embree-high" : "embree";
      break;
#else
      throw UsageError(std::string("--accel ") + (high ? "embree-high" : "embree") +
                       ": this build has no Embree (configure with -DTRACER_EMBREE=ON)");
#endif
    }
  }
  if (acc.instanced_scene) acc.name += "-two-level";  // bvh8's TwoLevelBvh, Embree's instance geometry
  acc.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return acc;
}

}  // namespace tracer
