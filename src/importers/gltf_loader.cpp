#include "importers/gltf_loader.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <numbers>
#include <optional>
#include <set>

#include "base/byte_budget.hpp"
#include "base/read_input.hpp"
#include "base/stopwatch.hpp"
#include "base/text.hpp"
#include "importers/indexed_mesh.hpp"
#include "importers/tinygltf.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;
namespace tg = tinygltf;

// The most triangles a scene may hold once its instances are expanded: a node tree that reuses a
// mesh 2^30 times in a few hundred bytes must fail, not exhaust memory (33.5M triangles is about
// 3.6 GB with their normals and texture coordinates).
constexpr uint64_t kMaxTriangles = uint64_t(1) << 25;
// Deeper node trees than this are refused (real files nest a few dozen levels).
constexpr int kMaxNodeDepth = 256;

// What tinygltf's file callbacks may read: files inside `root` (the scene's folder), each within
// `max_bytes`. An empty root reads nothing (a scene from memory).
struct FileAccess {
  fs::path root;
  uint64_t max_bytes = 0;
  CancelFlag cancel = nullptr;
  mutable std::string refused;  // why the last file could not be read (tinygltf wraps it)
  // The file inside the root `path` names, or nothing with `why` set.
  std::optional<fs::path> inside(const std::string& path, std::string* why) const {
    if (root.empty()) {
      if (why) *why = "'" + escaped(path) + "': a scene read from memory refers to no files";
      return std::nullopt;
    }
    std::error_code ec;
    const fs::path real = fs::weakly_canonical(path, ec);
    const fs::path rel = ec ? fs::path() : real.lexically_relative(root);
    if (ec || rel.empty() || *rel.begin() == "..") {
      if (why) *why = "'" + escaped(path) + "' lies outside the scene's folder: refused";
      return std::nullopt;
    }
    return real;
  }
};

// Whether it exists at all: reading it then says when it lies outside the folder.
bool file_exists(const std::string& path, void* user) {
  const auto* access = static_cast<const FileAccess*>(user);
  std::error_code ec;
  return !access->root.empty() && fs::exists(path, ec);
}

// No ~ or $VAR expansion: a URI names a file beside the scene, nothing else.
std::string expand_file_path(const std::string& path, void*) { return path; }

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const auto* access = static_cast<const FileAccess*>(user);
  const std::optional<fs::path> file = access->inside(path, &access->refused);
  if (!file) return false;
  try {
    const std::string bytes = read_input(file->string(), access->cancel, access->max_bytes);
    out->assign(bytes.begin(), bytes.end());
    return true;
  } catch (const InputError& e) {
    access->refused = e.what();
    if (err) *err = access->refused;
    return false;
  }
}

bool refuse_write(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
  if (err) *err = "tracer writes no files while loading";
  return false;
}

// Images stay encoded: tracer decodes the ones its materials use, within its texture limits.
bool keep_encoded(tg::Image* image, const int, std::string*, std::string*, int, int, const unsigned char* bytes,
                  int size, void*) {
  image->image.assign(bytes, bytes + size);
  return true;
}

// %XX escapes in a URI's path (glTF URIs are percent-encoded).
std::string decode_uri(const std::string& uri) {
  std::string out;
  for (size_t i = 0; i < uri.size(); ++i) {
    const auto hex = [](char c) {
      return c >= '0' && c <= '9' ? c - '0'
                                  : (c >= 'a' && c <= 'f' ? c - 'a' + 10 : (c >= 'A' && c <= 'F' ? c - 'A' + 10 : -1));
    };
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

Vec3 vec3_of(const std::vector<double>& v, Vec3 fallback) {
  return v.size() >= 3 ? Vec3{float(v[0]), float(v[1]), float(v[2])} : fallback;
}

const tg::Value* extension(const tg::ExtensionMap& map, const char* name) {
  const auto it = map.find(name);
  return it == map.end() ? nullptr : &it->second;
}

double number(const tg::Value* object, const char* key, double fallback) {
  if (!object || !object->IsObject() || !object->Has(key)) return fallback;
  const tg::Value& v = object->Get(key);
  return v.IsNumber() || v.IsInt() || v.IsReal() ? v.GetNumberAsDouble() : fallback;
}

const char* kSupportedExtensions[] = {
    "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior",
    "KHR_materials_specular",          "KHR_lights_punctual",        "KHR_mesh_quantization"};

bool supported(const std::string& ext) {
  return std::any_of(std::begin(kSupportedExtensions), std::end(kSupportedExtensions),
                     [&](const char* s) { return ext == s; });
}

// The elements of one accessor, checked to lie inside its buffer view and buffer.
struct Elements {
  const unsigned char* data = nullptr;
  size_t count = 0, stride = 0;
  int component_type = 0, components = 0;
  bool normalized = false;

  // Component k of element i as a float; normalised integers mapped to [0, 1] or [-1, 1].
  float get(size_t i, int k) const {
    const unsigned char* p = data + i * stride;
    switch (component_type) {
      case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float f;
        std::memcpy(&f, p + 4 * k, 4);
        return f;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        const float v = float(p[k]);
        return normalized ? v / 255.0f : v;
      }
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        const float v = float(int8_t(p[k]));
        return normalized ? std::max(v / 127.0f, -1.0f) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t u;
        std::memcpy(&u, p + 2 * k, 2);
        return normalized ? float(u) / 65535.0f : float(u);
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t s;
        std::memcpy(&s, p + 2 * k, 2);
        return normalized ? std::max(float(s) / 32767.0f, -1.0f) : float(s);
      }
      default:
        return 0.0f;
    }
  }
  uint32_t index(size_t i) const {
    const unsigned char* p = data + i * stride;
    if (component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE) return p[0];
    if (component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
      uint16_t u;
      std::memcpy(&u, p, 2);
      return u;
    }
    uint32_t u;
    std::memcpy(&u, p, 4);
    return u;
  }
};

