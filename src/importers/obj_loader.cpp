#include "importers/obj_loader.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <unordered_map>

#include "base/read_input.hpp"
#include "base/stopwatch.hpp"
#include "base/text.hpp"
#include "importers/mtl_parser.hpp"
#include "importers/obj_parser.hpp"
#include "importers/texture_batch.hpp"
#include "importers/warning_log.hpp"
#include "scene/texture.hpp"

namespace tracer {
namespace {

// The MTL maps tracer reads: which statement, its file name in MtlMaterial, the slot it fills and
// what a material whose file cannot be used does instead.
struct MtlMap {
  const char* keyword;
  std::string MtlMaterial::*file;
  TextureSlot Material::*slot;
  const char* otherwise;
};
const MtlMap kMtlMaps[] = {
    {"map_Kd", &MtlMaterial::diffuse_map, &Material::diffuse_texture, "those materials use Kd"},
    {"map_bump", &MtlMaterial::bump_map, &Material::bump_texture, "those materials are flat"},
    {"map_Ks", &MtlMaterial::specular_map, &Material::specular_texture, "those materials use Ks"},
    {"map_Ns", &MtlMaterial::shininess_map, &Material::shininess_texture, "those materials use Ns"},
    {"map_Ke", &MtlMaterial::emissive_map, &Material::emission_texture, "those materials use Ke"},
    {"norm", &MtlMaterial::normal_map, &Material::normal_texture, "those materials are flat"},
};
constexpr size_t kMapCount = std::size(kMtlMaps);

// kMapCount names per material, in material order, each map's ("" where none).
std::vector<std::string> texture_names(const std::vector<MtlMaterial>& materials) {
  std::vector<std::string> names;
  names.reserve(kMapCount * materials.size());
  for (const MtlMaterial& m : materials)
    for (const MtlMap& map : kMtlMaps) names.push_back(m.*map.file);
  return names;
}

namespace fs = std::filesystem;

// Resolves `mtllib` names: from files beside the OBJ (each read once, like the OBJ), or from one
// text in memory (tests, fuzzing), by the strict MTL parser (importers/mtl_parser.hpp).
class MtlSource {
 public:
  static MtlSource from_directory(fs::path dir, CancelFlag cancel) {
    return MtlSource(std::move(dir), {}, false, cancel);
  }
  static MtlSource from_text(std::string text) { return MtlSource({}, std::move(text), true, nullptr); }

  // One `mtllib` name read: its materials, or why not (a warning when it cannot be opened, an
  // error to throw when it is malformed, too large, or the read was cancelled).
  struct MtlRead {
    bool ok = false;
    std::string warn;
    MtlFile file;
    std::exception_ptr error;
  };

  // What `name` reads as, read once.
  const MtlRead& get(const std::string& name) {
    auto it = cache_.find(name);
    if (it == cache_.end()) it = cache_.emplace(name, read(name)).first;
    return it->second;
  }

  // Reads the MTL files of the OBJ's `mtllib` statements (each a list of names, of which the first
  // that reads is used) before the OBJ is parsed, and returns the texture names of the materials
  // they will give, in order (texture_names()): the textures can then be read while the geometry is
  // parsed. The prediction is checked against what the parse gives (load()), so it only ever
  // saves time.
  std::vector<std::string> prefetch(const std::vector<std::vector<std::string>>& statements) {
    std::vector<std::string> texnames;
    std::set<std::string> loaded;
    for (const auto& names : statements) {
      for (const std::string& n : names) {
        if (loaded.count(n)) break;
        const MtlRead& r = get(n);
        if (r.error) return texnames;  // the load stops there
        if (!r.ok) continue;
        loaded.insert(n);
        const std::vector<std::string> mine = texture_names(r.file.materials);
        texnames.insert(texnames.end(), mine.begin(), mine.end());
        break;
      }
    }
    return texnames;
  }

 private:
  // An MTL file is text of a few kilobytes; past this it is not one (/dev/zero, a runaway pipe).
  static constexpr uint64_t kMaxMtlBytes = uint64_t(64) << 20;

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
          r.warn = e.what();
          return r;
        }
      }
      strip_bom(text);
      r.file = parse_mtl(text, name, cancel_);
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

// The names of each `mtllib` statement, in file order, split at blanks as the parser splits them:
// found by a search for the word before the parse, so the MTL files and their textures can be
// read while the OBJ is parsed.
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

Material to_material(const MtlMaterial& m, const std::string& name) {
  Material mat;
  mat.name = m.name;
  mat.kd = m.kd;
  mat.ks = m.ks;
  mat.ke = m.ke;
  mat.tf = m.tf;
  mat.ni = m.ni;
  mat.ns = m.ns;
  mat.illum = m.illum;
  if (!is_finite(mat.kd) || !is_finite(mat.ks) || !is_finite(mat.ke) || !is_finite(mat.tf) || !std::isfinite(mat.ni) ||
      !std::isfinite(mat.ns)) {
    throw InputError(name + ": material " + in_quotes(m.name) + " has a non-finite colour or index");
  }
  return mat;
}

// The textures of a list of materials (texture_names(): kMtlMaps), each file read and decoded
// once. The other maps (map_Ka, map_d, the PBR extension's) are not read.
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
  // 2-4. Read, budgeted and decoded together (importers/texture_batch.hpp).
  TextureBatch batch = read_and_decode(
      files.size(), [&](size_t k) { return read_texture(files[k], limits.textures, cancel); }, limits, cancel);
  t.file_problem = std::move(batch.problem);
  t.decoded = std::move(batch.decoded);
  t.texnames = std::move(texnames);
  return t;
}

