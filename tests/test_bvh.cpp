// BVH correctness: every split x builder gives brute force's closest hit and occlusion answer on
// random rays and on every ray of a small render, for every scene; trees pass the validator;
// parallel builders build the sequential tree; degenerate inputs neither crash nor mislead.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <cstring>
#include <mutex>

#include "accel/accelerator.hpp"
#ifdef TRACER_HAVE_EMBREE
#include "accel/embree_accel.hpp"
#include "base/huge_pages.hpp"
#endif
#include "importers/obj_loader.hpp"
#include "render/render_tile.hpp"
#include "scene/builtin.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

// Wraps an accelerator and records every ray the renderer asks of it.
template <class Inner>
struct RecordingAccel {
  const Inner* inner;
  mutable std::vector<Ray> closest, any;
  bool intersect(const Ray& r, Hit& h) const {
    closest.push_back(r);
    return inner->intersect(r, h);
  }
  bool occluded(const Ray& r) const {
    any.push_back(r);
    return inner->occluded(r);
  }
};

struct RaySet {
  std::vector<Ray> closest, any;
};

// Random rays (both queries) plus the primary, shadow and AO rays of a small render.
RaySet rays_for(const Scene& scene, size_t random_count, int image) {
  RaySet set;
  set.closest = test::random_rays(scene, random_count, 1234);
  set.any = set.closest;
  // Occlusion with finite tfar too, as shadow rays have.
  for (size_t i = 0; i < set.any.size(); i += 2) set.any[i].tfar = length(scene.bounds.extent()) * 0.3f;
  const BruteForce brute(scene);
  RecordingAccel<BruteForce> rec{&brute, {}, {}};
  RenderSettings s;
  s.width = s.height = image;
  s.ao_samples = 2;
  Framebuffer fb(image, image);
  const CameraSpec cam = scene.camera ? *scene.camera
                                      : CameraSpec{scene.bounds.center() + Vec3{0, 0, length(scene.bounds.extent())},
                                                   scene.bounds.center(),
                                                   {0, 1, 0},
                                                   50.0f};
  PassContext ctx{&scene, Camera(cam, image, image), s, &fb};
  render_tile(rec, ctx, Tile{0, 0, image, image});
  set.closest.insert(set.closest.end(), rec.closest.begin(), rec.closest.end());
  set.any.insert(set.any.end(), rec.any.begin(), rec.any.end());
  return set;
}

struct Reference {
  std::vector<Hit> hits;
  std::vector<uint8_t> occluded;
  std::vector<uint8_t> occluded_from;  // the binary BVH's bottom-up query, from scattered origins
};

template <class A>
Reference answers(const A& accel, const RaySet& rays) {
  Reference ref;
  ref.hits.resize(rays.closest.size());
  ref.occluded.resize(rays.any.size());
  tbb::parallel_for(size_t(0), rays.closest.size(), [&](size_t i) { accel.intersect(rays.closest[i], ref.hits[i]); });
  tbb::parallel_for(size_t(0), rays.any.size(),
                    [&](size_t i) { ref.occluded[i] = accel.occluded(rays.any[i]) ? 1 : 0; });
  if constexpr (requires { accel.occluded_from(Ray{}, 0u); }) {
    // Its answer must not depend on the origin triangle: any triangle, a degenerate one, or an
    // index past the end (which falls back to the root) must all agree with occluded().
    const auto tris = uint32_t(accel.scene().size());
    ref.occluded_from.resize(rays.any.size());
    tbb::parallel_for(size_t(0), rays.any.size(), [&](size_t i) {
      const auto origin = uint32_t((uint64_t(i) * 2654435761u) % (uint64_t(tris) + 1));
      ref.occluded_from[i] = accel.occluded_from(rays.any[i], origin) ? 1 : 0;
    });
  }
  return ref;
}

// Returns the number of disagreements (and reports the first few).
size_t compare(const Reference& expected, const Reference& got, const std::string& what) {
  size_t bad = 0;
  for (size_t i = 0; i < expected.hits.size(); ++i) {
    const Hit& e = expected.hits[i];
    const Hit& g = got.hits[i];
    const bool same = e.valid() == g.valid() && (!e.valid() || (e.primID == g.primID && e.geomID == g.geomID &&
                                                                std::fabs(e.t - g.t) <= 1e-5f * std::max(1.0f, e.t)));
    if (!same && bad++ < 3) {
      ADD_FAILURE() << what << ": ray " << i << " expected tri " << e.tri << " t " << e.t << ", got tri " << g.tri
                    << " t " << g.t;
    }
  }
  for (size_t i = 0; i < expected.occluded.size(); ++i) {
    if (expected.occluded[i] != got.occluded[i] && bad++ < 3)
      ADD_FAILURE() << what << ": occluded ray " << i << " differs";
  }
  for (size_t i = 0; i < got.occluded_from.size(); ++i) {
    if (expected.occluded[i] != got.occluded_from[i] && bad++ < 3)
      ADD_FAILURE() << what << ": occluded_from ray " << i << " differs";
  }
  return bad;
}

