#include "scene/obj_loader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <tiny_obj_loader.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <streambuf>
#include <string_view>
#include <unordered_map>

#include "base/read_input.hpp"
#include "base/stopwatch.hpp"
#include "base/text.hpp"
#include "scene/mtl_parser.hpp"
#include "scene/texture.hpp"

namespace tracer {
namespace {

namespace fs = std::filesystem;

// How often the long loops poll the cancel flag: often enough to stop within milliseconds.
constexpr size_t kCancelStride = 1 << 16;

[[noreturn]] void fail_at(const std::string& name, size_t line, const std::string& what) {
  throw InputError(name + ":" + std::to_string(line) + ": " + what);
}

// Reads one number of an OBJ line. Accepts what tinyobjloader reads as a number (a leading '+',
// values that underflow to zero) and rejects what it would silently turn into 0 or infinity.
float parse_coordinate(std::string_view tok, const std::string& name, size_t line) {
  std::string_view digits = tok;
  if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
  double value = 0;
  const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec == std::errc{} && ptr == digits.data() + digits.size()) {
    if (!std::isfinite(value)) fail_at(name, line, "non-finite coordinate " + in_quotes(tok));
    if (std::fabs(float(value)) > kMaxCoordinate) {
      fail_at(name, line,
              "number out of range " + in_quotes(tok) + " (coordinates must lie within +-" + kMaxCoordinateText + ")");
    }
    return float(value);
  }
  if (ec == std::errc::result_out_of_range && ptr == digits.data() + digits.size()) {
    // Beyond double's range either way: strtod says which (0 for underflow, HUGE_VAL for overflow).
    const double approx = std::strtod(std::string(digits).c_str(), nullptr);
    if (std::fabs(approx) < 1.0) return 0.0f;
    fail_at(name, line, "number out of range " + in_quotes(tok));
  }
  fail_at(name, line, "malformed number " + in_quotes(tok));
}

long long parse_index(std::string_view part, std::string_view tok, const std::string& name, size_t line) {
  if (part.size() > 1 && part.front() == '+' && part[1] != '-' && part[1] != '+') part.remove_prefix(1);
  long long index = 0;
  const auto [ptr, ec] = std::from_chars(part.data(), part.data() + part.size(), index);
  if (part.empty() || ec != std::errc{} || ptr != part.data() + part.size()) {
    fail_at(name, line, "malformed face index " + in_quotes(tok));
  }
  return index;
}

// tinyobjloader is lenient by design: it reads an unparsable number as 0 and keeps going on short
// lines. This lint goes over the same lines (for_each_line splits them as tinyobjloader does) and
// rejects all of that with the file and line. It is a diagnostic: what tinyobjloader produced is
// checked again in build_scene, so nothing unchecked reaches the scene even where the two disagree.
void lint_obj_text(std::string_view text, const std::string& name, CancelFlag cancel) {
  size_t counts[3] = {0, 0, 0};  // v, vt, vn seen so far: OBJ indices refer backwards
  for_each_line(text, [&](std::string_view line, size_t line_no) {
    if (line_no % kCancelStride == 0) throw_if_cancelled(cancel);
    line = trim(line);
    if (line.empty() || line.front() == '#') return;
    const std::string_view keyword = next_token(line);
    if (keyword == "v" || keyword == "vt" || keyword == "vn") {
      const size_t needed = keyword == "vt" ? 1 : 3;
      size_t n = 0;
      for (std::string_view tok = next_token(line); !tok.empty(); tok = next_token(line), ++n) {
        parse_coordinate(tok, name, line_no);
      }
      if (n < needed) {
        fail_at(
            name, line_no,
            "'" + std::string(keyword) + "' needs " + std::to_string(needed) + " numbers, got " + std::to_string(n));
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
          const long long index = parse_index(part, tok, name, line_no);
          const auto count = static_cast<long long>(counts[slot]);
          if (index == 0 || index > count || index < -count) {
            static const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
            fail_at(name, line_no,
                    std::string(kinds[slot]) + " index " + std::to_string(index) + " out of range (" +
                        std::to_string(count) + " defined so far)");
          }
        }
      }
      if (corners < 3) fail_at(name, line_no, "face needs at least 3 vertices, got " + std::to_string(corners));
    }
  });
}

