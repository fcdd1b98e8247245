// Schedulers: byte-identical images across every scheduler, thread count and tile size, and every
// tile rendered exactly once. Runs under TSan in CI (names start with Sched).
#include <gtest/gtest.h>

#include <map>
#include <mutex>

#include "accel/accelerator.hpp"
#include "importers/obj_loader.hpp"
#include "render/render_image.hpp"
#include "render/render_tile.hpp"
#include "scene/builtin.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

struct Rendered {
  std::vector<uint8_t> rgb;
  std::map<std::tuple<int, int, int, int>, int> visits;
  RayCounts counts;
};

Rendered render_with(const Scene& scene, const Accelerator& acc, const SchedOptions& so, int size, bool packets = false,
                     bool streams = false) {
  RenderSettings s;
  s.packets = packets;
  s.streams = streams;
  s.width = size;
  s.height = size * 3 / 4 + 1;  // not a multiple of any tile size
  s.ao_samples = 4;
  Framebuffer fb(s.width, s.height);
  const CameraSpec cam = scene.camera ? *scene.camera : CameraSpec{{0, 1, 3}, {0, 1, 0}, {0, 1, 0}, 53.13f};
  PassContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
  RenderMonitor control;
  Rendered out;
  std::mutex m;
  control.on_tile = [&](const Tile& t) {
    std::lock_guard lock(m);
    ++out.visits[{t.x0, t.y0, t.x1, t.y1}];
  };
  EXPECT_TRUE(render_image(acc, ctx, so, control));
  out.rgb = tonemap(fb, s.exposure).rgb;
  out.counts = control.counts.load();
  // Every pixel covered by exactly one visited tile, each tile visited once.
  std::vector<int> cover(size_t(s.width) * size_t(s.height), 0);
  for (const auto& [t, n] : out.visits) {
    EXPECT_EQ(n, 1) << "tile visited " << n << " times";
    for (int y = std::get<1>(t); y < std::get<3>(t); ++y)
      for (int x = std::get<0>(t); x < std::get<2>(t); ++x) ++cover[size_t(y) * size_t(s.width) + size_t(x)];
  }
  EXPECT_EQ(std::count(cover.begin(), cover.end(), 1), std::ptrdiff_t(cover.size()));
  return out;
}

std::vector<Scene> scenes() {
  std::vector<Scene> v;
  v.push_back(make_cornell_box(500));
  if (test::have_shared_scenes()) {
    for (const char* name : {"Original", "Mirror", "Sphere", "Water"}) {
      v.push_back(load_obj(test::scene_path(std::string("cornell-box/CornellBox-") + name + ".obj"),
                           [](const std::string&) {}));
    }
  }
  return v;
}