// A small render of `scene` through `accel` (one tile, so no scheduler is involved).
template <class A>
Image8 render_small(const A& accel, const Scene& scene, int size) {
  RenderSettings s;
  s.width = s.height = size;
  const CameraSpec cam{{0, 1, 3}, {0, 1, 0}, {0, 1, 0}, 53.13f};
  Framebuffer fb(size, size);
  PassContext ctx{&scene, Camera(cam, size, size), s, &fb};
  render_tile(accel, ctx, Tile{0, 0, size, size});
  return tonemap(fb, s.exposure);
}

std::vector<BvhBuildOptions> all_builds() {
  std::vector<BvhBuildOptions> v;
  for (BvhSplit split : {BvhSplit::Sah, BvhSplit::Median}) {
    for (Strategy mode : {Strategy::Seq, Strategy::Async, Strategy::Queue, Strategy::Tbb}) {
      BvhBuildOptions o;
      o.split = split;
      o.strategy = mode;
      o.threads = 3;  // odd on purpose: more workers than this machine's cores
      v.push_back(o);
    }
  }
  return v;
}

std::string describe(const BvhBuildOptions& o) {
  return std::string(o.split == BvhSplit::Sah ? "sah/" : "median/") +
         std::string(name_of<Strategy>(kStrategyNames, o.strategy));
}

void check_scene_against_brute(const Scene& scene, size_t random_count, int image) {
  const RaySet rays = rays_for(scene, random_count, image);
  const Reference expected = answers(BruteForce(scene), rays);
  for (const BvhBuildOptions& o : all_builds()) {
    const Bvh bvh(scene, o);
    EXPECT_EQ(bvh.validate(), "") << describe(o);
    EXPECT_EQ(compare(expected, answers(bvh, rays), describe(o)), 0u) << describe(o);
  }
}

