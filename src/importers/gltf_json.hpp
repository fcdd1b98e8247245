// What tracer does with a glTF's JSON before tinygltf parses it: tinygltf recurses once per level
// of nesting (a 40 KB file of nested arrays overflowed the stack), keeps a data: URI alive three
// times over, and reads a property of the wrong type as absent. So the text is first scanned
// without recursion (its nesting bounded, each buffer's base64 payload decoded apart), then parsed
// once by nlohmann-json to check the type and range of every property tinygltf would drop, and to
// fill the one gap real exporters leave (a perspective camera without the znear tracer never uses).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "base/errors.hpp"
#include "importers/warning_log.hpp"

namespace tracer::gltf {

// Deeper JSON than this is refused before any parser sees it (real files nest a dozen levels;
// nlohmann-json and tinygltf recurse once per level).
inline constexpr int kMaxJsonDepth = 256;

// The JSON text tinygltf is handed, and the buffers' payloads that were moved out of it.
struct PreparedJson {
  // The text to parse; empty when the input's own bytes can be parsed as they are.
  std::string text;
  // The decoded bytes of buffers[k]'s data: URI for the k-th such buffer, in the order they
  // stand; the text names each by payload_name(k) and the file callbacks serve it from here.
  std::vector<std::vector<unsigned char>> payloads;
};

// The URI a moved payload is given in the text, and the payload a (joined) path names.
std::string payload_name(size_t k);
std::optional<size_t> payload_index(std::string_view path);

// A .gltf's JSON made ready for tinygltf, or (for a .glb, `bytes` starting with its magic) its
// JSON chunk checked and, where a gap is filled, the whole GLB rewritten. Throws InputError naming
// `name` and the property (or the byte where nesting went too deep).
PreparedJson prepare_json(std::string_view bytes, const std::string& name, WarningLog& warnings, CancelFlag cancel);

}  // namespace tracer::gltf