// A texture a material asked for: an image, how it is read (colour, or data for a normal map),
// and the linear factor folded into its texels.
struct TextureUse {
  int image = -1;
  bool data = false;
  Vec3 tint{1.0f};
  auto operator<=>(const TextureUse& o) const {
    return std::tie(image, data, tint.x, tint.y, tint.z) <=> std::tie(o.image, o.data, o.tint.x, o.tint.y, o.tint.z);
  }
  bool operator==(const TextureUse&) const = default;
};

class GltfScene {
 public:
  GltfScene(const tg::Model& model, std::string name, fs::path base_dir, const LoadLimits& limits, CancelFlag cancel,
            WarningLog& warnings)
      : model_(model),
        name_(std::move(name)),
        base_dir_(std::move(base_dir)),
        limits_(limits),
        cancel_(cancel),
        warnings_(warnings) {}

  Scene build() {
    scene_.source = name_;
    warn_unsupported();
    const int chosen = choose_scene();
    std::vector<int> roots;
    if (chosen >= 0) {
      roots = model_.scenes[size_t(chosen)].nodes;
    } else {  // no scenes: every node no other node names as a child
      std::vector<char> is_child(model_.nodes.size(), 0);
      for (const tg::Node& n : model_.nodes)
        for (int c : n.children)
          if (c >= 0 && size_t(c) < is_child.size()) is_child[size_t(c)] = 1;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(int(i));
    }
    // The instances' triangles counted first, so that a tree that would expand past the limit
    // fails before anything is allocated.
    std::vector<uint64_t> subtree(model_.nodes.size(), kUncounted);
    uint64_t total = 0;
    for (int root : roots) total = std::min(total + count_triangles(root, subtree, 0), kMaxTriangles + 1);
    if (total > kMaxTriangles) {
      throw error("its instances expand to more than " + std::to_string(kMaxTriangles) +
                  " triangles, more than tracer loads");
    }
    std::vector<char> on_path(model_.nodes.size(), 0);
    for (int root : roots) visit(root, Affine{}, on_path, 0);
    if (scene_.triangles.empty()) throw InputError(name_ + ": scene has no triangles");
    attach_textures();
    scene_.finalize();
    // A glTF camera has no point it looks at: the look-at point (where the lens focuses by
    // default) is taken level with the scene's centre along the view.
    for (CameraSpec& c : scene_.cameras) {
      const Vec3 forward = c.look - c.eye;
      const float d = dot(scene_.bounds.center() - c.eye, forward);
      if (d > 0.0f && std::isfinite(d)) c.look = c.eye + forward * d;
    }
    if (!scene_.cameras.empty()) scene_.camera = scene_.cameras.front();
    return std::move(scene_);
  }

 private:
  InputError error(const std::string& what) const { return InputError(name_ + ": " + what); }