TEST(BvhAgreement, CornellScenesMatchBruteForce) {
  if (!test::have_shared_scenes()) GTEST_SKIP();
  // Every Cornell file in ../shared/scenes/cornell-box (the water surface alone too).
  for (const char* name : {"CornellBox-Original", "CornellBox-Mirror", "CornellBox-Sphere", "CornellBox-Water",
                           "CornellBox-Glossy", "CornellBox-Glossy-Floor", "CornellBox-Empty-CO", "CornellBox-Empty-RG",
                           "CornellBox-Empty-Squashed", "CornellBox-Empty-White", "water"}) {
    SCOPED_TRACE(name);
    const Scene scene =
        load_obj(test::scene_path(std::string("cornell-box/") + name + ".obj"), [](const std::string&) {});
    check_scene_against_brute(scene, test::ray_budget(100'000), 32);
  }
}

TEST(BvhAgreement, BuiltinSceneMatchesBruteForce) {
  check_scene_against_brute(make_cornell_box(3000), test::ray_budget(100'000), 32);
}

TEST(BvhAgreement, LargeScenesMatchBruteForce) {
  if (!test::have_shared_scenes()) GTEST_SKIP();
  // Brute force is the bottleneck here (10,000 rays x 144k triangles): a tenth of the ray budget.
  for (const char* path : {"sponza/sponza.obj", "sibenik/sibenik.obj", "bunny/bunny.obj"}) {
    SCOPED_TRACE(path);
    const Scene scene = load_obj(test::scene_path(path), [](const std::string&) {});
    check_scene_against_brute(scene, test::ray_budget(100'000) / 10, 16);
  }
}

TEST(BvhAgreement, RenderedImagesMatchBruteForce) {
  if (!test::have_shared_scenes()) GTEST_SKIP();
  for (const char* name : {"Original", "Sphere", "Water"}) {
    const Scene scene =
        load_obj(test::scene_path(std::string("cornell-box/CornellBox-") + name + ".obj"), [](const std::string&) {});
    const auto reference = render_small(BruteForce(scene), scene, 40).rgb;
    for (const BvhBuildOptions& o : all_builds())
      EXPECT_EQ(render_small(Bvh(scene, o), scene, 40).rgb, reference) << name << " " << describe(o);
  }
}

void expect_parallel_builds_match(const Scene& scene) {
  for (BvhSplit split : {BvhSplit::Sah, BvhSplit::Median}) {
    BvhBuildOptions seq;
    seq.split = split;
    const Bvh reference(scene, seq);
    ASSERT_EQ(reference.validate(), "");
    for (Strategy mode : {Strategy::Async, Strategy::Queue, Strategy::Tbb}) {
      for (int threads : {1, 2, 3, 8}) {
        BvhBuildOptions o = seq;
        o.strategy = mode;
        o.threads = threads;
        const Bvh bvh(scene, o);
        SCOPED_TRACE(describe(o) + " threads " + std::to_string(threads));
        ASSERT_EQ(bvh.nodes().size(), reference.nodes().size());
        EXPECT_EQ(std::memcmp(bvh.nodes().data(), reference.nodes().data(), bvh.nodes().size() * sizeof(BvhNode)), 0);
        EXPECT_EQ(bvh.triangle_ids(), reference.triangle_ids());
      }
    }
  }
}

TEST(BuildDeterminism, ParallelBuildersMatchSequentialTree) {
  expect_parallel_builds_match(make_cornell_box(100'000));  // past PrimSplitter::kParallelSplit at the top
}

TEST(BuildDeterminism, ParallelBuildersMatchOnSphereScene) {
  if (!test::have_shared_scenes()) GTEST_SKIP();
  expect_parallel_builds_match(
      load_obj(test::scene_path("cornell-box/CornellBox-Sphere.obj"), [](const std::string&) {}));
}

TEST(BvhQuality, SahBeatsMedianAndStaysSmall) {
  const Scene scene = make_cornell_box(20'000);
  BvhBuildOptions sah, median;
  median.split = BvhSplit::Median;
  const Bvh a(scene, sah), b(scene, median);
  EXPECT_LT(a.stats().sah_cost, b.stats().sah_cost);
  EXPECT_LT(double(a.memory_bytes()) / double(scene.size()), 100.0);
  EXPECT_LE(a.stats().max_leaf_size, 4u);
  EXPECT_LE(b.stats().max_leaf_size, 2u);
}

TEST(BvhDegenerate, AwkwardInputs) {
  std::vector<std::pair<std::string, std::vector<Triangle>>> inputs;
  const Triangle t{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  inputs.push_back({"none", {}});
  inputs.push_back({"one", {t}});
  inputs.push_back({"two", {t, Triangle{{0, 0, 1}, {1, 0, 1}, {0, 1, 1}}}});
  inputs.push_back({"identical", std::vector<Triangle>(100, t)});
  std::vector<Triangle> coplanar, same_centroid, huge, zero_area;
  for (int i = 0; i < 200; ++i) {
    const float f = float(i);
    coplanar.push_back({{f, 0, 0}, {f + 1, 0, 0}, {f, 1 + f, 0}});
    // Rotated copies around one centre: all centroids equal, boxes differ.
    const float a = f * 0.1f;
    const Vec3 u{std::cos(a), std::sin(a), 0}, v{-std::sin(a), std::cos(a), 0.5f};
    same_centroid.push_back({u * 2.0f, v * 2.0f, -(u + v) * 2.0f});
    const float s = std::pow(10.0f, float(i % 30) - 15.0f);  // 1e-15 .. 1e14
    huge.push_back({{s, 0, 0}, {s * 2, 0, s}, {s, s, 0}});
    zero_area.push_back(i % 2 ? Triangle{{f, 0, 0}, {f + 1, 1, 1}, {f + 2, 2, 2}}
                              : Triangle{{f, 0, 0}, {f + 1, 0, 0}, {f, 1, 0}});
  }
  inputs.push_back({"coplanar", coplanar});
  inputs.push_back({"same_centroid", same_centroid});
  inputs.push_back({"huge_range", huge});
  inputs.push_back({"zero_area", zero_area});
  for (const auto& [name, tris] : inputs) {
    SCOPED_TRACE(name);
    const Scene scene = test::scene_of(tris);
    RaySet rays;
    rays.closest = tris.empty() ? std::vector<Ray>(10) : test::random_rays(scene, 5000, 3);
    for (Ray& r : rays.closest)
      if (r.dir == Vec3{}) r.dir = {0, 0, 1};
    // Rays straight down onto the triangles as well, so there are hits to agree on.
    for (size_t i = 0; i < tris.size(); ++i) {
      Ray r;
      r.org = tris[i].centroid() + Vec3{0, 0, 3};
      r.dir = {0, 0, -1};
      rays.closest.push_back(r);
    }
    rays.any = rays.closest;
    const Reference expected = answers(BruteForce(scene), rays);
    for (const BvhBuildOptions& o : all_builds()) {
      const Bvh bvh(scene, o);
      EXPECT_EQ(bvh.validate(), "") << describe(o);
      EXPECT_EQ(compare(expected, answers(bvh, rays), name + " " + describe(o)), 0u);
    }
  }
}

TEST(BvhAgreement, EmbreeAgreesOnCornellScenes) {
  if (!embree_available() || !test::have_shared_scenes()) GTEST_SKIP() << "no Embree in this build";
  for (const char* name : {"Original", "Sphere", "Water"}) {
    SCOPED_TRACE(name);
    const Scene scene =
        load_obj(test::scene_path(std::string("cornell-box/CornellBox-") + name + ".obj"), [](const std::string&) {});
    const RaySet rays = rays_for(scene, test::ray_budget(100'000) / 4, 24);
    const Accelerator embree = build_accelerator(scene, AccelOptions{.kind = AccelKind::Embree});
    const Reference ours = answers(Bvh(scene, BvhBuildOptions{}), rays);
    const Reference theirs = embree.visit([&](const auto& a) { return answers(a, rays); });
    // Embree's test is not watertight and breaks ties differently: allow disagreement only
    // where two triangles are hit at the same distance or the ray grazes an edge.
    size_t differ = 0;
    for (size_t i = 0; i < ours.hits.size(); ++i) {
      const Hit& a = ours.hits[i];
      const Hit& b = theirs.hits[i];
      if (a.valid() != b.valid() || (a.valid() && a.primID != b.primID && std::fabs(a.t - b.t) > 1e-4f * a.t)) ++differ;
    }
    EXPECT_LE(differ, ours.hits.size() / 10000 + 1) << "of " << ours.hits.size();
    // And the rendered images match (same rays, same shading): PSNR >= 40 dB.
    const Image8 a = render_small(Bvh(scene, BvhBuildOptions{}), scene, 64);
    const Image8 b = embree.visit([&](const auto& acc) { return render_small(acc, scene, 64); });
    // Embree's triangle test is not watertight: a camera ray exactly on a shared edge can slip
    // through (a black pixel) where ours hits. Allow that on at most 1% of pixels, nothing more.
    size_t differing = 0;
    for (size_t i = 0; i < a.rgb.size(); i += 3) {
      int d = 0;
      for (int k = 0; k < 3; ++k) d = std::max(d, std::abs(int(a.rgb[i + k]) - int(b.rgb[i + k])));
      differing += d > 2 ? 1 : 0;
    }
    EXPECT_LE(differing, a.rgb.size() / 3 / 100) << "pixels differing, PSNR " << test::psnr(a, b);
  }
}

TEST(BvhBuild, CancelFlagStopsEveryBuilderAndEmbree) {
  // A set flag makes each builder stop splitting and the constructor throw, whatever the mode.
  const Scene scene = make_cornell_box(20000);
  std::atomic<bool> cancel{true};
  for (const Strategy mode : {Strategy::Seq, Strategy::Async, Strategy::Queue, Strategy::Tbb}) {
    for (const AccelKind kind : {AccelKind::Bvh, AccelKind::Bvh8}) {
      AccelOptions o;
      o.kind = kind;
      o.bvh.strategy = mode;
      o.bvh.cancel = &cancel;
      EXPECT_THROW(build_accelerator(scene, o), Cancelled);
    }
  }
  if (embree_available()) {
    AccelOptions o;
    o.kind = AccelKind::Embree;
    o.bvh.cancel = &cancel;
    EXPECT_THROW(build_accelerator(scene, o), Cancelled);
  }
  cancel = false;  // and an unset flag changes nothing
  AccelOptions o{.kind = AccelKind::Bvh};
  o.bvh.cancel = &cancel;
  EXPECT_EQ(std::get<Bvh>(*build_accelerator(scene, o).impl).validate(), "");
}

#ifdef TRACER_HAVE_EMBREE
TEST(BvhAgreement, EmbreePacketsWithUnusedLanesOnItsAvx2Kernels) {
  // Without AVX-512 Embree has no 16-wide kernels: rtcOccluded16 and rtcIntersect16 then trace all
  // sixteen lanes, whatever the valid mask says. Packets with a few lanes, through its AVX2 code,
  // must give each ray its single-ray answer (and not stop on Embree's assertion of a bad lane).
  const Scene scene = make_cornell_box();
  const EmbreeAccel embree(scene, nullptr, "isa=avx2");
  const Vec3 org = scene.bounds.center();
  for (const uint32_t active : {0x1u, 0x8421u, 0x7ffeu, 0xffffu}) {
    SCOPED_TRACE(active);
    RayBundle bundle;
    RayPacket packet;
    for (int k = 0; k < kPacketSize; ++k) {
      if (!((active >> k) & 1u)) continue;
      const float a = 0.39f * float(k);
      const Vec3 dir = normalize(Vec3{std::cos(a), 0.3f * float(k % 5) - 0.6f, std::sin(a)});
      bundle.set_direction(k, dir);
      Ray r;
      r.org = org;
      r.dir = dir;
      packet.set(k, r);
    }
    bundle.org = org;
    bundle.tfar = 0.3f;  // some lanes reach a wall, some do not
    uint32_t expected_bundle = 0, expected_packet = 0;
    for (int k = 0; k < kPacketSize; ++k) {
      if (!((active >> k) & 1u)) continue;
      if (embree.occluded(bundle.ray(k))) expected_bundle |= 1u << k;
      if (embree.occluded(packet.ray(k))) expected_packet |= 1u << k;
    }
    EXPECT_EQ(embree.occluded_bundle_from(bundle, 0), expected_bundle);
    EXPECT_EQ(embree.occluded_packet(packet), expected_packet);
    Hit hits[kPacketSize];
    embree.intersect_packet(packet, hits);
    for (int k = 0; k < kPacketSize; ++k) {
      if (!((active >> k) & 1u)) continue;
      Hit single;
      EXPECT_EQ(embree.intersect(packet.ray(k), single), hits[k].valid()) << k;
      EXPECT_EQ(hits[k].primID, single.primID) << k;
      EXPECT_EQ(hits[k].t, single.t) << k;
    }
  }
}
#endif

}  // namespace
}  // namespace tracer

namespace tracer {
namespace {

// Arrays for the trees: small ones from the heap, 64-byte aligned; large ones their own 2 MiB
// aligned mapping (huge pages where the kernel gives them); growing keeps the contents.
TEST(LargeArrays, AlignedWritableAndGrowable) {
  for (const size_t bytes : {size_t(0), size_t(100), kHugeArrayMinBytes - 1, kHugeArrayMinBytes, size_t(9) << 20}) {
    SCOPED_TRACE(bytes);
    LargeBuffer<unsigned char> b(bytes);
    const auto at = reinterpret_cast<uintptr_t>(b.get());
    EXPECT_EQ(at % 64, 0u);
    if (bytes >= kHugeArrayMinBytes) {
      EXPECT_EQ(at % kHugePageBytes, 0u);
    }
    for (size_t i = 0; i < bytes; ++i) b[i] = static_cast<unsigned char>(i * 7);
    size_t wrong = 0;
    for (size_t i = 0; i < bytes; ++i) wrong += b[i] != static_cast<unsigned char>(i * 7) ? 1 : 0;
    EXPECT_EQ(wrong, 0u);
  }
  // Zero-filled buffers read as zero even where the memory was used and freed before (small ones
  // come from the heap, large ones from a fresh mapping), and are as aligned.
  for (int round = 0; round < 2; ++round) {
    for (const size_t bytes : {size_t(100), kHugeArrayMinBytes - 1, kHugeArrayMinBytes, size_t(9) << 20}) {
      SCOPED_TRACE(bytes);
      LargeBuffer<unsigned char> z(bytes, kZeroFilled);
      const auto at = reinterpret_cast<uintptr_t>(z.get());
      EXPECT_EQ(at % (bytes >= kHugeArrayMinBytes ? kHugePageBytes : 64), 0u);
      size_t nonzero = 0;
      for (size_t i = 0; i < bytes; ++i) nonzero += z[i] != 0 ? 1 : 0;
      EXPECT_EQ(nonzero, 0u);
      for (size_t i = 0; i < bytes; ++i) z[i] = 0xab;  // dirty, for the next round to reuse
    }
  }
  std::vector<uint32_t, LargeArrayAllocator<uint32_t>> v;
  for (uint32_t i = 0; i < 3'000'000; ++i) v.push_back(i);  // crosses into mappings and grows within them
  size_t wrong = 0;
  for (uint32_t i = 0; i < v.size(); ++i) wrong += v[i] != i ? 1 : 0;
  EXPECT_EQ(wrong, 0u);
}

}  // namespace
}  // namespace tracer