// tinyobjloader reads its input through a stream; this one serves the bytes already in memory and
// polls the cancel flag between chunks, so a Ctrl-C stops the parse of a large file at once.
class CancellableBuffer : public std::streambuf {
 public:
  CancellableBuffer(std::string_view bytes, CancelFlag cancel) : bytes_(bytes), cancel_(cancel) {}

 protected:
  int_type underflow() override {
    throw_if_cancelled(cancel_);
    if (served_ >= bytes_.size()) return traits_type::eof();
    char* begin = const_cast<char*>(bytes_.data()) + served_;  // read-only use: get area only
    const size_t n = std::min<size_t>(bytes_.size() - served_, 1 << 20);
    setg(begin, begin, begin + n);
    served_ += n;
    return traits_type::to_int_type(*begin);
  }

 private:
  std::string_view bytes_;
  CancelFlag cancel_;
  size_t served_ = 0;
};

// Resolves `mtllib` names: from files beside the OBJ (each read once, like the OBJ), or from one
// text in memory (tests, fuzzing). Our own strict parser reads them (scene/mtl_parser.hpp):
// tinyobjloader's reads `Kd 0.5` as red and a malformed number as 0.
class MtlSource : public tinyobj::MaterialReader {
 public:
  static MtlSource from_directory(fs::path dir, CancelFlag cancel) {
    return MtlSource(std::move(dir), {}, false, cancel);
  }
  static MtlSource from_text(std::string text) { return MtlSource({}, std::move(text), true, nullptr); }

  // tinyobjloader's callback for each `mtllib` name: what read() gives, from the cache when
  // prefetch() has read that name already. A malformed MTL (or one that never ends) throws here,
  // when the parse reaches its `mtllib` line, as if it had been read just now.
  bool operator()(const std::string& mtl_name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* material_map, std::string* warn, std::string*) override {
    const auto cached = cache_.find(mtl_name);
    const MtlRead r = cached != cache_.end() ? cached->second : read(mtl_name);
    if (r.error) std::rethrow_exception(r.error);
    if (!r.ok) {
      if (warn) *warn += r.warn;
      return false;
    }
    for (const tinyobj::material_t& t : r.materials) {
      material_map->insert({t.name, int(materials->size())});  // the first of a name wins
      materials->push_back(t);
    }
    return true;
  }

  // Reads the MTL files of the OBJ's `mtllib` statements (each a list of names, of which the first
  // that reads is used, as tinyobjloader does) before the parse, and returns the diffuse texture
  // names of the materials they will give, in order: the textures can then be read while the
  // geometry is parsed. A name split differently from tinyobjloader's is read again by it, and the
  // prediction is checked against what the parse gives (load()), so it only ever saves time.
  std::vector<std::string> prefetch(const std::vector<std::vector<std::string>>& statements) {
    std::vector<std::string> texnames;
    for (const auto& names : statements) {
      for (const std::string& n : names) {
        auto it = cache_.find(n);
        if (it == cache_.end()) it = cache_.emplace(n, read(n)).first;
        const MtlRead& r = it->second;
        if (r.error) return texnames;  // the parse stops there
        if (!r.ok) continue;
        for (const tinyobj::material_t& t : r.materials) texnames.push_back(t.diffuse_texname);
        break;
      }
    }
    return texnames;
  }

 private:
  // An MTL file is text of a few kilobytes; past this it is not one (/dev/zero, a runaway pipe).
  static constexpr uint64_t kMaxMtlBytes = uint64_t(64) << 20;