// What the statements of an OBJ make of its triangles: the materials its `mtllib` files define (in
// the order they are read), and which material and geometry each run of triangles takes. A
// `usemtl` names a material of the files read before it; `g` and `o` start a geometry.
struct Layout {
  std::vector<MtlMaterial> materials;
  std::vector<TriangleRun> runs;
  std::vector<Geometry> geometries;
  bool uses_default = false;  // some triangles have no material: the default one is appended
};

Layout lay_out(const ObjGeometry& obj, MtlSource& mtl, WarningLog& warnings) {
  Layout out;
  std::unordered_map<std::string, uint32_t> by_name;
  std::set<std::string> loaded;
  uint32_t material = kInvalidIndex;
  std::string group;
  bool open = false;  // whether geometries.back() takes the triangles at `at`
  uint64_t at = 0;
  const auto take_until = [&](uint64_t end) {
    if (end <= at) return;
    if (!open) {
      out.geometries.push_back({group, static_cast<uint32_t>(at), 0});
      open = true;
    }
    const auto geometry = static_cast<uint32_t>(out.geometries.size() - 1);
    if (out.runs.empty() || out.runs.back().material != material || out.runs.back().geometry != geometry) {
      out.runs.push_back({at, material, geometry});
    }
    at = end;
  };
  const auto close = [&] {
    if (open) out.geometries.back().triangle_count = static_cast<uint32_t>(at - out.geometries.back().first_triangle);
    open = false;
  };
  for (const ObjStatement& s : obj.statements()) {
    take_until(s.triangle);
    switch (s.kind) {
      case ObjStatement::Kind::UseMtl: {
        const auto it = by_name.find(s.names[0]);
        material = it == by_name.end() ? kInvalidIndex : it->second;
        if (it == by_name.end()) warnings.add("material [ '" + s.names[0] + "' ] not found in .mtl");
        break;
      }
      case ObjStatement::Kind::Group:
        close();
        group = s.names[0];
        break;
      case ObjStatement::Kind::MtlLib: {
        if (s.names.empty()) warnings.add("'mtllib' without a file name (line " + std::to_string(s.line) + ")");
        bool found = false;
        for (const std::string& n : s.names) {
          if (loaded.count(n)) {
            found = true;
            break;
          }
          const MtlSource::MtlRead& r = mtl.get(n);
          if (r.error) std::rethrow_exception(r.error);
          if (!r.warn.empty()) warnings.add(r.warn);
          if (!r.ok) continue;
          loaded.insert(n);
          for (const std::string& w : r.file.warnings) warnings.add(w);
          for (const MtlMaterial& m : r.file.materials) {
            by_name.try_emplace(m.name, static_cast<uint32_t>(out.materials.size()));  // the first of a name wins
            out.materials.push_back(m);
          }
          found = true;
          break;
        }
        if (!s.names.empty() && !found) warnings.add("Failed to load material file(s). Use default material.");
        break;
      }
    }
  }
  take_until(obj.triangle_count());
  close();
  const auto default_material = static_cast<uint32_t>(out.materials.size());
  for (TriangleRun& r : out.runs) {
    if (r.material == kInvalidIndex) r.material = default_material, out.uses_default = true;
  }
  return out;
}

