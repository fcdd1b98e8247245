// Pinhole camera: one primary ray through each pixel centre.
#pragma once

#include <cmath>
#include <numbers>

#include "math/ray.hpp"
#include "math/sampling.hpp"
#include "scene/scene.hpp"

namespace tracer {

// The default vertical field of view, 2*atan(1/2) = 53.13 degrees: with it the default framing of
// the McGuire Cornell files (2 units wide, centred at 0,1,0) puts the eye at 0,1,3, the study's camera.
inline constexpr float kDefaultFovDegrees = 53.130102f;

// Frames `bounds` from the front (+z looking down -z): the front face fills the view vertically
// or horizontally, whichever is larger.
inline CameraSpec frame_bounds(const Aabb& bounds, float fov_degrees = kDefaultFovDegrees) {
  const Vec3 c = bounds.center();
  const Vec3 half = bounds.extent() * 0.5f;
  const float tan_half = std::tan(fov_degrees * float(std::numbers::pi) / 360.0f);
  const float distance = std::max(half.x, half.y) / tan_half + half.z;
  return CameraSpec{c + Vec3{0.0f, 0.0f, distance}, c, {0.0f, 1.0f, 0.0f}, fov_degrees};
}

// Frame `frame` of `frames`: `spec` with its eye turned about the look point, around the up
// axis, by orbit_degrees * frame / frames (so 360 over N frames loops without a repeated frame).
inline CameraSpec frame_camera(const CameraSpec& spec, int frame, int frames, double orbit_degrees) {
  if (frames <= 1 || orbit_degrees == 0.0) return spec;
  const double angle = orbit_degrees * double(frame) / double(frames) * std::numbers::pi / 180.0;
  const Vec3 k = normalize(spec.up);
  const Vec3 v = spec.eye - spec.look;
  // Rodrigues: v cos + (k x v) sin + k (k . v)(1 - cos).
  const float c = float(std::cos(angle)), s = float(std::sin(angle));
  CameraSpec out = spec;
  out.eye = spec.look + v * c + cross(k, v) * s + k * (dot(k, v) * (1.0f - c));
  return out;
}

class Camera {
 public:
  Camera() = default;
  Camera(const CameraSpec& spec, int width, int height) : eye_(spec.eye) {
    const Vec3 forward = normalize(spec.look - spec.eye);
    const Vec3 right = normalize(cross(forward, spec.up));
    const Vec3 up = cross(right, forward);
    lens_right_ = right * spec.lens_radius;
    lens_up_ = up * spec.lens_radius;
    lens_ = spec.lens_radius > 0.0f;
    focus_ = spec.focus_distance > 0.0f ? spec.focus_distance : length(spec.look - spec.eye);
    const float tan_half = std::tan(spec.fov_degrees * float(std::numbers::pi) / 360.0f);
    const float aspect = float(width) / float(height);
    // Pixel (x, y) maps to forward + (2*(x+0.5)/w - 1)*du + (1 - 2*(y+0.5)/h)*dv.
    du_ = right * (tan_half * aspect);
    dv_ = up * tan_half;
    forward_ = forward;
    inv_w_ = 1.0f / float(width);
    inv_h_ = 1.0f / float(height);
  }

  // The unit view direction, and the distance along it of the plane in focus.
  Vec3 forward() const { return forward_; }
  float focus_distance() const { return focus_; }
  // The angle one pixel spans at the image centre: the spread of a ray cone through a pixel.
  float pixel_spread() const { return 2.0f * length(dv_) * inv_h_; }
  // The ray through the centre of pixel (x, y).
  Ray primary_ray(int x, int y) const { return ray_through(float(x) + 0.5f, float(y) + 0.5f); }

  // The ray through image position (px, py), in pixels from the top-left corner.
  Ray ray_through(float px, float py) const {
    const float sx = 2.0f * px * inv_w_ - 1.0f;
    const float sy = 1.0f - 2.0f * py * inv_h_;
    Ray r;
    r.org = eye_;
    r.dir = normalize(forward_ + du_ * sx + dv_ * sy);
    return r;
  }

  // Whether the camera has a lens (depth of field): then each sample takes a lens point.
  bool thin_lens() const { return lens_; }
  // The ray through image position (px, py) leaving the lens at the point the two numbers
  // (u1, u2) in [0, 1) give (concentric_disk): it passes through the pinhole ray's point on the
  // plane in focus, so that plane stays sharp and a point at depth z blurs into a circle of radius
  // lens_radius * |1 - z / focus_distance| there. Without a lens, the pinhole ray.
  Ray ray_through(float px, float py, float u1, float u2) const {
    Ray r = ray_through(px, py);
    if (!lens_) return r;
    const Vec3 in_focus = eye_ + r.dir * (focus_ / dot(r.dir, forward_));
    const Vec2 d = concentric_disk(u1, u2);
    r.org = eye_ + lens_right_ * d.x + lens_up_ * d.y;
    r.dir = normalize(in_focus - r.org);
    return r;
  }

 private:
  Vec3 eye_, forward_, du_, dv_;
  Vec3 lens_right_{0.0f}, lens_up_{0.0f};  // the lens's axes, times its radius
  float focus_ = 1.0f;                     // distance of the plane in focus along forward_
  bool lens_ = false;
  float inv_w_ = 1.0f, inv_h_ = 1.0f;
};

}  // namespace tracer
