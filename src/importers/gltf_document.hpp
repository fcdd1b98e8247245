// The glTF document as tinygltf parses it, and what reading it safely takes: files confined to
// the scene's folder, accessors checked against their buffers before a byte is read, the values
// of extensions.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "base/errors.hpp"
#include "importers/load_limits.hpp"
#include "importers/tinygltf.hpp"
#include "importers/warning_log.hpp"
#include "math/vec.hpp"

namespace tracer::gltf {

// Parses .gltf JSON or (when the bytes start with its magic) .glb. External buffers are read from
// `base_dir` or below only, each within limits.max_obj_bytes (an empty base_dir reads no file:
// only data: URIs resolve); images are left encoded. tinygltf's warnings go to `warnings`.
// Throws InputError naming `name`, Cancelled when `cancel` is set.
tinygltf::Model parse(std::string_view bytes, const std::string& name, const std::filesystem::path& base_dir,
                      const LoadLimits& limits, CancelFlag cancel, WarningLog& warnings);

// The file `path` names when it lies inside `root` (symbolic links followed), or nothing with
// `why` set. An empty root holds nothing (a scene read from memory).
std::optional<std::filesystem::path> inside_folder(const std::filesystem::path& root, const std::string& path,
                                                   std::string* why);

// %XX escapes in a URI's path (glTF URIs are percent-encoded).
std::string decode_uri(const std::string& uri);

// The extensions tracer reads (others are warned about, or refused when the file requires them).
bool supported_extension(const std::string& name);
// An extension object of `map`, or nullptr.
const tinygltf::Value* extension(const tinygltf::ExtensionMap& map, const char* name);
// A number member of an extension object, or `fallback`.
double number(const tinygltf::Value* object, const char* key, double fallback);
// Three numbers of a factor array, or `fallback`.
Vec3 vec3_of(const std::vector<double>& v, Vec3 fallback);

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

// Accessor `accessor`'s elements, checked to lie inside its buffer view and buffer (a count the
// bytes cannot hold is refused before anything is read); `where` names it in errors
// ("scene.gltf: mesh 0 primitive 0 POSITION").
Elements elements(const tinygltf::Model& model, int accessor, const std::string& where);
// The same, of exactly `components` components a element.
Elements vectors(const tinygltf::Model& model, int accessor, int components, const std::string& where);

}  // namespace tracer::gltf