  // One `mtllib` name read: its materials, or why not (a warning when it cannot be opened, an
  // error to throw when it is malformed, too large, or the read was cancelled).
  struct MtlRead {
    bool ok = false;
    std::string warn;
    std::vector<tinyobj::material_t> materials;
    std::exception_ptr error;
  };

  MtlRead read(const std::string& mtl_name) const {
    MtlRead r;
    try {
      std::string text;
      std::string name = "<mtl>";
      if (in_memory_) {
        text = text_;
      } else {
        const fs::path path = dir_ / mtl_name;
        name = path.string();
        try {
          text = read_input(name, cancel_, kMaxMtlBytes);
        } catch (const InputTooLarge&) {
          throw;  // a file that never ends is an error, not a missing material library
        } catch (const InputError& e) {
          r.warn = std::string(e.what()) + "\n";
          return r;
        }
      }
      strip_bom(text);
      for (const MtlMaterial& m : parse_mtl(text, name, cancel_)) {
        tinyobj::material_t t{};  // zeroed: its texture options have no initialisers
        t.name = m.name;
        for (int i = 0; i < 3; ++i) {
          t.ambient[i] = m.ka[i];
          t.diffuse[i] = m.kd[i];
          t.specular[i] = m.ks[i];
          t.emission[i] = m.ke[i];
          t.transmittance[i] = m.tf[i];
        }
        t.shininess = m.ns;
        t.ior = m.ni;
        t.dissolve = m.dissolve;
        t.illum = m.illum;
        t.diffuse_texname = m.diffuse_map;
        t.bump_texname = m.bump_map;
        r.materials.push_back(std::move(t));
      }
      r.ok = true;
    } catch (...) {
      r.error = std::current_exception();
    }
    return r;
  }

  MtlSource(fs::path dir, std::string text, bool in_memory, CancelFlag cancel)
      : dir_(std::move(dir)), text_(std::move(text)), in_memory_(in_memory), cancel_(cancel) {}
  fs::path dir_;
  std::string text_;
  bool in_memory_;
  CancelFlag cancel_;
  std::map<std::string, MtlRead> cache_;
};

// The names of each `mtllib` statement, in file order, split at blanks (tinyobjloader also honours
// backslash escapes; such a name is then simply not prefetched).
std::vector<std::vector<std::string>> mtllib_statements(std::string_view text) {
  std::vector<std::vector<std::string>> statements;
  for (size_t at = text.find("mtllib"); at != std::string_view::npos; at = text.find("mtllib", at + 6)) {
    size_t line_start = at;
    while (line_start > 0 && (text[line_start - 1] == ' ' || text[line_start - 1] == '\t')) --line_start;
    if (line_start > 0 && text[line_start - 1] != '\n' && text[line_start - 1] != '\r') continue;
    if (at + 6 >= text.size() || (text[at + 6] != ' ' && text[at + 6] != '\t')) continue;
    size_t end = text.find_first_of("\r\n", at);
    std::string_view rest = text.substr(at + 6, (end == std::string_view::npos ? text.size() : end) - at - 6);
    std::vector<std::string> names;
    for (std::string_view tok = next_token(rest); !tok.empty(); tok = next_token(rest)) names.emplace_back(tok);
    if (!names.empty()) statements.push_back(std::move(names));
  }
  return statements;
}

// Groups warnings by kind (the text with its quoted names and numbers left out), so 80,000
// undefined material names make one line with a count and the first place, not 80,000 lines.
class WarningLog {
 public:
  void add(const std::string& message) {
    const std::string key = kind_of(message);
    auto [it, inserted] = index_.try_emplace(key, entries_.size());
    if (inserted) entries_.push_back({message, 0});
    ++entries_[it->second].count;
  }
  void add_lines(const std::string& text) {
    size_t begin = 0;
    while (begin < text.size()) {
      size_t end = text.find('\n', begin);
      if (end == std::string::npos) end = text.size();
      const std::string_view line = trim(std::string_view(text).substr(begin, end - begin));
      if (!line.empty()) add(std::string(line));
      begin = end + 1;
    }
  }
  void flush(const std::string& name, const WarningSink& sink) const {
    for (const Entry& e : entries_) {
      std::string line = name + ": " + escaped(e.first);
      if (e.count > 1) line += " (" + std::to_string(e.count) + " times; the first shown)";
      sink(line);
    }
  }