// The scene's materials, their textures attached (with one grouped warning for those not used).
void add_materials(Scene& scene, const Layout& layout, MaterialTextures textures, const std::string& name,
                   WarningLog& warnings) {
  std::vector<uint32_t> texture_of(textures.decoded.size(), kInvalidIndex);
  for (size_t k = 0; k < textures.decoded.size(); ++k) {
    if (!textures.decoded[k]) continue;
    texture_of[k] = uint32_t(scene.textures.size());
    scene.textures.push_back(std::move(*textures.decoded[k]));
  }
  const std::vector<std::string>& problem = textures.problem;  // per texture name
  size_t missing[kMapCount] = {};
  std::string first_missing[kMapCount];
  for (size_t i = 0; i < layout.materials.size(); ++i) {
    const MtlMaterial& m = layout.materials[i];
    Material mat = to_material(m, name);
    for (size_t k = 0; k < kMapCount; ++k) {
      std::string why = problem[kMapCount * i + k];
      uint32_t& slot = (mat.*kMtlMaps[k].slot).texture;
      if (const uint32_t file = textures.file_of[kMapCount * i + k]; file != kInvalidIndex) {
        slot = texture_of[file];
        if (slot == kInvalidIndex) why = textures.file_problem[file];
      }
      if (!why.empty() && missing[k]++ == 0) first_missing[k] = in_quotes(m.*kMtlMaps[k].file) + ": " + why;
    }
    mat.bump_multiplier = m.bump_multiplier;
    mat.normal_scale = m.normal_scale;
    // map_Ke without Ke: the texture is the emission (as map_Kd without Kd shows its texture).
    if (mat.emission_texture.present() && !mat.emissive()) mat.ke = Vec3{1.0f};
    scene.materials.push_back(std::move(mat));
  }
  for (size_t k = 0; k < kMapCount; ++k) {
    if (missing[k] == 0) continue;
    warnings.add(std::to_string(missing[k]) + " " + kMtlMaps[k].keyword + " texture(s) not used (first " +
                 first_missing[k] + "); " + kMtlMaps[k].otherwise);
  }
  if (layout.uses_default) scene.materials.push_back(Material{});
}

Scene load(std::string_view text, const std::string& name, const fs::path& base_dir, MtlSource mtl,
           const WarningSink& warn_in, CancelFlag cancel, const LoadLimits& limits, LoadPhases* phases) {
  const WarningSink warn = warn_in ? warn_in : WarningSink(default_warning);
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // a UTF-8 byte-order mark
  WarningLog warnings;
  LoadPhases local;
  LoadPhases& ph = phases ? *phases : local;
  // The geometry parsed while the textures its MTL files name are read and decoded (when the
  // caller's loop runs the two at once); a parse error wins over anything the textures hit.
  std::vector<std::string> predicted = mtl.prefetch(mtllib_statements(text));
  if (!limits.read_textures) predicted.clear();
  ObjGeometry obj;
  Layout layout;
  std::optional<MaterialTextures> early;
  std::exception_ptr failed[2];
  limits.for_each(2, [&](size_t task) {
    const auto task_start = Clock::now();
    try {
      if (task == 0) {
        obj = ObjGeometry::parse(text, name, limits.for_each, cancel, limits.chunk_bytes);
        layout = lay_out(obj, mtl, warnings);
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
  if (obj.triangle_count() == 0) throw InputError(name + ": scene has no triangles");
  refuse_past_memory(limits, name, obj.triangle_count(), obj.any_normal(), obj.any_uv());
  std::vector<std::string> texnames = texture_names(layout.materials);
  if (!limits.read_textures) texnames.assign(texnames.size(), std::string());
  if (!early || early->texnames != texnames) {  // not foreseen: read them now
    const auto textures_start = Clock::now();
    early = read_material_textures(std::move(texnames), base_dir, limits, cancel);
    ph.textures_ms = ms_since(textures_start);
  }
  const auto build_start = Clock::now();
  Scene scene;
  scene.source = name;
  add_materials(scene, layout, std::move(*early), name, warnings);
  std::vector<uint32_t> geometry_first;
  for (const Geometry& g : layout.geometries) geometry_first.push_back(g.first_triangle);
  obj.assemble(scene, layout.runs, geometry_first, limits.for_each, cancel);
  scene.geometries = std::move(layout.geometries);
  scene.finalize();
  ph.assembly_ms = ms_since(build_start);
  warnings.flush(name, warn);
  return scene;
}

}  // namespace

Scene load_obj(const std::string& path, const WarningSink& warn, CancelFlag cancel, const LoadLimits& limits,
               LoadPhases* phases) {
  const auto read_start = Clock::now();
  const InputBytes bytes = map_input(path, cancel, limits.max_obj_bytes);
  if (phases) phases->read_ms = ms_since(read_start);
  const fs::path base_dir = path == "-" ? fs::path() : fs::path(path).parent_path();
  return load(bytes.view(), path == "-" ? std::string("<stdin>") : path, base_dir,
              MtlSource::from_directory(base_dir.empty() ? fs::path(".") : base_dir, cancel), warn, cancel, limits,
              phases);
}

Scene load_obj_from_string(const std::string& obj_text, const std::string& mtl_text, const std::string& name,
                           const WarningSink& warn, const LoadLimits& limits) {
  return load(obj_text, name, fs::path("."), MtlSource::from_text(mtl_text), warn, nullptr, limits, nullptr);
}

}  // namespace tracer
