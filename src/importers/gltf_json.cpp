#include "importers/gltf_json.hpp"

#include <openssl/evp.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <functional>
#include <memory>

#include "base/text.hpp"

namespace tracer::gltf {
namespace {

using nlohmann::json;

constexpr std::string_view kPayloadPrefix = ":tracer-data-uri:";
constexpr uint32_t kGlbMagic = 0x46546C67, kJsonChunk = 0x4E4F534A;

uint32_t le32(std::string_view b, size_t at) {
  uint32_t v;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}

// One container of the scan: whether it is an object, the key being read (objects of the first
// levels only: that is all the payload rule looks at) and the element index (arrays).
struct Frame {
  bool object = false;
  bool expect_key = false;
  std::string_view key;
  size_t index = 0;
};

// The end of the string whose opening quote is at `open` (the index of its closing quote), or
// npos when it does not end; whether it holds an escape.
size_t string_end(std::string_view s, size_t open, bool& escaped) {
  escaped = false;
  for (size_t i = open + 1; i < s.size(); ++i) {
    if (s[i] == '\\') {
      escaped = true;
      ++i;
    } else if (s[i] == '"') {
      return i;
    }
  }
  return std::string_view::npos;
}

// Base64 to bytes (OpenSSL's decoder, streaming: the input is never copied).
std::optional<std::vector<unsigned char>> decode_base64(std::string_view text) {
  std::unique_ptr<EVP_ENCODE_CTX, void (*)(EVP_ENCODE_CTX*)> ctx(EVP_ENCODE_CTX_new(), EVP_ENCODE_CTX_free);
  if (!ctx) return std::nullopt;
  EVP_DecodeInit(ctx.get());
  std::vector<unsigned char> out(text.size() / 4 * 3 + 3);
  size_t written = 0;
  constexpr size_t kStep = size_t(1) << 20;
  for (size_t at = 0; at < text.size(); at += kStep) {
    const int n = int(std::min(kStep, text.size() - at));
    int got = 0;
    if (EVP_DecodeUpdate(ctx.get(), out.data() + written, &got,
                         reinterpret_cast<const unsigned char*>(text.data() + at), n) < 0) {
      return std::nullopt;
    }
    written += size_t(got);
  }
  int got = 0;
  if (EVP_DecodeFinal(ctx.get(), out.data() + written, &got) < 0) return std::nullopt;
  out.resize(written + size_t(got));
  return out;
}

// One pass over the text without recursion: nesting bounded, and each buffers[i].uri that is a
// base64 data: URI decoded into `out.payloads` and replaced in `out.text` by its payload name.
// (A GLB's buffer is its BIN chunk: `move_payloads` false leaves its rare data: URIs to tinygltf.)
void scan(std::string_view s, const std::string& name, PreparedJson& out, CancelFlag cancel, bool move_payloads) {
  std::vector<Frame> stack;
  size_t copied = 0;  // how much of `s` is in out.text already (when any payload was moved)
  for (size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (c == '{' || c == '[') {
      if (stack.size() >= size_t(kMaxJsonDepth)) {
        throw InputError(name + ": its JSON nests deeper than " + std::to_string(kMaxJsonDepth) + " levels (at byte " +
                         std::to_string(i) + "): refused");
      }
      stack.push_back({c == '{', c == '{', {}, 0});
      if ((i & 0xffff) == 0) throw_if_cancelled(cancel);
    } else if (c == '}' || c == ']') {
      if (!stack.empty()) stack.pop_back();
    } else if (c == ',') {
      if (!stack.empty()) {
        if (stack.back().object) stack.back().expect_key = true;
        ++stack.back().index;
      }
    } else if (c == ':') {
      if (!stack.empty()) stack.back().expect_key = false;
    } else if (c == '"') {
      bool escaped = false;
      const size_t end = string_end(s, i, escaped);
      if (end == std::string_view::npos) return;  // unterminated: the parser says so
      const std::string_view value = s.substr(i + 1, end - i - 1);
      if (!stack.empty() && stack.back().object && stack.back().expect_key) {
        if (stack.size() <= 3) stack.back().key = value;
      } else if (move_payloads && stack.size() == 3 && stack[0].object && stack[0].key == "buffers" &&
                 !stack[1].object && stack[2].object && stack[2].key == "uri" && !escaped &&
                 value.starts_with("data:")) {
        const size_t comma = value.find(',');
        if (comma != std::string_view::npos && value.substr(0, comma).ends_with(";base64")) {
          throw_if_cancelled(cancel);
          std::optional<std::vector<unsigned char>> bytes = decode_base64(value.substr(comma + 1));
          if (!bytes) {
            throw InputError(name + ": buffers[" + std::to_string(stack[1].index) +
                             "].uri: its data: URI is not valid base64");
          }
          out.text.append(s.substr(copied, i - copied));
          out.text += '"' + payload_name(out.payloads.size()) + '"';
          out.payloads.push_back(std::move(*bytes));
          copied = end + 1;
        }
      }
      i = end;
    }
  }
  if (!out.payloads.empty()) out.text.append(s.substr(copied));
}

// --- properties: what tinygltf would read as absent when its type is wrong -----------------------

class Checker {
 public:
  Checker(const std::string& name, WarningLog& warnings, const std::vector<std::vector<unsigned char>>& payloads)
      : name_(name), warnings_(warnings), payloads_(payloads) {}

