#include "scene/obj_loader.hpp"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string_view>

#include "base/errors.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void fail_at(const std::string& name, size_t line, const std::string& what) {
  throw InputError(name + ":" + std::to_string(line) + ": " + what);
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::string_view next_token(std::string_view& s) {
  s = trim(s);
  size_t end = 0;
  while (end < s.size() && s[end] != ' ' && s[end] != '\t') ++end;
  std::string_view tok = s.substr(0, end);
  s.remove_prefix(end);
  return tok;
}

std::string quoted(std::string_view tok) {
  std::string t(tok.substr(0, 40));
  return "'" + t + (tok.size() > 40 ? "...'" : "'");
}

// tinyobjloader is lenient by design: it reads an unparsable number as 0, keeps going on short
// lines and does not range-check face indices (an out-of-range index would later read past the
// vertex array). This pass rejects all of that with the file and line, before tinyobjloader
// builds the real data.
void validate_obj_text(std::string_view text, const std::string& name) {
  size_t counts[3] = {0, 0, 0};  // v, vt, vn seen so far: OBJ indices refer backwards
  size_t line_no = 0;
  while (!text.empty()) {
    ++line_no;
    const size_t nl = text.find('\n');
    std::string_view line = text.substr(0, nl);
    text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
    line = trim(line);
    if (line.empty() || line.front() == '#') continue;
    const std::string_view keyword = next_token(line);
    if (keyword == "v" || keyword == "vt" || keyword == "vn") {
      const size_t needed = keyword == "vt" ? 1 : 3;
      size_t n = 0;
      for (std::string_view tok = next_token(line); !tok.empty(); tok = next_token(line), ++n) {
        float value = 0;
        const auto [ptr, ec] = std::from_chars(tok.data(), tok.data() + tok.size(), value);
        if (ec == std::errc::result_out_of_range) fail_at(name, line_no, "number out of range " + quoted(tok));
        if (ec != std::errc{} || ptr != tok.data() + tok.size()) fail_at(name, line_no, "malformed number " + quoted(tok));
        if (!std::isfinite(value)) fail_at(name, line_no, "non-finite coordinate " + quoted(tok));
      }
      if (n < needed) {
        fail_at(name, line_no, "'" + std::string(keyword) + "' needs " + std::to_string(needed) +
                                   " numbers, got " + std::to_string(n));
      }
      ++counts[keyword == "v" ? 0 : (keyword == "vt" ? 1 : 2)];
    } else if (keyword == "f") {
      size_t corners = 0;
      for (std::string_view tok = next_token(line); !tok.empty(); tok = next_token(line), ++corners) {
        // v, v/vt, v//vn or v/vt/vn
        std::string_view rest = tok;
        for (int slot = 0; slot < 3 && !rest.empty(); ++slot) {
          const size_t slash = rest.find('/');
          const std::string_view part = rest.substr(0, slash);
          rest.remove_prefix(slash == std::string_view::npos ? rest.size() : slash + 1);
          if (part.empty() && slot == 1) continue;  // v//vn
          long long index = 0;
          const auto [ptr, ec] = std::from_chars(part.data(), part.data() + part.size(), index);
          if (ec != std::errc{} || ptr != part.data() + part.size() || part.empty()) {
            fail_at(name, line_no, "malformed face index " + quoted(tok));
          }
          const auto count = static_cast<long long>(counts[slot]);
          if (index == 0 || index > count || index < -count) {
            static const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
            fail_at(name, line_no, std::string(kinds[slot]) + " index " + std::to_string(index) +
                                       " out of range (" + std::to_string(count) + " defined so far)");
          }
        }
      }
      if (corners < 3) fail_at(name, line_no, "face needs at least 3 vertices, got " + std::to_string(corners));
    }
  }
}

