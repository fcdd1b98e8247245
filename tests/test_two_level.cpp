// The two-level tree of an instanced scene: a glTF placing one mesh by translations, rotations,
// non-uniform scales and a mirror (written here by tinygltf's writer) loads as one mesh and its
// instances, its hits agree with the same scene flattened, its counters count both levels, and
// it renders like the flattened scene in every integrator, the same image on every scheduler.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <array>
#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "accel/accelerator.hpp"
#include "importers/gltf_loader.hpp"
#include "importers/indexed_mesh.hpp"
#include "importers/scene_file.hpp"
#include "io/exr_io.hpp"
#include "scene_writers.hpp"
#include "test_util.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;
using Matrix = std::array<double, 16>;

// A lumpy ellipsoid (not symmetric, so a mirror shows), with normals and texture coordinates.
IndexedMesh blob(int rings, int segments) {
  IndexedMesh m;
  for (int r = 0; r <= rings; ++r) {
    const double theta = std::numbers::pi * r / rings;
    for (int s = 0; s <= segments; ++s) {
      const double phi = 2.0 * std::numbers::pi * s / segments;
      const double x = std::sin(theta) * std::cos(phi), y = std::cos(theta), z = std::sin(theta) * std::sin(phi);
      m.positions.push_back(Vec3{float(x), float(0.6 * y + 0.25 * x * x), float(0.8 * z)});
      m.normals.push_back(Vec3{float(x), float(y / 0.6), float(z / 0.8)});
      m.uvs.push_back(Vec2{float(s) / float(segments), float(r) / float(rings)});
    }
  }
  for (int r = 0; r < rings; ++r) {
    for (int s = 0; s < segments; ++s) {
      const auto a = uint32_t(r * (segments + 1) + s), b = a + 1, c = a + uint32_t(segments + 1), d = c + 1;
      for (uint32_t i : {a, c, b, b, c, d}) m.indices.push_back(i);
    }
  }
  return m;
}

IndexedMesh quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  IndexedMesh m;
  m.positions = {a, b, c, d};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// Column-major T * R(axis, angle) * S, as a glTF node's matrix.
Matrix trs(Vec3 t, Vec3 axis, double angle, Vec3 s) {
  const Vec3 n = normalize(axis);
  const double c = std::cos(angle), si = std::sin(angle), x = n.x, y = n.y, z = n.z;
  const double r[3][3] = {{c + x * x * (1 - c), x * y * (1 - c) - z * si, x * z * (1 - c) + y * si},
                          {y * x * (1 - c) + z * si, c + y * y * (1 - c), y * z * (1 - c) - x * si},
                          {z * x * (1 - c) - y * si, z * y * (1 - c) + x * si, c + z * z * (1 - c)}};
  const double sc[3] = {s.x, s.y, s.z};
  Matrix m{};
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) m[size_t(4 * col + row)] = r[row][col] * sc[col];
  m[12] = t.x, m[13] = t.y, m[14] = t.z, m[15] = 1.0;
  return m;
}

// The blob placed six times (a translation, a rotation with a non-uniform scale, a mirror, a
// sheared matrix), a floor once and an emissive lamp twice, as a glTF in `dir`.
std::string write_instanced_scene(const std::string& dir) {
  Scene s;
  s.materials.resize(3);
  s.materials[0].kd = Vec3{0.8f, 0.3f, 0.2f};
  s.materials[1].kd = Vec3{0.7f};
  s.materials[2].kd = Vec3{0.0f};
  s.materials[2].ke = Vec3{8.0f};
  append_mesh(s, "blob", blob(16, 24), 0);
  append_mesh(s, "floor", quad({-6, -1, -6}, {-6, -1, 6}, {6, -1, 6}, {6, -1, -6}), 1);
  append_mesh(s, "lamp", quad({-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 0, 0.5f}, {-0.5f, 0, 0.5f}), 2);
  s.finalize();
  test::GltfWriteOptions options;
  options.placements[0] = {trs({-2, 0, 0}, {0, 1, 0}, 0.0, {1, 1, 1}),
                           trs({0, 0.3f, 0}, {0, 1, 0}, 0.7, {1.5f, 0.7f, 1.0f}),
                           trs({2, 0, 0}, {0, 1, 0}, 0.0, {-1, 1, 1}),
                           trs({0, 0.5f, -2.5f}, {1, 0.3f, 0}, 1.1, {0.5f, 1.8f, 0.9f}),
                           trs({-1, 1.4f, 1.5f}, {0, 0, 1}, 2.5, {0.4f, 0.4f, -0.6f}),
                           {0.8, 0.2, 0, 0, -0.1, 1.1, 0.3, 0, 0, 0, -0.7, 0, 0.5, -0.2, 2.2, 1}};
  options.placements[2] = {trs({-1.5f, 4, 0}, {0, 1, 0}, 0.0, {1, 1, 1}),
                           trs({1.5f, 4, 0.5f}, {0, 1, 0}, 0.3, {1.5f, 1, 0.5f})};
  const std::string path = dir + "/inst.gltf";
  test::write_gltf(s, path, options);
  return path;
}

