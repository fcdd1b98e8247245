#include "scene_writers.hpp"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <unordered_map>

#include "importers/tinygltf.hpp"

namespace tracer::test {
namespace {

namespace tg = tinygltf;

// The distinct corners of a run of triangles (position, normal, texture coordinates, byte for
// byte) and each corner's index among them, as a scan's or an exporter's file shares vertices.
struct SharedCorners {
  std::vector<float> pos, nrm, uv;
  std::vector<uint32_t> indices;
  SharedCorners(const Scene& scene, size_t first, size_t end, bool flip_v) {
    std::unordered_map<std::string, uint32_t> seen;
    for (size_t k = first; k < end; ++k) {
      const Triangle& tri = scene.triangles[k];
      for (int c = 0; c < 3; ++c) {
        const Vec3 p = c == 0 ? tri.v0 : c == 1 ? tri.v1 : tri.v2;
        float v[8] = {p.x, p.y, p.z, 0, 0, 0, 0, 0};
        if (!scene.corner_normals.empty()) {
          const Vec3 n = scene.corner_normals[3 * k + size_t(c)];
          v[3] = n.x, v[4] = n.y, v[5] = n.z;
        }
        if (!scene.corner_uvs.empty()) {
          const Vec2 w = scene.corner_uvs[3 * k + size_t(c)];
          v[6] = w.x, v[7] = flip_v ? float(1.0 - double(w.y)) : w.y;
        }
        const auto [it, fresh] =
            seen.try_emplace(std::string(reinterpret_cast<const char*>(v), sizeof v), uint32_t(pos.size() / 3));
        if (fresh) {
          pos.insert(pos.end(), v, v + 3);
          if (!scene.corner_normals.empty()) nrm.insert(nrm.end(), v + 3, v + 6);
          if (!scene.corner_uvs.empty()) uv.insert(uv.end(), v + 6, v + 8);
        }
        indices.push_back(it->second);
      }
    }
  }
};

// Appends `bytes` to buffer 0 as a new buffer view (4-byte aligned) and an accessor over it.
int add_accessor(tg::Model& m, const void* data, size_t count, int type, int components, bool with_bounds,
                 int component_type = TINYGLTF_COMPONENT_TYPE_FLOAT) {
  tg::Buffer& buf = m.buffers[0];
  while (buf.data.size() % 4) buf.data.push_back(0);
  tg::BufferView view;
  view.buffer = 0;
  view.byteOffset = buf.data.size();
  view.byteLength = count * size_t(components) * 4;
  const auto* p = static_cast<const unsigned char*>(data);
  buf.data.insert(buf.data.end(), p, p + view.byteLength);
  m.bufferViews.push_back(view);
  tg::Accessor a;
  a.bufferView = int(m.bufferViews.size() - 1);
  a.componentType = component_type;
  a.count = count;
  a.type = type;
  if (with_bounds) {  // glTF requires POSITION's min and max
    const auto* f = static_cast<const float*>(data);
    a.minValues.assign(3, INFINITY);
    a.maxValues.assign(3, -INFINITY);
    for (size_t i = 0; i < count; ++i) {
      for (int k = 0; k < 3; ++k) {
        a.minValues[size_t(k)] = std::min(a.minValues[size_t(k)], double(f[3 * i + size_t(k)]));
        a.maxValues[size_t(k)] = std::max(a.maxValues[size_t(k)], double(f[3 * i + size_t(k)]));
      }
    }
  }
  m.accessors.push_back(a);
  return int(m.accessors.size() - 1);
}

tg::Value object(std::initializer_list<std::pair<const char*, tg::Value>> fields) {
  tg::Value::Object o;
  for (const auto& [k, v] : fields) o[k] = v;
  return tg::Value(o);
}

tg::Material to_gltf(const Material& mat) {
  tg::Material g;
  g.name = mat.name;
  auto& pbr = g.pbrMetallicRoughness;
  const auto rgb = [](Vec3 c) { return std::vector<double>{c.x, c.y, c.z, 1.0}; };
  // GGX alpha from the Phong exponent (tracer's Ggx::from_phong_exponent), roughness its root.
  const double alpha = std::clamp(std::sqrt(2.0 / (std::max(double(mat.ns), 0.0) + 2.0)), 0.01, 1.0);
  pbr.roughnessFactor = std::sqrt(alpha);
  pbr.metallicFactor = 0.0;
  switch (mat.surface()) {
    case SurfaceKind::Mirror:
      pbr.baseColorFactor = rgb(mat.ks);
      pbr.metallicFactor = 1.0;
      pbr.roughnessFactor = 0.0;
      break;
    case SurfaceKind::Dielectric:
      pbr.baseColorFactor = rgb(mat.tf);
      g.extensions["KHR_materials_transmission"] = object({{"transmissionFactor", tg::Value(1.0)}});
      g.extensions["KHR_materials_ior"] = object({{"ior", tg::Value(double(mat.ni))}});
      pbr.roughnessFactor = 0.0;
      break;
    case SurfaceKind::MetallicRoughness:
      pbr.baseColorFactor = rgb(mat.kd);
      pbr.metallicFactor = mat.metallic;
      pbr.roughnessFactor = mat.roughness;
      if (mat.specular_f90 != 1.0f || !(mat.specular_f0 == Vec3{0.04f})) {
        const Vec3 c = mat.specular_f0 / (0.04f * std::max(mat.specular_f90, 1e-6f));
        g.extensions["KHR_materials_specular"] = object(
            {{"specularFactor", tg::Value(double(mat.specular_f90))},
             {"specularColorFactor",
              tg::Value(tg::Value::Array{tg::Value(double(c.x)), tg::Value(double(c.y)), tg::Value(double(c.z))})}});
      }
      break;
    case SurfaceKind::Diffuse: {
      pbr.baseColorFactor = rgb(mat.kd);
      const Vec3 ks = mat.illum >= 2 ? mat.ks : Vec3{0.0f};
      if (ks == Vec3{0.0f}) {
        g.extensions["KHR_materials_specular"] = object({{"specularFactor", tg::Value(0.0)}});
      } else {
        const tg::Value::Array colour{tg::Value(ks.x / 0.04), tg::Value(ks.y / 0.04), tg::Value(ks.z / 0.04)};
        g.extensions["KHR_materials_specular"] = object({{"specularColorFactor", tg::Value(colour)}});
      }
      break;
    }
  }
  if (mat.emissive()) {
    const double strength = std::max({mat.ke.x, mat.ke.y, mat.ke.z});
    g.emissiveFactor = {mat.ke.x / strength, mat.ke.y / strength, mat.ke.z / strength};
    if (strength != 1.0) {
      g.extensions["KHR_materials_emissive_strength"] = object({{"emissiveStrength", tg::Value(strength)}});
    }
  }
  return g;
}

void use_extensions(tg::Model& m) {
  for (const tg::Material& g : m.materials)
    for (const auto& [name, value] : g.extensions)
      if (std::find(m.extensionsUsed.begin(), m.extensionsUsed.end(), name) == m.extensionsUsed.end())
        m.extensionsUsed.push_back(name);
}

}  // namespace

void write_gltf(const Scene& scene, const std::string& path, const GltfWriteOptions& options) {
  tg::Model m;
  m.asset.version = "2.0";
  m.asset.generator = "tracer tests";
  m.buffers.resize(1);
  if (!options.binary) m.buffers[0].uri = std::filesystem::path(path).stem().string() + ".bin";
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    tg::Material g = to_gltf(scene.materials[i]);
    if (const auto it = options.base_color_images.find(uint32_t(i)); it != options.base_color_images.end()) {
      tg::Image image;
      image.uri = it->second;
      m.images.push_back(image);
      tg::Texture t;
      t.source = int(m.images.size() - 1);
      m.textures.push_back(t);
      g.pbrMetallicRoughness.baseColorTexture.index = int(m.textures.size() - 1);
      g.pbrMetallicRoughness.baseColorFactor = {1.0, 1.0, 1.0, 1.0};
    }
    m.materials.push_back(g);
  }
  use_extensions(m);
  tg::Scene root;
  // The nodes placing the last mesh written: one per transform listed for geometry g (one
  // untransformed if none), each with a copy of the mesh with distinct_meshes.
  const auto place = [&](uint32_t g) {
    const auto placed = options.placements.find(g);
    const size_t nodes = placed == options.placements.end() ? 1 : placed->second.size();
    for (size_t k = 0; k < nodes; ++k) {
      tg::Node node;
      if (options.distinct_meshes && k > 0) m.meshes.push_back(m.meshes.back());
      node.mesh = int(m.meshes.size() - 1);
      if (placed != options.placements.end()) node.matrix.assign(placed->second[k].begin(), placed->second[k].end());
      m.nodes.push_back(node);
      root.nodes.push_back(int(m.nodes.size() - 1));
    }
  };
  tg::Mesh all;  // with one_mesh: every geometry's primitives
  for (uint32_t g = 0; g < scene.geometries.size(); ++g) {
    const Geometry& geom = scene.geometries[g];
    tg::Mesh mesh;
    mesh.name = geom.name;
    const size_t end = size_t(geom.first_triangle) + geom.triangle_count;
    for (size_t t = geom.first_triangle; t < end;) {
      size_t run = t;
      while (run < end && scene.tri_material[run] == scene.tri_material[t]) ++run;
      const SharedCorners corners(scene, t, run, /*flip_v=*/true);
      tg::Primitive p;
      p.mode = TINYGLTF_MODE_TRIANGLES;
      p.material = int(scene.tri_material[t]);
      const auto& c = corners;
      p.attributes["POSITION"] = add_accessor(m, c.pos.data(), c.pos.size() / 3, TINYGLTF_TYPE_VEC3, 3, true);
      if (!c.nrm.empty()) {
        p.attributes["NORMAL"] = add_accessor(m, c.nrm.data(), c.nrm.size() / 3, TINYGLTF_TYPE_VEC3, 3, false);
      }
      if (!c.uv.empty()) {
        p.attributes["TEXCOORD_0"] = add_accessor(m, c.uv.data(), c.uv.size() / 2, TINYGLTF_TYPE_VEC2, 2, false);
      }
      p.indices = add_accessor(m, c.indices.data(), c.indices.size(), TINYGLTF_TYPE_SCALAR, 1, false,
                               TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT);
      mesh.primitives.push_back(p);
      t = run;
    }
    if (options.one_mesh) {
      all.primitives.insert(all.primitives.end(), mesh.primitives.begin(), mesh.primitives.end());
      continue;
    }
    m.meshes.push_back(mesh);
    place(g);
  }
  if (options.one_mesh && !all.primitives.empty()) {
    all.name = "scene";
    m.meshes.push_back(all);
    place(0);
  }
  if (scene.camera) {
    const CameraSpec& c = *scene.camera;
    const Vec3 back = normalize(c.eye - c.look), right = normalize(cross(c.up, back)), up = cross(back, right);
    tg::Camera camera;
    camera.type = "perspective";
    camera.perspective.yfov = double(c.fov_degrees) * M_PI / 180.0;
    camera.perspective.znear = 0.01;
    m.cameras.push_back(camera);
    tg::Node node;
    node.camera = 0;
    node.matrix = {right.x, right.y, right.z, 0, up.x,    up.y,    up.z,    0,
                   back.x,  back.y,  back.z,  0, c.eye.x, c.eye.y, c.eye.z, 1};
    m.nodes.push_back(node);
    root.nodes.push_back(int(m.nodes.size() - 1));
  }
  tg::Value::Array lights;
  for (const Light& l : scene.lights) {
    if (!l.is_point()) continue;
    const double intensity = std::max({l.power.x, l.power.y, l.power.z});
    tg::Light light;
    light.type = "point";
    light.intensity = intensity * 683.0;  // candela: glTF's unit (gltf_viewpoints.cpp)
    light.color = {l.power.x / intensity, l.power.y / intensity, l.power.z / intensity};
    m.lights.push_back(light);
    tg::Node node;
    node.translation = {l.position.x, l.position.y, l.position.z};
    node.extensions["KHR_lights_punctual"] = object({{"light", tg::Value(int(m.lights.size() - 1))}});
    m.nodes.push_back(node);
    root.nodes.push_back(int(m.nodes.size() - 1));
  }
  if (!m.lights.empty()) m.extensionsUsed.push_back("KHR_lights_punctual");
  m.scenes.push_back(root);
  m.defaultScene = 0;
  tg::TinyGLTF writer;
  if (!writer.WriteGltfSceneToFile(&m, path, false, options.binary, true, options.binary)) {
    throw std::runtime_error("write_gltf: cannot write " + path);
  }
}

