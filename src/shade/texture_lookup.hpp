// What the textures say at a hit: each slot's coordinates (scene/slot_coordinates.hpp), the diffuse
// colour filtered to the ray's footprint (ray cones and the texture level of detail) and the
// shading normal moved by the bump map.
#pragma once

#include <algorithm>
#include <cmath>

#include "math/ray.hpp"
#include "scene/scene.hpp"
#include "scene/slot_coordinates.hpp"

namespace tracer {

// The texture coordinates at a hit, interpolated from its triangle's corners `c`.
inline Vec2 hit_uv(const Vec2* c, const Hit& hit) { return interpolate_uv(c, hit.u, hit.v); }

// The shading normal `ns` moved by the material's normal map or bump map. A normal map (glTF's
// normalTexture) gives the normal in the frame of the tangent dp/du made perpendicular to ns,
// the bitangent on dp/dv's side and ns (per-triangle tangents, as glTF prescribes where a mesh
// gives none). A bump map, as pbrt's bump mapping does: the surface displaced along ns by
// bump_multiplier * height(u, v) in scene units, whose tangents are dp/du + ns dh/du and
// dp/dv + ns dh/dv (dh/du, dh/dv by central differences one texel wide), the normal their cross
// product on ns's side. dp/du, dp/dv come from the triangle's positions and texture coordinates.
// A normal that would face away from the viewer `wo` (where the BSDF would return black: the
// fringes of shading normals) is tilted back until it faces it, just.
inline Vec3 bumped_normal(const Scene& scene, const Hit& hit, const Material& mat, Vec3 ns, Vec3 wo) {
  const bool normal_map = mat.normal_texture.present();
  const TextureSlot& slot = normal_map ? mat.normal_texture : mat.bump_texture;
  Vec2 c[3];
  if (!slot_corners(scene, hit.tri, slot, c)) return ns;
  const Triangle tri = scene.world_triangle(hit.tri, hit.inst);
  const float du1 = c[1].x - c[0].x, dv1 = c[1].y - c[0].y, du2 = c[2].x - c[0].x, dv2 = c[2].y - c[0].y;
  const float det = du1 * dv2 - dv1 * du2;
  if (!(std::fabs(det) > 1e-20f)) return ns;  // degenerate texture coordinates: no tangents
  const Vec3 e1 = tri.v1 - tri.v0, e2 = tri.v2 - tri.v0;
  const Vec3 dpdu = (e1 * dv2 - e2 * dv1) * (1.0f / det), dpdv = (e2 * du1 - e1 * du2) * (1.0f / det);
  const auto [u, v] = hit_uv(c, hit);
  Vec3 n;
  if (normal_map) {
    const Vec3 t_raw = dpdu - ns * dot(ns, dpdu);
    const float t_len = length(t_raw);
    if (!(t_len > 0.0f) || !std::isfinite(t_len)) return ns;
    const Vec3 t = t_raw / t_len;
    const Vec3 b = dot(cross(ns, t), dpdv) < 0.0f ? -cross(ns, t) : cross(ns, t);
    const Vec3 m = scene.textures[slot.texture].data(u, v, slot.sampler) * 2.0f - Vec3{1.0f};
    n = t * (m.x * mat.normal_scale) + b * (m.y * mat.normal_scale) + ns * m.z;
  } else {
    const Texture& tex = scene.textures[slot.texture];
    const Sampler& sm = slot.sampler;
    const float hu = 0.5f / float(tex.width()), hv = 0.5f / float(tex.height());
    const float dhdu = (tex.height(u + hu, v, sm) - tex.height(u - hu, v, sm)) / (2.0f * hu) * mat.bump_multiplier;
    const float dhdv = (tex.height(u, v + hv, sm) - tex.height(u, v - hv, sm)) / (2.0f * hv) * mat.bump_multiplier;
    n = cross(dpdu + ns * dhdu, dpdv + ns * dhdv);
  }
  const float len = length(n);
  if (!(len > 0.0f) || !std::isfinite(len)) return ns;
  n = n / len;
  if (dot(n, ns) < 0.0f) n = -n;
  constexpr float kMinCos = 0.01f;
  if (const float cos_o = dot(n, wo); cos_o < kMinCos) n = normalize(n + wo * (kMinCos - cos_o));
  return n;
}

// The footprint of the rays through one pixel, as a cone (Akenine-Moller et al. 2019, "Texture
// Level of Detail Strategies for Real-Time Ray Tracing", Ray Tracing Gems ch. 20): its width where
// the ray starts and the angle it widens by. A camera ray's cone spans its pixel; a mirror or
// glass keeps the cone going (flat surfaces: no change of spread); after any other bounce a path
// no longer has a footprint (width 0: the finest texels).
struct RayCone {
  float width = 0.0f, spread = 0.0f;
  bool active() const { return spread > 0.0f; }
  // The cone's width at distance t along the ray.
  float width_at(float t) const { return width + spread * t; }
};

// The texture level of detail of a cone of width `width` meeting the hit triangle at incidence
// cosine `cos_incidence`: log2 of the texels its footprint spans, through the triangle's ratio of
// texture area (in texels; corners `c` as the slot reads them) to surface area.
inline float texture_lod(const Scene& scene, const Hit& hit, const Vec2* c, const Texture& t, float width,
                         float cos_incidence) {
  const Triangle tri = scene.world_triangle(hit.tri, hit.inst);
  const float texels = std::fabs((c[1].x - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (c[1].y - c[0].y)) *
                       float(t.width()) * float(t.height());
  const float area = length(cross(tri.v1 - tri.v0, tri.v2 - tri.v0));
  const float lod = 0.5f * std::log2(texels / area) + std::log2(width / std::max(cos_incidence, 1e-3f));
  return std::isfinite(lod) ? lod : 0.0f;
}

// A colour slot's linear texel at a hit, filtered to the footprint of `cone` (trilinearly between
// mip levels; from the texels where the cone is inactive) and addressed as the slot says; or
// `otherwise` where the slot is empty or the triangle has no such coordinates.
inline Vec3 slot_color(const Scene& scene, const Hit& hit, const TextureSlot& slot, Vec3 otherwise,
                       const RayCone& cone = {}, float cos_incidence = 1.0f) {
  Vec2 c[3];
  if (!slot_corners(scene, hit.tri, slot, c)) return otherwise;
  const auto [u, v] = hit_uv(c, hit);
  const Texture& t = scene.textures[slot.texture];
  if (!cone.active()) return t.bilinear(u, v, slot.sampler);
  return t.filtered(u, v, texture_lod(scene, hit, c, t, cone.width_at(hit.t), cos_incidence), slot.sampler);
}

// A data slot's values in [0, 1] at a hit (the stored bytes, no sRGB decoding: glTF's
// metallicRoughnessTexture), bilinear at full resolution as normal maps are read; `otherwise`
// where the slot is empty or the triangle has no such coordinates.
inline Vec3 slot_data(const Scene& scene, const Hit& hit, const TextureSlot& slot, Vec3 otherwise) {
  Vec2 c[3];
  if (!slot_corners(scene, hit.tri, slot, c)) return otherwise;
  const auto [u, v] = hit_uv(c, hit);
  return scene.textures[slot.texture].data(u, v, slot.sampler);
}

// The vertex colour at a hit (white where the scene has none).
inline Vec3 vertex_color(const Scene& scene, const Hit& hit) {
  if (scene.corner_colors.empty()) return Vec3{1.0f};
  const Vec3* c = &scene.corner_colors[3 * size_t(hit.tri)];
  return c[0] * (1.0f - hit.u - hit.v) + c[1] * hit.u + c[2] * hit.v;
}

// The diffuse colour at a hit: the material's map_Kd (baseColorTexture), else Kd, times the
// vertex colour. `cos_incidence`: |cos| of the ray with the surface.
inline Vec3 diffuse_color(const Scene& scene, const Hit& hit, const Material& mat, const RayCone& cone = {},
                          float cos_incidence = 1.0f) {
  const Vec3 c = slot_color(scene, hit, mat.diffuse_texture, mat.kd, cone, cos_incidence);
  return scene.corner_colors.empty() ? c : c * vertex_color(scene, hit);
}

}  // namespace tracer