Scene load(const std::string& path, bool keep_instances) {
  LoadLimits limits;
  limits.keep_instances = keep_instances;
  return load_gltf(path, {}, nullptr, limits);
}

class TwoLevel : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir();
    path_ = write_instanced_scene(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string dir_, path_;
};

TEST_F(TwoLevel, AMeshPlacedSeveralTimesIsKeptOnce) {
  const Scene kept = load(path_, true), flat = load(path_, false);
  ASSERT_TRUE(kept.instanced());
  EXPECT_FALSE(flat.instanced());
  EXPECT_EQ(kept.meshes.size(), 3u);
  EXPECT_EQ(kept.instances.size(), 9u);
  EXPECT_EQ(kept.instanced_size(), flat.size());
  EXPECT_EQ(kept.size(), 24u * 16u * 2u + 4u);
  // Each placement of the lamp is an area light and its emitters; the mirror is known.
  EXPECT_EQ(kept.lights.size(), flat.lights.size());
  EXPECT_EQ(kept.emitters.size(), flat.emitters.size());
  int mirrors = 0;
  for (const Instance& in : kept.instances) mirrors += in.mirrors ? 1 : 0;
  EXPECT_EQ(mirrors, 3);  // (-1, 1, 1), (0.4, 0.4, -0.6) and the matrix of determinant -0.63
  const TwoLevelBvh tree(kept, BvhBuildOptions{});
  EXPECT_EQ(tree.validate(), "");
  const auto info = test::run_tracer("info " + path_);
  EXPECT_NE(info.output.find("triangles   " + std::to_string(flat.size()) + " ("), std::string::npos) << info.output;
  EXPECT_NE(info.output.find("degenerate), placed by 9 instances of 3 meshes holding " + std::to_string(kept.size()) +
                             " unique"),
            std::string::npos)
      << info.output;
}

// The same triangle, placed: its corners within a rounding of each other (a mirrored instance
// keeps the mesh's corner order, which the flattened copy reverses).
bool same_triangle(const Triangle& a, const Triangle& b) {
  const auto near = [](Vec3 p, Vec3 q) { return length(p - q) <= 1e-4f * (1.0f + length(p)); };
  return near(a.v0, b.v0) && ((near(a.v1, b.v1) && near(a.v2, b.v2)) || (near(a.v1, b.v2) && near(a.v2, b.v1)));
}

