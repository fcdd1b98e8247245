#include "importers/gltf_viewpoints.hpp"

#include <cmath>
#include <numbers>

#include "base/errors.hpp"
#include "base/text.hpp"
#include "scene/camera.hpp"
#include "scene/value_limits.hpp"

namespace tracer::gltf {

namespace tg = tinygltf;

std::optional<CameraSpec> camera_of(const tg::Model& model_, const std::string& file, WarningLog& warnings_, int index,
                                    const Affine& world) {
  const auto error = [&](const std::string& w) { return InputError(file + ": " + w); };
  if (size_t(index) >= model_.cameras.size()) throw error("camera " + std::to_string(index) + " does not exist");
  const tg::Camera& c = model_.cameras[size_t(index)];
  if (c.type != "perspective") {
    warnings_.add("camera " + std::to_string(index) + " is " + in_quotes(c.type) +
                  ": only perspective cameras are used");
    return std::nullopt;
  }
  const double yfov = c.perspective.yfov, degrees = yfov * 180.0 / std::numbers::pi;
  if (!(degrees >= kMinFovDegrees && degrees <= kMaxFovDegrees)) {
    throw error("camera " + std::to_string(index) + ": yfov " + format_number(yfov) + " (" + format_number(degrees) +
                " degrees) is not in [" + format_number(kMinFovDegrees) + ", " + format_number(kMaxFovDegrees) +
                "] degrees, the field of view every camera of tracer's is held to");
  }
  CameraSpec spec;
  spec.eye = world.point(Vec3{0.0f});
  const Vec3 forward = world.vector(Vec3{0.0f, 0.0f, -1.0f}), up = world.vector(Vec3{0.0f, 1.0f, 0.0f});
  const float len = length(forward);
  if (!(len > 0.0f) || !std::isfinite(len) || !(length(cross(forward, up)) > 0.0f)) {
    throw error("camera " + std::to_string(index) + ": its node's transform collapses the view direction");
  }
  spec.look = spec.eye + forward / len;
  spec.up = normalize(up);
  spec.fov_degrees = float(yfov * 180.0 / std::numbers::pi);
  return spec;
}

std::optional<Light> point_light_of(const tg::Model& model_, const std::string& file, WarningLog& warnings_,
                                    const tg::Value& ext, const Affine& world) {
  const auto error = [&](const std::string& w) { return InputError(file + ": " + w); };
  const int index = int(gltf::number(&ext, "light", -1.0));
  if (index < 0 || size_t(index) >= model_.lights.size())
    throw error("light " + std::to_string(index) + " does not exist");
  const tg::Light& l = model_.lights[size_t(index)];
  if (l.type != "point") {
    warnings_.add("light " + std::to_string(index) + " is a " + in_quotes(l.type) +
                  " light: only point lights are used");
    return std::nullopt;
  }
  Light light;
  light.position = world.point(Vec3{0.0f});
  light.power = gltf::vec3_of(l.color, Vec3{1.0f}) * float(l.intensity);
  if (!is_finite(light.position) || !is_finite(light.power) || light.power.x < 0.0f || light.power.y < 0.0f ||
      light.power.z < 0.0f || max_component(light.power) > kMaxLightIntensity) {
    throw error("light " + std::to_string(index) + ": position or intensity not finite, negative or above " +
                format_number(kMaxLightIntensity) + " (--light-intensity's limit)");
  }
  return light;
}

}  // namespace tracer::gltf
