#include "importers/gltf_loader.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <set>
#include <string_view>
#include <unordered_set>

#include "base/memory_limit.hpp"
#include "base/read_input.hpp"
#include "base/stopwatch.hpp"
#include "base/text.hpp"
#include "importers/gltf_counts.hpp"
#include "importers/gltf_document.hpp"
#include "importers/gltf_materials.hpp"
#include "importers/gltf_primitive.hpp"
#include "importers/gltf_viewpoints.hpp"
#include "importers/indexed_mesh.hpp"
#include "scene/scene_info.hpp"
#include "scene/value_limits.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;
namespace tg = tinygltf;
using gltf::kSaturated;
using gltf::Placed;
using gltf::Summary;

// The most triangles a scene may hold (what a triangle index addresses): the unique triangles of an
// instanced scene, all of them once a flat one's instances are expanded. Memory usually refuses
// a scene long before (the estimate below).
constexpr uint64_t kMaxTriangles = UINT32_MAX;
// Deeper node trees than this are refused (real files nest a few dozen levels).
constexpr int kMaxNodeDepth = 256;
// Node visits beyond the document's node count. A conforming document's nodes form trees, each
// walked once; a node that is the child of several parents is walked once per path, and 40 levels
// of such nodes make 2^40 paths in a few hundred bytes. Sharing is allowed up to this many extra
// visits (a binary tree of 2^20 shared instances walks 2^21 nodes); 2^21 placed cameras take
// 0.1 s natively and 4.3 s in fuzz_gltf (coverage and ASan; 2^24 visits took it past its 10 s).
constexpr uint64_t kMaxSharedVisits = uint64_t(1) << 21;

// The document's nodes walked from the chosen scene's roots: meshes placed by their transforms,
// cameras and lights; materials through gltf::Materials.
class GltfScene {
 public:
  GltfScene(const tg::Model& model, std::string name, fs::path base_dir, const LoadLimits& limits, CancelFlag cancel,
            WarningLog& warnings)
      : model_(model),
        name_(std::move(name)),
        base_dir_(std::move(base_dir)),
        limits_(limits),
        cancel_(cancel),
        warnings_(warnings),
        materials_(model_, name_, base_dir_, limits_, cancel_, warnings_) {}

  Scene build() {
    scene_.source = name_;
    warn_unsupported();
    const std::vector<int> roots = root_nodes();
    // The instances' triangles counted first (once per node: a subtree counts the same wherever
    // it is reached), so that a tree that would not fit fails before anything is allocated.
    std::vector<uint64_t> subtree(model_.nodes.size(), kUncounted);
    std::vector<Placed> placed(model_.nodes.size());
    places_.assign(model_.nodes.size(), 0);
    Placed all;
    std::set<int> used_meshes;
    for (int root : roots) all.add(count_placed(root, subtree, placed, used_meshes, 0));
    const Footprint f = footprint(all, used_meshes);
    instanced_ = f.instanced;
    const uint64_t total = f.triangles, primitives = f.primitives, instances = f.instances, estimate = f.bytes;
    if (estimate > limits_.max_memory) {
      const std::string count = total >= kSaturated ? "more than 2^62" : std::to_string(total);
      const std::string what =
          instanced_ ? "its " + count + " unique triangles, " +
                           (instances >= kSaturated ? "more than 2^62" : std::to_string(instances)) + " instances"
                     : "the " + count + " triangles its instances expand to";
      throw InputError(memory_refusal(where(what + (limits_.accel_bytes_per_triangle ? " and their accelerator" : "")),
                                      estimate, limits_.max_memory));
    }
    if (total > kMaxTriangles) {
      throw error(std::string(instanced_ ? "its meshes hold" : "its instances expand to") + " more than " +
                  std::to_string(kMaxTriangles) + " triangles, more than a triangle index addresses");
    }
    // Cameras, lights and the nodes above them cost little memory, so the memory estimate does not
    // bound their visits.
    check_visits(all.nodes);
    // Reserved once: grown by doubling, the arrays would take up to twice the estimate.
    scene_.triangles.reserve(total);
    scene_.tri_geom.reserve(total);
    scene_.tri_prim.reserve(total);
    scene_.tri_material.reserve(total);
    if (any_attribute("NORMAL")) scene_.corner_normals.reserve(3 * total);
    if (any_attribute("TEXCOORD_0")) scene_.corner_uvs.reserve(3 * total);
    if (any_attribute("TEXCOORD_1")) scene_.corner_uvs1.reserve(3 * total);
    if (any_attribute("COLOR_0")) scene_.corner_colors.reserve(3 * total);
    scene_.geometries.reserve(primitives);
    if (instanced_) scene_.instances.reserve(instances);
    // Each node's own transform once: a shared node is walked once per path that reaches it.
    locals_.reserve(model_.nodes.size());
    for (size_t i = 0; i < model_.nodes.size(); ++i) locals_.push_back(local_transform(model_.nodes[i], i, &warnings_));
    std::vector<char> on_path(model_.nodes.size(), 0);
    for (int root : roots)
      if (places_[size_t(root)]) visit(root, Affine{}, on_path, 0);
    if (scene_.triangles.empty()) throw InputError(name_ + ": scene has no triangles");
    materials_.attach_textures(scene_);
    scene_.finalize();
    look_at_centre();
    if (!scene_.cameras.empty()) scene_.camera = scene_.cameras.front();
    return std::move(scene_);
  }