// Random rays through the scene hit the same triangle at the same distance (up to the float
// rounding of moving the ray rather than the triangles) in the two-level tree, the flattened
// scene's 8-wide BVH and Embree's; any-hit answers agree on segments ending just short of the
// hit and just past it.
TEST_F(TwoLevel, HitsAgreeWithTheFlattenedScene) {
  const Scene kept = load(path_, true), flat = load(path_, false);
  const Accelerator two = build_accelerator(kept, {});
  ASSERT_TRUE(two.instanced());
  const WideBvh wide(flat, BvhBuildOptions{});
#ifdef TRACER_HAVE_EMBREE
  const EmbreeAccel embree(flat), embree_two(kept);  // Embree's instance geometry
#endif
  const TwoLevelBvh& tree = std::get<TwoLevelBvh>(*two.impl);
  size_t hits = 0;
  for (const Ray& ray : test::random_rays(flat, test::ray_budget(20000), 7)) {
    Hit a, b;
    const bool ha = tree.intersect(ray, a), hb = wide.intersect(ray, b);
    ASSERT_EQ(ha, hb) << "ray " << hits;
#ifdef TRACER_HAVE_EMBREE
    Hit c, d;
    ASSERT_EQ(embree.intersect(ray, c), hb);
    ASSERT_EQ(embree_two.intersect(ray, d), hb);
    if (hb) {
      EXPECT_EQ(c.tri, b.tri);
      EXPECT_EQ(d.tri, a.tri);
      EXPECT_EQ(d.inst, a.inst);
      EXPECT_EQ(d.geomID, a.geomID);
      EXPECT_NEAR(d.t, a.t, 1e-4f * (1.0f + a.t));
    }
#endif
    if (!ha) {
      EXPECT_FALSE(tree.occluded(ray));
      continue;
    }
    ++hits;
    EXPECT_NEAR(a.t, b.t, 1e-4f * (1.0f + b.t));
    ASSERT_LT(a.inst, kept.instances.size());
    EXPECT_TRUE(same_triangle(kept.world_triangle(a.tri, a.inst), flat.triangles[b.tri]));
    EXPECT_EQ(kept.tri_material[a.tri], flat.tri_material[b.tri]);
    EXPECT_EQ(a.geomID, kept.tri_geom[a.tri]);
    Ray shorter = ray;
    shorter.tfar = b.t * 0.999f;
    EXPECT_EQ(tree.occluded(shorter), wide.occluded(shorter));
    shorter.tfar = b.t * 1.001f;
    EXPECT_EQ(tree.occluded(shorter), wide.occluded(shorter));
  }
  EXPECT_GT(hits, test::ray_budget(20000) / 10);
}

// An AO bundle (up to 16 rays from one point) gets, lane by lane, the answer occluded() gives
// each of its rays, the top level and each instance's mesh searched with the bundle's open rays.
TEST_F(TwoLevel, BundlesAnswerAsSingleRays) {
  const Scene kept = load(path_, true);
  const TwoLevelBvh tree(kept, BvhBuildOptions{});
  const std::vector<Ray> rays = test::random_rays(kept, test::ray_budget(20000), 11);
  size_t occluded = 0;
  for (size_t i = 0; i + 16 <= rays.size(); i += 16) {
    RayBundle bundle;
    bundle.org = rays[i].org;
    bundle.tfar = i % 32 == 0 ? kInfinity : 2.0f;
    for (int k = 0; k < 16; ++k) {
      if ((i / 16 + size_t(k)) % 5 != 0) bundle.set_direction(k, rays[i + size_t(k)].dir);
    }
    TraversalCounts counts;
    const uint32_t bits = tree.occluded_bundle_from(bundle, 0), counted = tree.occluded_bundle_from(bundle, 0, counts);
    EXPECT_EQ(bits, counted);
    EXPECT_EQ(counts.rays, uint64_t(std::popcount(bundle.active)));
    for (int k = 0; k < 16; ++k) {
      const bool expected = (bundle.active >> k & 1) && tree.occluded(bundle.ray(k));
      ASSERT_EQ(bool(bits >> k & 1), expected) << "bundle " << i / 16 << " lane " << k;
      occluded += expected ? 1 : 0;
    }
  }
  EXPECT_GT(occluded, rays.size() / 10);
}