 private:
  static std::string kind_of(std::string_view message) {
    std::string key;
    char quote = 0;
    for (char c : message) {
      if (quote) {
        if (c == quote) quote = 0, key += c;
        continue;
      }
      if (c == '\'' || c == '"') quote = c;
      if (c >= '0' && c <= '9') {
        if (key.empty() || key.back() != '#') key += '#';
        continue;
      }
      key += c;
    }
    return key;
  }
  struct Entry {
    std::string first;
    size_t count;
  };
  std::vector<Entry> entries_;
  std::unordered_map<std::string, size_t> index_;
};

Material to_material(const tinyobj::material_t& m, const std::string& name) {
  Material mat;
  mat.name = m.name;
  mat.kd = {float(m.diffuse[0]), float(m.diffuse[1]), float(m.diffuse[2])};
  mat.ks = {float(m.specular[0]), float(m.specular[1]), float(m.specular[2])};
  mat.ke = {float(m.emission[0]), float(m.emission[1]), float(m.emission[2])};
  mat.tf = {float(m.transmittance[0]), float(m.transmittance[1]), float(m.transmittance[2])};
  mat.ni = float(m.ior);
  mat.ns = float(m.shininess);
  mat.illum = m.illum;
  if (!is_finite(mat.kd) || !is_finite(mat.ks) || !is_finite(mat.ke) || !is_finite(mat.tf) || !std::isfinite(mat.ni) ||
      !std::isfinite(mat.ns)) {
    throw InputError(name + ": material " + in_quotes(m.name) + " has a non-finite colour or index");
  }
  return mat;
}

struct Parsed {
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
};

// tinyobjloader's errors say "line N" somewhere in their text; ours start with file:N.
std::string parser_error(const std::string& name, const std::string& err) {
  const std::string first = std::string(trim(std::string_view(err).substr(0, err.find('\n'))));
  const size_t at = first.find("line ");
  if (at != std::string::npos) {
    size_t line = 0;
    const char* b = first.data() + at + 5;
    const auto [ptr, ec] = std::from_chars(b, first.data() + first.size(), line);
    if (ec == std::errc{} && ptr != b) return name + ":" + std::to_string(line) + ": " + escaped(first);
  }
  return name + ": " + (first.empty() ? std::string("parse error") : escaped(first));
}

Parsed parse(std::string_view text, const std::string& name, MtlSource& mtl, WarningLog& warnings, CancelFlag cancel) {
  lint_obj_text(text, name, cancel);
  Parsed p;
  CancellableBuffer buffer(text, cancel);
  std::istream in(&buffer);
  std::string warn, err;
  const bool ok = tinyobj::LoadObj(&p.attrib, &p.shapes, &p.materials, &warn, &err, &in, &mtl, /*triangulate=*/true,
                                   /*default_vcols_fallback=*/false);
  warnings.add_lines(warn);
  if (!ok || !err.empty()) throw InputError(parser_error(name, err));
  return p;
}

// The map_Kd textures of a list of materials (their diffuse texture names, in material order),
// each file read and decoded once. The other maps (bump, Ks, Ka, alpha) are not used by any
// integrator, so not read.
struct MaterialTextures {
  std::vector<std::string> texnames;            // what this was made for
  std::vector<std::string> problem;             // per material: why its texture is not used
  std::vector<uint32_t> file_of;                // per material: its file, or kInvalidIndex
  std::vector<std::string> file_problem;        // per file
  std::vector<std::optional<Texture>> decoded;  // per file
};