  // What the scene will hold and take: a mesh placed more than once is kept once, with its
  // placements as instances (unless limits_.keep_instances is false); the estimate is its arrays
  // and the accelerator's bytes per triangle, saturating at UINT64_MAX.
  struct Footprint {
    bool instanced = false;
    uint64_t triangles = 0, primitives = 0, instances = 0, bytes = 0;
  };
  Footprint footprint(const Placed& all, const std::set<int>& used_meshes) const {
    uint64_t unique = 0, unique_primitives = 0;
    for (int m : used_meshes) {
      unique += mesh_triangles(m);
      unique_primitives += model_.meshes[size_t(m)].primitives.size();
    }
    Footprint f;
    f.instanced = limits_.keep_instances && all.triangles > unique;
    f.triangles = f.instanced ? unique : all.triangles;
    f.primitives = f.instanced ? unique_primitives : all.primitives;
    f.instances = f.instanced ? all.instances : 0;
    const int uv_sets = int(any_attribute("TEXCOORD_0")) + int(any_attribute("TEXCOORD_1"));
    const uint64_t per_triangle =
        Scene::bytes_per_triangle(any_attribute("NORMAL"), uv_sets, any_attribute("COLOR_0")) +
        limits_.accel_bytes_per_triangle;
    constexpr uint64_t kPerPrimitive = sizeof(Geometry) + 32;  // and its name
    f.bytes = f.triangles >= kSaturated / per_triangle || f.primitives >= kSaturated / kPerPrimitive ||
                      f.instances >= kSaturated / kBytesPerInstance
                  ? UINT64_MAX
                  : f.triangles * per_triangle + f.primitives * kPerPrimitive + f.instances * kBytesPerInstance;
    return f;
  }

