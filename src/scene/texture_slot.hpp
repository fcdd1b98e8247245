// How a material reads one texture: which texture, through which set of texture coordinates, moved
// by which transform, sampled how outside [0, 1) and between texels. Written once, for every slot
// of every material (glTF's textureInfo with its sampler and KHR_texture_transform; OBJ's maps).
#pragma once

#include <cmath>
#include <cstdint>

#include "base/invalid_index.hpp"
#include "math/vec.hpp"

namespace tracer {

// glTF's sampler wrap modes (OBJ's maps repeat).
enum class Wrap : uint8_t { Repeat, ClampToEdge, MirroredRepeat };

// What a lookup does between and outside texels: glTF's sampler. `nearest`: the magnification
// filter takes the nearest texel instead of blending four; `mipmaps` false: the minification
// filter reads the full-resolution texels however far the footprint spans (NEAREST or LINEAR
// without a mip-map mode).
struct Sampler {
  Wrap wrap_s = Wrap::Repeat, wrap_t = Wrap::Repeat;
  bool nearest = false;
  bool mipmaps = true;
  bool operator==(const Sampler&) const = default;
};

// An affine map of texture coordinates, (u, v) -> (a u + b v + c, d u + e v + f), in tracer's
// convention (v = 0 the image's bottom row). KHR_texture_transform's offset, rotation and scale
// become one (gltf_materials.cpp converts them from glTF's v-down space).
struct UvTransform {
  float a = 1.0f, b = 0.0f, c = 0.0f;
  float d = 0.0f, e = 1.0f, f = 0.0f;
  Vec2 apply(Vec2 uv) const { return {a * uv.x + b * uv.y + c, d * uv.x + e * uv.y + f}; }
  // How much the map scales areas: the texel footprint of a transformed lookup.
  float area_scale() const { return std::fabs(a * e - b * d); }
  bool identity() const { return a == 1.0f && b == 0.0f && c == 0.0f && d == 0.0f && e == 1.0f && f == 0.0f; }
  bool operator==(const UvTransform&) const = default;
};

// One texture slot of a material: kInvalidIndex where the material has no texture there.
struct TextureSlot {
  uint32_t texture = kInvalidIndex;  // an index into Scene::textures
  uint8_t uv_set = 0;                // 0: TEXCOORD_0 (OBJ's vt); 1: TEXCOORD_1
  Sampler sampler;
  UvTransform transform;
  bool present() const { return texture != kInvalidIndex; }
  bool operator==(const TextureSlot&) const = default;
};

}  // namespace tracer