TEST(Sched, ImagesIdenticalAcrossSchedulersThreadsAndTiles) {
  const int size = int(test::ray_budget(100'000) >= 100'000 ? 48 : 24);
  for (const Scene& scene : scenes()) {
    SCOPED_TRACE(scene.source);
    const Accelerator acc = build_accelerator(scene, AccelOptions{.kind = AccelKind::Bvh});
    SchedOptions seq;
    seq.strategy = Strategy::Seq;
    const Rendered reference = render_with(scene, acc, seq, size);
    EXPECT_EQ(reference.counts.primary, uint64_t(size) * uint64_t(size * 3 / 4 + 1));
    for (Strategy kind : {Strategy::Async, Strategy::Queue, Strategy::Atomic, Strategy::Tbb}) {
      for (int threads : {1, 2, 3, 8}) {
        for (int tile : {7, 16}) {
          SchedOptions so;
          so.strategy = kind;
          so.threads = threads;
          so.tile = tile;
          so.block = tile * 4;
          SCOPED_TRACE(std::string(name_of<Strategy>(kStrategyNames, kind)) + " threads " + std::to_string(threads) +
                       " tile " + std::to_string(tile));
          const Rendered r = render_with(scene, acc, so, size);
          EXPECT_EQ(r.rgb, reference.rgb);
          EXPECT_EQ(r.counts.total(), reference.counts.total());
          if (kind == Strategy::Async) break;  // rows: the tile size does not apply
        }
      }
    }
  }
}

TEST(Sched, PacketsAndTheWideBvhGiveTheSameImageOnEveryScheduler) {
  // The 8-wide BVH with and without packets (primary rays in 4x4 packets, AO rays in bundles or
  // in sorted streams per 16x16 chunk), and the binary BVH with AO bundles, against the scalar
  // BVH's image; tile sizes not a multiple of the 4x4 packet leave partial packets at every
  // tile's edge, and tiles of 7 and 37 pixels partial stream chunks.
  const int size = int(test::ray_budget(100'000) >= 100'000 ? 48 : 24);
  for (const Scene& scene : scenes()) {
    SCOPED_TRACE(scene.source);
    SchedOptions seq;
    seq.strategy = Strategy::Seq;
    const Rendered reference =
        render_with(scene, build_accelerator(scene, AccelOptions{.kind = AccelKind::Bvh}), seq, size);
    const Accelerator wide = build_accelerator(scene, AccelOptions{.kind = AccelKind::Bvh8});
    const Accelerator binary = build_accelerator(scene, AccelOptions{.kind = AccelKind::Bvh});
    for (Strategy kind : {Strategy::Seq, Strategy::Async, Strategy::Queue, Strategy::Atomic, Strategy::Tbb}) {
      for (const int variant : {0, 1, 2, 3, 4}) {
        const bool packets = variant > 0, streams = variant >= 3;
        SchedOptions so;
        so.strategy = kind;
        so.threads = variant == 4 ? 1 : 2;
        so.tile = variant == 4 ? 37 : 7;
        so.block = 30;
        static const char* names[] = {" bvh8 single rays", " bvh8 packets", " bvh bundles", " bvh8 streams",
                                      " bvh8 streams, 1 thread, tile 37"};
        SCOPED_TRACE(std::string(name_of<Strategy>(kStrategyNames, kind)) + names[variant]);
        const Rendered r = render_with(scene, variant == 2 ? binary : wide, so, size, packets, streams);
        EXPECT_EQ(r.rgb, reference.rgb);
        EXPECT_EQ(r.counts.total(), reference.counts.total());
      }
    }
  }
}

// A path-traced image's raw sums (not only its 8-bit rendering), rendered in the passes of
// sample_passes().
std::vector<float> path_sums(const Scene& scene, const Accelerator& acc, const SchedOptions& so, int size) {
  RenderSettings s;
  s.width = size;
  s.height = size * 3 / 4 + 1;
  s.integrator = Integrator::Path;
  s.spp = 6;  // passes of 1, 1, 2, 2
  Framebuffer fb(s.width, s.height);
  const CameraSpec cam = scene.camera ? *scene.camera : CameraSpec{{0, 1, 3}, {0, 1, 0}, {0, 1, 0}, 53.13f};
  PassContext ctx{&scene, Camera(cam, s.width, s.height), s, &fb};
  RenderMonitor control;
  EXPECT_TRUE(render_round(acc, ctx, sample_passes(s), so, control));
  EXPECT_EQ(fb.min_samples(), uint32_t(s.spp));
  std::vector<float> sums;
  for (size_t i = 0; i < fb.pixel_count(); ++i) {
    for (int c = 0; c < 3; ++c) sums.push_back(fb.sums()[i][c]);
  }
  return sums;
}

TEST(Sched, PathImagesIdenticalAcrossSchedulersThreadsTilesAndAccelerators) {
  // The random numbers are a function of (pixel, sample, bounce), each pass adds each pixel's
  // sum of its samples, and passes are added in order: every float of the sums is the same
  // however the work was cut.
  const int size = int(test::ray_budget(100'000) >= 100'000 ? 24 : 12);
  for (const Scene& scene : scenes()) {
    SCOPED_TRACE(scene.source);
    const Accelerator bvh = build_accelerator(scene, AccelOptions{.kind = AccelKind::Bvh});
    SchedOptions seq;
    seq.strategy = Strategy::Seq;
    const std::vector<float> reference = path_sums(scene, bvh, seq, size);
    for (Strategy kind : {Strategy::Async, Strategy::Queue, Strategy::Atomic, Strategy::Tbb}) {
      SchedOptions so;
      so.strategy = kind;
      so.threads = 3;
      so.tile = 5;
      so.block = 17;
      EXPECT_EQ(path_sums(scene, bvh, so, size), reference) << name_of<Strategy>(kStrategyNames, kind);
    }
    for (AccelKind kind : {AccelKind::Bvh8, AccelKind::BruteSimd}) {
      SchedOptions so;
      so.strategy = Strategy::Tbb;
      so.threads = 2;
      EXPECT_EQ(path_sums(scene, build_accelerator(scene, AccelOptions{.kind = kind}), so, size), reference)
          << name_of<AccelKind>(kAccelKindNames, kind);
    }
  }
}

TEST(Sched, CancelStopsEarlyAndLeavesRestUntouched) {
  const Scene scene = make_cornell_box(0);
  const Accelerator acc = build_accelerator(scene, AccelOptions{.kind = AccelKind::Bvh});
  for (Strategy kind : {Strategy::Seq, Strategy::Async, Strategy::Queue, Strategy::Atomic, Strategy::Tbb}) {
    SCOPED_TRACE(std::string(name_of<Strategy>(kStrategyNames, kind)));
    RenderSettings s;
    s.width = s.height = 64;
    s.ao_samples = 1;
    Framebuffer fb(s.width, s.height);
    PassContext ctx{&scene, Camera(*scene.camera, s.width, s.height), s, &fb};
    std::atomic<bool> cancel{false};
    RenderMonitor control;
    control.cancel = &cancel;
    std::atomic<int> tiles{0};
    control.on_tile = [&](const Tile&) {
      if (++tiles == 3) cancel = true;
    };
    SchedOptions so;
    so.strategy = kind;
    so.threads = 2;
    EXPECT_FALSE(render_image(acc, ctx, so, control));
    EXPECT_LT(control.pixels_done.load(), uint64_t(s.width) * uint64_t(s.height));
  }
}

TEST(Sched, EmbreePacketsTraceTheSameRaysAsEmbreeSingleRays) {
  // Embree's packet API (rtcIntersect16 per 4x4 block, rtcOccluded16 for its shadow rays and each
  // hit's AO rays, or its stream API for the AO rays) against its single-ray API: the same rays, counted alike.
  // Embree's packet and single-ray kernels are not bit-exact with each other (one byte of 48x37x3 differs on Sphere),
  // so the images must agree to within 50 dB rather than byte for byte.
  if (!embree_available()) GTEST_SKIP() << "no Embree in this build";
  const int size = int(test::ray_budget(100'000) >= 100'000 ? 48 : 24);
  for (const Scene& scene : scenes()) {
    SCOPED_TRACE(scene.source);
    const Accelerator embree = build_accelerator(scene, AccelOptions{.kind = AccelKind::Embree});
    SchedOptions so;
    so.threads = 2;
    so.tile = 7;
    const Rendered single = render_with(scene, embree, so, size);
    for (const bool streams : {false, true}) {  // AO rays by rtcOccluded16 per hit, or rtcOccluded1M
      SCOPED_TRACE(streams ? "streams" : "packets");
      const Rendered packets = render_with(scene, embree, so, size, true, streams);
      EXPECT_EQ(packets.counts.primary, single.counts.primary);
      EXPECT_EQ(packets.counts.shadow, single.counts.shadow);
      EXPECT_EQ(packets.counts.ao, single.counts.ao);
      Image8 a{size, size * 3 / 4 + 1, single.rgb}, b{size, size * 3 / 4 + 1, packets.rgb};
      EXPECT_GE(test::psnr(a, b), 50.0);
    }
  }
}

TEST(ParallelForTiles, EveryPixelExactlyOnceWithEveryStrategy) {
  // The loop knows nothing of rendering: count how often each pixel's tile is handed out.
  constexpr int kW = 97, kH = 61;  // not multiples of any tile or block size
  for (const EnumName<Strategy>& e : kStrategyNames) {
    for (const int threads : {1, 3}) {
      SCOPED_TRACE(std::string(e.name) + " threads " + std::to_string(threads));
      SchedOptions so;
      so.strategy = e.value;
      so.threads = threads;
      so.tile = 8;
      so.block = 20;
      std::vector<std::atomic<int>> visits(kW * kH);
      std::atomic<size_t> calls{0};
      EXPECT_TRUE(parallel_for_tiles(kW, kH, so, nullptr, [&](const Tile& t) {
        ++calls;
        for (int y = t.y0; y < t.y1; ++y) {
          for (int x = t.x0; x < t.x1; ++x) visits[size_t(y) * kW + size_t(x)]++;
        }
      }));
      EXPECT_EQ(calls.load(), tiles_for(kW, kH, so).size());
      size_t wrong = 0;
      for (const auto& v : visits) wrong += v.load() != 1;
      EXPECT_EQ(wrong, 0u);
    }
  }
}

}  // namespace
}  // namespace tracer