// A packet's lanes get the hits intersect() gives their rays, bit for bit: coherent packets (one
// origin, directions a few degrees apart, as a 4x4 pixel block's) and incoherent ones (random
// rays, whose shear axes differ, so the mesh level takes its ray-by-ray path), some lanes off.
TEST_F(TwoLevel, PacketsAnswerAsSingleRays) {
  const Scene kept = load(path_, true);
  const TwoLevelBvh tree(kept, BvhBuildOptions{});
  const std::vector<Ray> rays = test::random_rays(kept, test::ray_budget(20000), 12);
  size_t hit = 0;
  for (size_t i = 0; i + 16 <= rays.size(); i += 16) {
    const bool coherent = (i / 16) % 2 == 0;
    RayPacket packet;
    for (int k = 0; k < 16; ++k) {
      if ((i / 16 + size_t(k)) % 7 == 0) continue;  // a lane off
      Ray r = rays[i + size_t(k)];
      if (coherent) {
        r.org = rays[i].org;
        r.dir = normalize(rays[i].dir + 0.02f * Vec3{float(k % 4) - 1.5f, float(k / 4) - 1.5f, 0.5f});
      }
      packet.set(k, r);
    }
    Hit hits[16], counted[16];
    TraversalCounts counts;
    tree.intersect_packet(packet, hits);
    tree.intersect_packet(packet, counted, counts);
    for (int k = 0; k < 16; ++k) {
      if (!(packet.active >> k & 1)) continue;
      Hit alone;
      tree.intersect(packet.ray(k), alone);
      for (const Hit* h : {&hits[k], &counted[k]}) {
        ASSERT_EQ(h->tri, alone.tri) << "packet " << i / 16 << " lane " << k;
        ASSERT_EQ(h->inst, alone.inst) << "packet " << i / 16 << " lane " << k;
        ASSERT_EQ(std::bit_cast<uint32_t>(h->t), std::bit_cast<uint32_t>(alone.t));
        ASSERT_EQ(std::bit_cast<uint32_t>(h->u), std::bit_cast<uint32_t>(alone.u));
        ASSERT_EQ(std::bit_cast<uint32_t>(h->v), std::bit_cast<uint32_t>(alone.v));
        ASSERT_EQ(h->geomID, alone.geomID);
        ASSERT_EQ(h->primID, alone.primID);
      }
      hit += alone.valid() ? 1 : 0;
    }
    EXPECT_EQ(counts.rays, uint64_t(std::popcount(packet.active)));
  }
  EXPECT_GT(hit, rays.size() / 10);
}

// --count counts the top level's nodes and, below each instance entered, its mesh tree's: one
// instance placed untransformed (the ray in its space is the ray) counts the top root and exactly
// what the mesh's own tree counts; another far away is never entered.
TEST(TwoLevelCounts, BothLevelsAreCounted) {
  Scene s;
  s.materials.resize(1);
  append_mesh(s, "blob", blob(12, 16), 0);
  s.meshes.push_back({"blob", TriangleRange::all(s), {}});
  Affine far;
  far.m[0][3] = 100.0;
  s.instances = {make_instance(0, Affine{}), make_instance(0, far)};
  s.finalize();
  Scene alone;
  alone.materials.resize(1);
  append_mesh(alone, "blob", blob(12, 16), 0);
  alone.finalize();
  const TwoLevelBvh tree(s, BvhBuildOptions{});
  const WideBvh wide(alone, BvhBuildOptions{});
  ASSERT_EQ(tree.validate(), "");
  Ray ray;
  ray.org = Vec3{0.1f, 0.2f, 5.0f};
  ray.dir = normalize(Vec3{0.0f, -0.05f, -1.0f});
  TraversalCounts two, one;
  Hit a, b;
  ASSERT_TRUE(tree.intersect(ray, a, two));
  ASSERT_TRUE(wide.intersect(ray, b, one));
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.tri, b.tri);
  EXPECT_EQ(a.inst, 0u);
  EXPECT_EQ(two.rays, 1u);
  EXPECT_EQ(two.nodes, one.nodes + 1);  // the top level's root
  EXPECT_EQ(two.packs, one.packs);
  EXPECT_EQ(two.triangles, one.triangles);
  TraversalCounts any_two, any_one;
  EXPECT_TRUE(tree.occluded(ray, any_two));
  EXPECT_TRUE(wide.occluded(ray, any_one));
  EXPECT_EQ(any_two.nodes, any_one.nodes + 1);
}

