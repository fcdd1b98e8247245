// A scene's textures read and decoded together, by every importer: each read and its header
// checked in parallel; the budget decided in order, so which texture is left out never depends on
// threads; the rest decoded in parallel, while their decoders' transient buffers fit what is left
// of the budget.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "importers/load_limits.hpp"
#include "scene/texture.hpp"

namespace tracer {

struct TextureBatch {
  std::vector<std::optional<Texture>> decoded;  // per source; empty where it is not used
  std::vector<std::string> problem;             // per source: why it is not used ("" where it is)
};

// Sources 0..count-1: read(k) gives source k's bytes and header (read_texture, encoded_texture)
// or throws InputError, its problem. The budget is limits.textures.max_total_bytes, run on
// limits.for_each. Cancelled when `cancel` is set.
TextureBatch read_and_decode(size_t count, const std::function<EncodedTexture(size_t)>& read, const LoadLimits& limits,
                             CancelFlag cancel);

}  // namespace tracer