void write_ply(const Scene& scene, const std::string& path, PlyEncoding encoding) {
  const SharedCorners c(scene, 0, scene.triangles.size(), /*flip_v=*/false);
  const bool normals = !c.nrm.empty(), uvs = !c.uv.empty();
  const size_t vertices = c.pos.size() / 3;
  std::string out = "ply\nformat ";
  out += encoding == PlyEncoding::Ascii          ? "ascii"
         : encoding == PlyEncoding::BinaryLittle ? "binary_little_endian"
                                                 : "binary_big_endian";
  out += " 1.0\ncomment written by tracer's tests\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals) out += "property float nx\nproperty float ny\nproperty float nz\n";
  if (uvs) out += "property float u\nproperty float v\n";
  out += "element face " + std::to_string(scene.triangles.size()) +
         "\nproperty list uchar int vertex_indices\nend_header\n";
  const auto put = [&](auto value) {
    if (encoding == PlyEncoding::Ascii) {
      char text[64];
      if constexpr (std::is_same_v<decltype(value), float>) {
        std::snprintf(text, sizeof text, "%.9g ", double(value));
      } else {
        std::snprintf(text, sizeof text, "%d ", int(value));
      }
      out += text;
      return;
    }
    unsigned char b[sizeof value];
    std::memcpy(b, &value, sizeof value);
    if (encoding == PlyEncoding::BinaryBig) std::reverse(b, b + sizeof value);
    out.append(reinterpret_cast<const char*>(b), sizeof value);
  };
  const auto end_row = [&] {
    if (encoding == PlyEncoding::Ascii) out.back() = '\n';
  };
  for (size_t i = 0; i < vertices; ++i) {
    for (int k = 0; k < 3; ++k) put(c.pos[3 * i + size_t(k)]);
    if (normals)
      for (int k = 0; k < 3; ++k) put(c.nrm[3 * i + size_t(k)]);
    if (uvs)
      for (int k = 0; k < 2; ++k) put(c.uv[2 * i + size_t(k)]);
    end_row();
  }
  for (size_t t = 0; t < scene.triangles.size(); ++t) {
    put(uint8_t(3));
    for (int k = 0; k < 3; ++k) put(int32_t(c.indices[3 * t + size_t(k)]));
    end_row();
  }
  std::ofstream(path, std::ios::binary) << out;
}

}  // namespace tracer::test