  // What tracer info prints, each node counted once however often it is reached: counts and
  // bounds from per-node sums (the bounds are those of the instances' boxes), and the world
  // transform walked only down to the cameras and lights that are listed.
  SceneInfo summarize() {
    warn_unsupported();
    const std::vector<int> roots = root_nodes();
    std::vector<uint64_t> state(model_.nodes.size(), kUncounted);
    std::vector<Summary> sums(model_.nodes.size());
    Summary all;
    for (int root : roots) all.add(summarize_node(root, state, sums, 0), Affine{});
    SceneInfo info;
    info.source = name_;
    info.triangles = all.placed.triangles;
    info.geometries = all.placed.primitives;
    info.vertices = all.vertices;
    info.degenerate = all.degenerate;
    info.unlisted_area_lights = all.emissive;
    info.bounds = all.box;
    std::set<int> used_meshes;
    for (size_t i = 0; i < model_.nodes.size(); ++i) {
      const int mesh = model_.nodes[i].mesh;
      if (state[i] != kUncounted && mesh >= 0 && size_t(mesh) < model_.meshes.size()) used_meshes.insert(mesh);
    }
    const Footprint f = footprint(all.placed, used_meshes);
    if (f.instanced) {
      info.unique_triangles = f.triangles;
      info.meshes = used_meshes.size();
      info.instances = f.instances;
    }
    info.estimated_bytes = f.bytes;
    if (all.placed.primitives > 0 && uses_default_material()) info.materials.push_back(Material{}.name);
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      info.materials.push_back(model_.materials[i].name.empty() ? "material " + std::to_string(i)
                                                                : model_.materials[i].name);
    }
    check_visits(all.listed);
    std::vector<char> on_path(model_.nodes.size(), 0);
    for (int root : roots) visit_listed(root, Affine{}, sums, on_path, 0);
    info.lights = scene_.lights;
    scene_.bounds = info.bounds;
    look_at_centre();
    info.cameras = scene_.cameras;
    return info;
  }

 private:
  InputError error(const std::string& what) const { return InputError(where(what)); }
  std::string where(const std::string& what) const { return name_ + ": " + what; }

  void warn_unsupported() {
    for (const std::string& ext : model_.extensionsRequired) {
      if (!gltf::supported_extension(ext))
        throw error("requires extension " + in_quotes(ext) + ", which tracer does not support");
    }
    for (const std::string& ext : model_.extensionsUsed) {
      if (!gltf::supported_extension(ext)) warnings_.add("extension " + in_quotes(ext) + " is not supported: ignored");
    }
    if (!model_.skins.empty()) {
      warnings_.add(std::to_string(model_.skins.size()) + " skin(s) not applied: meshes are rendered as bound");
    }
    if (!model_.animations.empty()) {
      warnings_.add(std::to_string(model_.animations.size()) + " animation(s) ignored: the scene is rendered at rest");
    }
  }

  int choose_scene() {
    if (model_.scenes.empty()) return -1;
    const int chosen =
        model_.defaultScene >= 0 && size_t(model_.defaultScene) < model_.scenes.size() ? model_.defaultScene : 0;
    if (model_.scenes.size() > 1) {
      warnings_.add(std::to_string(model_.scenes.size()) + " scenes: rendering scene " + std::to_string(chosen));
    }
    return chosen;
  }

  bool uses_default_material() const {
    for (const tg::Mesh& m : model_.meshes)
      for (const tg::Primitive& p : m.primitives)
        if (p.material < 0) return true;
    return false;
  }

  // The chosen scene's root nodes; with no scenes, every node no other node names as a child.
  std::vector<int> root_nodes() {
    const int chosen = choose_scene();
    if (chosen >= 0) return model_.scenes[size_t(chosen)].nodes;
    std::vector<int> roots;
    std::vector<char> is_child(model_.nodes.size(), 0);
    for (const tg::Node& n : model_.nodes)
      for (int c : n.children)
        if (c >= 0 && size_t(c) < is_child.size()) is_child[size_t(c)] = 1;
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      if (!is_child[i]) roots.push_back(int(i));
    return roots;
  }

  Summary summarize_node(int index, std::vector<uint64_t>& state, std::vector<Summary>& sums, int depth) {
    throw_if_cancelled(cancel_);
    check_node(index, depth);
    uint64_t& s = state[size_t(index)];
    if (s == kCounting) throw error("node " + std::to_string(index) + " is its own ancestor");
    if (s != kUncounted) return sums[size_t(index)];
    s = kCounting;
    const tg::Node& node = model_.nodes[size_t(index)];
    Summary here;  // in the node's own frame first
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size()) {
        throw error("mesh " + std::to_string(node.mesh) + " does not exist (the file has " +
                    std::to_string(model_.meshes.size()) + ")");
      }
      const tg::Mesh& m = model_.meshes[size_t(node.mesh)];
      for (size_t k = 0; k < m.primitives.size(); ++k) {
        auto [it, fresh] = meshes_.try_emplace({node.mesh, int(k)});
        if (fresh)
          it->second = gltf::primitive_mesh(model_, name_, warnings_, m.primitives[k], primitive_name(node.mesh, k));
        if (!it->second) continue;
        const int material = m.primitives[k].material;
        bool emissive = false;
        if (material >= 0 && size_t(material) < model_.materials.size()) {
          const std::vector<double>& e = model_.materials[size_t(material)].emissiveFactor;
          emissive = e.size() >= 3 && (e[0] > 0.0 || e[1] > 0.0 || e[2] > 0.0);
        }
        here.add(gltf::summary_of(*it->second, emissive), Affine{});
      }
      here.placed.instances = 1;
    }
    for (int child : node.children) {
      here.add(summarize_node(child, state, sums, depth + 1), local_transform(model_.nodes[size_t(child)]));
    }
    if (here.listed > 0 || node.camera >= 0 || gltf::extension(node.extensions, "KHR_lights_punctual"))
      here.listed = std::min(here.listed + 1, kSaturated);
    s = 0;
    sums[size_t(index)] = here;
    return here;
  }

  // The cameras and lights below `index`, placed; subtrees without any are not entered.
  void visit_listed(int index, const Affine& parent, const std::vector<Summary>& sums, std::vector<char>& on_path,
                    int depth) {
    throw_if_cancelled(cancel_);
    if (!sums[size_t(index)].listed) return;
    const tg::Node& node = model_.nodes[size_t(index)];
    const Affine world = parent * local_transform(node);
    if (!world.finite()) throw error("node " + std::to_string(index) + " has a transform that is not finite");
    if (node.camera >= 0) add_camera(node.camera, world);
    if (const tg::Value* light = gltf::extension(node.extensions, "KHR_lights_punctual")) add_light(*light, world);
    for (int child : node.children) visit_listed(child, world, sums, on_path, depth + 1);
  }

  // A glTF camera has no point it looks at: the look-at point (where the lens focuses by
  // default) is taken level with the scene's centre along the view.
  void look_at_centre() {
    for (CameraSpec& c : scene_.cameras) {
      const Vec3 forward = c.look - c.eye;
      const float d = dot(scene_.bounds.center() - c.eye, forward);
      if (d > 0.0f && std::isfinite(d)) c.look = c.eye + forward * d;
    }
  }

  // The specification's node transform. A zero quaternion, which it does not allow but exporters
  // have written, is read as no rotation and said (into `warnings`, once per node).
  static Affine local_transform(const tg::Node& n, size_t index = 0, WarningLog* warnings = nullptr) {
    const auto warn = [&](const std::string& what) {
      if (warnings) warnings->add("node " + std::to_string(index) + " " + what);
    };
    if (n.matrix.size() == 16) return Affine::from_column_major(n.matrix.data());  // TRS beside: gltf_json
    const double t[3] = {n.translation.size() == 3 ? n.translation[0] : 0.0,
                         n.translation.size() == 3 ? n.translation[1] : 0.0,
                         n.translation.size() == 3 ? n.translation[2] : 0.0};
    double q[4] = {0.0, 0.0, 0.0, 1.0};
    if (n.rotation.size() == 4) {
      const double len = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] +
                                   n.rotation[2] * n.rotation[2] + n.rotation[3] * n.rotation[3]);
      if (len > 0.0) {
        for (int i = 0; i < 4; ++i) q[i] = n.rotation[size_t(i)] / len;
      } else {
        warn("has a zero rotation quaternion (not a rotation): read as none");
      }
    }
    const double s[3] = {n.scale.size() == 3 ? n.scale[0] : 1.0, n.scale.size() == 3 ? n.scale[1] : 1.0,
                         n.scale.size() == 3 ? n.scale[2] : 1.0};
    return Affine::from_trs(t, q, s);
  }

  static constexpr uint64_t kUncounted = ~uint64_t(0), kCounting = ~uint64_t(0) - 1;

  // Whether any primitive has the attribute (the scene then keeps it for every triangle).
  bool any_attribute(const char* name) const {
    for (const tg::Mesh& m : model_.meshes)
      for (const tg::Primitive& p : m.primitives)
        if (p.attributes.count(name)) return true;
    return false;
  }

  void check_visits(uint64_t visits) const {
    const uint64_t max_visits = model_.nodes.size() + kMaxSharedVisits;
    if (visits > max_visits) {
      throw error("its nodes, children of more than one parent, expand to more than " + std::to_string(max_visits) +
                  " node instances, more than tracer walks");
    }
  }

  void check_node(int index, int depth) const {
    if (index < 0 || size_t(index) >= model_.nodes.size()) {
      throw error("node " + std::to_string(index) + " does not exist (the file has " +
                  std::to_string(model_.nodes.size()) + ")");
    }
    if (depth >= kMaxNodeDepth) throw error("nodes nest deeper than " + std::to_string(kMaxNodeDepth) + " levels");
  }

  // The triangles mesh `index` declares (before its accessors are checked: at most what they say).
  uint64_t mesh_triangles(int index) const {
    if (index < 0 || size_t(index) >= model_.meshes.size()) return 0;
    uint64_t n = 0;
    const tg::Mesh& m = model_.meshes[size_t(index)];
    for (size_t k = 0; k < m.primitives.size(); ++k) {
      const tg::Primitive& p = m.primitives[k];
      const auto pos = p.attributes.find("POSITION");
      if (pos == p.attributes.end()) continue;
      const std::string what = primitive_name(index, k);
      const uint64_t count = p.indices >= 0 ? gltf::elements(model_, p.indices, where(what + " indices")).count
                                            : gltf::elements(model_, pos->second, where(what + " POSITION")).count;
      const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
      if (mode == TINYGLTF_MODE_TRIANGLES) n += count / 3;
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP || mode == TINYGLTF_MODE_TRIANGLE_FAN) n += count > 2 ? count - 2 : 0;
    }
    return n;
  }

  Placed count_placed(int index, std::vector<uint64_t>& subtree, std::vector<Placed>& placed, std::set<int>& used,
                      int depth) {
    check_node(index, depth);
    uint64_t& state = subtree[size_t(index)];
    if (state == kCounting) throw error("node " + std::to_string(index) + " is its own ancestor");
    if (state != kUncounted) return placed[size_t(index)];
    state = kCounting;
    const tg::Node& node = model_.nodes[size_t(index)];
    Placed sum;
    if (node.mesh >= 0 && size_t(node.mesh) < model_.meshes.size()) {
      sum.triangles = mesh_triangles(node.mesh);
      sum.primitives = model_.meshes[size_t(node.mesh)].primitives.size();
      sum.instances = 1;
      used.insert(node.mesh);
    }
    for (int child : node.children) sum.add(count_placed(child, subtree, placed, used, depth + 1));
    // A subtree that places nothing (no mesh, camera or light) is not walked, so not counted.
    places_[size_t(index)] =
        node.mesh >= 0 || node.camera >= 0 || sum.nodes > 0 || gltf::extension(node.extensions, "KHR_lights_punctual");
    if (places_[size_t(index)]) sum.nodes = std::min(sum.nodes + 1, kSaturated);
    state = 0;
    placed[size_t(index)] = sum;
    return sum;
  }

  void visit(int index, const Affine& parent, std::vector<char>& on_path, int depth) {
    throw_if_cancelled(cancel_);
    check_node(index, depth);
    if (on_path[size_t(index)]) throw error("node " + std::to_string(index) + " is its own ancestor");
    const tg::Node& node = model_.nodes[size_t(index)];
    const Affine world = parent * locals_[size_t(index)];
    if (!world.finite()) throw error("node " + std::to_string(index) + " has a transform that is not finite");
    if (node.mesh >= 0) add_mesh_instance(node, world);
    if (node.camera >= 0) add_camera(node.camera, world);
    if (const tg::Value* light = gltf::extension(node.extensions, "KHR_lights_punctual")) add_light(*light, world);
    on_path[size_t(index)] = 1;
    for (int child : node.children)
      if (places_[size_t(child)]) visit(child, world, on_path, depth + 1);
    on_path[size_t(index)] = 0;
  }

  // One primitive as an indexed triangle mesh (its index list made triangles whatever its mode).
  std::string primitive_name(int mesh, size_t k) const {
    const std::string& name = model_.meshes[size_t(mesh)].name;
    return "mesh " + std::to_string(mesh) + (name.empty() ? "" : " " + in_quotes(name)) + " primitive " +
           std::to_string(k);
  }

  void add_mesh_instance(const tg::Node& node, const Affine& world) {
    if (size_t(node.mesh) >= model_.meshes.size()) {
      throw error("mesh " + std::to_string(node.mesh) + " does not exist (the file has " +
                  std::to_string(model_.meshes.size()) + ")");
    }
    // The same mesh placed again by the same transform, as traced (a node listed twice, nested
    // identity nodes), is the same surface twice: it adds nothing to the image but a descent per
    // ray and a tie at every hit, so it is placed once.
    Placement placement{node.mesh, {}};
    const Transform traced = Transform::of(world);
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 4; ++k) placement.m[size_t(4 * r + k)] = traced.m[r][k] + 0.0f;  // -0 as 0
    if (!placements_.insert(placement).second) {
      warnings_.add(
          "meshes placed again by the same transform as an earlier placement (the same surface twice): "
          "placed once");
      return;
    }
    if (node.skin >= 0) warnings_.add("skinned meshes are rendered as bound, unposed");
    if (instanced_) return add_instance(node.mesh, world);
    const tg::Mesh& m = model_.meshes[size_t(node.mesh)];
    for (size_t k = 0; k < m.primitives.size(); ++k) {
      const tg::Primitive& p = m.primitives[k];
      const std::string what = primitive_name(node.mesh, k);
      auto [it, fresh] = meshes_.try_emplace({node.mesh, int(k)});
      if (fresh) it->second = gltf::primitive_mesh(model_, name_, warnings_, p, what);
      if (!it->second) continue;
      const IndexedMesh& mesh = *it->second;
      if (scene_.triangles.size() + mesh.triangle_count() > kMaxTriangles) {
        throw error("its instances expand to more than " + std::to_string(kMaxTriangles) +
                    " triangles, more than tracer loads");
      }
      const size_t first = scene_.triangles.size();
      append_mesh(scene_, m.name.empty() ? what : m.name, mesh, material_for(p, mesh, what), world);
      for (size_t t = first; t < scene_.triangles.size(); ++t) {
        const Triangle& tri = scene_.triangles[t];
        for (const Vec3& v : {tri.v0, tri.v1, tri.v2}) {
          if (!is_finite(v) || std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > kMaxCoordinate) {
            throw error(what + ": its node's transform moves a vertex beyond +-" + std::string(kMaxCoordinateText));
          }
        }
      }
    }
  }

  // Instance mode: glTF mesh `mesh` as one scene mesh (its primitives appended once, in its own
  // space) and this placement of it.
  // The scene material of primitive `p`, once its texture slots are known to read sets it has.
  uint32_t material_for(const tg::Primitive& p, const IndexedMesh& mesh, const std::string& what) {
    const uint32_t index = materials_.material(p.material, scene_);
    const Material& m = scene_.materials[index];
    for (const TextureSlot* t : m.slots()) {
      if (t->present() && t->uv_set == 1 && mesh.uvs1.empty()) {
        throw error(what + ": material " + in_quotes(m.name) + " reads TEXCOORD_1, which the primitive lacks");
      }
    }
    return index;
  }

  void add_instance(int mesh, const Affine& world) {
    auto [it, fresh] = scene_meshes_.try_emplace(mesh, kInvalidIndex);
    if (fresh) it->second = add_scene_mesh(mesh);
    if (it->second == kInvalidIndex) return;  // no triangles
    const double det = world.determinant();
    const Affine inverse = world.inverse();
    if (det == 0.0 || !inverse.finite()) {
      warnings_.add("instances with a singular transform (a zero scale) place nothing: not rendered");
      return;
    }
    const Aabb& box = object_boxes_[it->second];
    for (int k = 0; k < 8; ++k) {
      const Vec3 v =
          world.point({(k & 1) ? box.hi.x : box.lo.x, (k & 2) ? box.hi.y : box.lo.y, (k & 4) ? box.hi.z : box.lo.z});
      if (!is_finite(v) || std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > kMaxCoordinate) {
        throw error(primitive_name(mesh, 0) + ": its node's transform moves a vertex beyond +-" +
                    std::string(kMaxCoordinateText));
      }
    }
    scene_.instances.push_back(make_instance(it->second, world));
  }

  // Appends glTF mesh `mesh`'s primitives untransformed as one scene mesh; returns its index, or
  // kInvalidIndex when it has no triangles.
  uint32_t add_scene_mesh(int mesh) {
    const tg::Mesh& m = model_.meshes[size_t(mesh)];
    const auto first = uint32_t(scene_.triangles.size());
    Aabb box;
    for (size_t k = 0; k < m.primitives.size(); ++k) {
      const tg::Primitive& p = m.primitives[k];
      const std::string what = primitive_name(mesh, k);
      auto [it, fresh] = meshes_.try_emplace({mesh, int(k)});
      if (fresh) it->second = gltf::primitive_mesh(model_, name_, warnings_, p, what);
      if (!it->second) continue;
      for (const Vec3& v : it->second->positions) box.extend(v);  // each within range (primitive_mesh)
      append_mesh(scene_, m.name.empty() ? what : m.name, *it->second, material_for(p, *it->second, what));
      it->second.reset();  // placed once: its arrays are the scene's now
    }
    const auto count = uint32_t(scene_.triangles.size() - first);
    if (count == 0) return kInvalidIndex;
    scene_.meshes.push_back({m.name.empty() ? "mesh " + std::to_string(mesh) : m.name, {first, count}, {}});
    object_boxes_.push_back(box);
    return uint32_t(scene_.meshes.size() - 1);
  }

  void add_camera(int index, const Affine& world) {
    if (std::optional<CameraSpec> c = gltf::camera_of(model_, name_, warnings_, index, world))
      scene_.cameras.push_back(*c);
  }

  void add_light(const tg::Value& ext, const Affine& world) {
    if (std::optional<Light> l = gltf::light_of(model_, name_, warnings_, ext, world)) scene_.lights.push_back(*l);
  }

  const tg::Model& model_;
  std::string name_;
  fs::path base_dir_;
  const LoadLimits& limits_;
  CancelFlag cancel_;
  WarningLog& warnings_;
  Scene scene_;
  std::map<std::pair<int, int>, std::optional<IndexedMesh>> meshes_;  // (mesh, primitive)
  bool instanced_ = false;                                            // meshes kept once, placed by instances
  std::map<int, uint32_t> scene_meshes_;                              // glTF mesh -> Scene::meshes index
  std::vector<Aabb> object_boxes_;                                    // per scene mesh, of its vertices
  std::vector<Affine> locals_;                                        // per node, its own transform
  // Each mesh placed so far and its transform, as the renderer's floats.
  struct Placement {
    int mesh;
    std::array<float, 12> m;
    bool operator==(const Placement&) const = default;
  };
  struct PlacementHash {
    size_t operator()(const Placement& p) const {
      return std::hash<std::string_view>{}(std::string_view(reinterpret_cast<const char*>(p.m.data()), sizeof p.m)) ^
             (size_t(p.mesh) * 0x9e3779b97f4a7c15ull);
    }
  };
  std::unordered_set<Placement, PlacementHash> placements_;
  std::vector<char> places_;  // per node: its subtree holds a mesh, camera or light
  gltf::Materials materials_;
};

