// Google Benchmark microbenchmarks: the triangle and box tests, BVH builds per split and builder,
// and traversal throughput per ray type (primary, shadow, AO) for every accelerator, on the rays
// the renderer really traces. Run: build/release/bench/tracer_microbench [--benchmark_filter=...]
#include <benchmark/benchmark.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <atomic>
#include <bit>
#include <filesystem>
#include <memory>
#include <string>

#include "accel/accelerator.hpp"
#include "importers/obj_loader.hpp"
#include "math/sampling.hpp"
#include "render/ao.hpp"
#include "render/render_tile.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"
#include "scene/views.hpp"

namespace tracer {
namespace {

struct RecordedRays {
  std::vector<Ray> primary, shadow, ao;
  std::vector<uint32_t> shadow_from, ao_from;  // the triangle each shadow / AO ray leaves
};

// Records the workload's rays by rendering with a recording accelerator over the SAH BVH.
struct Recorder {
  const Bvh* bvh;
  RecordedRays* out;
  bool intersect(const Ray& r, Hit& h) const {
    out->primary.push_back(r);
    return bvh->intersect(r, h);
  }
  bool occluded(const Ray& r) const { return bvh->occluded(r); }
  bool occluded_from(const Ray& r, uint32_t origin) const {
    // Shadow rays stop short of their light (finite tfar); AO rays here have tfar = infinity.
    const bool ao = r.tfar == kInfinity;
    (ao ? out->ao : out->shadow).push_back(r);
    (ao ? out->ao_from : out->shadow_from).push_back(origin);
    return bvh->occluded_from(r, origin);
  }
};

struct SceneCase {
  std::string name;
  std::shared_ptr<Scene> scene;
  std::shared_ptr<Bvh> bvh;
  RecordedRays rays;
};

// The recorded AO rays as the renderer bundles them: each hit's rays (same origin, consecutive).
struct AoBundle {
  RayBundle rays;
  uint32_t origin;
};

std::vector<AoBundle> ao_bundles(const RecordedRays& r) {
  std::vector<AoBundle> out;
  for (size_t i = 0; i < r.ao.size();) {
    AoBundle b;
    b.rays.org = r.ao[i].org;
    b.rays.tnear = r.ao[i].tnear;
    b.rays.tfar = r.ao[i].tfar;
    b.origin = r.ao_from[i];
    for (int k = 0; k < kPacketSize && i < r.ao.size() && r.ao[i].org == b.rays.org && r.ao_from[i] == b.origin;
         ++k, ++i) {
      b.rays.set_direction(k, r.ao[i].dir);
    }
    out.push_back(b);
  }
  return out;
}

std::vector<SceneCase>& cases() {
  static std::vector<SceneCase> all = [] {
    std::vector<SceneCase> v;
    const auto add = [&](const std::string& name, Scene s) {
      SceneCase c;
      c.name = name;
      c.scene = std::make_shared<Scene>(std::move(s));
      c.bvh = std::make_shared<Bvh>(*c.scene, BvhBuildOptions{});
      // 16 AO rays per hit, as the renderer's default: each hit's AO rays are recorded one after
      // the other, so they can also be traced as the renderer's bundles.
      RenderSettings rs;
      rs.width = rs.height = 64;
      rs.ao_samples = 16;
      Framebuffer fb(rs.width, rs.height);
      const CameraSpec cam = c.scene->camera ? *c.scene->camera : frame_bounds(c.scene->bounds);
      PassContext ctx{c.scene.get(), Camera(cam, rs.width, rs.height), rs, &fb};
      Recorder rec{c.bvh.get(), &c.rays};
      render_tile(rec, ctx, Tile{0, 0, rs.width, rs.height});
      v.push_back(std::move(c));
    };
    add("builtin-spheres", make_cornell_box(20000));
    const std::string dir = TRACER_SCENES_DIR;
    for (const auto& [name, path] : {std::pair{"Original", "/cornell-box/CornellBox-Original.obj"},
                                     {"Sphere", "/cornell-box/CornellBox-Sphere.obj"},
                                     {"Water", "/cornell-box/CornellBox-Water.obj"},
                                     {"Sponza", "/sponza/sponza.obj"},
                                     {"Sibenik", "/sibenik/sibenik.obj"},
                                     {"Bunny", "/bunny/bunny.obj"}}) {
      if (std::filesystem::exists(dir + path)) add(name, load_obj(dir + path, [](const std::string&) {}));
    }
    return v;
  }();
  return all;
}

void BM_TriangleTest(benchmark::State& state) {
  const SceneCase& c = cases().front();
  const Ray ray = c.rays.primary[c.rays.primary.size() / 2];
  const RayShear shear(ray);
  const auto& tris = c.scene->triangles;
  size_t hits = 0;
  for (auto _ : state) {
    for (const Triangle& t : tris) {
      TriangleHit th;
      hits += intersect_triangle(shear, t, 0.0f, kInfinity, th) ? 1 : 0;
    }
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(tris.size()));
}
BENCHMARK(BM_TriangleTest);

void BM_BoxTest(benchmark::State& state) {
  const SceneCase& c = cases().front();
  const RayBoxTest box(c.rays.primary[c.rays.primary.size() / 2]);
  const auto& nodes = c.bvh->nodes();
  float acc = 0;
  for (auto _ : state) {
    for (const BvhNode& n : nodes) acc += box.enter(n, 0.0f, kInfinity) == kInfinity ? 0.0f : 1.0f;
  }
  benchmark::DoNotOptimize(acc);
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(nodes.size()));
}
BENCHMARK(BM_BoxTest);

// Incoherent rays on the views people render (views.tsv): at each primary hit of a 256x256
// image, one diffuse bounce (cosine-distributed about the normal, closest hit: what a path
// tracer's second ray is) and 16 AO rays (the study's directions, any hit), all leaving the
// surface as the renderer's rays do.
struct IncoherentRays {
  std::string name;
  std::shared_ptr<Scene> scene;
  std::vector<Ray> bounce, ao;
};

IncoherentRays record_incoherent(const View& view) {
  IncoherentRays out;
  out.name = view.name;
  out.scene = std::make_shared<Scene>(load_obj(view.obj, [](const std::string&) {}));
  const Bvh bvh(*out.scene, BvhBuildOptions{});
  constexpr int kSize = 256;
  const Camera camera(view.camera, kSize, kSize);
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      const Ray primary = camera.primary_ray(x, y);
      Hit hit;
      if (!bvh.intersect(primary, hit)) continue;
      const Triangle& tri = out.scene->triangles[hit.tri];
      Vec3 n = normalize(tri.normal());
      if (dot(n, primary.dir) > 0.0f) n = -n;
      const Vec3 p = tri.v0 * (1.0f - hit.u - hit.v) + tri.v1 * hit.u + tri.v2 * hit.v;
      Ray r;
      r.org = offset_origin(p, n);
      const uint32_t pixel = uint32_t(y * kSize + x);
      const SampleRng bounce_rng(pixel, 0, 1);
      r.dir = Frame(n).to_world(cosine_hemisphere(bounce_rng.draw(0), bounce_rng.draw(1)));
      out.bounce.push_back(r);
      for (uint32_t i = 0; i < 16; ++i) {
        const SampleRng rng(pixel, i);
        r.dir = ao_direction(n, rng.draw(0), rng.draw(1));
        out.ao.push_back(r);
      }
    }
  }
  return out;
}

