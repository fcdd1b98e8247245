// The render workload, defined once so every accelerator and scheduler traces the same rays:
// per pixel one primary ray through the pixel centre; at a hit one shadow ray per light and N
// ambient-occlusion rays. Templated on the accelerator so the per-ray path has no virtual call.
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstdint>
#include <numbers>

#include "base/enum_names.hpp"
#include "math/ray.hpp"
#include "math/ray_packet.hpp"
#include "math/rng.hpp"
#include "parallel/tiles.hpp"
#include "render/framebuffer.hpp"
#include "scene/camera.hpp"
#include "scene/scene.hpp"
#include "shade/optics.hpp"

namespace tracer {

// What a pixel's radiance is made of: the study's workload (direct light from the lights'
// centroids, ambient occlusion, every surface diffuse), or Whitted ray tracing (direct light
// with hard shadows, perfect mirror reflection and dielectric refraction to max_depth).
enum class Integrator { Ao, Whitted };
inline constexpr EnumName<Integrator> kIntegratorNames[] = {{Integrator::Ao, "ao"}, {Integrator::Whitted, "whitted"}};

struct RenderSettings {
  int width = 1024;
  int height = 1024;
  int ao_samples = 16;            // 0 turns ambient occlusion off (the ambient term is then unoccluded)
  float ao_distance = kInfinity;  // tfar of the AO rays
  float ambient = 0.25f;          // ambient light, times Kd and the unoccluded AO fraction
  float exposure = 1.5f;          // tone-mapping exposure
  uint32_t seed = 0;
  Integrator integrator = Integrator::Ao;
  int max_depth = 8;  // whitted: reflections and refractions followed per path
  // Trace rays together where the accelerator can (primary rays in 4x4-pixel packets, a block's
  // shadow rays, each hit's AO rays as one bundle): the same image, faster.
  bool packets = true;
};

struct RayCounts {
  uint64_t primary = 0, shadow = 0, ao = 0, secondary = 0;  // secondary: reflected and refracted rays
  uint64_t total() const { return primary + shadow + ao + secondary; }
  RayCounts& operator+=(const RayCounts& o) {
    primary += o.primary;
    shadow += o.shadow;
    ao += o.ao;
    secondary += o.secondary;
    return *this;
  }
};

// Thread-safe accumulation of per-tile counts (one atomic add per tile, never per ray).
struct AtomicRayCounts {
  std::atomic<uint64_t> primary{0}, shadow{0}, ao{0}, secondary{0};
  void add(const RayCounts& c) {
    primary.fetch_add(c.primary, std::memory_order_relaxed);
    shadow.fetch_add(c.shadow, std::memory_order_relaxed);
    ao.fetch_add(c.ao, std::memory_order_relaxed);
    secondary.fetch_add(c.secondary, std::memory_order_relaxed);
  }
  RayCounts load() const { return {primary.load(), shadow.load(), ao.load(), secondary.load()}; }
};

// Everything one tile needs; shared read-only by all workers except the disjoint framebuffer pixels.
struct RenderContext {
  const Scene* scene = nullptr;
  Camera camera;
  RenderSettings settings;
  Framebuffer* framebuffer = nullptr;
};

// Moves a surface point off its surface along the geometric normal (on the side the new ray
// leaves from), by a margin that grows with the coordinates' magnitude like float rounding does.
inline Vec3 offset_origin(Vec3 p, Vec3 n) {
  const float eps = 1e-4f * (1.0f + max_component(abs(p)));
  return p + n * eps;
}

// Uniform direction on the sphere, mirrored into n's hemisphere when below it (the study's
// trick: no rejection loop, same distribution as uniform hemisphere sampling).
inline Vec3 ao_direction(Vec3 n, float r1, float r2) {
  const float z = 1.0f - 2.0f * r1;
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * std::numbers::pi_v<float> * r2;
  Vec3 d{r * std::cos(phi), r * std::sin(phi), z};
  return dot(d, n) < 0.0f ? -d : d;
}

// Accelerators that trace a RayPacket at once (the 8-wide BVH, Embree's packet API).
template <class A>
concept PacketAccelerator = requires(const A& a, const RayPacket& p, Hit* h) {
  a.intersect_packet(p, h);
};

// Accelerators that answer the AO rays of one shading point as one bundle (both BVHs, Embree).
template <class A>
concept BundleAccelerator = requires(const A& a, const RayBundle& b) {
  a.occluded_bundle_from(b, 0u);
};

// An occlusion query for a ray leaving scene triangle `origin`: accelerators that can start the
// search at that triangle's leaf (the binary BVH) do; the others search from the root.
template <class Accel>
bool occluded_leaving(const Accel& accel, const Ray& ray, uint32_t origin) {
  if constexpr (requires { accel.occluded_from(ray, origin); }) {
    return accel.occluded_from(ray, origin);
  } else {
    return accel.occluded(ray);
  }
}

// Accelerators that answer a packet of unrelated occlusion rays at once (Embree's packet API).
template <class A>
concept OcclusionPacketAccelerator = requires(const A& a, const RayPacket& p) {
  { a.occluded_packet(p) } -> std::same_as<uint32_t>;
};

// A primary hit being shaded: the normal on the side the camera sees, the origin of the rays it
// sends, and the colour so far.
struct SurfacePoint {
  Vec3 position, n, origin, albedo_over_pi, color;  // origin: position moved off the surface along n
  Vec3 shading_n;  // the normal shading uses: n, or the interpolated vertex normal on n's side
  bool front;      // the ray hit the side the triangle's winding faces
  const Material* mat;
  uint32_t tri, geomID;
};

inline SurfacePoint surface_point(const RenderContext& ctx, const Ray& primary, const Hit& hit) {
  const Scene& scene = *ctx.scene;
  const Triangle& tri = scene.triangles[hit.tri];
  SurfacePoint sp;
  sp.mat = &scene.materials[scene.tri_material[hit.tri]];
  sp.n = normalize(tri.normal());
  sp.front = dot(sp.n, primary.dir) <= 0.0f;
  if (!sp.front) sp.n = -sp.n;  // shade the side the camera sees
  // Barycentric position: more precise than org + t*dir far from the camera.
  const Vec3 p = tri.v0 * (1.0f - hit.u - hit.v) + tri.v1 * hit.u + tri.v2 * hit.v;
  sp.position = p;
  sp.shading_n = sp.n;
  sp.origin = offset_origin(p, sp.n);
  sp.albedo_over_pi = sp.mat->kd * std::numbers::inv_pi_v<float>;
  sp.color = sp.mat->ke;
  sp.tri = hit.tri;
  sp.geomID = hit.geomID;
  return sp;
}

// The shadow ray from `sp` toward `light` and what the light adds if nothing blocks it; false
// when the light cannot contribute (it is the surface's own emitter, or behind the surface).
inline bool light_sample(const SurfacePoint& sp, const Light& light, Ray& shadow, Vec3& contribution) {
  if (light.geomID == sp.geomID) return false;  // an emitter does not light itself
  const Vec3 to_light = light.position - sp.origin;
  const float d2 = dot(to_light, to_light);
  if (!(d2 > 0.0f)) return false;
  const float d = std::sqrt(d2);
  const Vec3 wi = to_light / d;
  if (dot(sp.n, wi) <= 0.0f) return false;  // below the surface itself, whatever the shading normal
  const float cos_surface = dot(sp.shading_n, wi);
  if (cos_surface <= 0.0f) return false;
  // Irradiance from a light of area A at distance d: power * cos_l / (d^2 + A/pi), exact on the
  // axis of a disk of that area and free of the 1/d^2 blow-up near the lamp; 1/d^2 for points.
  const float cos_light = light.is_point() ? 1.0f : std::fabs(dot(light.normal, wi));
  const float falloff = cos_light / (d2 + light.area * std::numbers::inv_pi_v<float>);
  shadow = Ray{};
  shadow.org = sp.origin;
  shadow.dir = wi;
  shadow.tfar = d * (1.0f - 1e-4f);  // stop short of the light's own surface
  contribution = sp.albedo_over_pi * light.power * (falloff * cos_surface);
  return true;
}

// Adds the ambient term, scaled by the fraction of `sp`'s AO rays that escape, and returns the
// pixel's colour.
template <class Accel>
Vec3 finish_with_ambient(const Accel& accel, const RenderContext& ctx, int x, int y, const SurfacePoint& sp,
                         RayCounts& counts) {
  const RenderSettings& s = ctx.settings;
  float unoccluded = 1.0f;
  if (s.ao_samples > 0) {
    const uint32_t pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
    const auto direction = [&](int i) {
      const SampleRng rng(pixel, uint32_t(i), s.seed);
      return ao_direction(sp.n, rng.draw(0), rng.draw(1));
    };
    int open = 0;
    bool bundled = false;
    if constexpr (BundleAccelerator<Accel>) {
      if (s.packets) {
        // Up to 16 rays at a time; each gets the answer it gets alone, so the image is the same.
        for (int first = 0; first < s.ao_samples; first += kPacketSize) {
          RayBundle bundle;
          bundle.org = sp.origin;
          bundle.tfar = s.ao_distance;
          const int count = std::min(kPacketSize, s.ao_samples - first);
          for (int k = 0; k < count; ++k) bundle.set_direction(k, direction(first + k));
          open += count - std::popcount(accel.occluded_bundle_from(bundle, sp.tri));
        }
        bundled = true;
      }
    }
    if (!bundled) {
      for (int i = 0; i < s.ao_samples; ++i) {
        Ray ao;
        ao.org = sp.origin;
        ao.dir = direction(i);
        ao.tfar = s.ao_distance;
        open += occluded_leaving(accel, ao, sp.tri) ? 0 : 1;
      }
    }
    counts.ao += uint64_t(s.ao_samples);
    unoccluded = float(open) / float(s.ao_samples);
  }
  return sp.color + sp.mat->kd * (s.ambient * unoccluded);
}

// Adds to sp.color what every light gives it, one shadow ray per light, in the lights' order.
template <class Accel>
void add_direct_light(const Accel& accel, const RenderContext& ctx, SurfacePoint& sp, RayCounts& counts) {
  for (const Light& light : ctx.scene->lights) {
    Ray shadow;
    Vec3 contribution;
    if (!light_sample(sp, light, shadow, contribution)) continue;
    ++counts.shadow;
    if (!occluded_leaving(accel, shadow, sp.tri)) sp.color += contribution;
  }
}

// The colour of pixel (x, y) whose primary ray `primary` found `hit` (invalid: nothing).
template <class Accel>
Vec3 shade_hit(const Accel& accel, const RenderContext& ctx, int x, int y, const Ray& primary, const Hit& hit,
               RayCounts& counts) {
  if (!hit.valid()) return Vec3{0.0f};
  SurfacePoint sp = surface_point(ctx, primary, hit);
  add_direct_light(accel, ctx, sp, counts);
  return finish_with_ambient(accel, ctx, x, y, sp, counts);
}

template <class Accel>
Vec3 shade_pixel(const Accel& accel, const RenderContext& ctx, int x, int y, RayCounts& counts) {
  const Ray primary = ctx.camera.primary_ray(x, y);
  ++counts.primary;
  Hit hit;
  accel.intersect(primary, hit);
  return shade_hit(accel, ctx, x, y, primary, hit, counts);
}

// A 4x4 pixel block at (bx, by), clipped to the tile: its primary rays as one packet, then per
// light its shadow rays as one packet (one call where the accelerator takes occlusion packets),
// then each hit's AO rays. Each ray gets the answer it gets alone and every pixel sums its lights
// in the same order, so the image is the one shade_pixel() makes.
template <class Accel>
void shade_block(const Accel& accel, const RenderContext& ctx, const Tile& tile, int bx, int by, RayCounts& counts) {
  RayPacket packet;
  Ray rays[kPacketSize];
  for (int k = 0; k < kPacketSize; ++k) {
    const int x = bx + k % kPacketEdge, y = by + k / kPacketEdge;
    if (x >= tile.x1 || y >= tile.y1) continue;
    rays[k] = ctx.camera.primary_ray(x, y);
    packet.set(k, rays[k]);
  }
  Hit hits[kPacketSize];
  accel.intersect_packet(packet, hits);
  counts.primary += uint64_t(std::popcount(packet.active));
  SurfacePoint sps[kPacketSize];
  uint32_t lit = 0;  // lanes that hit something
  for (uint32_t bits = packet.active; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    if (!hits[k].valid()) {
      ctx.framebuffer->at(bx + k % kPacketEdge, by + k / kPacketEdge) = Vec3{0.0f};
      continue;
    }
    sps[k] = surface_point(ctx, rays[k], hits[k]);
    lit |= 1u << k;
  }
  for (const Light& light : ctx.scene->lights) {
    RayPacket shadows;
    Vec3 contribution[kPacketSize];
    for (uint32_t bits = lit; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      Ray shadow;
      if (light_sample(sps[k], light, shadow, contribution[k])) shadows.set(k, shadow);
    }
    if (shadows.active == 0) continue;
    counts.shadow += uint64_t(std::popcount(shadows.active));
    uint32_t blocked = 0;
    if constexpr (OcclusionPacketAccelerator<Accel>) {
      blocked = accel.occluded_packet(shadows);
    } else {
      for (uint32_t bits = shadows.active; bits; bits &= bits - 1) {
        const int k = __builtin_ctz(bits);
        if (occluded_leaving(accel, shadows.ray(k), sps[k].tri)) blocked |= 1u << k;
      }
    }
    for (uint32_t bits = shadows.active & ~blocked; bits; bits &= bits - 1) {
      const int k = __builtin_ctz(bits);
      sps[k].color += contribution[k];
    }
  }
  for (uint32_t bits = lit; bits; bits &= bits - 1) {
    const int k = __builtin_ctz(bits);
    const int x = bx + k % kPacketEdge, y = by + k / kPacketEdge;
    ctx.framebuffer->at(x, y) = finish_with_ambient(accel, ctx, x, y, sps[k], counts);
  }
}

// The vertex normals of the hit triangle interpolated at the hit, turned to the side of the
// geometric normal `n` (which faces the ray); `n` itself where the scene has none.
inline Vec3 interpolated_normal(const Scene& scene, const Hit& hit, Vec3 n) {
  if (scene.corner_normals.empty()) return n;
  const Vec3* c = &scene.corner_normals[3 * size_t(hit.tri)];
  const Vec3 s = c[0] * (1.0f - hit.u - hit.v) + c[1] * hit.u + c[2] * hit.v;
  const float len = length(s);
  if (!(len > 0.0f) || !std::isfinite(len)) return n;
  const Vec3 unit = s / len;
  return dot(unit, n) < 0.0f ? -unit : unit;
}

// Whitted ray tracing along `ray`, `depth` specular bounces from the camera: what the surface it
// hits emits, plus its direct light and ambient term where diffuse, its mirror image where a
// mirror, and where a dielectric the Fresnel-weighted reflected and (filtered by Tf) refracted
// images, with total internal reflection; nothing past max_depth bounces or when nothing is hit.
template <class Accel>
Vec3 whitted_radiance(const Accel& accel, const RenderContext& ctx, const Ray& ray, int depth, RayCounts& counts) {
  Hit hit;
  if (!accel.intersect(ray, hit)) return Vec3{0.0f};
  SurfacePoint sp = surface_point(ctx, ray, hit);  // sp.n faces the ray's side
  sp.shading_n = interpolated_normal(*ctx.scene, hit, sp.n);
  const Material& mat = *sp.mat;
  const bool deeper = depth < ctx.settings.max_depth;
  switch (mat.surface()) {
    case SurfaceKind::Mirror: {
      if (!deeper) return sp.color;
      Ray reflected;
      reflected.org = sp.origin;
      reflected.dir = reflect(ray.dir, sp.shading_n);
      ++counts.secondary;
      return sp.color + mat.ks * whitted_radiance(accel, ctx, reflected, depth + 1, counts);
    }
    case SurfaceKind::Dielectric: {
      if (!deeper) return sp.color;
      const float eta_i = sp.front ? 1.0f : mat.ni, eta_t = sp.front ? mat.ni : 1.0f;  // front: entering
      const float f = fresnel_dielectric(-dot(ray.dir, sp.shading_n), eta_i, eta_t);
      Ray reflected;
      reflected.org = sp.origin;
      reflected.dir = reflect(ray.dir, sp.shading_n);
      ++counts.secondary;
      Vec3 color = sp.color + whitted_radiance(accel, ctx, reflected, depth + 1, counts) * f;
      Vec3 transmitted;
      if (f < 1.0f && refract(ray.dir, sp.shading_n, eta_i / eta_t, transmitted)) {
        Ray refracted;
        refracted.org = offset_origin(sp.position, -sp.n);  // off the surface, on the far side
        refracted.dir = transmitted;
        ++counts.secondary;
        color += mat.tf * whitted_radiance(accel, ctx, refracted, depth + 1, counts) * (1.0f - f);
      }
      return color;
    }
    case SurfaceKind::Diffuse:
      break;
  }
  add_direct_light(accel, ctx, sp, counts);
  return sp.color + mat.kd * ctx.settings.ambient;
}

template <class Accel>
RayCounts render_tile(const Accel& accel, const RenderContext& ctx, const Tile& tile) {
  RayCounts counts;
  if (ctx.settings.integrator == Integrator::Whitted) {
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = tile.x0; x < tile.x1; ++x) {
        ++counts.primary;
        ctx.framebuffer->at(x, y) = whitted_radiance(accel, ctx, ctx.camera.primary_ray(x, y), 0, counts);
      }
    }
    return counts;
  }
  if constexpr (PacketAccelerator<Accel>) {
    if (ctx.settings.packets) {
      for (int by = tile.y0; by < tile.y1; by += kPacketEdge) {
        for (int bx = tile.x0; bx < tile.x1; bx += kPacketEdge) shade_block(accel, ctx, tile, bx, by, counts);
      }
      return counts;
    }
  }
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) ctx.framebuffer->at(x, y) = shade_pixel(accel, ctx, x, y, counts);
  }
  return counts;
}

}  // namespace tracer