  void warn_unsupported() {
    for (const std::string& ext : model_.extensionsRequired) {
      if (!supported(ext)) throw error("requires extension " + in_quotes(ext) + ", which tracer does not support");
    }
    for (const std::string& ext : model_.extensionsUsed) {
      if (!supported(ext)) warnings_.add("extension " + in_quotes(ext) + " is not supported: ignored");
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

  static Affine local_transform(const tg::Node& n) {
    if (n.matrix.size() == 16) return Affine::from_column_major(n.matrix.data());
    const double t[3] = {n.translation.size() == 3 ? n.translation[0] : 0.0,
                         n.translation.size() == 3 ? n.translation[1] : 0.0,
                         n.translation.size() == 3 ? n.translation[2] : 0.0};
    double q[4] = {0.0, 0.0, 0.0, 1.0};
    if (n.rotation.size() == 4) {
      const double len = std::sqrt(n.rotation[0] * n.rotation[0] + n.rotation[1] * n.rotation[1] +
                                   n.rotation[2] * n.rotation[2] + n.rotation[3] * n.rotation[3]);
      if (len > 0.0)
        for (int i = 0; i < 4; ++i) q[i] = n.rotation[size_t(i)] / len;
    }
    const double s[3] = {n.scale.size() == 3 ? n.scale[0] : 1.0, n.scale.size() == 3 ? n.scale[1] : 1.0,
                         n.scale.size() == 3 ? n.scale[2] : 1.0};
    return Affine::from_trs(t, q, s);
  }

  static constexpr uint64_t kUncounted = ~uint64_t(0), kCounting = ~uint64_t(0) - 1;

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
      const uint64_t count = p.indices >= 0 ? elements(p.indices, what + " indices").count
                                            : elements(pos->second, what + " POSITION").count;
      const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
      if (mode == TINYGLTF_MODE_TRIANGLES) n += count / 3;
      if (mode == TINYGLTF_MODE_TRIANGLE_STRIP || mode == TINYGLTF_MODE_TRIANGLE_FAN) n += count > 2 ? count - 2 : 0;
    }
    return n;
  }

  // The triangles node `index` and its descendants place (memoised; saturating past the limit).
  uint64_t count_triangles(int index, std::vector<uint64_t>& subtree, int depth) const {
    check_node(index, depth);
    uint64_t& n = subtree[size_t(index)];
    if (n == kCounting) throw error("node " + std::to_string(index) + " is its own ancestor");
    if (n != kUncounted) return n;
    n = kCounting;
    const tg::Node& node = model_.nodes[size_t(index)];
    uint64_t sum = std::min(mesh_triangles(node.mesh), kMaxTriangles + 1);
    for (int child : node.children) sum = std::min(sum + count_triangles(child, subtree, depth + 1), kMaxTriangles + 1);
    n = sum;
    return n;
  }

  void visit(int index, const Affine& parent, std::vector<char>& on_path, int depth) {
    throw_if_cancelled(cancel_);
    check_node(index, depth);
    if (on_path[size_t(index)]) throw error("node " + std::to_string(index) + " is its own ancestor");
    const tg::Node& node = model_.nodes[size_t(index)];
    const Affine world = parent * local_transform(node);
    if (!world.finite()) throw error("node " + std::to_string(index) + " has a transform that is not finite");
    if (node.mesh >= 0) add_mesh_instance(node, world);
    if (node.camera >= 0) add_camera(node.camera, world);
    if (const tg::Value* light = extension(node.extensions, "KHR_lights_punctual")) add_light(*light, world);
    on_path[size_t(index)] = 1;
    for (int child : node.children) visit(child, world, on_path, depth + 1);
    on_path[size_t(index)] = 0;
  }