  // Returns whether the document was changed (a gap filled).
  bool check(json& doc) {
    if (!doc.is_object()) throw error("", "the JSON is not an object");
    index_of(doc, "scene", "scene");
    const json* scenes = array_of(doc, "scenes", "scenes");
    if (doc.contains("scene") && doc["scene"].is_number_unsigned()) {
      const uint64_t s = doc["scene"].get<uint64_t>();
      const size_t n = scenes ? scenes->size() : 0;
      if (s >= n) {
        throw error("scene", std::to_string(s) + " names no scene (the file has " + std::to_string(n) + ")");
      }
    }
    each(scenes, "scenes", [&](const json& o, const std::string& at) { indices_of(o, "nodes", at + ".nodes"); });
    for (const char* key : {"extensionsRequired", "extensionsUsed"}) {
      if (const json* a = array_of(doc, key, key)) {
        for (size_t k = 0; k < a->size(); ++k) {
          if (!(*a)[k].is_string()) throw error(std::string(key) + "[" + std::to_string(k) + "]", "not a string");
        }
      }
    }
    each(array_of(doc, "nodes", "nodes"), "nodes", [&](const json& o, const std::string& at) { node(o, at); });
    each(array_of(doc, "meshes", "meshes"), "meshes", [&](const json& m, const std::string& at) {
      each(array_of(m, "primitives", at + ".primitives"), at + ".primitives",
           [&](const json& p, const std::string& pa) {
             for (const char* key : {"indices", "material", "mode"}) index_of(p, key, pa + "." + key);
             if (const json* attributes = object_of(p, "attributes", pa + ".attributes")) {
               for (const auto& [k, v] : attributes->items()) index(v, pa + ".attributes." + k);
             }
           });
    });
    each(array_of(doc, "accessors", "accessors"), "accessors", [&](const json& o, const std::string& at) {
      for (const char* key : {"bufferView", "byteOffset", "componentType", "count"}) index_of(o, key, at + "." + key);
      string_of(o, "type", at + ".type");
      bool_of(o, "normalized", at + ".normalized");
    });
    each(array_of(doc, "bufferViews", "bufferViews"), "bufferViews", [&](const json& o, const std::string& at) {
      for (const char* key : {"buffer", "byteOffset", "byteLength", "byteStride", "target"}) {
        index_of(o, key, at + "." + key);
      }
    });
    each(array_of(doc, "buffers", "buffers"), "buffers", [&](const json& o, const std::string& at) {
      index_of(o, "byteLength", at + ".byteLength");
      uri_of(o, at);
      payload_size(o, at);
    });
    each(array_of(doc, "images", "images"), "images", [&](const json& o, const std::string& at) {
      index_of(o, "bufferView", at + ".bufferView");
      string_of(o, "mimeType", at + ".mimeType");
      uri_of(o, at);
    });
    each(array_of(doc, "textures", "textures"), "textures", [&](const json& o, const std::string& at) {
      for (const char* key : {"source", "sampler"}) index_of(o, key, at + "." + key);
    });
    each(array_of(doc, "materials", "materials"), "materials",
         [&](const json& o, const std::string& at) { material(o, at); });
    bool changed = false;
    each_mutable(doc, "cameras", [&](json& o, const std::string& at) { changed |= camera(o, at); });
    if (const json* ext = object_of(doc, "extensions", "extensions")) {
      if (const json* lights = object_of(*ext, "KHR_lights_punctual", "extensions.KHR_lights_punctual")) {
        const std::string at = "extensions.KHR_lights_punctual.lights";
        each(array_of(*lights, "lights", at), at, [&](const json& l, const std::string& la) {
          string_of(l, "type", la + ".type");
          numbers_of(l, "color", 3, la + ".color");
          number_of(l, "intensity", la + ".intensity");
        });
      }
    }
    return changed;
  }

