// The 8-wide BVH: the same closest hit and occlusion answer as the binary BVH (and so brute
// force) on random rays and every ray of a small render, for every SIMD target this CPU has,
// forced one by one; the validator holds; watertightness survives.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <memory>
#include <random>

#include "render/render_tile.hpp"
#include "render/stream_order.hpp"

#include "accel/accelerator.hpp"
#include "accel/builders/spatial_split.hpp"
#include "importers/obj_loader.hpp"
#include "scene/builtin.hpp"
#include "scene/camera.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

// Every SIMD target this CPU has, each tree built for one (a narrower one where the CPU lacks it).
std::vector<SimdTarget> targets() { return {SimdTarget::Auto, SimdTarget::Avx2, SimdTarget::Sse4}; }
std::string target_name(SimdTarget t) {
  return std::string(name_of<SimdTarget>(kSimdTargetNames, t)) + " -> " + SimdDispatch::of(t).name();
}
BvhBuildOptions for_target(SimdTarget t, BvhBuildOptions o = {}) {
  o.simd = t;
  return o;
}

size_t disagreements(const Scene& scene, const std::vector<Ray>& rays, const BvhBuildOptions& wide_options = {}) {
  const Bvh bin(scene, BvhBuildOptions{});
  const WideBvh wide(scene, wide_options);
  EXPECT_EQ(wide.validate(), "");
  size_t bad = 0;
  for (const Ray& r : rays) {
    Hit a, b;
    const bool ha = bin.intersect(r, a), hb = wide.intersect(r, b);
    const bool same = ha == hb && (!ha || (a.tri == b.tri && a.t == b.t && a.u == b.u && a.v == b.v &&
                                           a.primID == b.primID && a.geomID == b.geomID));
    if (!same && bad++ < 3)
      ADD_FAILURE() << "closest hit differs: tri " << a.tri << " t " << a.t << " vs tri " << b.tri << " t " << b.t;
    Ray shadow = r;
    shadow.tfar = ha ? a.t * 0.5f : length(scene.bounds.extent()) * 0.3f;
    if (bin.occluded(r) != wide.occluded(r) || bin.occluded(shadow) != wide.occluded(shadow)) {
      if (bad++ < 3) ADD_FAILURE() << "occluded differs";
    }
  }
  return bad;
}

// The built-in box with spheres, and from ../shared/scenes two Cornell boxes, Sponza and the Bunny.
std::vector<Scene> agreement_scenes() {
  std::vector<Scene> scenes;
  scenes.push_back(make_cornell_box(5000));
  if (test::have_shared_scenes()) {
    for (const char* p : {"cornell-box/CornellBox-Original.obj", "cornell-box/CornellBox-Water.obj",
                          "sponza/sponza.obj", "bunny/bunny.obj"}) {
      scenes.push_back(load_obj(test::scene_path(p), [](const std::string&) {}));
    }
  }
  return scenes;
}

// Runs `check` on every agreement scene with every SIMD target this CPU has, one by one.
void for_each_target_and_scene(const std::function<void(const Scene&, SimdTarget)>& check) {
  const std::vector<Scene> scenes = agreement_scenes();
  for (const SimdTarget target : targets()) {
    SCOPED_TRACE(target_name(target));
    for (const Scene& scene : scenes) {
      SCOPED_TRACE(scene.source);
      check(scene, target);
    }
  }
}

