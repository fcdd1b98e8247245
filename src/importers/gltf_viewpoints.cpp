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

// glTF's lights are photometric (candela for point and spot lights, lux for directional ones),
// tracer's radiometric: divided by 683 lm/W, as Blender's importer does (its default, "Standard"
// conversion), so a glTF lamp lights a scene as brightly beside its emissive surfaces (whose
// strength is radiance already) as in Blender and Cycles.
constexpr double kLumensPerWatt = 683.0;

std::optional<Light> light_of(const tg::Model& model_, const std::string& file, WarningLog& warnings_,
                              const tg::Value& ext, const Affine& world) {
  const auto error = [&](const std::string& w) { return InputError(file + ": " + w); };
  const int index = int(gltf::number(&ext, "light", -1.0));
  if (index < 0 || size_t(index) >= model_.lights.size())
    throw error("light " + std::to_string(index) + " does not exist");
  const tg::Light& l = model_.lights[size_t(index)];
  const std::string what = "light " + std::to_string(index);
  Light light;
  if (l.type == "point") {
    light.kind = LightKind::Point;
  } else if (l.type == "spot") {
    light.kind = LightKind::Spot;
  } else if (l.type == "directional") {
    light.kind = LightKind::Directional;
  } else {
    warnings_.add(what + " is of unknown type " + in_quotes(l.type) + ": not used");
    return std::nullopt;
  }
  if (l.range > 0.0 && light.kind != LightKind::Directional) {
    warnings_.add("a light's range not used: lights fall off with the inverse square of distance only");
  }
  light.position = world.point(Vec3{0.0f});
  if (light.kind != LightKind::Point) {
    const Vec3 axis = world.vector(Vec3{0.0f, 0.0f, -1.0f});  // the node's -z
    const float len = length(axis);
    if (!(len > 0.0f) || !std::isfinite(len)) throw error(what + ": its node's transform leaves no direction");
    light.normal = axis / len;
  }
  if (light.kind == LightKind::Spot) {
    const double inner = l.spot.innerConeAngle, outer = l.spot.outerConeAngle;
    if (!(inner >= 0.0) || !(outer > inner) || !(outer <= std::numbers::pi / 2 + 1e-9)) {
      throw error(what + ": spot cone angles inner " + format_number(inner) + ", outer " + format_number(outer) +
                  " (the specification's 0 <= inner < outer <= pi/2)");
    }
    light.cos_inner = float(std::cos(inner));
    light.cos_outer = float(std::cos(outer));
  }
  light.power = gltf::vec3_of(l.color, Vec3{1.0f}) * float(l.intensity / kLumensPerWatt);
  if (!is_finite(light.position) || !is_finite(light.power) || light.power.x < 0.0f || light.power.y < 0.0f ||
      light.power.z < 0.0f || max_component(light.power) > kMaxLightIntensity) {
    throw error(what + ": position or intensity not finite, negative or above " + format_number(kMaxLightIntensity) +
                " (--light-intensity's limit)");
  }
  return light;
}

}  // namespace tracer::gltf