// The order a ray stream is traced in after sorting, per batch: direction octant first, then the
// origin's Morton code on a 1024^3 grid over the scene's bounds (rays that start close and go the
// same way walk the same nodes).
std::vector<uint32_t> sorted_order(const std::vector<Ray>& rays, size_t begin, size_t end, const Aabb& bounds) {
  const auto spread = [](uint32_t v) {  // 10 bits to every third of 30
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x30000ffu;
    v = (v | (v << 8)) & 0x300f00fu;
    v = (v | (v << 4)) & 0x30c30c3u;
    return (v | (v << 2)) & 0x9249249u;
  };
  const Vec3 extent = max(bounds.hi - bounds.lo, Vec3{1e-20f});
  const Vec3 scale{1023.0f / extent.x, 1023.0f / extent.y, 1023.0f / extent.z};
  std::vector<uint64_t> keys(end - begin);
  for (size_t i = begin; i < end; ++i) {
    const Ray& r = rays[i];
    const Vec3 d = r.org - bounds.lo;
    const Vec3 q = min(max(Vec3{d.x * scale.x, d.y * scale.y, d.z * scale.z}, Vec3{0.0f}), Vec3{1023.0f});
    const uint32_t octant = uint32_t(r.dir.x < 0) | uint32_t(r.dir.y < 0) << 1 | uint32_t(r.dir.z < 0) << 2;
    const uint32_t morton = spread(uint32_t(q.x)) | spread(uint32_t(q.y)) << 1 | spread(uint32_t(q.z)) << 2;
    keys[i - begin] = uint64_t(octant) << 61 | uint64_t(morton) << 31 | uint64_t(i - begin);
  }
  std::sort(keys.begin(), keys.end());
  std::vector<uint32_t> order(keys.size());
  for (size_t k = 0; k < keys.size(); ++k) order[k] = uint32_t(begin + (keys[k] & 0x7fffffffu));
  return order;
}