 private:
  InputError error(const std::string& at, const std::string& what) const {
    return InputError(name_ + ": " + (at.empty() ? "" : at + ": ") + what);
  }
  static std::string shown(const json& v) {
    std::string text = v.dump();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return text;
  }

  const json* member(const json& o, const char* key) const {
    if (!o.is_object()) return nullptr;
    const auto it = o.find(key);
    return it == o.end() ? nullptr : &*it;
  }
  void each(const json* array, const std::string& at, const std::function<void(const json&, const std::string&)>& f) {
    if (!array) return;
    for (size_t i = 0; i < array->size(); ++i) {
      const std::string where = at + "[" + std::to_string(i) + "]";
      if (!(*array)[i].is_object()) throw error(where, shown((*array)[i]) + " is not an object");
      f((*array)[i], where);
    }
  }
  void each_mutable(json& doc, const char* key, const std::function<void(json&, const std::string&)>& f) {
    if (!array_of(doc, key, key)) return;
    json& array = doc[key];
    for (size_t i = 0; i < array.size(); ++i) {
      const std::string where = std::string(key) + "[" + std::to_string(i) + "]";
      if (!array[i].is_object()) throw error(where, shown(array[i]) + " is not an object");
      f(array[i], where);
    }
  }
  const json* array_of(const json& o, const char* key, const std::string& at) const {
    const json* v = member(o, key);
    if (v && !v->is_array()) throw error(at, shown(*v) + " is not an array");
    return v;
  }
  const json* object_of(const json& o, const char* key, const std::string& at) const {
    const json* v = member(o, key);
    if (v && !v->is_object()) throw error(at, shown(*v) + " is not an object");
    return v;
  }
  void index(const json& v, const std::string& at) const {
    if (!v.is_number_unsigned()) throw error(at, shown(v) + " is not a non-negative integer");
  }
  void index_of(const json& o, const char* key, const std::string& at) const {
    if (const json* v = member(o, key)) index(*v, at);
  }
  void indices_of(const json& o, const char* key, const std::string& at) const {
    if (const json* a = array_of(o, key, at)) {
      for (size_t k = 0; k < a->size(); ++k) index((*a)[k], at + "[" + std::to_string(k) + "]");
    }
  }
  void string_of(const json& o, const char* key, const std::string& at) const {
    if (const json* v = member(o, key); v && !v->is_string()) throw error(at, shown(*v) + " is not a string");
  }
  void bool_of(const json& o, const char* key, const std::string& at) const {
    if (const json* v = member(o, key); v && !v->is_boolean()) throw error(at, shown(*v) + " is not true or false");
  }
  void number(const json& v, const std::string& at) const {
    if (!v.is_number() || !std::isfinite(v.get<double>())) throw error(at, shown(v) + " is not a finite number");
  }
  const json* number_of(const json& o, const char* key, const std::string& at) const {
    const json* v = member(o, key);
    if (v) number(*v, at);
    return v;
  }
  // An array of exactly `count` finite numbers (0: any count).
  const json* numbers_of(const json& o, const char* key, size_t count, const std::string& at) const {
    const json* a = array_of(o, key, at);
    if (!a) return nullptr;
    if (count && a->size() != count) {
      throw error(at, std::to_string(a->size()) + " numbers, not " + std::to_string(count));
    }
    for (size_t k = 0; k < a->size(); ++k) number((*a)[k], at + "[" + std::to_string(k) + "]");
    return a;
  }
  void texture_info(const json& o, const char* key, const std::string& at) const {
    if (const json* t = object_of(o, key, at)) {
      index_of(*t, "index", at + ".index");
      index_of(*t, "texCoord", at + ".texCoord");
      number_of(*t, "scale", at + ".scale");
    }
  }

