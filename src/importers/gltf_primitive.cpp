#include "importers/gltf_primitive.hpp"

#include <algorithm>
#include <cmath>

#include "base/errors.hpp"
#include "base/text.hpp"
#include "scene/value_limits.hpp"

namespace tracer::gltf {

namespace tg = tinygltf;

std::optional<IndexedMesh> primitive_mesh(const tg::Model& model_, const std::string& file, WarningLog& warnings_,
                                          const tg::Primitive& p, const std::string& what) {
  const auto where = [&](const std::string& w) { return file + ": " + w; };
  const auto error = [&](const std::string& w) { return InputError(where(w)); };
  const int mode = p.mode < 0 ? TINYGLTF_MODE_TRIANGLES : p.mode;
  if (mode < TINYGLTF_MODE_TRIANGLES || mode > TINYGLTF_MODE_TRIANGLE_FAN) {
    warnings_.add(what + ": points and lines are not rendered (mode " + std::to_string(mode) + ")");
    return std::nullopt;
  }
  if (!p.targets.empty()) warnings_.add(what + ": morph targets not applied");
  const auto pos = p.attributes.find("POSITION");
  if (pos == p.attributes.end()) throw error(what + ": no POSITION attribute");
  IndexedMesh mesh;
  const gltf::Elements positions = gltf::vectors(model_, pos->second, 3, where(what + " POSITION"));
  if (positions.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT &&
      std::find(model_.extensionsUsed.begin(), model_.extensionsUsed.end(), "KHR_mesh_quantization") ==
          model_.extensionsUsed.end()) {
    warnings_.add(what +
                  " POSITION: integer components without KHR_mesh_quantization in extensionsUsed: read as "
                  "that extension defines them");
  }
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
    const gltf::Elements normals = gltf::vectors(model_, n->second, 3, where(what + " NORMAL"));
    if (normals.count != positions.count) throw error(what + ": NORMAL and POSITION counts differ");
    mesh.normals.resize(normals.count);
    for (size_t i = 0; i < normals.count; ++i) {
      const Vec3 v{normals.get(i, 0), normals.get(i, 1), normals.get(i, 2)};
      mesh.normals[i] = is_finite(v) ? v : Vec3{0.0f};
    }
  }
  for (const auto& [set, out] : {std::pair{"TEXCOORD_0", &mesh.uvs}, std::pair{"TEXCOORD_1", &mesh.uvs1}}) {
    const auto t = p.attributes.find(set);
    if (t == p.attributes.end()) continue;
    const gltf::Elements uvs = gltf::vectors(model_, t->second, 2, where(what + " " + set));
    if (uvs.count != positions.count) throw error(what + ": " + set + " and POSITION counts differ");
    out->resize(uvs.count);
    for (size_t i = 0; i < uvs.count; ++i) {
      const float u = uvs.get(i, 0), v = uvs.get(i, 1);
      // glTF's v runs down the image, OBJ's (and tracer's) up.
      (*out)[i] = std::isfinite(u) && std::isfinite(v) ? Vec2{u, 1.0f - v} : Vec2{};
    }
  }
  if (const auto c = p.attributes.find("COLOR_0"); c != p.attributes.end()) {
    // Linear RGB or RGBA, float or normalised unsigned bytes or shorts (the specification's
    // types); alpha is not read (surfaces are opaque).
    const std::string at = where(what + " COLOR_0");
    const gltf::Elements colors = gltf::elements(model_, c->second, at);
    const bool integer = colors.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                         colors.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
    if ((colors.components != 3 && colors.components != 4) ||
        (colors.component_type != TINYGLTF_COMPONENT_TYPE_FLOAT && !(integer && colors.normalized))) {
      throw InputError(at + " (accessor " + std::to_string(c->second) +
                       "): not VEC3 or VEC4 of floats or normalised unsigned bytes or shorts");
    }
    if (colors.count != positions.count) throw error(what + ": COLOR_0 and POSITION counts differ");
    mesh.colors.resize(colors.count);
    for (size_t i = 0; i < colors.count; ++i) {
      const Vec3 v{colors.get(i, 0), colors.get(i, 1), colors.get(i, 2)};
      mesh.colors[i] = is_finite(v) ? min(max(v, Vec3{0.0f}), Vec3{1.0f}) : Vec3{1.0f};
    }
  }
  std::vector<uint32_t> list;
  if (p.indices >= 0) {
    const gltf::Elements ix = gltf::elements(model_, p.indices, where(what + " indices"));
    if (ix.components != 1 || (ix.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                               ix.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                               ix.component_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)) {
      throw error(what + " indices: not unsigned integer scalars");
    }
    list.resize(ix.count);
    for (size_t i = 0; i < ix.count; ++i) {
      list[i] = ix.index(i);
      if (list[i] >= positions.count) {
        throw error(what + ": index " + std::to_string(list[i]) + " out of range (" + std::to_string(positions.count) +
                    " vertices)");
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

}  // namespace tracer::gltf