MaterialTextures read_material_textures(std::vector<std::string> texnames, const fs::path& base_dir,
                                        const LoadLimits& limits, CancelFlag cancel) {
  MaterialTextures t;
  // 1. Which file each material names (sequential: directory listings are cached).
  t.problem.resize(texnames.size());
  t.file_of.assign(texnames.size(), kInvalidIndex);
  std::vector<fs::path> files;
  std::map<fs::path, uint32_t> file_index;
  FileFinder finder;
  for (size_t i = 0; i < texnames.size(); ++i) {
    if (texnames[i].empty()) continue;
    if (const std::optional<fs::path> file = finder.find(base_dir, texnames[i]); !file) {
      t.problem[i] = "not found";
    } else {
      const auto [it, fresh] = file_index.try_emplace(*file, uint32_t(files.size()));
      if (fresh) files.push_back(*file);
      t.file_of[i] = it->second;
    }
  }
  // 2. Every file read and its header checked, in parallel; 3. the total budget decided in file
  // order (so which texture is left out never depends on threads); 4. the rest decoded in parallel.
  std::vector<EncodedTexture> encoded(files.size());
  t.file_problem.resize(files.size());
  t.decoded.resize(files.size());
  const auto guarded = [&](size_t k, auto&& work) {
    try {
      work();
    } catch (const InputError& e) {
      t.file_problem[k] = e.what();
    }
  };
  limits.for_each(files.size(),
                  [&](size_t k) { guarded(k, [&] { encoded[k] = read_texture(files[k], limits.textures, cancel); }); });
  throw_if_cancelled(cancel);
  uint64_t texture_bytes = 0;
  for (size_t k = 0; k < files.size(); ++k) {
    if (!t.file_problem[k].empty()) continue;
    if (texture_bytes + encoded[k].decoded_bytes() > limits.textures.max_total_bytes) {
      t.file_problem[k] = "the scene's textures would take more than " +
                          std::to_string(limits.textures.max_total_bytes >> 20) + " MiB (--max-texture-mib raises it)";
      encoded[k] = {};
      continue;
    }
    texture_bytes += encoded[k].decoded_bytes();
  }
  limits.for_each(files.size(), [&](size_t k) {
    if (t.file_problem[k].empty()) guarded(k, [&] { t.decoded[k] = decode_texture(encoded[k]); });
    encoded[k] = {};  // the encoded bytes are no longer needed
  });
  throw_if_cancelled(cancel);
  t.texnames = std::move(texnames);
  return t;
}

std::vector<std::string> diffuse_texnames(const std::vector<tinyobj::material_t>& materials) {
  std::vector<std::string> names;
  names.reserve(materials.size());
  for (const tinyobj::material_t& m : materials) names.push_back(m.diffuse_texname);
  return names;
}