  void node(const json& o, const std::string& at) const {
    for (const char* key : {"mesh", "camera", "skin"}) index_of(o, key, at + "." + key);
    indices_of(o, "children", at + ".children");
    numbers_of(o, "translation", 3, at + ".translation");
    numbers_of(o, "rotation", 4, at + ".rotation");
    numbers_of(o, "scale", 3, at + ".scale");
    if (const json* m = numbers_of(o, "matrix", 16, at + ".matrix")) {
      // Column-major: the last row is elements 3, 7, 11 and 15.
      if ((*m)[3].get<double>() != 0.0 || (*m)[7].get<double>() != 0.0 || (*m)[11].get<double>() != 0.0 ||
          (*m)[15].get<double>() != 1.0) {
        throw error(at + ".matrix", "not affine (its last row is not 0 0 0 1): a node's matrix is a transform");
      }
      // Not allowed beside a matrix, and what tinygltf then leaves unread: said, the matrix kept.
      if (o.contains("translation") || o.contains("rotation") || o.contains("scale")) {
        warnings_.add(at + ": both a matrix and translation/rotation/scale (not allowed): the matrix used");
      }
    }
  }

  void material(const json& o, const std::string& at) const {
    numbers_of(o, "emissiveFactor", 3, at + ".emissiveFactor");
    string_of(o, "alphaMode", at + ".alphaMode");
    bool_of(o, "doubleSided", at + ".doubleSided");
    texture_info(o, "normalTexture", at + ".normalTexture");
    texture_info(o, "emissiveTexture", at + ".emissiveTexture");
    if (const json* pbr = object_of(o, "pbrMetallicRoughness", at + ".pbrMetallicRoughness")) {
      const std::string pa = at + ".pbrMetallicRoughness";
      numbers_of(*pbr, "baseColorFactor", 4, pa + ".baseColorFactor");
      number_of(*pbr, "metallicFactor", pa + ".metallicFactor");
      number_of(*pbr, "roughnessFactor", pa + ".roughnessFactor");
      texture_info(*pbr, "baseColorTexture", pa + ".baseColorTexture");
      texture_info(*pbr, "metallicRoughnessTexture", pa + ".metallicRoughnessTexture");
    }
  }

  // A URI names a file inside the scene's folder: not an absolute path, another scheme, or a
  // name the shell would expand (tracer expands nothing).
  void uri_of(const json& o, const std::string& at) const {
    const json* v = member(o, "uri");
    if (!v) return;
    if (!v->is_string()) throw error(at + ".uri", shown(*v) + " is not a string");
    const std::string& uri = v->get_ref<const std::string&>();
    if (uri.starts_with("data:") || uri.starts_with(kPayloadPrefix)) return;
    size_t scheme = 0;
    while (scheme < uri.size() && (std::isalnum(static_cast<unsigned char>(uri[scheme])) || uri[scheme] == '+' ||
                                   uri[scheme] == '-' || uri[scheme] == '.')) {
      ++scheme;
    }
    const bool has_scheme = scheme > 1 && scheme < uri.size() && uri[scheme] == ':';
    if (uri.starts_with('/') || uri.starts_with('\\') || has_scheme || uri.starts_with('~') ||
        uri.find('$') != std::string::npos) {
      throw error(at + ".uri", in_quotes(escaped(uri)) +
                                   " is refused: a URI names a file inside the scene's folder by a relative path "
                                   "(no absolute path, scheme, ~ or $VARIABLE)");
    }
  }

  // Whether it filled the znear that the glTF schema requires and tracer never reads.
  bool camera(json& o, const std::string& at) {
    string_of(o, "type", at + ".type");
    const json* type = member(o, "type");
    if (!type || *type != "perspective") return false;
    const std::string pa = at + ".perspective";
    if (!object_of(o, "perspective", pa)) throw error(pa, "missing (the camera's type is perspective)");
    json& p = o["perspective"];
    if (!number_of(p, "yfov", pa + ".yfov")) throw error(pa + ".yfov", "missing");
    number_of(p, "zfar", pa + ".zfar");
    number_of(p, "aspectRatio", pa + ".aspectRatio");
    if (number_of(p, "znear", pa + ".znear")) return false;
    warnings_.add(pa + ": no znear (required by glTF; tracer clips nothing, so it is not needed)");
    p["znear"] = 0.001;
    return true;
  }