void register_incoherent() {
  const std::string views_path = std::string(TRACER_SCENES_DIR) + "/views.tsv";
  if (!std::filesystem::exists(views_path)) return;
  static std::vector<IncoherentRays> all;
  for (const View& v : load_views(views_path)) all.push_back(record_incoherent(v));
  for (IncoherentRays& c : all) {
    auto wide = std::make_shared<Accelerator>(build_accelerator(*c.scene, AccelOptions{.kind = AccelKind::Bvh8}));
    auto embree =
        embree_available()
            ? std::make_shared<Accelerator>(build_accelerator(*c.scene, AccelOptions{.kind = AccelKind::Embree}))
            : nullptr;
    for (const bool any_hit : {false, true}) {
      const std::vector<Ray>* rays = any_hit ? &c.ao : &c.bounce;
      const double mrays = double(rays->size()) * 1e-6;
      const std::string kind = any_hit ? "/ao" : "/bounce";
      // One ray at a time, in the order recorded (pixel by pixel), through bvh8 and Embree.
      for (const auto& [accel_name, accel] : {std::pair{"bvh8", wide}, std::pair{"embree", embree}}) {
        if (!accel) continue;
        benchmark::RegisterBenchmark(("BM_Incoherent/" + c.name + "/" + accel_name + kind).c_str(),
                                     [accel = accel, rays, any_hit, mrays](benchmark::State& st) {
                                       size_t n = 0;
                                       accel->visit([&](const auto& a) {
                                         Hit h;
                                         for (auto _ : st) {
                                           for (const Ray& r : *rays) n += any_hit ? a.occluded(r) : a.intersect(r, h);
                                         }
                                       });
                                       benchmark::DoNotOptimize(n);
                                       st.counters["Mrays/s"] =
                                           benchmark::Counter(mrays, benchmark::Counter::kIsIterationInvariantRate);
                                     })
            ->Unit(benchmark::kMillisecond);
      }
      // A stream: batches of 4096 rays sorted (octant, origin Morton code) and traced in that
      // order through bvh8, the sort timed with the traversal.
      const Aabb bounds = c.scene->bounds;
      benchmark::RegisterBenchmark(
          ("BM_Incoherent/" + c.name + "/bvh8-sorted" + kind).c_str(),
          [wide, rays, any_hit, mrays, bounds](benchmark::State& st) {
            const WideBvh& w = std::get<WideBvh>(*wide->impl);
            constexpr size_t kBatch = 4096;
            size_t n = 0;
            Hit h;
            for (auto _ : st) {
              for (size_t b = 0; b < rays->size(); b += kBatch) {
                for (const uint32_t i : sorted_order(*rays, b, std::min(rays->size(), b + kBatch), bounds))
                  n += any_hit ? w.occluded((*rays)[i]) : w.intersect((*rays)[i], h);
              }
            }
            benchmark::DoNotOptimize(n);
            st.counters["Mrays/s"] = benchmark::Counter(mrays, benchmark::Counter::kIsIterationInvariantRate);
          })
          ->Unit(benchmark::kMillisecond);
    }
  }
}