TEST(WideBvh, AgreesWithBinaryBvhOnEveryTarget) {
  for_each_target_and_scene([](const Scene& scene, SimdTarget target) {
    EXPECT_EQ(disagreements(scene, test::random_rays(scene, test::ray_budget(100'000) / 5, 77), for_target(target)),
              0u);
  });
}

// Trees of different targets side by side in one process: each runs its own kernels.
TEST(WideBvh, TheSimdTargetIsEachTreesOwn) {
  const Scene scene = make_cornell_box(500);
  const WideBvh sse4(scene, for_target(SimdTarget::Sse4)), best(scene, for_target(SimdTarget::Auto));
  EXPECT_EQ(sse4.simd().name(), "SSE4");
  EXPECT_EQ(best.simd().name(), SimdDispatch::of(SimdTarget::Auto).name());
  EXPECT_EQ(SimdDispatch::of(SimdTarget::Auto).name(), SimdDispatch::of(SimdTarget::Avx512).name());
  for (const Ray& r : test::random_rays(scene, 2000, 5)) {
    Hit a, b;
    EXPECT_EQ(sse4.intersect(r, a), best.intersect(r, b));
    EXPECT_EQ(a.tri, b.tri);
    EXPECT_EQ(a.t, b.t);
  }
}

// Spatial splits cut references, never triangles: the same hits as the binary tree.
TEST(WideBvh, SpatialSplitsAgreeWithBinaryBvhOnEveryTarget) {
  BvhBuildOptions high;
  high.split_budget = kHighSplitBudget;
  for_each_target_and_scene([&](const Scene& scene, SimdTarget target) {
    EXPECT_EQ(
        disagreements(scene, test::random_rays(scene, test::ray_budget(100'000) / 5, 78), for_target(target, high)),
        0u);
  });
}

TEST(WideBvh, RaysStartingOnTrianglesAndAlongEdges) {
  // The study's SIMD occlusion bug: a ray leaving a surface must not hit the surface it left.
  const Scene scene = make_cornell_box(2000);
  const WideBvh wide(scene, BvhBuildOptions{});
  const Bvh bin(scene, BvhBuildOptions{});
  size_t checked = 0;
  for (size_t i = 0; i < scene.size(); i += 7) {
    const Triangle& t = scene.triangles[i];
    Vec3 n = normalize(t.normal());
    Ray r;
    r.org = t.centroid() + n * 1e-4f;
    r.dir = n;
    Hit a, b;
    EXPECT_EQ(bin.intersect(r, a), wide.intersect(r, b));
    EXPECT_EQ(a.tri, b.tri);
    EXPECT_NE(b.tri, uint32_t(i));
    EXPECT_EQ(bin.occluded(r), wide.occluded(r));
    // Along an edge, in the triangle's plane.
    r.org = t.v0 - (t.v1 - t.v0);
    r.dir = normalize(t.v1 - t.v0);
    EXPECT_EQ(bin.intersect(r, a), wide.intersect(r, b));
    EXPECT_EQ(a.tri, b.tri);
    ++checked;
  }
  EXPECT_GT(checked, 100u);
}

// The counters on a tree whose root holds one leaf of one triangle: a ray that hits it visits the
// root, the pack and its triangle; one that misses every child box visits the root alone.
TEST(WideBvh, CountersSayWhatTheTraversalVisited) {
  const Scene scene = test::scene_of({Triangle{{-1, -1, 0}, {1, -1, 0}, {0, 1, 0}}});
  const WideBvh bvh(scene, BvhBuildOptions{});
  Ray through;
  through.org = {0, 0, 2};
  through.dir = {0, 0, -1};
  Ray beside = through;
  beside.org = {5, 0, 2};
  TraversalCounts closest, any;
  Hit hit;
  EXPECT_TRUE(bvh.intersect(through, hit, closest));
  EXPECT_EQ(closest, (TraversalCounts{.rays = 1, .nodes = 1, .packs = 1, .triangles = 1}));
  EXPECT_FALSE(bvh.intersect(beside, hit, closest));
  EXPECT_EQ(closest, (TraversalCounts{.rays = 2, .nodes = 2, .packs = 1, .triangles = 1}));
  EXPECT_TRUE(bvh.occluded(through, any));
  EXPECT_FALSE(bvh.occluded(beside, any));
  EXPECT_EQ(any, (TraversalCounts{.rays = 2, .nodes = 2, .packs = 1, .triangles = 1}));
  // A bundle of both counts each ray's visits as the two rays alone do.
  RayBundle bundle;
  bundle.org = through.org;
  bundle.set_direction(0, through.dir);
  bundle.set_direction(1, Vec3{1, 0, 0});  // along the plane, above it: misses
  TraversalCounts bundled;
  EXPECT_EQ(bvh.occluded_bundle_from(bundle, 0, bundled) & 1u, 1u);
  EXPECT_EQ(bundled.rays, 2u);
  EXPECT_LE(bundled.nodes, 2u);
  EXPECT_EQ(bundled.packs, 1u);
}

TEST(WideBvh, DegenerateInputs) {
  const Triangle t{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (const auto& tris : {std::vector<Triangle>{}, std::vector<Triangle>{t}, std::vector<Triangle>(50, t)}) {
    const Scene scene = test::scene_of(tris);
    const WideBvh wide(scene, BvhBuildOptions{});
    EXPECT_EQ(wide.validate(), "");
    Ray r;
    r.org = {0.25f, 0.25f, 1};
    r.dir = {0, 0, -1};
    Hit h;
    EXPECT_EQ(wide.intersect(r, h), !tris.empty());
    EXPECT_EQ(wide.occluded(r), !tris.empty());
    if (!tris.empty()) {
      EXPECT_EQ(h.tri, 0u);
    }
  }
}

// Many spheres in a row: enough triangles (about 150k) that the top splits run data-parallel.
Scene many_spheres() {
  Scene scene;
  scene.materials.push_back(Material{});
  for (int i = 0; i < 12; ++i) {
    const IndexedMesh m = make_uv_sphere({float(i) * 1.5f, float(i % 3), 0.0f}, 1.0f + 0.1f * float(i), 160, 40);
    scene.add_mesh("sphere", m.vertices, m.indices, 0);
  }
  scene.finalize();
  return scene;
}

// One wide node as a list of its children: box, and the sorted triangles below it.
struct WideChild {
  std::array<float, 6> box;  // lo, hi
  std::vector<uint32_t> tris;
  bool leaf;
  bool operator==(const WideChild&) const = default;
};
using WideShape = std::vector<std::vector<WideChild>>;  // nodes depth first

void collect(const WideBvh& w, uint32_t node, std::vector<uint32_t>& out) {
  const WideNode& n = w.nodes()[node];
  for (int i = 0; i < kWideWidth && n.lo_x[i] <= n.hi_x[i]; ++i) {
    if (n.count[i] == 0) {
      collect(w, n.child[i], out);
    } else {
      out.insert(out.end(), w.packs()[n.child[i]].id, w.packs()[n.child[i]].id + n.count[i]);
    }
  }
}

void shape_of(const WideBvh& w, uint32_t node, WideShape& shape) {
  const WideNode& n = w.nodes()[node];
  const size_t self = shape.size();
  shape.emplace_back();
  for (int i = 0; i < kWideWidth && n.lo_x[i] <= n.hi_x[i]; ++i) {
    WideChild c{{n.lo_x[i], n.lo_y[i], n.lo_z[i], n.hi_x[i], n.hi_y[i], n.hi_z[i]}, {}, n.count[i] != 0};
    if (c.leaf) {
      c.tris.assign(w.packs()[n.child[i]].id, w.packs()[n.child[i]].id + n.count[i]);
    } else {
      collect(w, n.child[i], c.tris);
    }
    std::sort(c.tris.begin(), c.tris.end());
    const bool leaf = c.leaf;
    shape[self].push_back(std::move(c));
    if (!leaf) shape_of(w, n.child[i], shape);
  }
}

// The reference: the binary SAH tree (leaves of up to eight) collapsed greedily, as the 8-wide
// tree was once built: open the inner node with the largest box until eight children remain or
// only subtrees of at most eight triangles, largest subtree first; those become packs.
struct Collapse {
  const Bvh& bin;
  uint32_t count(uint32_t i) const {
    const BvhNode& n = bin.nodes()[i];
    return n.leaf() ? n.count : count(n.index) + count(n.index + 1);
  }
  void tris(uint32_t i, std::vector<uint32_t>& out) const {
    const BvhNode& n = bin.nodes()[i];
    if (!n.leaf()) return tris(n.index, out), tris(n.index + 1, out);
    out.insert(out.end(), bin.triangle_ids().begin() + n.index, bin.triangle_ids().begin() + n.index + n.count);
  }
  void shape(uint32_t root, WideShape& out) const {
    const auto packable = [&](uint32_t i) { return count(i) <= uint32_t(kWideWidth); };
    std::vector<uint32_t> kids{root};
    if (!packable(root)) kids = {bin.nodes()[root].index, bin.nodes()[root].index + 1};
    while (kids.size() < size_t(kWideWidth)) {
      int best = -1;
      float best_area = -1.0f;
      for (size_t i = 0; i < kids.size(); ++i) {
        const BvhNode& n = bin.nodes()[kids[i]];
        if (!packable(kids[i]) && Aabb{n.lo, n.hi}.half_area() > best_area) {
          best = int(i);
          best_area = Aabb{n.lo, n.hi}.half_area();
        }
      }
      if (best < 0) break;
      const uint32_t first = bin.nodes()[kids[size_t(best)]].index;
      kids[size_t(best)] = first;
      kids.insert(kids.begin() + best + 1, first + 1);
    }
    std::stable_sort(kids.begin(), kids.end(), [&](uint32_t a, uint32_t b) { return count(a) > count(b); });
    const size_t self = out.size();
    out.emplace_back();
    for (const uint32_t k : kids) {
      const BvhNode& n = bin.nodes()[k];
      WideChild c{{n.lo.x, n.lo.y, n.lo.z, n.hi.x, n.hi.y, n.hi.z}, {}, packable(k)};
      tris(k, c.tris);
      std::sort(c.tris.begin(), c.tris.end());
      out[self].push_back(std::move(c));
      if (!packable(k)) shape(k, out);
    }
  }
};

// The direct build gives the tree the greedy collapse of the binary SAH tree gives (same nodes,
// boxes and packs, depth first), so it is no worse a tree; SAH and median splits.
TEST(WideBvh, DirectBuildGivesTheCollapsedBinaryTree) {
  std::vector<Scene> scenes = agreement_scenes();
  scenes.push_back(many_spheres());
  for (const Scene& scene : scenes) {
    SCOPED_TRACE(scene.source);
    for (const BvhSplit split : {BvhSplit::Sah, BvhSplit::Median}) {
      BvhBuildOptions options;
      options.split = split;
      const WideBvh wide(scene, options);
      options.max_leaf = kWideWidth;
      const Bvh bin(scene, options);
      WideShape direct, collapsed;
      shape_of(wide, 0, direct);
      Collapse{bin}.shape(0, collapsed);
      ASSERT_EQ(direct.size(), collapsed.size());
      EXPECT_TRUE(direct == collapsed);
    }
  }
}

// Every executor and thread count builds the same tree, byte for byte, with and without spatial
// splits.
class WideBvhBudget : public testing::TestWithParam<float> {};
INSTANTIATE_TEST_SUITE_P(Budgets, WideBvhBudget, testing::Values(0.0f, kHighSplitBudget));

TEST_P(WideBvhBudget, SameTreeUnderEveryExecutorAndThreadCount) {
  const Scene scene = many_spheres();
  ASSERT_GT(scene.size(), 100'000u);
  BvhBuildOptions options;
  options.split_budget = GetParam();
  options.strategy = Strategy::Seq;
  const WideBvh ref(scene, options);
  EXPECT_EQ(ref.validate(), "");
  for (const Strategy mode : {Strategy::Async, Strategy::Queue, Strategy::Tbb}) {
    for (const int threads : {1, 2, 4}) {
      SCOPED_TRACE(testing::Message() << int(mode) << " " << threads);
      options.strategy = mode;
      options.threads = threads;
      const WideBvh w(scene, options);
      ASSERT_EQ(w.nodes().size(), ref.nodes().size());
      ASSERT_EQ(w.packs().size(), ref.packs().size());
      EXPECT_EQ(std::memcmp(w.nodes().data(), ref.nodes().data(), ref.nodes().size() * sizeof(WideNode)), 0);
      EXPECT_EQ(std::memcmp(w.packs().data(), ref.packs().data(), ref.packs().size() * sizeof(TrianglePack)), 0);
    }
  }
}

// Small triangles scattered in a room, crossed by long diagonal slivers (a vault's ribs, a
// stair's rails): the slivers' boxes swallow the room, so the binned SAH's children overlap;
// spatial splits must cut them within their budget, keep every hit, and visit fewer nodes and
// packs per ray.
TEST(WideBvh, SpatialSplitsCutLongTrianglesWithinTheBudget) {
  std::vector<Triangle> tris;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (int i = 0; i < 8000; ++i) {
    const Vec3 a{u(rng) * 10, u(rng) * 10, u(rng) * 10};
    tris.push_back({a, a + Vec3{u(rng), u(rng), u(rng)} * 0.3f, a + Vec3{u(rng), u(rng), u(rng)} * 0.3f});
  }
  for (int i = 0; i < 100; ++i) {
    const Vec3 a{u(rng) * 10, u(rng) * 10, -10.0f}, b{u(rng) * 10, u(rng) * 10, 10.0f};
    tris.push_back({a, b, b + Vec3{u(rng), u(rng), 0.0f} * 0.2f});
  }
  const Scene scene = test::scene_of(tris);
  BvhBuildOptions high;
  high.split_budget = kHighSplitBudget;
  const WideBvh medium_tree(scene, BvhBuildOptions{}), high_tree(scene, high);
  EXPECT_FALSE(medium_tree.spatial_splits());
  ASSERT_TRUE(high_tree.spatial_splits());
  EXPECT_EQ(high_tree.validate(), "");
  std::vector<uint32_t> medium_refs, high_refs;
  collect(medium_tree, 0, medium_refs);
  collect(high_tree, 0, high_refs);
  EXPECT_EQ(medium_refs.size(), tris.size());
  EXPECT_GT(high_refs.size(), tris.size() * 21 / 20) << "spatial splits should add references";
  EXPECT_LE(high_refs.size(), tris.size() * 6 / 5) << "at most 20 % more references";
  const std::vector<Ray> rays = test::random_rays(scene, 20'000, 9);
  EXPECT_EQ(disagreements(scene, rays, BvhBuildOptions{}), 0u) << "medium";
  EXPECT_EQ(disagreements(scene, rays, high), 0u);
  TraversalCounts m, h;
  for (const Ray& r : rays) {
    Hit a, b;
    medium_tree.intersect(r, a, m);
    high_tree.intersect(r, b, h);
  }
  // Measured: 156k -> 127k nodes, 134k -> 70k packs, 8100 triangles -> 9526 references.
  EXPECT_LT(double(h.nodes + h.packs), 0.8 * double(m.nodes + m.packs))
      << "nodes " << m.nodes << " -> " << h.nodes << ", packs " << m.packs << " -> " << h.packs;
}

// Boxes a few denormals thick on one axis, long triangles (side by side, none overlapping)
// crossing them: the spatial binning skips the axis it cannot divide, and the tree stays valid
// and exact.
TEST(WideBvh, SpatialSplitsOnDenormalThinBoxes) {
  std::vector<Triangle> tris;
  const float z = std::numeric_limits<float>::denorm_min();
  for (int i = 0; i < 300; ++i) {
    const float y = 0.5f * float(i);
    tris.push_back({{-50.0f, y, 0.0f}, {50.0f, y, z * float(i % 3)}, {float(i % 7) - 3.0f, y + 0.4f, z}});
  }
  const Scene scene = test::scene_of(tris);
  BvhBuildOptions high;
  high.split_budget = kHighSplitBudget;
  const WideBvh tree(scene, high);
  EXPECT_EQ(tree.validate(), "");
  // Rays from above and below the sheet.
  std::vector<Ray> rays;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> x(-60.0f, 60.0f), y(-2.0f, 152.0f);
  for (int i = 0; i < 5000; ++i) {
    Ray r;
    r.org = {x(rng), y(rng), i % 2 ? 5.0f : -5.0f};
    r.dir = normalize(Vec3{x(rng), y(rng), 0.0f} - r.org);
    rays.push_back(r);
  }
  EXPECT_EQ(disagreements(scene, rays, high), 0u);
}

// A cut triangle's parts: each side's box holds every point of the triangle on that side (within
// the reference's box), lies in the triangle's box, and is empty where the triangle does not reach.
TEST(SpatialSplit, ClippedBoxesHoldTheirPartOfTheTriangle) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f), w(0.0f, 1.0f);
  int cut = 0;
  for (int k = 0; k < 2000; ++k) {
    const Triangle t{{u(rng) * 100, u(rng), u(rng)}, {u(rng), u(rng) * 100, u(rng)}, {u(rng), u(rng), u(rng) * 100}};
    const int axis = k % 3;
    const Aabb tb = t.bounds();
    const float pos = tb.lo[axis] + (tb.hi[axis] - tb.lo[axis]) * (1.2f * w(rng) - 0.1f);
    Aabb left, right;
    clip_triangle(t, tb, axis, pos, left, right);
    EXPECT_EQ(left.empty(), tb.lo[axis] > pos);
    EXPECT_EQ(right.empty(), tb.hi[axis] < pos);
    if (!left.empty() && !right.empty()) ++cut;
    for (const Aabb* b : {&left, &right}) {
      if (!b->empty()) {
        EXPECT_TRUE(tb.contains(*b));
      }
    }
    for (int s = 0; s < 200; ++s) {
      float b1 = w(rng), b2 = w(rng);
      if (b1 + b2 > 1.0f) b1 = 1.0f - b1, b2 = 1.0f - b2;
      const Vec3 p = t.v0 * (1.0f - b1 - b2) + t.v1 * b1 + t.v2 * b2;
      const Aabb& side = p[axis] <= pos ? left : right;
      Aabb point;
      point.extend(p);
      // p itself is rounded; the box must hold it to within that rounding.
      Aabb grown = side;
      for (int a = 0; a < 3; ++a) {
        const float slack = 1e-5f * std::max(std::fabs(p[a]), 1.0f);
        grown.lo[a] -= slack;
        grown.hi[a] += slack;
      }
      if (!grown.contains(point)) {
        ADD_FAILURE() << "point outside its side's box, axis " << axis << " plane " << pos;
        return;
      }
    }
  }
  EXPECT_GT(cut, 1000);
}

TEST(WideBvh, WatertightClosedSphere) {
  const IndexedMesh m = make_uv_sphere({0.1f, 0.2f, -0.3f}, 2.0f, 48, 24);
  Scene scene;
  scene.materials.push_back(Material{});
  scene.add_mesh("sphere", m.vertices, m.indices, 0);
  scene.finalize();
  for (const SimdTarget target : targets()) {
    const WideBvh wide(scene, for_target(target));
    size_t leaks = 0;
    for (size_t i = 0; i < m.vertices.size(); ++i) {
      for (const Vec3 origin : {Vec3{0.1f, 0.2f, -0.3f}, Vec3{0.5f, 0.1f, 0.0f}}) {
        Ray r;
        r.org = origin;
        r.dir = normalize(m.vertices[i] - origin);
        Hit h;
        leaks += wide.intersect(r, h) ? 0 : 1;
        leaks += wide.occluded(r) ? 0 : 1;
      }
    }
    EXPECT_EQ(leaks, 0u) << target_name(target);
  }
}

TEST(SimdBruteForce, AgreesWithScalarBruteForceOnEveryTarget) {
  std::vector<Scene> scenes;
  scenes.push_back(make_cornell_box(300));
  const Triangle t{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  scenes.push_back(test::scene_of({t}));                           // one pack, seven padding lanes
  scenes.push_back(test::scene_of(std::vector<Triangle>(17, t)));  // ties across packs
  if (test::have_shared_scenes())
    scenes.push_back(load_obj(test::scene_path("cornell-box/CornellBox-Sphere.obj"), [](const std::string&) {}));
  for (const SimdTarget target : targets()) {
    for (const Scene& scene : scenes) {
      SCOPED_TRACE(target_name(target) + " " + scene.source + " " + std::to_string(scene.size()));
      const BruteForce scalar(scene);
      const SimdBruteForce simd(scene, target);
      std::vector<Ray> rays = test::random_rays(scene, 3000, 11);
      for (size_t i = 0; i < scene.size(); i += 3) {  // straight at triangles, and from their surfaces
        Ray r;
        r.org = scene.triangles[i].centroid() + Vec3{0.01f, 0.02f, 3.0f};
        r.dir = normalize(scene.triangles[i].centroid() - r.org);
        rays.push_back(r);
        r.org = scene.triangles[i].centroid();
        r.dir = normalize(scene.triangles[i].normal());
        rays.push_back(r);
      }
      size_t bad = 0;
      for (const Ray& r : rays) {
        Hit a, b;
        const bool ha = scalar.intersect(r, a), hb = simd.intersect(r, b);
        if (ha != hb || a.tri != b.tri || (ha && (a.t != b.t || a.u != b.u || a.v != b.v))) ++bad;
        if (scalar.occluded(r) != simd.occluded(r)) ++bad;
      }
      EXPECT_EQ(bad, 0u) << "of " << rays.size();
    }
  }
}

// Traces `rays` in packets of 16 (lane k of packet j is rays[16 j + k]; lanes whose bit is clear
// in `lane_mask` left out) and counts lanes whose hit differs from the single-ray one.
size_t packet_disagreements(const WideBvh& wide, const std::vector<Ray>& rays, uint32_t lane_mask = 0xffffu) {
  size_t bad = 0;
  for (size_t first = 0; first < rays.size(); first += kPacketSize) {
    RayPacket packet;
    for (int k = 0; k < kPacketSize && first + size_t(k) < rays.size(); ++k) {
      if ((lane_mask >> k) & 1u) packet.set(k, rays[first + size_t(k)]);
    }
    Hit hits[kPacketSize];
    hits[0].tri = 12345;  // an inactive lane's hit must be left alone
    wide.intersect_packet(packet, hits);
    for (int k = 0; k < kPacketSize; ++k) {
      if (!((packet.active >> k) & 1u)) {
        if (k == 0 && hits[0].tri != 12345u) ++bad;
        continue;
      }
      Hit single;
      const bool hs = wide.intersect(rays[first + size_t(k)], single);
      const Hit& h = hits[k];
      const bool same = hs == h.valid() && h.tri == single.tri && h.t == single.t && h.u == single.u &&
                        h.v == single.v && h.geomID == single.geomID && h.primID == single.primID;
      if (!same && bad++ < 3)
        ADD_FAILURE() << "packet lane " << k << ": tri " << h.tri << " t " << h.t << " vs " << single.tri << " t "
                      << single.t;
    }
  }
  return bad;
}

// The primary rays of a width x height image in 4x4-pixel packets, as the renderer makes them.
std::vector<Ray> primary_rays_in_packet_order(const Scene& scene, int width, int height) {
  const CameraSpec spec = scene.camera ? *scene.camera : frame_bounds(scene.bounds);
  const Camera camera(spec, width, height);
  std::vector<Ray> rays;
  Ray none;
  none.dir = {0, 0, 1};
  for (int by = 0; by < height; by += kPacketEdge) {
    for (int bx = 0; bx < width; bx += kPacketEdge) {
      for (int k = 0; k < kPacketSize; ++k) {
        const int x = bx + k % kPacketEdge, y = by + k / kPacketEdge;
        rays.push_back(x < width && y < height ? camera.primary_ray(x, y) : none);
      }
    }
  }
  return rays;
}

TEST(RayPackets, SameHitsAsSingleRaysOnEveryTarget) {
  for_each_target_and_scene([](const Scene& scene, SimdTarget target) {
    const WideBvh wide(scene, for_target(target));
    // Coherent: every primary ray of a 61x47 render (partial packets at the right and bottom).
    EXPECT_EQ(packet_disagreements(wide, primary_rays_in_packet_order(scene, 61, 47)), 0u);
    // Incoherent: random rays, mostly packets whose rays do not share shear axes.
    const std::vector<Ray> random = test::random_rays(scene, test::ray_budget(20'000) / 4, 5);
    EXPECT_EQ(packet_disagreements(wide, random), 0u);
    // Sparse packets: only some lanes active.
    EXPECT_EQ(packet_disagreements(wide, primary_rays_in_packet_order(scene, 24, 24), 0x8421u), 0u);
  });
}

TEST(RayPackets, RaysThroughVerticesAndEdges) {
  // Vertical rays straight down through every vertex of the box's axis-aligned walls and the
  // spheres: edge functions come out exactly zero, the lanes the scalar test decides in double.
  const Scene scene = make_cornell_box(800);
  std::vector<Ray> rays;
  for (const Triangle& t : scene.triangles) {
    for (const Vec3& v : {t.v0, t.v1, t.v2, (t.v0 + t.v1) * 0.5f}) {
      Ray r;
      r.org = {v.x, scene.bounds.hi.y + 1.0f, v.z};
      r.dir = {0, -1, 0};
      rays.push_back(r);
      r.org = {v.x, v.y, scene.bounds.hi.z + 1.0f};  // and along -z through the same points
      r.dir = {0, 0, -1};
      rays.push_back(r);
    }
  }
  std::stable_partition(rays.begin(), rays.end(),
                        [](const Ray& r) { return r.dir.y != 0.0f; });  // shared axes per packet
  for (const SimdTarget target : targets()) {
    const WideBvh wide(scene, for_target(target));
    EXPECT_EQ(packet_disagreements(wide, rays), 0u) << target_name(target);
  }
}

// An occlusion bundle and the triangle its rays leave.
struct BundleCase {
  RayBundle rays;
  uint32_t origin;
};

// AO-style bundles as the renderer makes them: from random points of random triangles, on both
// sides, offset off the surface or exactly on it (the study's black-image case: a ray that can
// hit the triangle it starts on), unbounded or with a finite tfar; every eighth lane along an
// axis (zero direction components); some bundles sparse or short; and some naming a wrong,
// degenerate or past-the-end origin triangle, which must not change any answer.
std::vector<BundleCase> bundles_for(const Scene& scene, size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  const auto tris = uint32_t(scene.size());
  const float finite = length(scene.bounds.extent()) * 0.2f;
  const Vec3 axes[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<BundleCase> out;
  for (size_t b = 0; b < count; ++b) {
    const uint32_t tri = uint32_t(rng() % tris);
    const Triangle& t = scene.triangles[tri];
    float r1 = u01(rng), r2 = u01(rng);
    if (r1 + r2 > 1.0f) {
      r1 = 1.0f - r1;
      r2 = 1.0f - r2;
    }
    const Vec3 p = t.v0 * (1.0f - r1 - r2) + t.v1 * r1 + t.v2 * r2;
    Vec3 n = t.degenerate() ? Vec3{0, 1, 0} : normalize(t.normal());
    if (b % 2 == 1) n = -n;
    BundleCase c;
    c.rays.org = b % 5 == 0 ? p : offset_origin(p, n);
    c.rays.tfar = b % 3 == 0 ? finite : kInfinity;
    uint32_t lanes = 0xffffu;
    if (b % 7 == 0) lanes = 0x8421u | (rng() & 0xffffu);     // sparse
    if (b % 11 == 0) lanes = (1u << (1 + rng() % 15)) - 1u;  // the first few lanes only
    for (int k = 0; k < kPacketSize; ++k) {
      if (!((lanes >> k) & 1u)) continue;
      c.rays.set_direction(k, k % 8 == 7 ? axes[rng() % 6] : ao_direction(n, u01(rng), u01(rng)));
    }
    c.origin = b % 13 == 0 ? uint32_t(rng() % (uint64_t(tris) + 2)) : tri;
    out.push_back(c);
  }
  return out;
}

// Lanes whose bundle answer differs from occluded() of the lane's ray alone.
template <class A>
size_t bundle_disagreements(const A& accel, const std::vector<BundleCase>& cases) {
  size_t bad = 0;
  for (const BundleCase& c : cases) {
    const uint32_t got = accel.occluded_bundle_from(c.rays, c.origin);
    if ((got & ~c.rays.active) != 0 && bad++ < 3) ADD_FAILURE() << "a lane without a ray reported occluded";
    for (uint32_t bits = c.rays.active; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      const bool alone = accel.occluded(c.rays.ray(k));
      if (alone != (((got >> k) & 1u) != 0) && bad++ < 3)
        ADD_FAILURE() << "bundle lane " << k << " from triangle " << c.origin << ": alone " << alone;
    }
  }
  return bad;
}

// One bundle of `lanes` rays above each vertex and edge midpoint of the box's axis-aligned walls
// and spheres: lane 0 straight down through the point (edge functions exactly zero, decided in
// double), the others spread below it.
std::vector<BundleCase> vertex_and_edge_cases(const Scene& scene, int lanes, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u01(0.0f, 1.0f);
  std::vector<BundleCase> cases;
  for (uint32_t i = 0; i < scene.size(); ++i) {
    const Triangle& t = scene.triangles[i];
    for (const Vec3& v : {t.v0, t.v1, t.v2, (t.v0 + t.v1) * 0.5f}) {
      BundleCase c;
      c.rays.org = {v.x, scene.bounds.hi.y + 1.0f, v.z};
      c.rays.set_direction(0, {0, -1, 0});
      for (int k = 1; k < lanes; ++k) c.rays.set_direction(k, ao_direction({0, -1, 0}, u01(rng), u01(rng)));
      c.origin = i;
      cases.push_back(c);
    }
  }
  return cases;
}

TEST(RayBundles, SameAnswersAsSingleRaysOnEveryTarget) {
  for_each_target_and_scene([](const Scene& scene, SimdTarget target) {
    const std::vector<BundleCase> cases = bundles_for(scene, test::ray_budget(20'000) / kPacketSize, 17);
    const Bvh binary(scene, for_target(target));
    EXPECT_EQ(bundle_disagreements(binary, cases), 0u) << "bvh";
    const WideBvh wide(scene, for_target(target));
    EXPECT_EQ(bundle_disagreements(wide, cases), 0u) << "bvh8";
  });
}

TEST(RayBundles, RaysThroughVerticesAndEdges) {
  const Scene scene = make_cornell_box(800);
  const std::vector<BundleCase> cases = vertex_and_edge_cases(scene, kPacketSize, 3);
  for (const SimdTarget target : targets()) {
    EXPECT_EQ(bundle_disagreements(Bvh(scene, for_target(target)), cases), 0u) << target_name(target) << " bvh";
    EXPECT_EQ(bundle_disagreements(WideBvh(scene, for_target(target)), cases), 0u) << target_name(target) << " bvh8";
  }
}

// The rays of `cases` (every active lane, in order) as sorted streams of up to kCapacity rays.
std::vector<std::unique_ptr<RayStream>> streams_of(const std::vector<BundleCase>& cases) {
  std::vector<std::unique_ptr<RayStream>> out;
  for (const BundleCase& c : cases) {
    for (uint32_t bits = c.rays.active; bits; bits &= bits - 1) {
      if (out.empty() || out.back()->full()) out.push_back(std::make_unique<RayStream>());
      out.back()->push(c.rays.ray(__builtin_ctz(bits)), 0);
    }
  }
  for (auto& s : out) sort_stream(*s);
  return out;
}

// Rays whose stream answer differs from occluded() of the ray alone.
template <class A>
size_t stream_disagreements(const A& accel, const std::vector<std::unique_ptr<RayStream>>& streams) {
  size_t bad = 0;
  for (const auto& s : streams) {
    StreamMask got;
    accel.occluded_stream(*s, got);
    for (uint32_t i = 0; i < s->size; ++i) {
      const bool alone = accel.occluded(s->ray(i));
      if (alone != got.test(i) && bad++ < 3) ADD_FAILURE() << "stream ray " << i << ": alone " << alone;
    }
    for (uint32_t i = s->size; i < RayStream::kCapacity; ++i) {
      if (got.test(i) && bad++ < 3) ADD_FAILURE() << "a slot without a ray reported occluded";
    }
  }
  return bad;
}

TEST(RayStreams, SameAnswersAsSingleRaysOnEveryTarget) {
  // The bundles' AO-style rays (on and off the surface, along the axes, finite and unbounded),
  // sorted and traced as streams: packets of up to 16 rays from different points, the occluder
  // cache carried from group to group.
  for_each_target_and_scene([](const Scene& scene, SimdTarget target) {
    const auto streams = streams_of(bundles_for(scene, test::ray_budget(20'000) / kPacketSize, 23));
    const WideBvh wide(scene, for_target(target));
    EXPECT_EQ(stream_disagreements(wide, streams), 0u) << "bvh8";
  });
}

TEST(RayStreams, RaysThroughVerticesAndEdges) {
  const Scene scene = make_cornell_box(800);
  const std::vector<BundleCase> cases = vertex_and_edge_cases(scene, 4, 5);
  const auto streams = streams_of(cases);
  for (const SimdTarget target : targets())
    EXPECT_EQ(stream_disagreements(WideBvh(scene, for_target(target)), streams), 0u) << target_name(target);
}

TEST(RayStreams, EmbreeStreamsAnswerAsEmbreeSingleRays) {
  if (!embree_available()) GTEST_SKIP() << "no Embree in this build";
  const Scene scene = make_cornell_box(3000);
  const Accelerator embree = build_accelerator(scene, AccelOptions{.kind = AccelKind::Embree});
  const auto streams = streams_of(bundles_for(scene, test::ray_budget(20'000) / kPacketSize, 29));
  embree.visit([&](const auto& a) {
    if constexpr (requires(const RayStream& s, StreamMask& m) { a.occluded_stream(s, m); }) {
      EXPECT_EQ(stream_disagreements(a, streams), 0u);
    } else {
      ADD_FAILURE() << "Embree has no stream kernel";
    }
  });
}

TEST(RayStreams, TheSortIsAStablePermutationGroupedByShearClass) {
  // Random directions with zero components, exact axes and a zero vector among them.
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto s = std::make_unique<RayStream>();
  for (uint32_t i = 0; i < RayStream::kCapacity - 5; ++i) {
    Ray r;
    r.org = {u(rng), u(rng), u(rng)};
    r.dir = {u(rng), u(rng), u(rng)};
    if (i % 9 == 0) r.dir.y = 0.0f;
    if (i % 31 == 0) r.dir = {0.0f, i % 2 ? 1.0f : -1.0f, 0.0f};
    if (i == 100) r.dir = {0.0f, 0.0f, 0.0f};
    if (i == 200) r.dir = {1e-45f, -1e-45f, 0.0f};  // denormal: the key's scale overflows to inf
    s->push(r, uint16_t(i % 256));
  }
  sort_stream(*s);
  std::vector<uint32_t> seen(s->size, 0);
  uint32_t begin = 0;
  for (uint32_t cls = 0; cls < 6; ++cls) {
    ASSERT_LE(begin, s->class_end[cls]);
    for (uint32_t at = begin; at < s->class_end[cls]; ++at) {
      const uint32_t i = s->order[at];
      ASSERT_LT(i, s->size);
      ++seen[i];
      EXPECT_EQ(shear_class(s->ray(i).dir), cls) << "ray " << i;
      if (at > begin) {
        const uint32_t prev = s->order[at - 1];
        const auto key = [&](uint32_t k) { return stream_key(s->ray(k).dir.x, s->ray(k).dir.y, s->ray(k).dir.z); };
        EXPECT_TRUE(key(prev) < key(i) || (key(prev) == key(i) && prev < i)) << "at " << at;
      }
    }
    begin = s->class_end[cls];
  }
  EXPECT_EQ(begin, s->size);
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1u), std::ptrdiff_t(s->size)) << "not a permutation";
  // The same rays give the same order.
  std::vector<uint32_t> first(s->order, s->order + s->size);
  sort_stream(*s);
  EXPECT_TRUE(std::equal(first.begin(), first.end(), s->order));
}

TEST(RayStreams, CountersCountTheStreamStage) {
  const Scene scene = make_cornell_box(800);
  const WideBvh wide(scene, BvhBuildOptions{});
  const auto streams = streams_of(bundles_for(scene, 600, 31));
  ASSERT_FALSE(streams.empty());
  TraversalCounts counts;
  StreamMask counted, plain;
  wide.occluded_stream(*streams[0], counted, counts);
  wide.occluded_stream(*streams[0], plain);
  EXPECT_EQ(counts.rays, streams[0]->size);
  EXPECT_GT(counts.nodes, 0u);
  EXPECT_GT(counts.packs, 0u);
  EXPECT_TRUE(std::equal(std::begin(counted.words), std::end(counted.words), std::begin(plain.words)));
}

}  // namespace
}  // namespace tracer