  // A moved data: URI holds exactly byteLength bytes (tinygltf's rule, said here in the file's terms).
  void payload_size(const json& o, const std::string& at) const {
    const json* uri = member(o, "uri");
    const json* length = member(o, "byteLength");
    if (!uri || !length || !uri->is_string() || !length->is_number_unsigned()) return;
    const std::optional<size_t> k = payload_index(uri->get_ref<const std::string&>());
    if (!k || *k >= payloads_.size()) return;
    const uint64_t want = length->get<uint64_t>(), have = payloads_[*k].size();
    if (want != have) {
      throw error(
          at, "its data: URI holds " + std::to_string(have) + " bytes, its byteLength says " + std::to_string(want));
    }
  }

  const std::string& name_;
  WarningLog& warnings_;
  const std::vector<std::vector<unsigned char>>& payloads_;
};

// Parses (nlohmann-json: the text is small once payloads are moved out) and checks the JSON; the
// text to use instead when a gap was filled.
std::optional<std::string> check_properties(std::string_view text, const std::string& name, WarningLog& warnings,
                                            const std::vector<std::vector<unsigned char>>& payloads) {
  json doc = json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return std::nullopt;  // not JSON: tinygltf's message says where
  if (!Checker(name, warnings, payloads).check(doc)) return std::nullopt;
  return doc.dump();
}

}  // namespace

std::string payload_name(size_t k) { return std::string(kPayloadPrefix) + std::to_string(k); }

std::optional<size_t> payload_index(std::string_view path) {
  const size_t at = path.rfind(kPayloadPrefix);
  if (at == std::string_view::npos) return std::nullopt;
  const std::string_view digits = path.substr(at + kPayloadPrefix.size());
  if (digits.empty() || digits.size() > 9) return std::nullopt;
  size_t k = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    k = k * 10 + size_t(c - '0');
  }
  return k;
}

PreparedJson prepare_json(std::string_view bytes, const std::string& name, WarningLog& warnings, CancelFlag cancel) {
  PreparedJson out;
  if (bytes.empty()) throw InputError(name + ": an empty file, not a glTF file");
  if (bytes.size() >= 4 && le32(bytes, 0) == kGlbMagic) {
    if (bytes.size() < 20) return out;  // tinygltf names the truncation
    const uint32_t version = le32(bytes, 4);
    if (version != 2) {
      throw InputError(name + ": GLB version " + std::to_string(version) + ": tracer reads glTF 2.0 (version 2)");
    }
    const uint32_t json_length = le32(bytes, 12);
    if (le32(bytes, 16) != kJsonChunk || json_length > bytes.size() - 20) return out;  // tinygltf's message
    const std::string_view chunk = bytes.substr(20, json_length);
    scan(chunk, name, out, cancel, /*move_payloads=*/false);
    const std::optional<std::string> filled = check_properties(chunk, name, warnings, out.payloads);
    if (!filled) return out;
    // The GLB again around the new JSON chunk (padded with spaces to 4 bytes, as the format asks).
    std::string chunk_text = *filled;
    chunk_text.resize((chunk_text.size() + 3) / 4 * 4, ' ');
    const std::string_view rest = bytes.substr(20 + json_length);
    out.text.reserve(20 + chunk_text.size() + rest.size());
    const auto put32 = [&](uint32_t v) { out.text.append(reinterpret_cast<const char*>(&v), 4); };
    put32(kGlbMagic);
    put32(2);
    put32(uint32_t(20 + chunk_text.size() + rest.size()));
    put32(uint32_t(chunk_text.size()));
    put32(kJsonChunk);
    out.text += chunk_text;
    out.text.append(rest);
    return out;
  }
  scan(bytes, name, out, cancel, /*move_payloads=*/true);
  const std::string_view text = out.payloads.empty() ? bytes : std::string_view(out.text);
  if (std::optional<std::string> filled = check_properties(text, name, warnings, out.payloads)) {
    out.text = std::move(*filled);
  }
  return out;
}

}  // namespace tracer::gltf
