// The render workload, defined once so every accelerator and scheduler traces the same rays:
// per pixel one primary ray through the pixel centre; at a hit one shadow ray per light and N
// ambient-occlusion rays. Templated on the accelerator so the per-ray path has no virtual call.
#pragma once

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "math/ray.hpp"
#include "math/ray_packet.hpp"
#include "math/rng.hpp"
#include "parallel/tiles.hpp"
#include "render/framebuffer.hpp"
#include "scene/camera.hpp"
#include "scene/scene.hpp"

namespace tracer {

struct RenderSettings {
  int width = 1024;
  int height = 1024;
  int ao_samples = 16;            // 0 turns ambient occlusion off (the ambient term is then unoccluded)
  float ao_distance = kInfinity;  // tfar of the AO rays
  float ambient = 0.25f;          // ambient light, times Kd and the unoccluded AO fraction
  float exposure = 1.5f;          // tone-mapping exposure
  uint32_t seed = 0;
  bool packets = false;  // primary rays in 4x4-pixel packets (accelerators that have them)
};

struct RayCounts {
  uint64_t primary = 0, shadow = 0, ao = 0;
  uint64_t total() const { return primary + shadow + ao; }
  RayCounts& operator+=(const RayCounts& o) {
    primary += o.primary;
    shadow += o.shadow;
    ao += o.ao;
    return *this;
  }
};

// Thread-safe accumulation of per-tile counts (one atomic add per tile, never per ray).
struct AtomicRayCounts {
  std::atomic<uint64_t> primary{0}, shadow{0}, ao{0};
  void add(const RayCounts& c) {
    primary.fetch_add(c.primary, std::memory_order_relaxed);
    shadow.fetch_add(c.shadow, std::memory_order_relaxed);
    ao.fetch_add(c.ao, std::memory_order_relaxed);
  }
  RayCounts load() const { return {primary.load(), shadow.load(), ao.load()}; }
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

// Accelerators that trace a RayPacket at once (the 8-wide BVH).
template <class A>
concept PacketAccelerator = requires(const A& a, const RayPacket& p, Hit* h) {
  a.intersect_packet(p, h);
};

// Accelerators that answer the AO rays of one shading point as one bundle (both BVHs).
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

// The colour of pixel (x, y) whose primary ray `primary` found `hit` (invalid: nothing).
template <class Accel>
Vec3 shade_hit(const Accel& accel, const RenderContext& ctx, int x, int y, const Ray& primary, const Hit& hit,
               RayCounts& counts) {
  const Scene& scene = *ctx.scene;
  const RenderSettings& s = ctx.settings;
  if (!hit.valid()) return Vec3{0.0f};

  const Triangle& tri = scene.triangles[hit.tri];
  const Material& mat = scene.materials[scene.tri_material[hit.tri]];
  Vec3 n = normalize(tri.normal());
  if (dot(n, primary.dir) > 0.0f) n = -n;  // shade the side the camera sees
  // Barycentric position: more precise than org + t*dir far from the camera.
  const Vec3 p = tri.v0 * (1.0f - hit.u - hit.v) + tri.v1 * hit.u + tri.v2 * hit.v;
  const Vec3 origin = offset_origin(p, n);
  const Vec3 albedo_over_pi = mat.kd * std::numbers::inv_pi_v<float>;

  Vec3 color = mat.ke;
  for (const Light& light : scene.lights) {
    if (light.geomID == hit.geomID) continue;  // an emitter does not light itself
    const Vec3 to_light = light.position - origin;
    const float d2 = dot(to_light, to_light);
    if (!(d2 > 0.0f)) continue;
    const float d = std::sqrt(d2);
    const Vec3 wi = to_light / d;
    const float cos_surface = dot(n, wi);
    if (cos_surface <= 0.0f) continue;
    // Irradiance from a light of area A at distance d: power * cos_l / (d^2 + A/pi), exact on the
    // axis of a disk of that area and free of the 1/d^2 blow-up near the lamp; 1/d^2 for points.
    const float cos_light = light.is_point() ? 1.0f : std::fabs(dot(light.normal, wi));
    const float falloff = cos_light / (d2 + light.area * std::numbers::inv_pi_v<float>);
    Ray shadow;
    shadow.org = origin;
    shadow.dir = wi;
    shadow.tfar = d * (1.0f - 1e-4f);  // stop short of the light's own surface
    ++counts.shadow;
    if (occluded_leaving(accel, shadow, hit.tri)) continue;
    color += albedo_over_pi * light.power * (falloff * cos_surface);
  }

  float unoccluded = 1.0f;
  if (s.ao_samples > 0) {
    const uint32_t pixel = uint32_t(y) * uint32_t(s.width) + uint32_t(x);
    const auto direction = [&](int i) {
      const SampleRng rng(pixel, uint32_t(i), s.seed);
      return ao_direction(n, rng.draw(0), rng.draw(1));
    };
    int open = 0;
    bool bundled = false;
    if constexpr (BundleAccelerator<Accel>) {
      if (s.packets) {
        // Up to 16 rays at a time; each gets the answer it gets alone, so the image is the same.
        for (int first = 0; first < s.ao_samples; first += kPacketSize) {
          RayBundle bundle;
          bundle.org = origin;
          bundle.tfar = s.ao_distance;
          const int count = std::min(kPacketSize, s.ao_samples - first);
          for (int k = 0; k < count; ++k) bundle.set_direction(k, direction(first + k));
          open += count - std::popcount(accel.occluded_bundle_from(bundle, hit.tri));
        }
        bundled = true;
      }
    }
    if (!bundled) {
      for (int i = 0; i < s.ao_samples; ++i) {
        Ray ao;
        ao.org = origin;
        ao.dir = direction(i);
        ao.tfar = s.ao_distance;
        open += occluded_leaving(accel, ao, hit.tri) ? 0 : 1;
      }
    }
    counts.ao += uint64_t(s.ao_samples);
    unoccluded = float(open) / float(s.ao_samples);
  }
  color += mat.kd * (s.ambient * unoccluded);
  return color;
}

template <class Accel>
Vec3 shade_pixel(const Accel& accel, const RenderContext& ctx, int x, int y, RayCounts& counts) {
  const Ray primary = ctx.camera.primary_ray(x, y);
  ++counts.primary;
  Hit hit;
  accel.intersect(primary, hit);
  return shade_hit(accel, ctx, x, y, primary, hit, counts);
}

template <class Accel>
RayCounts render_tile(const Accel& accel, const RenderContext& ctx, const Tile& tile) {
  RayCounts counts;
  if constexpr (PacketAccelerator<Accel>) {
    if (ctx.settings.packets) {
      // Primary rays 4x4 pixels at a time (fewer at the tile's right and bottom edges); each
      // lane's hit is the one its ray gets alone, so the image does not change.
      for (int by = tile.y0; by < tile.y1; by += kPacketEdge) {
        for (int bx = tile.x0; bx < tile.x1; bx += kPacketEdge) {
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
          for (uint32_t bits = packet.active; bits; bits &= bits - 1) {
            const int k = __builtin_ctz(bits);
            const int x = bx + k % kPacketEdge, y = by + k / kPacketEdge;
            ++counts.primary;
            ctx.framebuffer->at(x, y) = shade_hit(accel, ctx, x, y, rays[k], hits[k], counts);
          }
        }
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