// What a render of the instanced scene shows is the flattened scene's image (rendered by --accel
// bvh, which loads it expanded) up to the rounding of moving rays rather than triangles: means
// within 1e-4 relative and no pixel off by more than 1e-3 (measured: 1.4e-5 at most, path).
TEST_F(TwoLevel, RendersLikeTheFlattenedScene) {
  const std::string common = path_ + " -q --width 64 --height 48 --eye 0,2.5,9 --look 0,0,0 --exr float";
  for (const std::string integrator : {"ao", "whitted --spp 2", "path --spp 8"}) {
    SCOPED_TRACE(integrator);
    const std::string a = dir_ + "/two.exr", b = dir_ + "/flat.exr";
    ASSERT_EQ(test::run_tracer("render " + common + " --integrator " + integrator + " -o " + a).exit_code, 0);
    ASSERT_EQ(test::run_tracer("render " + common + " --accel bvh --integrator " + integrator + " -o " + b).exit_code,
              0);
    const Framebuffer fa = read_exr(a), fb = read_exr(b);
    double sum_a = 0.0, sum_b = 0.0, worst = 0.0;
    for (int y = 0; y < fa.height(); ++y) {
      for (int x = 0; x < fa.width(); ++x) {
        const Vec3 pa = fa.radiance(x, y), pb = fb.radiance(x, y);
        sum_a += double(pa.x + pa.y + pa.z);
        sum_b += double(pb.x + pb.y + pb.z);
        worst = std::max(worst, double(max_component(abs(pa - pb))));
      }
    }
    EXPECT_GT(sum_a, 0.0);
    EXPECT_NEAR(sum_a, sum_b, 1e-4 * sum_b);
    EXPECT_LT(worst, 1e-3);
  }
}

// The instanced image does not depend on the scheduler or the thread count.
TEST_F(TwoLevel, TheImageIsTheSameOnEveryScheduler) {
  const std::string common = "render " + path_ + " -q --width 48 --height 32 --integrator path --spp 4 -o ";
  ASSERT_EQ(test::run_tracer(common + dir_ + "/a.png --threads 1").exit_code, 0);
  ASSERT_EQ(test::run_tracer(common + dir_ + "/b.png --threads 2 --sched queue --tile 8").exit_code, 0);
  ASSERT_EQ(test::run_tracer(common + dir_ + "/c.png --threads 2 --sched async").exit_code, 0);
  EXPECT_EQ(test::read_bytes(dir_ + "/a.png"), test::read_bytes(dir_ + "/b.png"));
  EXPECT_EQ(test::read_bytes(dir_ + "/a.png"), test::read_bytes(dir_ + "/c.png"));
}

// 10,000 instances of the Bunny, 1.44 billion placed triangles, load and render at 256x256 in a
// peak resident set below 1 GiB (the process's own accounting, --stats-json's peak_rss_mib).
TEST(TwoLevelScale, TenThousandBunniesFitInAGibibyte) {
  if (!test::have_shared_scenes()) GTEST_SKIP() << "../shared/scenes not found";
  const std::string dir = test::temp_dir();
  const Scene bunny = load_scene_file(test::scene_path("bunny/bunny.obj"));
  ASSERT_EQ(bunny.geometries.size(), 1u);
  const Aabb b = bunny.bounds;
  const double step = 1.2 * double(std::max(b.extent().x, b.extent().z));
  test::GltfWriteOptions options;
  for (int i = 0; i < 100; ++i) {
    for (int j = 0; j < 100; ++j) {
      options.placements[0].push_back(
          trs({float(i * step), 0.0f, float(-j * step)}, {0, 1, 0}, 0.37 * (i + 3 * j), {1, 1, 1}));
    }
  }
  const std::string path = dir + "/bunnies.gltf";
  test::write_gltf(bunny, path, options);
  const auto r = test::run_tracer("render " + path + " -q --width 256 --height 256 --integrator ao --eye " +
                                  std::to_string(-3 * step) + ",3," + std::to_string(3 * step) + " --look " +
                                  std::to_string(50 * step) + ",0," + std::to_string(-50 * step) + " -o " + dir +
                                  "/b.png --stats-json " + dir + "/s.json");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json stats = nlohmann::json::parse(std::ifstream(dir + "/s.json"));
  EXPECT_EQ(stats["triangles"].get<uint64_t>(), bunny.size());
  EXPECT_GT(stats["rays"]["primary"].get<uint64_t>(), 0u);
  if (!test::kUnderSanitizer) {
    EXPECT_LT(stats["peak_rss_mib"].get<double>(), 1024.0);
  }
  const auto info = test::run_tracer("info " + path);
  EXPECT_NE(info.output.find("(0 degenerate), placed by 10000 instances of 1 meshes"), std::string::npos)
      << info.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace tracer