std::string read_file(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(path + ": cannot open: no such file");
  if (fs::is_directory(path, ec)) throw InputError(path + ": cannot open: is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path + ": read error");
  return ss.str();
}

void default_warning(const std::string& message) { std::cerr << "tracer: warning: " << message << "\n"; }

Scene build_scene(const tinyobj::ObjReader& reader, const std::string& name, const fs::path& base_dir,
                  const WarningSink& warn) {
  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  Scene scene;
  scene.source = name;
  scene.vertex_count = attrib.vertices.size() / 3;

  size_t missing_textures = 0;
  std::string first_missing;
  for (const tinyobj::material_t& m : reader.GetMaterials()) {
    Material mat;
    mat.name = m.name;
    mat.kd = {float(m.diffuse[0]), float(m.diffuse[1]), float(m.diffuse[2])};
    mat.ks = {float(m.specular[0]), float(m.specular[1]), float(m.specular[2])};
    mat.ke = {float(m.emission[0]), float(m.emission[1]), float(m.emission[2])};
    mat.ni = float(m.ior);
    mat.illum = m.illum;
    if (!is_finite(mat.kd) || !is_finite(mat.ks) || !is_finite(mat.ke) || !std::isfinite(mat.ni)) {
      throw InputError(name + ": material '" + m.name + "' has a non-finite colour or index");
    }
    for (const std::string* tex : {&m.diffuse_texname, &m.ambient_texname, &m.specular_texname,
                                   &m.bump_texname, &m.alpha_texname}) {
      std::error_code ec;
      if (!tex->empty() && !fs::exists(base_dir / *tex, ec)) {
        if (missing_textures++ == 0) first_missing = *tex;
      }
    }
    scene.materials.push_back(std::move(mat));
  }
  if (missing_textures > 0) {
    warn(name + ": " + std::to_string(missing_textures) + " texture reference(s) not found (first: '" +
         first_missing + "'); using material colours");
  }
  const auto default_material = static_cast<uint32_t>(scene.materials.size());
  bool used_default = false;

  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const tinyobj::mesh_t& mesh = shape.mesh;
    Geometry g;
    g.name = shape.name;
    g.first_triangle = static_cast<uint32_t>(scene.triangles.size());
    const auto geom_id = static_cast<uint32_t>(scene.geometries.size());
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const size_t fv = mesh.num_face_vertices[f];
      if (fv == 3) {
        Vec3 p[3];
        for (size_t k = 0; k < 3; ++k) {
          const auto vi = static_cast<size_t>(mesh.indices[offset + k].vertex_index);
          if (vi >= scene.vertex_count) throw InputError(name + ": face vertex index out of range");
          p[k] = {float(attrib.vertices[3 * vi]), float(attrib.vertices[3 * vi + 1]), float(attrib.vertices[3 * vi + 2])};
        }
        const int mid = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
        uint32_t material = default_material;
        if (mid >= 0 && static_cast<size_t>(mid) < scene.materials.size()) {
          material = static_cast<uint32_t>(mid);
        } else {
          used_default = true;
        }
        scene.tri_prim.push_back(static_cast<uint32_t>(scene.triangles.size() - g.first_triangle));
        scene.triangles.push_back({p[0], p[1], p[2]});
        scene.tri_geom.push_back(geom_id);
        scene.tri_material.push_back(material);
      }
      offset += fv;
    }
    g.triangle_count = static_cast<uint32_t>(scene.triangles.size() - g.first_triangle);
    if (g.triangle_count > 0) scene.geometries.push_back(std::move(g));
  }
  if (used_default) scene.materials.push_back(Material{});
  if (scene.triangles.empty()) throw InputError(name + ": scene has no triangles");
  scene.finalize();
  return scene;
}

void forward_warnings(const std::string& text, const std::string& name, const WarningSink& warn) {
  // tinyobjloader repeats some warnings once per use of a material: report each once.
  std::istringstream lines(text);
  std::vector<std::string> seen;
  for (std::string line; std::getline(lines, line);) {
    const std::string t(trim(line));
    if (t.empty() || std::find(seen.begin(), seen.end(), t) != seen.end()) continue;
    seen.push_back(t);
    warn(name + ": " + t);
  }
}

std::string first_line(const std::string& text) {
  const std::string_view t = trim(std::string_view(text).substr(0, text.find('\n')));
  return t.empty() ? "parse error" : std::string(t);
}

}  // namespace

Scene load_obj(const std::string& path, const WarningSink& warn_in) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  const std::string text = read_file(path);
  validate_obj_text(text, path);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  const fs::path base_dir = fs::path(path).parent_path();
  config.mtl_search_path = base_dir.empty() ? std::string("./") : base_dir.string() + "/";
  tinyobj::ObjReader reader;
  // ParseFromString cannot resolve `mtllib` against a directory, so let tinyobjloader read the
  // file itself; the validation above already read and vetted its text.
  if (!reader.ParseFromFile(path, config)) throw InputError(path + ": " + first_line(reader.Error()));
  forward_warnings(reader.Warning(), path, warn);
  return build_scene(reader, path, base_dir, warn);
}

Scene load_obj_from_string(const std::string& obj_text, const std::string& mtl_text,
                           const std::string& name, const WarningSink& warn_in) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  validate_obj_text(obj_text, name);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(obj_text, mtl_text, config)) throw InputError(name + ": " + first_line(reader.Error()));
  forward_warnings(reader.Warning(), name, warn);
  return build_scene(reader, name, fs::path("."), warn);
}

}  // namespace tracer