// Turns what tinyobjloader produced into a Scene, checking every value that is kept: vertices
// finite and within range, every face index inside the vertex array, material ids in range.
Scene build_scene(const Parsed& parsed, const std::string& name, MaterialTextures textures, WarningLog& warnings,
                  CancelFlag cancel) {
  const tinyobj::attrib_t& attrib = parsed.attrib;
  Scene scene;
  scene.source = name;
  scene.vertex_count = attrib.vertices.size() / 3;
  for (size_t i = 0; i < attrib.vertices.size(); ++i) {
    const float c = attrib.vertices[i];
    if (!std::isfinite(c) || std::fabs(c) > kMaxCoordinate) {
      throw InputError(name + ": vertex " + std::to_string(i / 3 + 1) + " has a coordinate out of range (" +
                       std::to_string(c) + ")");
    }
  }

  std::vector<uint32_t> texture_of(textures.decoded.size(), kInvalidIndex);
  for (size_t k = 0; k < textures.decoded.size(); ++k) {
    if (!textures.decoded[k]) continue;
    texture_of[k] = uint32_t(scene.textures.size());
    scene.textures.push_back(std::move(*textures.decoded[k]));
  }
  std::vector<std::string>& problem = textures.problem;
  const std::vector<uint32_t>& file_of = textures.file_of;
  const std::vector<std::string>& file_problem = textures.file_problem;
  size_t missing_textures = 0;
  std::string first_missing;
  for (size_t i = 0; i < parsed.materials.size(); ++i) {
    const tinyobj::material_t& m = parsed.materials[i];
    Material mat = to_material(m, name);
    if (file_of[i] != kInvalidIndex) {
      mat.diffuse_texture = texture_of[file_of[i]];
      if (mat.diffuse_texture == kInvalidIndex) problem[i] = file_problem[file_of[i]];
    }
    if (!problem[i].empty() && missing_textures++ == 0)
      first_missing = in_quotes(m.diffuse_texname) + ": " + problem[i];
    scene.materials.push_back(std::move(mat));
  }
  if (missing_textures > 0) {
    warnings.add(std::to_string(missing_textures) + " map_Kd texture(s) not used (first " + first_missing +
                 "); those materials use Kd");
  }
  const auto default_material = static_cast<uint32_t>(scene.materials.size());
  bool used_default = false;

  size_t faces_seen = 0;
  const size_t normal_count = attrib.normals.size() / 3;
  const size_t uv_count = attrib.texcoords.size() / 2;
  bool any_normal = false, any_uv = false;
  std::vector<Vec3> corner_normals;
  std::vector<Vec2> corner_uvs;
  // Sized once: growing six arrays by doubling cost a third of this function on large scenes.
  size_t triangle_faces = 0;
  for (const tinyobj::shape_t& shape : parsed.shapes) {
    for (const unsigned int fv : shape.mesh.num_face_vertices) triangle_faces += fv == 3 ? 1 : 0;
  }
  corner_normals.reserve(3 * triangle_faces);
  corner_uvs.reserve(3 * triangle_faces);
  scene.triangles.reserve(triangle_faces);
  scene.tri_prim.reserve(triangle_faces);
  scene.tri_geom.reserve(triangle_faces);
  scene.tri_material.reserve(triangle_faces);
  for (const tinyobj::shape_t& shape : parsed.shapes) {
    const tinyobj::mesh_t& mesh = shape.mesh;
    Geometry g;
    g.name = shape.name;
    g.first_triangle = static_cast<uint32_t>(scene.triangles.size());
    const auto geom_id = static_cast<uint32_t>(scene.geometries.size());
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      if (++faces_seen % kCancelStride == 0) throw_if_cancelled(cancel);
      const size_t fv = mesh.num_face_vertices[f];
      if (offset + fv > mesh.indices.size())
        throw InputError(name + ": face " + std::to_string(faces_seen) + " is incomplete");
      if (fv == 3) {
        Vec3 p[3];
        for (size_t k = 0; k < 3; ++k) {
          const auto vi = static_cast<size_t>(mesh.indices[offset + k].vertex_index);
          if (vi >= scene.vertex_count)
            throw InputError(name + ": face " + std::to_string(faces_seen) + " has a vertex index out of range");
          p[k] = {attrib.vertices[3 * vi], attrib.vertices[3 * vi + 1], attrib.vertices[3 * vi + 2]};
          const int ni = mesh.indices[offset + k].normal_index;
          Vec3 normal{0.0f};
          if (ni >= 0) {
            if (size_t(ni) >= normal_count)
              throw InputError(name + ": face " + std::to_string(faces_seen) + " has a normal index out of range");
            normal = {attrib.normals[3 * size_t(ni)], attrib.normals[3 * size_t(ni) + 1],
                      attrib.normals[3 * size_t(ni) + 2]};
            if (!is_finite(normal)) throw InputError(name + ": normal " + std::to_string(ni + 1) + " is not finite");
            any_normal = true;
          }
          corner_normals.push_back(normal);
          const int ti = mesh.indices[offset + k].texcoord_index;
          Vec2 uv;
          if (ti >= 0) {
            if (size_t(ti) >= uv_count)
              throw InputError(name + ": face " + std::to_string(faces_seen) +
                               " has a texture coordinate index out of range");
            uv = {attrib.texcoords[2 * size_t(ti)], attrib.texcoords[2 * size_t(ti) + 1]};
            if (!std::isfinite(uv.x) || !std::isfinite(uv.y))
              throw InputError(name + ": texture coordinate " + std::to_string(ti + 1) + " is not finite");
            any_uv = true;
          }
          corner_uvs.push_back(uv);
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
  if (any_normal) scene.corner_normals = std::move(corner_normals);
  if (any_uv) scene.corner_uvs = std::move(corner_uvs);
  scene.finalize();
  return scene;
}

void default_warning(const std::string& message) { std::cerr << "tracer: warning: " << message << "\n"; }

Scene load(std::string& text, const std::string& name, const fs::path& base_dir, MtlSource mtl,
           const WarningSink& warn_in, CancelFlag cancel, const LoadLimits& limits, LoadPhases* phases) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  strip_bom(text);
  WarningLog warnings;
  LoadPhases local;
  LoadPhases& ph = phases ? *phases : local;
  // The geometry parsed while the textures its MTL files name are read and decoded (when the
  // caller's loop runs the two at once); a parse error wins over anything the textures hit.
  std::vector<std::string> predicted = mtl.prefetch(mtllib_statements(text));
  Parsed parsed;
  std::optional<MaterialTextures> early;
  std::exception_ptr failed[2];
  limits.for_each(2, [&](size_t task) {
    const auto task_start = Clock::now();
    try {
      if (task == 0) {
        parsed = parse(text, name, mtl, warnings, cancel);
        ph.parse_ms = ms_since(task_start);
      } else if (!predicted.empty()) {
        early = read_material_textures(std::move(predicted), base_dir, limits, cancel);
        ph.textures_ms = ms_since(task_start);
      }
    } catch (...) {
      failed[task] = std::current_exception();
    }
  });
  for (const std::exception_ptr& e : failed) {
    if (e) std::rethrow_exception(e);
  }
  std::vector<std::string> texnames = diffuse_texnames(parsed.materials);
  if (!early || early->texnames != texnames) {  // not foreseen: read them now
    const auto textures_start = Clock::now();
    early = read_material_textures(std::move(texnames), base_dir, limits, cancel);
    ph.textures_ms = ms_since(textures_start);
  }
  const auto build_start = Clock::now();
  Scene scene = build_scene(parsed, name, std::move(*early), warnings, cancel);
  ph.assembly_ms = ms_since(build_start);
  warnings.flush(name, warn);
  return scene;
}

}  // namespace

Scene load_obj(const std::string& path, const WarningSink& warn, CancelFlag cancel, const LoadLimits& limits,
               LoadPhases* phases) {
  const auto read_start = Clock::now();
  std::string text = read_input(path, cancel, limits.max_obj_bytes);
  if (phases) phases->read_ms = ms_since(read_start);
  const fs::path base_dir = path == "-" ? fs::path() : fs::path(path).parent_path();
  return load(text, path == "-" ? std::string("<stdin>") : path, base_dir,
              MtlSource::from_directory(base_dir.empty() ? fs::path(".") : base_dir, cancel), warn, cancel, limits,
              phases);
}

Scene load_obj_from_string(const std::string& obj_text, const std::string& mtl_text, const std::string& name,
                           const WarningSink& warn) {
  std::string text = obj_text;
  return load(text, name, fs::path("."), MtlSource::from_text(mtl_text), warn, nullptr, LoadLimits{}, nullptr);
}

}  // namespace tracer