void register_dynamic() {
  for (SceneCase& c : cases()) {
    for (BvhSplit split : {BvhSplit::Sah, BvhSplit::Median}) {
      for (Strategy mode : {Strategy::Seq, Strategy::Async, Strategy::Queue, Strategy::Tbb}) {
        const std::string name = std::string("BM_BvhBuild/") + c.name + "/" +
                                 (split == BvhSplit::Sah ? "sah/" : "median/") +
                                 std::string(name_of<Strategy>(kStrategyNames, mode));
        benchmark::RegisterBenchmark(name.c_str(),
                                     [&c, split, mode](benchmark::State& st) {
                                       BvhBuildOptions o;
                                       o.split = split;
                                       o.strategy = mode;
                                       size_t bytes = 0;
                                       for (auto _ : st) {
                                         const Bvh bvh(*c.scene, o);
                                         bytes = bvh.memory_bytes();
                                         benchmark::DoNotOptimize(bvh.nodes().data());
                                       }
                                       st.counters["Mtris/s"] =
                                           benchmark::Counter(double(c.scene->size()) * 1e-6,
                                                              benchmark::Counter::kIsIterationInvariantRate);
                                       st.counters["bytes/tri"] = double(bytes) / double(c.scene->size());
                                     })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    }
    if (embree_available()) {
      benchmark::RegisterBenchmark(
          (std::string("BM_BvhBuild/") + c.name + "/embree").c_str(),
          [&c](benchmark::State& st) {
            for (auto _ : st)
              benchmark::DoNotOptimize(build_accelerator(*c.scene, AccelOptions{.kind = AccelKind::Embree}).impl.get());
            st.counters["Mtris/s"] =
                benchmark::Counter(double(c.scene->size()) * 1e-6, benchmark::Counter::kIsIterationInvariantRate);
          })
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
    {
      // Primary rays of a 1024x1024 image (the renderer's default size, so the packets are as
      // coherent as in a real render): 4x4-pixel packets through the 8-wide BVH, against the
      // same rays one at a time through the binary SAH BVH, the 8-wide BVH and Embree.
      constexpr int kSize = 1024;
      auto wide = std::make_shared<Accelerator>(build_accelerator(*c.scene, AccelOptions{.kind = AccelKind::Bvh8}));
      auto packets = std::make_shared<std::vector<RayPacket>>();
      auto singles = std::make_shared<std::vector<Ray>>();
      const CameraSpec spec = c.scene->camera ? *c.scene->camera : frame_bounds(c.scene->bounds);
      const Camera camera(spec, kSize, kSize);
      for (int by = 0; by < kSize; by += kPacketEdge) {
        for (int bx = 0; bx < kSize; bx += kPacketEdge) {
          RayPacket p;
          for (int k = 0; k < kPacketSize; ++k) {
            p.set(k, camera.primary_ray(bx + k % kPacketEdge, by + k / kPacketEdge));
            singles->push_back(p.ray(k));
          }
          packets->push_back(p);
        }
      }
      const double mrays = double(singles->size()) * 1e-6;
      benchmark::RegisterBenchmark(("BM_Primary1024/" + c.name + "/bvh8-packets").c_str(), [wide, packets, mrays](
                                                                                               benchmark::State& st) {
        const WideBvh& w = std::get<WideBvh>(*wide->impl);
        Hit hits[kPacketSize];
        size_t n = 0;
        for (auto _ : st) {
          for (const RayPacket& p : *packets) {
            w.intersect_packet(p, hits);
            n += hits[0].valid();
          }
        }
        benchmark::DoNotOptimize(n);
        st.counters["Mrays/s"] = benchmark::Counter(mrays, benchmark::Counter::kIsIterationInvariantRate);
      })->Unit(benchmark::kMillisecond);
      struct Named {
        const char* name;
        std::shared_ptr<Accelerator> accel;  // null: not built in
      };
      const Named singles_on[] = {
          {"bvh-sah", std::make_shared<Accelerator>(build_accelerator(*c.scene, AccelOptions{.kind = AccelKind::Bvh}))},
          {"bvh8", wide},
          {"embree", embree_available() ? std::make_shared<Accelerator>(
                                              build_accelerator(*c.scene, AccelOptions{.kind = AccelKind::Embree}))
                                        : nullptr}};
      for (const auto& [accel_name, accel] : singles_on) {
        if (!accel) continue;
        benchmark::RegisterBenchmark(("BM_Primary1024/" + c.name + "/" + accel_name).c_str(),
                                     [accel = accel, singles, mrays](benchmark::State& st) {
                                       size_t n = 0;
                                       accel->visit([&](const auto& a) {
                                         Hit h;
                                         for (auto _ : st) {
                                           for (const Ray& r : *singles) n += a.intersect(r, h);
                                         }
                                       });
                                       benchmark::DoNotOptimize(n);
                                       st.counters["Mrays/s"] =
                                           benchmark::Counter(mrays, benchmark::Counter::kIsIterationInvariantRate);
                                     })
            ->Unit(benchmark::kMillisecond);
      }
    }
    std::vector<std::pair<std::string, AccelOptions>> accels = {{"bvh-sah", AccelOptions{.kind = AccelKind::Bvh}}};
    AccelOptions median;
    median.bvh.split = BvhSplit::Median;
    accels.emplace_back("bvh-median", median);
    accels.emplace_back("bvh8", AccelOptions{.kind = AccelKind::Bvh8});
    if (embree_available()) accels.emplace_back("embree", AccelOptions{.kind = AccelKind::Embree});
    for (const auto& [accel_name, options] : accels) {
      auto accel = std::make_shared<Accelerator>(build_accelerator(*c.scene, options));
      // Shadow and AO rays go through occluded_leaving(), as in the renderer: the binary BVH starts
      // them at their origin triangle's leaf. "ao-from-root" is the same AO rays from the root;
      // "ao-bundles" the same AO rays in the renderer's bundles (--packets), 16 per hit.
      for (int kind = 0; kind < 5; ++kind) {
        static const char* kinds[] = {"primary", "shadow", "ao", "ao-from-root", "ao-bundles"};
        if (kind == 3 && options.kind != AccelKind::Bvh) continue;
        if (kind == 4 && options.kind != AccelKind::Bvh && options.kind != AccelKind::Bvh8) continue;
        const std::vector<Ray>* rays = kind == 0 ? &c.rays.primary : (kind == 1 ? &c.rays.shadow : &c.rays.ao);
        const std::vector<uint32_t>* from = kind == 1 ? &c.rays.shadow_from : &c.rays.ao_from;
        if (rays->empty()) continue;
        auto bundles =
            std::make_shared<std::vector<AoBundle>>(kind == 4 ? ao_bundles(c.rays) : std::vector<AoBundle>{});
        // The rays (or bundles) [begin, end) through `a`, as the renderer asks for them.
        const auto trace = [rays, from, kind, bundles](const auto& a, size_t begin, size_t end) {
          size_t n = 0;
          Hit h;
          if constexpr (BundleAccelerator<std::decay_t<decltype(a)>>) {
            if (kind == 4) {
              for (size_t i = begin; i < end; ++i)
                n += size_t(std::popcount(a.occluded_bundle_from((*bundles)[i].rays, (*bundles)[i].origin)));
              return n;
            }
          }
          for (size_t i = begin; i < end; ++i) {
            const Ray& r = (*rays)[i];
            n += kind == 0 ? a.intersect(r, h) : kind == 3 ? a.occluded(r) : occluded_leaving(a, r, (*from)[i]);
          }
          return n;
        };
        const size_t items = kind == 4 ? bundles->size() : rays->size();
        const double mrays = double(rays->size()) * 1e-6;
        // One thread, and two (the same rays split in chunks over a two-thread oneTBB arena).
        for (const int threads : {1, 2}) {
          const std::string name =
              "BM_Traverse/" + c.name + "/" + accel_name + "/" + kinds[kind] + (threads == 2 ? "/2threads" : "");
          auto* b = benchmark::RegisterBenchmark(name.c_str(), [accel, trace, items, mrays,
                                                                threads](benchmark::State& st) {
            std::atomic<size_t> n{0};
            tbb::task_arena arena(threads);
            accel->visit([&](const auto& a) {
              for (auto _ : st) {
                if (threads == 1) {
                  n += trace(a, 0, items);
                  continue;
                }
                arena.execute([&] {
                  tbb::parallel_for(tbb::blocked_range<size_t>(0, items, 64),
                                    [&](const tbb::blocked_range<size_t>& r) { n += trace(a, r.begin(), r.end()); });
                });
              }
            });
            benchmark::DoNotOptimize(n.load());
            st.counters["Mrays/s"] = benchmark::Counter(mrays, benchmark::Counter::kIsIterationInvariantRate);
          });
          b->Unit(benchmark::kMillisecond);
          if (threads == 2) b->UseRealTime();  // the main thread's CPU time would count only its half
        }
      }
    }
  }
}

}  // namespace
}  // namespace tracer

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  tracer::register_dynamic();
  tracer::register_incoherent();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
