#include "importers/gltf_document.hpp"

#include <algorithm>
#include <cstring>

#include "base/read_input.hpp"
#include "base/text.hpp"
#include "importers/gltf_json.hpp"

namespace tracer::gltf {
namespace {

namespace fs = std::filesystem;
namespace tg = tinygltf;

// What tinygltf's file callbacks may read: files inside `root` (the scene's folder), each within
// `max_bytes`. An empty root reads nothing (a scene from memory).
struct FileAccess {
  fs::path root;
  uint64_t max_bytes = 0;
  CancelFlag cancel = nullptr;
  std::vector<std::vector<unsigned char>>* payloads = nullptr;  // buffers' data: URIs, decoded apart
  mutable std::string refused;  // why the last file could not be read (tinygltf wraps it)
  // The payload a (joined) path names, if any.
  std::vector<unsigned char>* payload(const std::string& path) const {
    const std::optional<size_t> k = payload_index(path);
    return payloads && k && *k < payloads->size() ? &(*payloads)[*k] : nullptr;
  }
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
  if (access->payload(path)) return true;
  std::error_code ec;
  return !access->root.empty() && fs::exists(path, ec);
}

// No ~ or $VAR expansion: a URI names a file beside the scene, nothing else.
std::string expand_file_path(const std::string& path, void*) { return path; }

bool read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  const auto* access = static_cast<const FileAccess*>(user);
  if (std::vector<unsigned char>* payload = access->payload(path)) {
    out->swap(*payload);  // handed over, never copied: tinygltf swaps it into the buffer
    payload->clear();
    return true;
  }
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

bool is_glb(std::string_view bytes) { return bytes.size() >= 4 && bytes.substr(0, 4) == "glTF"; }

// The first line of tinygltf's messages, which end each problem with a newline.
std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
  return line.empty() ? "not a valid glTF file" : line;
}

const char* kSupportedExtensions[] = {"KHR_materials_emissive_strength",
                                      "KHR_materials_transmission",
                                      "KHR_materials_ior",
                                      "KHR_materials_specular",
                                      "KHR_lights_punctual",
                                      "KHR_mesh_quantization",
                                      "KHR_texture_transform"};

}  // namespace

std::optional<fs::path> inside_folder(const fs::path& root, const std::string& path, std::string* why) {
  FileAccess access;
  access.root = root;
  return access.inside(path, why);
}

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
  if (map.empty()) return nullptr;  // find() would build a std::string from name on every call
  const auto it = map.find(name);
  return it == map.end() ? nullptr : &it->second;
}

double number(const tg::Value* object, const char* key, double fallback) {
  if (!object || !object->IsObject() || !object->Has(key)) return fallback;
  const tg::Value& v = object->Get(key);
  return v.IsNumber() || v.IsInt() || v.IsReal() ? v.GetNumberAsDouble() : fallback;
}

bool supported_extension(const std::string& ext) {
  return std::any_of(std::begin(kSupportedExtensions), std::end(kSupportedExtensions),
                     [&](const char* s) { return ext == s; });
}

tg::Model parse(std::string_view bytes, const std::string& name, const fs::path& base_dir, const LoadLimits& limits,
                CancelFlag cancel, WarningLog& warnings) {
  if (bytes.size() > UINT32_MAX) throw InputError(name + ": larger than the 4 GiB a glTF file may be");
  PreparedJson prepared = prepare_json(bytes, name, warnings, cancel);
  if (!prepared.text.empty()) bytes = prepared.text;
  FileAccess access;
  if (!base_dir.empty()) access = {fs::weakly_canonical(base_dir), limits.max_obj_bytes, cancel};
  access.payloads = &prepared.payloads;
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
  if (!ok) {
    throw InputError(name + ": " +
                     (!access.refused.empty() ? access.refused : first_line(err.empty() ? tg_warn : err)));
  }
  for (size_t start = 0; start < tg_warn.size();) {
    const size_t end = std::min(tg_warn.find('\n', start), tg_warn.size());
    if (end > start) warnings.add(tg_warn.substr(start, end - start));
    start = end + 1;
  }
  return model;
}

Elements elements(const tg::Model& model, int accessor, const std::string& what) {
  if (accessor < 0 || size_t(accessor) >= model.accessors.size()) {
    throw InputError(what + ": accessor " + std::to_string(accessor) + " does not exist (the file has " +
                     std::to_string(model.accessors.size()) + ")");
  }
  const tg::Accessor& a = model.accessors[size_t(accessor)];
  const std::string where = what + " (accessor " + std::to_string(accessor) + ")";
  if (a.sparse.isSparse) throw InputError(where + ": sparse accessors are not supported");
  if (a.bufferView < 0 || size_t(a.bufferView) >= model.bufferViews.size()) {
    throw InputError(where + ": no buffer view (buffer view " + std::to_string(a.bufferView) + ")");
  }
  const tg::BufferView& view = model.bufferViews[size_t(a.bufferView)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size()) {
    throw InputError(where + ": buffer " + std::to_string(view.buffer) + " does not exist");
  }
  const size_t buffer_size = model.buffers[size_t(view.buffer)].data.size();
  if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset) {
    throw InputError(where + ": buffer view " + std::to_string(a.bufferView) + " runs past the end of its buffer (" +
                     std::to_string(buffer_size) + " bytes)");
  }
  Elements e;
  const int component_size = tg::GetComponentSizeInBytes(uint32_t(a.componentType));
  e.components = tg::GetNumComponentsInType(uint32_t(a.type));
  if (component_size <= 0 || e.components <= 0 || a.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE ||
      a.componentType == TINYGLTF_COMPONENT_TYPE_INT) {
    throw InputError(where + ": component type " + std::to_string(a.componentType) + " or type " +
                     std::to_string(a.type) + " is not valid here");
  }
  const size_t element = size_t(component_size) * size_t(e.components);
  e.stride = view.byteStride ? view.byteStride : element;
  if (e.stride < element) throw InputError(where + ": byte stride smaller than an element");
  e.count = a.count;
  if (a.count > 0) {
    const size_t avail = a.byteOffset <= view.byteLength ? view.byteLength - a.byteOffset : 0;
    if (avail < element || (a.count - 1) > (avail - element) / e.stride) {
      throw InputError(where + ": " + std::to_string(a.count) + " elements run past the end of buffer view " +
                       std::to_string(a.bufferView) + " (" + std::to_string(view.byteLength) + " bytes)");
    }
  }
  e.data = model.buffers[size_t(view.buffer)].data.data() + view.byteOffset + a.byteOffset;
  e.component_type = a.componentType;
  e.normalized = a.normalized;
  return e;
}

Elements vectors(const tg::Model& model, int accessor, int components, const std::string& what) {
  const Elements e = elements(model, accessor, what);
  // glTF allows float attributes, and (KHR_mesh_quantization) 8- and 16-bit integers; a 32-bit
  // integer attribute is not valid and would read as nothing.
  if (e.component_type == TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
    throw InputError(what + " (accessor " + std::to_string(accessor) +
                     "): component type 5125 (UNSIGNED_INT) is not allowed for a vertex attribute");
  }
  if (e.components != components) {
    throw InputError(what + " (accessor " + std::to_string(accessor) + "): " + std::to_string(e.components) +
                     " components, not " + std::to_string(components));
  }
  return e;
}

}  // namespace tracer::gltf