  Elements elements(int accessor, const std::string& what) const {
    if (accessor < 0 || size_t(accessor) >= model_.accessors.size()) {
      throw error(what + ": accessor " + std::to_string(accessor) + " does not exist (the file has " +
                  std::to_string(model_.accessors.size()) + ")");
    }
    const tg::Accessor& a = model_.accessors[size_t(accessor)];
    const std::string where = what + " (accessor " + std::to_string(accessor) + ")";
    if (a.sparse.isSparse) throw error(where + ": sparse accessors are not supported");
    if (a.bufferView < 0 || size_t(a.bufferView) >= model_.bufferViews.size()) {
      throw error(where + ": no buffer view (buffer view " + std::to_string(a.bufferView) + ")");
    }
    const tg::BufferView& view = model_.bufferViews[size_t(a.bufferView)];
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size()) {
      throw error(where + ": buffer " + std::to_string(view.buffer) + " does not exist");
    }
    const size_t buffer_size = model_.buffers[size_t(view.buffer)].data.size();
    if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset) {
      throw error(where + ": buffer view " + std::to_string(a.bufferView) + " runs past the end of its buffer (" +
                  std::to_string(buffer_size) + " bytes)");
    }
    Elements e;
    const int component_size = tg::GetComponentSizeInBytes(uint32_t(a.componentType));
    e.components = tg::GetNumComponentsInType(uint32_t(a.type));
    if (component_size <= 0 || e.components <= 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE ||
        a.componentType == TINYGLTF_COMPONENT_TYPE_INT) {
      throw error(where + ": component type " + std::to_string(a.componentType) + " or type " + std::to_string(a.type) +
                  " is not valid here");
    }
    const size_t element = size_t(component_size) * size_t(e.components);
    e.stride = view.byteStride ? view.byteStride : element;
    if (e.stride < element) throw error(where + ": byte stride smaller than an element");
    e.count = a.count;
    if (a.count > 0) {
      const size_t avail = a.byteOffset <= view.byteLength ? view.byteLength - a.byteOffset : 0;
      if (avail < element || (a.count - 1) > (avail - element) / e.stride) {
        throw error(where + ": " + std::to_string(a.count) + " elements run past the end of buffer view " +
                    std::to_string(a.bufferView) + " (" + std::to_string(view.byteLength) + " bytes)");
      }
    }
    e.data = model_.buffers[size_t(view.buffer)].data.data() + view.byteOffset + a.byteOffset;
    e.component_type = a.componentType;
    e.normalized = a.normalized;
    return e;
  }

  Elements vectors(int accessor, int components, const std::string& what) const {
    const Elements e = elements(accessor, what);
    if (e.components != components) {
      throw error(what + " (accessor " + std::to_string(accessor) + "): " + std::to_string(e.components) +
                  " components, not " + std::to_string(components));
    }
    return e;
  }

  // One primitive as an indexed triangle mesh (its index list made triangles whatever its mode).
  std::optional<IndexedMesh> primitive_mesh(const tg::Primitive& p, const std::string& what) {
    const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode < TINYGLTF_MODE_TRIANGLES || mode > TINYGLTF_MODE_TRIANGLE_FAN) {
      warnings_.add(what + ": points and lines are not rendered (mode " + std::to_string(mode) + ")");
      return std::nullopt;
    }
    if (!p.targets.empty()) warnings_.add(what + ": morph targets not applied");
    const auto pos = p.attributes.find("POSITION");
    if (pos == p.attributes.end()) throw error(what + ": no POSITION attribute");
    IndexedMesh mesh;
    const Elements positions = vectors(pos->second, 3, what + " POSITION");
    mesh.positions.resize(positions.count);
    for (size_t i = 0; i < positions.count; ++i) {
      const Vec3 v{positions.get(i, 0), positions.get(i, 1), positions.get(i, 2)};
      if (!is_finite(v) || std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > kMaxCoordinate) {
        throw error(what + " POSITION: vertex " + std::to_string(i) + " is not finite or lies beyond +-" +
                    kMaxCoordinateText);
      }
      mesh.positions[i] = v;
    }
    if (const auto n = p.attributes.find("NORMAL"); n != p.attributes.end()) {
      const Elements normals = vectors(n->second, 3, what + " NORMAL");
      if (normals.count != positions.count) throw error(what + ": NORMAL and POSITION counts differ");
      mesh.normals.resize(normals.count);
      for (size_t i = 0; i < normals.count; ++i) {
        const Vec3 v{normals.get(i, 0), normals.get(i, 1), normals.get(i, 2)};
        mesh.normals[i] = is_finite(v) ? v : Vec3{0.0f};
      }
    }
    if (const auto t = p.attributes.find("TEXCOORD_0"); t != p.attributes.end()) {
      const Elements uvs = vectors(t->second, 2, what + " TEXCOORD_0");
      if (uvs.count != positions.count) throw error(what + ": TEXCOORD_0 and POSITION counts differ");
      mesh.uvs.resize(uvs.count);
      for (size_t i = 0; i < uvs.count; ++i) {
        const float u = uvs.get(i, 0), v = uvs.get(i, 1);
        // glTF's v runs down the image, OBJ's (and tracer's) up.
        mesh.uvs[i] = std::isfinite(u) && std::isfinite(v) ? Vec2{u, 1.0f - v} : Vec2{};
      }
    }
    if (p.attributes.count("COLOR_0")) warnings_.add("vertex colours (COLOR_0) not used");
    std::vector<uint32_t> list;
    if (p.indices >= 0) {
      const Elements ix = elements(p.indices, what + " indices");
      if (ix.components != 1 || (ix.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                                 ix.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                                 ix.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)) {
        throw error(what + " indices: not unsigned integer scalars");
      }
      list.resize(ix.count);
      for (size_t i = 0; i < ix.count; ++i) {
        list[i] = ix.index(i);
        if (list[i] >= positions.count) {
          throw error(what + ": index " + std::to_string(list[i]) + " out of range (" +
                      std::to_string(positions.count) + " vertices)");
        }
      }
    } else {
      if (positions.count > UINT32_MAX) throw error(what + ": more than 2^32 vertices");
      list.resize(positions.count);
      for (size_t i = 0; i < list.size(); ++i) list[i] = uint32_t(i);
    }
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (list.size() % 3 != 0) warnings_.add(what + ": index count not a multiple of 3 (the rest ignored)");
      list.resize(list.size() / 3 * 3);
      mesh.indices = std::move(list);
    } else {
      for (size_t i = 0; i + 2 < list.size(); ++i) {
        const bool strip = mode == TINYGLTF_MODE_TRIANGLE_STRIP;
        const uint32_t a = strip ? list[i + (i & 1)] : list[0], b = strip ? list[i + 1 - (i & 1)] : list[i + 1];
        mesh.indices.insert(mesh.indices.end(), {a, b, list[i + 2]});
      }
    }
    return mesh;
  }

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
    if (node.skin >= 0) warnings_.add("skinned meshes are rendered as bound, unposed");
    const tg::Mesh& m = model_.meshes[size_t(node.mesh)];
    for (size_t k = 0; k < m.primitives.size(); ++k) {
      const tg::Primitive& p = m.primitives[k];
      const std::string what = primitive_name(node.mesh, k);
      auto [it, fresh] = meshes_.try_emplace({node.mesh, int(k)});
      if (fresh) it->second = primitive_mesh(p, what);
      if (!it->second) continue;
      const IndexedMesh& mesh = *it->second;
      if (scene_.triangles.size() + mesh.triangle_count() > kMaxTriangles) {
        throw error("its instances expand to more than " + std::to_string(kMaxTriangles) +
                    " triangles, more than tracer loads");
      }
      const size_t first = scene_.triangles.size();
      append_mesh(scene_, m.name.empty() ? what : m.name, mesh, material(p.material), world);
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

  void add_camera(int index, const Affine& world) {
    if (size_t(index) >= model_.cameras.size()) throw error("camera " + std::to_string(index) + " does not exist");
    const tg::Camera& c = model_.cameras[size_t(index)];
    if (c.type != "perspective") {
      warnings_.add("camera " + std::to_string(index) + " is " + in_quotes(c.type) +
                    ": only perspective cameras are used");
      return;
    }
    const double yfov = c.perspective.yfov;
    if (!(yfov > 0.0 && yfov < std::numbers::pi)) {
      throw error("camera " + std::to_string(index) + ": yfov " + std::to_string(yfov) + " is not in (0, pi)");
    }
    CameraSpec spec;
    spec.eye = world.point(Vec3{0.0f});
    const Vec3 forward = world.vector(Vec3{0.0f, 0.0f, -1.0f}), up = world.vector(Vec3{0.0f, 1.0f, 0.0f});
    const float len = length(forward);
    if (!(len > 0.0f) || !std::isfinite(len) || !(length(cross(forward, up)) > 0.0f)) {
      throw error("camera " + std::to_string(index) + ": its node's transform collapses the view direction");
    }
    spec.look = spec.eye + forward / len;
    spec.up = normalize(up);
    spec.fov_degrees = float(yfov * 180.0 / std::numbers::pi);
    scene_.cameras.push_back(spec);
  }

  void add_light(const tg::Value& ext, const Affine& world) {
    const int index = int(number(&ext, "light", -1.0));
    if (index < 0 || size_t(index) >= model_.lights.size())
      throw error("light " + std::to_string(index) + " does not exist");
    const tg::Light& l = model_.lights[size_t(index)];
    if (l.type != "point") {
      warnings_.add("light " + std::to_string(index) + " is a " + in_quotes(l.type) +
                    " light: only point lights are used");
      return;
    }
    Light light;
    light.position = world.point(Vec3{0.0f});
    light.power = vec3_of(l.color, Vec3{1.0f}) * float(l.intensity);
    if (!is_finite(light.position) || !is_finite(light.power) || light.power.x < 0.0f || light.power.y < 0.0f ||
        light.power.z < 0.0f) {
      throw error("light " + std::to_string(index) + ": position or intensity not finite, or negative");
    }
    scene_.lights.push_back(light);
  }

  // The tracer material of glTF material `index` (-1: tracer's grey default), made at first use.
  uint32_t material(int index) {
    if (index >= 0 && size_t(index) >= model_.materials.size()) {
      throw error("material " + std::to_string(index) + " does not exist (the file has " +
                  std::to_string(model_.materials.size()) + ")");
    }
    auto [it, fresh] = materials_.try_emplace(index, uint32_t(scene_.materials.size()));
    if (!fresh) return it->second;
    if (index < 0) {
      scene_.materials.push_back(Material{});
      return it->second;
    }
    scene_.materials.push_back(map_material(model_.materials[size_t(index)], index));
    return it->second;
  }

  // docs/FORMATS.md: how glTF's metallic-roughness model becomes tracer's.
  Material map_material(const tg::Material& g, int index) {
    Material mat;
    mat.name = g.name.empty() ? "material " + std::to_string(index) : g.name;
    const tg::PbrMetallicRoughness& pbr = g.pbrMetallicRoughness;
    const Vec3 base = vec3_of(pbr.baseColorFactor, Vec3{1.0f});
    const float metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
    const float roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
    if (!is_finite(base) || !std::isfinite(pbr.metallicFactor) || !std::isfinite(pbr.roughnessFactor)) {
      throw error("material " + in_quotes(mat.name) + " has a non-finite factor");
    }
    if (g.alphaMode != "OPAQUE" || (pbr.baseColorFactor.size() == 4 && pbr.baseColorFactor[3] < 1.0)) {
      warnings_.add("alpha (alphaMode " + g.alphaMode + ", base colour alpha) not rendered: surfaces are opaque");
    }
    if (pbr.metallicRoughnessTexture.index >= 0) {
      warnings_.add("metallicRoughnessTexture not used: its material's factors are");
    }
    if (g.emissiveTexture.index >= 0) warnings_.add("emissiveTexture not used: the emissive factor is");
    const tg::Value* strength = extension(g.extensions, "KHR_materials_emissive_strength");
    const double emissive_strength = number(strength, "emissiveStrength", 1.0);
    if (g.emissiveFactor.size() >= 3) {
      mat.ke = {float(g.emissiveFactor[0] * emissive_strength), float(g.emissiveFactor[1] * emissive_strength),
                float(g.emissiveFactor[2] * emissive_strength)};
    }
    const tg::Value* transmission = extension(g.extensions, "KHR_materials_transmission");
    const float transmitted = float(number(transmission, "transmissionFactor", 0.0));
    const float ior = float(number(extension(g.extensions, "KHR_materials_ior"), "ior", 1.5));
    const tg::Value* specular = extension(g.extensions, "KHR_materials_specular");
    const float specular_factor = float(number(specular, "specularFactor", 1.0));
    Vec3 specular_colour{1.0f};
    if (specular && specular->IsObject() && specular->Has("specularColorFactor")) {
      const tg::Value& c = specular->Get("specularColorFactor");
      if (c.IsArray() && c.ArrayLen() == 3) {
        specular_colour = {float(c.Get(0).GetNumberAsDouble()), float(c.Get(1).GetNumberAsDouble()),
                           float(c.Get(2).GetNumberAsDouble())};
      }
    }
    if (!is_finite(mat.ke) || !std::isfinite(transmitted) || !std::isfinite(ior) || !std::isfinite(specular_factor) ||
        !is_finite(specular_colour) || mat.ke.x < 0.0f || mat.ke.y < 0.0f || mat.ke.z < 0.0f) {
      throw error("material " + in_quotes(mat.name) + " has a non-finite or negative extension value");
    }
    // The dielectric reflectance at normal incidence: ((ior - 1) / (ior + 1))^2, 0.04 at 1.5.
    const float f0_ior = ior >= 1.0f ? ((ior - 1.0f) / (ior + 1.0f)) * ((ior - 1.0f) / (ior + 1.0f)) : 0.04f;
    const Vec3 f0 = min(specular_colour * f0_ior, Vec3{1.0f}) * std::max(specular_factor, 0.0f);
    Vec3 diffuse_tint{1.0f};
    if (transmitted > 0.0f) {
      if (transmitted < 1.0f) warnings_.add("partial transmission rendered as full transmission (glass)");
      if (roughness > 0.0f) warnings_.add("rough transmission rendered smooth");
      mat.illum = 7;
      mat.ni = ior > 0.0f ? ior : 1.5f;
      mat.tf = base;
      mat.kd = base;
    } else if (metallic >= 1.0f && roughness == 0.0f) {
      mat.illum = 3;
      mat.ks = base;
      mat.kd = Vec3{0.0f};
    } else {
      mat.illum = 2;
      mat.kd = base * (1.0f - metallic);
      mat.ks = f0 * (1.0f - metallic) + base * metallic;
      // GGX alpha = roughness^2 (glTF); tracer's glossy lobe reads it from a Phong exponent.
      const float alpha = std::max(roughness * roughness, 1e-4f);
      mat.ns = 2.0f / (alpha * alpha) - 2.0f;
      diffuse_tint = Vec3{1.0f - metallic};
      if (metallic > 0.0f && pbr.baseColorTexture.index >= 0) {
        warnings_.add("a metallic base colour texture tints the specular by its factor only");
      }
    }
    if (pbr.baseColorTexture.index >= 0 && mat.illum == 2) {
      mat.diffuse_texture =
          texture(pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, false, base * diffuse_tint);
    }
    if (g.normalTexture.index >= 0) {
      mat.normal_texture = texture(g.normalTexture.index, g.normalTexture.texCoord, true, Vec3{1.0f});
      mat.normal_scale = float(g.normalTexture.scale);
      if (!std::isfinite(mat.normal_scale))
        throw error("material " + in_quotes(mat.name) + ": normal scale not finite");
    }
    return mat;
  }

  // A slot for texture `index` read as colour (tinted) or as data; filled by attach_textures().
  uint32_t texture(int index, int tex_coord, bool data, Vec3 tint) {
    if (size_t(index) >= model_.textures.size()) throw error("texture " + std::to_string(index) + " does not exist");
    const tg::Texture& t = model_.textures[size_t(index)];
    if (t.source < 0 || size_t(t.source) >= model_.images.size()) {
      throw error("texture " + std::to_string(index) + ": image " + std::to_string(t.source) + " does not exist");
    }
    if (tex_coord != 0) warnings_.add("texture coordinate sets other than TEXCOORD_0 not used: TEXCOORD_0 is");
    if (t.sampler >= 0 && size_t(t.sampler) < model_.samplers.size()) {
      const tg::Sampler& s = model_.samplers[size_t(t.sampler)];
      if (s.wrapS != TINYGLTF_TEXTURE_WRAP_REPEAT || s.wrapT != TINYGLTF_TEXTURE_WRAP_REPEAT) {
        warnings_.add("texture wrap modes other than repeat rendered as repeat");
      }
    }
    if (extension(t.extensions, "KHR_texture_transform")) warnings_.add("KHR_texture_transform not applied");
    const TextureUse use{t.source, data, data ? Vec3{1.0f} : tint};
    const auto [it, fresh] = texture_slots_.try_emplace(use, uint32_t(texture_uses_.size()));
    if (fresh) texture_uses_.push_back(use);
    return it->second;
  }

  // Reads and decodes each image the materials use (in parallel, within the texture budget, in
  // image order), then points the materials at them; an image that cannot be read leaves its
  // materials their factors, with a warning.
  void attach_textures() {
    std::vector<int> images;
    for (const TextureUse& u : texture_uses_) images.push_back(u.image);
    std::sort(images.begin(), images.end());
    images.erase(std::unique(images.begin(), images.end()), images.end());
    std::vector<EncodedTexture> encoded(images.size());
    std::vector<std::string> problem(images.size());
    std::vector<std::optional<Texture>> decoded(images.size());
    const auto guarded = [&](size_t k, auto&& work) {
      try {
        work();
      } catch (const InputError& e) {
        problem[k] = e.what();
      }
    };
    limits_.for_each(images.size(), [&](size_t k) { guarded(k, [&] { encoded[k] = read_image(images[k]); }); });
    throw_if_cancelled(cancel_);
    uint64_t kept = 0, largest_transient = 0;
    const uint64_t budget = limits_.textures.max_total_bytes;
    for (size_t k = 0; k < images.size(); ++k) {
      if (!problem[k].empty()) continue;
      const uint64_t final_bytes = encoded[k].decoded_bytes();
      const uint64_t transient = encoded[k].decode_peak_bytes() - final_bytes;
      if (kept + final_bytes + std::max(largest_transient, transient) > budget) {
        problem[k] = encoded[k].name + ": the scene's textures would take more than " + std::to_string(budget >> 20) +
                     " MiB to decode (--max-texture-mib raises it)";
        encoded[k] = {};
        continue;
      }
      kept += final_bytes;
      largest_transient = std::max(largest_transient, transient);
    }
    ByteBudget transients(budget - kept);
    limits_.for_each(images.size(), [&](size_t k) {
      if (problem[k].empty()) {
        const ByteBudget::Taken held(transients, encoded[k].decode_peak_bytes() - encoded[k].decoded_bytes());
        guarded(k, [&] { decoded[k] = decode_texture(encoded[k]); });
      }
      encoded[k] = {};
    });
    throw_if_cancelled(cancel_);
    // Slot -> scene texture (kInvalidIndex where its image failed).
    std::vector<uint32_t> slot_texture(texture_uses_.size(), kInvalidIndex);
    for (size_t s = 0; s < texture_uses_.size(); ++s) {
      const TextureUse& u = texture_uses_[s];
      const size_t k = size_t(std::lower_bound(images.begin(), images.end(), u.image) - images.begin());
      if (!decoded[k]) continue;
      slot_texture[s] = uint32_t(scene_.textures.size());
      scene_.textures.push_back(u.tint == Vec3{1.0f} ? *decoded[k] : decoded[k]->tinted(u.tint));
    }
    for (size_t k = 0; k < images.size(); ++k) {
      if (!problem[k].empty()) warnings_.add("texture not used: " + problem[k]);
    }
    for (Material& m : scene_.materials) {
      if (m.diffuse_texture != kInvalidIndex) m.diffuse_texture = slot_texture[m.diffuse_texture];
      if (m.normal_texture != kInvalidIndex) m.normal_texture = slot_texture[m.normal_texture];
    }
  }

  // An image's encoded bytes: from a buffer view, a data: URI (tinygltf decoded it) or a file
  // inside the scene's folder.
  EncodedTexture read_image(int index) const {
    const tg::Image& image = model_.images[size_t(index)];
    const std::string what = "image " + std::to_string(index);
    if (!image.image.empty()) {
      return encoded_texture(name_ + " " + what, std::string(image.image.begin(), image.image.end()), limits_.textures);
    }
    if (image.bufferView >= 0) throw InputError(name_ + " " + what + ": its buffer view could not be read");
    if (image.uri.empty()) throw InputError(name_ + " " + what + ": neither a URI nor a buffer view");
    if (base_dir_.empty()) throw InputError(name_ + " " + what + ": a scene read from memory refers to no files");
    const std::string uri = decode_uri(image.uri);
    FileAccess access{fs::weakly_canonical(base_dir_), limits_.max_obj_bytes, cancel_};
    std::string why;
    FileFinder finder;
    const std::optional<fs::path> file = finder.find(base_dir_, uri);
    if (!file) throw InputError((base_dir_ / uri).string() + ": not found");
    if (!access.inside(file->string(), &why)) throw InputError(name_ + " " + what + ": " + why);
    return read_texture(*file, limits_.textures, cancel_);
  }

  const tg::Model& model_;
  std::string name_;
  fs::path base_dir_;
  const LoadLimits& limits_;
  CancelFlag cancel_;
  WarningLog& warnings_;
  Scene scene_;
  std::map<std::pair<int, int>, std::optional<IndexedMesh>> meshes_;  // (mesh, primitive)
  std::map<int, uint32_t> materials_;
  std::map<TextureUse, uint32_t> texture_slots_;
  std::vector<TextureUse> texture_uses_;
};