Scene load(std::string_view bytes, const std::string& name, const fs::path& base_dir, const WarningSink& warn_in,
           CancelFlag cancel, const LoadLimits& limits, LoadPhases* phases) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  const auto parse_start = Clock::now();
  WarningLog warnings;
  const tg::Model model = gltf::parse(bytes, name, base_dir, limits, cancel, warnings);
  if (phases) phases->parse_ms = ms_since(parse_start);
  const auto build_start = Clock::now();
  Scene scene = GltfScene(model, name, base_dir, limits, cancel, warnings).build();
  if (phases) phases->assembly_ms = ms_since(build_start);
  warnings.flush(name, warn);
  return scene;
}

}  // namespace

SceneInfo gltf_info(const std::string& path, const WarningSink& warn_in, CancelFlag cancel, const LoadLimits& limits) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  const InputBytes bytes = map_input(path, cancel, limits.max_obj_bytes);
  const fs::path dir = fs::path(path).parent_path();
  WarningLog warnings;
  const tg::Model model = gltf::parse(bytes.view(), path, dir.empty() ? fs::path(".") : dir, limits, cancel, warnings);
  LoadLimits geometry_only = limits;
  geometry_only.read_textures = false;
  SceneInfo info = GltfScene(model, path, dir, geometry_only, cancel, warnings).summarize();
  warnings.flush(path, warn);
  return info;
}

Scene load_gltf(const std::string& path, const WarningSink& warn, CancelFlag cancel, const LoadLimits& limits,
                LoadPhases* phases) {
  const auto read_start = Clock::now();
  const InputBytes bytes = map_input(path, cancel, limits.max_obj_bytes);
  if (phases) phases->read_ms = ms_since(read_start);
  const fs::path dir = fs::path(path).parent_path();
  return load(bytes.view(), path, dir.empty() ? fs::path(".") : dir, warn, cancel, limits, phases);
}

Scene load_gltf_from_memory(std::string_view bytes, const std::string& name, const WarningSink& warn,
                            const LoadLimits& limits) {
  return load(bytes, name, fs::path(), warn, nullptr, limits, nullptr);
}

}  // namespace tracer
