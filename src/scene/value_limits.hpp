// The range of each physical quantity a scene holds, one rule whatever sets it: an MTL statement,
// a glTF property, a views.tsv field or a flag. Beyond them a value is refused (it is a typo or an
// attack, and far past them the renderer's sums overflow).
#pragma once

namespace tracer {

inline constexpr float kMaxReflectance = 1.0f;  // Ka Kd Ks Tf, glTF factors: fractions of light
// Radiance, however it enters: emission (MTL Ke, glTF emissive x strength), --env and each
// environment-map texel (which --env then scales).
inline constexpr float kMaxEmission = 1e6f;
inline constexpr float kMaxShininess = 1e6f;        // Ns
inline constexpr float kMaxIor = 100.0f;            // Ni, glTF ior (0 is accepted: exporters write it for "unset")
inline constexpr double kMaxLightIntensity = 1e30;  // a point light's intensity (--light-intensity, glTF lights)
// A camera's vertical field of view in degrees (--fov, views.tsv, a glTF camera's yfov).
inline constexpr double kMinFovDegrees = 1e-3;
inline constexpr double kMaxFovDegrees = 179.0;

}  // namespace tracer