bool is_glb(std::string_view bytes) { return bytes.size() >= 4 && bytes.substr(0, 4) == "glTF"; }

// The first line of tinygltf's messages, which end each problem with a newline.
std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line.empty() ? "not a valid glTF file" : line;
}

Scene load(std::string_view bytes, const std::string& name, const fs::path& base_dir, const WarningSink& warn_in,
           CancelFlag cancel, const LoadLimits& limits, LoadPhases* phases) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  const auto parse_start = Clock::now();
  if (bytes.size() > UINT32_MAX) throw InputError(name + ": larger than the 4 GiB a glTF file may be");
  FileAccess access;
  if (!base_dir.empty()) access = {fs::weakly_canonical(base_dir), limits.max_obj_bytes, cancel};
  tg::TinyGLTF reader;
  reader.SetFsCallbacks({&file_exists, &expand_file_path, &read_whole_file, &refuse_write, &access});
  reader.SetImageLoader(&keep_encoded, nullptr);
  tg::Model model;
  std::string err, tg_warn;
  const std::string dir = base_dir.empty() ? std::string() : base_dir.string();
  const bool ok =
      is_glb(bytes)
          ? reader.LoadBinaryFromMemory(&model, &err, &tg_warn, reinterpret_cast<const unsigned char*>(bytes.data()),
                                        unsigned(bytes.size()), dir)
          : reader.LoadASCIIFromString(&model, &err, &tg_warn, bytes.data(), unsigned(bytes.size()), dir);
  throw_if_cancelled(cancel);
  if (!ok) throw InputError(name + ": " + (!access.refused.empty() ? access.refused : first_line(err.empty() ? tg_warn : err)));
  WarningLog warnings;
  for (size_t start = 0; start < tg_warn.size();) {
    const size_t end = std::min(tg_warn.find('\n', start), tg_warn.size());
    if (end > start) warnings.add(tg_warn.substr(start, end - start));
    start = end + 1;
  }
  if (phases) phases->parse_ms = ms_since(parse_start);
  const auto build_start = Clock::now();
  Scene scene = GltfScene(model, name, base_dir, limits, cancel, warnings).build();
  if (phases) phases->assembly_ms = ms_since(build_start);
  warnings.flush(name, warn);
  return scene;
}

}  // namespace

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
