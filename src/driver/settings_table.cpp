#include "driver/settings_table.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "base/errors.hpp"
#include "base/whole_number.hpp"
#include "driver/parse.hpp"
#include "driver/render_options.hpp"
#include "io/image_io.hpp"
#include "scene/camera.hpp"
#include "scene/value_limits.hpp"

namespace tracer::driver {

std::string IntegratorSet::names(std::string_view separator) const {
  std::string out;
  // Path first: the integrator most flags that apply to a few belong to.
  for (const Integrator i : {Integrator::Path, Integrator::Whitted, Integrator::Ao}) {
    if (has(i))
      out += (out.empty() ? "" : std::string(separator)) + std::string(name_of<Integrator>(kIntegratorNames, i));
  }
  return out;
}

std::string Setting::flag() const {
  // The last long name: "scene,-m,--scene" and "--eye,-v" alike.
  std::string best;
  for (size_t pos = 0; pos <= names.size();) {
    const size_t comma = std::min(names.find(',', pos), names.size());
    const std::string name = names.substr(pos, comma - pos);
    if (name.rfind("--", 0) == 0 && best.empty()) best = name;
    pos = comma + 1;
  }
  return best;
}

namespace {

using json = nlohmann::json;

template <class T>
struct Unwrap {
  using type = T;
  static constexpr bool optional = false;
};
template <class T>
struct Unwrap<std::optional<T>> {
  using type = T;
  static constexpr bool optional = true;
};

// A row's field: the member of RenderArgs it reads and writes.
template <class T>
using Field = T& (*)(RenderArgs&);
template <class T>
const T& get(Field<T> field, const RenderArgs& a) {
  return field(const_cast<RenderArgs&>(a));
}

// What a value type needs for a row: its text, its range, its JSON.
template <class V>
struct Codec {
  std::function<V(const std::string& name, const std::string& text)> parse;
  std::function<std::string(const V&)> format;
  std::function<void(const std::string& name, const V&)> check;  // null: every value parse gives is in range
  std::function<V(const std::string& name, const json&)> from_json;
};

// The shortest text that reads back as the same value of its type.
template <class F>
std::string shortest(F v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

double json_number(const std::string& name, const json& value) {
  if (!value.is_number()) throw UsageError(name + ": expected a number, got " + value.dump());
  return value.get<double>();
}

// The command line's numbers are whole words (base/whole_number.hpp); the viewer's JSON numbers
// are nlohmann-json's.
template <class I>
Codec<I> whole(long long lo, long long hi) {
  Codec<I> c;
  c.parse = [lo, hi](const std::string& name, const std::string& text) {
    long long v = 0;
    const WholeNumber read = read_whole_number(text, v);
    if (read == WholeNumber::NotANumber) throw UsageError(name + ": expected a whole number, got '" + text + "'");
    // Checked on the text as given: a number beyond long long is quoted as typed.
    if (read == WholeNumber::OutOfRange || v < lo || v > hi)
      throw UsageError(name + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " +
                       text);
    return I(v);
  };
  c.format = [](const I& v) { return std::to_string(v); };
  c.check = [lo, hi](const std::string& name, const I& v) { check_range(name, (long long)v, lo, hi); };
  c.from_json = [lo, hi](const std::string& name, const json& value) {
    const double v = json_number(name, value);
    if (v != std::floor(v)) throw UsageError(name + ": expected a whole number, got " + value.dump());
    if (!(v >= double(lo) && v <= double(hi)))
      throw UsageError(name + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " +
                       value.dump());
    return I(v);
  };
  return c;
}

template <class F>
Codec<F> real(double lo, double hi, LowEnd low = LowEnd::Closed) {
  Codec<F> c;
  c.parse = [](const std::string& name, const std::string& text) {
    double v = 0;
    const WholeNumber read = read_whole_number(text, v);
    if (read == WholeNumber::NotANumber) throw UsageError(name + ": expected a number, got '" + text + "'");
    if (read == WholeNumber::OutOfRange)
      throw UsageError(name + ": '" + text + "' is out of range (not a finite number)");
    return F(v);
  };
  c.format = [](const F& v) { return shortest(v); };
  c.check = [lo, hi, low](const std::string& name, const F& v) { check_range_real(name, double(v), lo, hi, low); };
  c.from_json = [](const std::string& name, const json& value) { return F(json_number(name, value)); };
  return c;
}

template <class E>
Codec<E> choice(std::span<const EnumName<E>> names, std::string what) {
  Codec<E> c;
  c.parse = [names, what](const std::string& name, const std::string& text) {
    return parse_name<E>(names, text, name, what);
  };
  c.format = [names](const E& v) { return std::string(name_of<E>(names, v)); };
  c.from_json = [names, what](const std::string& name, const json& value) {
    if (!value.is_string()) throw UsageError(name + ": expected a name, got " + value.dump());
    return parse_name<E>(names, value.get<std::string>(), name, what);
  };
  return c;
}

// x,y,z: a position (within the coordinates floats hold), a direction (not zero) or a radiance.
enum class VecKind { Point, Direction, Radiance };
Codec<Vec3> vector(VecKind kind) {
  Codec<Vec3> c;
  c.parse = [](const std::string& name, const std::string& text) { return parse_vec3(name, text); };
  c.format = [](const Vec3& v) { return shortest(v.x) + "," + shortest(v.y) + "," + shortest(v.z); };
  c.check = [kind](const std::string& name, const Vec3& v) {
    const std::string text = shortest(v.x) + "," + shortest(v.y) + "," + shortest(v.z);
    for (const float x : {v.x, v.y, v.z}) {
      if (!std::isfinite(x)) throw UsageError(name + ": '" + text + "' is out of range (not a finite float)");
    }
    switch (kind) {
      case VecKind::Point:
        if (std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > kMaxCoordinate)
          throw UsageError(name + ": coordinates must lie within +-" + kMaxCoordinateText + ", got '" + text + "'");
        break;
      case VecKind::Direction:
        if (length(v) == 0.0f) throw UsageError(name + ": must not be the zero vector");
        break;
      case VecKind::Radiance:
        if (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f || max_component(v) > 1e30f)
          throw UsageError(name + ": each component must be in [0, 1e30], got '" + text + "'");
        break;
    }
  };
  c.from_json = [](const std::string& name, const json& value) {
    if (!value.is_array() || value.size() != 3) throw UsageError(name + ": expected [x, y, z], got " + value.dump());
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      const double x = json_number(name, value[size_t(i)]);
      if (!(std::fabs(x) <= 1e12))
        throw UsageError(name + ": " + value[size_t(i)].dump() + " is outside [-1e12, 1e12]");
      v[i] = float(x);
    }
    return v;
  };
  return c;
}

// A name (a file, a view): any text, or with `nonempty` any but the empty one.
Codec<std::string> name_codec(bool nonempty) {
  Codec<std::string> c;
  c.parse = [nonempty](const std::string& name, const std::string& text) {
    if (nonempty && text.empty()) throw UsageError(name + ": an empty file name");
    return text;
  };
  c.format = [](const std::string& v) { return v; };
  return c;
}

// A row of a single value of type T (V, or an optional V: not given until set).
template <class T, class V = typename Unwrap<T>::type>
Setting row(Setting s, Field<T> field, Codec<V> c) {
  constexpr bool optional = Unwrap<T>::optional;
  const auto value = [field](const RenderArgs& a) -> std::optional<V> {
    if constexpr (optional) {
      return get(field, a);
    } else {
      return get(field, a);
    }
  };
  s.text = [value, c](const RenderArgs& a) -> std::optional<std::string> {
    const std::optional<V> v = value(a);
    if (!v) return std::nullopt;
    if constexpr (std::is_same_v<V, std::string>) {
      if (v->empty()) return std::nullopt;
    }
    return c.format(*v);
  };
  s.check = [value, c](const RenderArgs& a, const std::string& name) {
    if (const std::optional<V> v = value(a); v && c.check) c.check(name, *v);
  };
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field, c, flag = s.flag()](RenderArgs& a, const std::string& text) { field(a) = c.parse(flag, text); };
  if (!s.key.empty()) {
    s.read_json = [field, c, key = s.key](RenderArgs& a, const json& v) { field(a) = c.from_json(key, v); };
    s.json = [value, c](const RenderArgs& a) -> json {
      const std::optional<V> v = value(a);
      if (!v) return nullptr;
      if constexpr (std::is_same_v<V, Vec3>) {
        return json::array({v->x, v->y, v->z});
      } else if constexpr (std::is_enum_v<V>) {
        return c.format(*v);
      } else {
        return *v;
      }
    };
  }
  return s;
}

Setting toggle(Setting s, Field<bool> field) {
  s.toggle = true;
  s.text = [field](const RenderArgs& a) -> std::optional<std::string> {
    return get(field, a) ? std::optional<std::string>("") : std::nullopt;
  };
  s.check = [](const RenderArgs&, const std::string&) {};
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field](RenderArgs& a, const std::string&) { field(a) = true; };
  return s;
}

// --packets and --no-packets: the two settings of one optional toggle.
Setting tristate(Setting s, Field<std::optional<bool>> field, bool on) {
  s.toggle = true;
  s.text = [field, on](const RenderArgs& a) -> std::optional<std::string> {
    return get(field, a) == on ? std::optional<std::string>("") : std::nullopt;
  };
  s.check = [](const RenderArgs&, const std::string&) {};
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field, on](RenderArgs& a, const std::string&) { field(a) = on; };
  return s;
}

// A repeatable flag: each given value appended.
Setting points(Setting s, Field<std::vector<Vec3>> field) {
  const Codec<Vec3> c = vector(VecKind::Point);
  s.repeatable = true;
  s.text = [field, c](const RenderArgs& a) -> std::optional<std::string> {
    std::string out;
    for (const Vec3& v : get(field, a)) out += (out.empty() ? "" : " ") + c.format(v);
    return out.empty() ? std::nullopt : std::optional<std::string>(out);
  };
  s.check = [field, c](const RenderArgs& a, const std::string& name) {
    for (const Vec3& v : get(field, a)) c.check(name, v);
  };
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field, c, flag = s.flag()](RenderArgs& a, const std::string& text) {
    field(a).push_back(c.parse(flag, text));
  };
  return s;
}

constexpr IntegratorSet kPath{Integrator::Path};
constexpr IntegratorSet kLit{Integrator::Path, Integrator::Whitted};  // light from beyond the scene
constexpr IntegratorSet kAo{Integrator::Ao};

std::string number_text(double v) { return (std::ostringstream() << v).str(); }

std::vector<Setting> make_table() {
  using G = SettingGroup;
  std::vector<Setting> t;
  // The scene: what is loaded (tracer info reads these too).
  t.push_back(row<std::string>(
      {.names = "scene,-m,--scene",
       .help = "scene to render: .obj, .gltf, .glb or .ply (default: the built-in Cornell box)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.scene; }, name_codec(true)));
  t.push_back(row<std::string>(
      {.names = "--view",
       .help = "render a named view: its scene, camera and light (e.g. sponza, cornell-water)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.view; }, name_codec(false)));
  t.push_back(row<std::string>(
      {.names = "--views",
       .help = "the views file for --view (default ../shared/scenes/views.tsv)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.views; }, name_codec(true)));
  t.push_back(row<int>(
      {.names = "--builtin-spheres",
       .help = "built-in scene: add two spheres of about this many triangles each",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.builtin_spheres; }, whole<int>(0, 10'000'000)));
  t.push_back(points(
      {.names = "--light", .help = "add a point light at x,y,z (repeatable)", .role = Role::Scene, .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.lights; }));
  t.push_back(toggle(
      {.names = "--no-scene-lights",
       .help = "drop the scene's emissive lights, keep only --light ones",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.no_scene_lights; }));
  t.push_back(row<std::optional<double>>(
      {.names = "--light-intensity",
       .help = "point light intensity (default: (scene diagonal / 2)^2)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.light_intensity; }, real<double>(0.0, kMaxLightIntensity)));
  t.push_back(row<std::string>(
      {.names = "--env-map",
       .help = "light the scene from beyond with this equirectangular environment map (.exr "
               "or .hdr, linear radiance; times --env)",
       .applies = kLit,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.env_map; }, name_codec(true)));
  t.push_back(row<double>(
      {.names = "--env-rotation", .help = "degrees the --env-map turns about +y", .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.env_rotation; }, real<double>(-1e6, 1e6)));
  t.push_back(row<std::optional<int>>(
      {.names = "--camera",
       .help = "a glTF scene's camera N, counting from 0 in node order (default 0)",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.camera; }, whole<int>(0, 1 << 30)));
  t.push_back(row<long long>(
      {.names = "--max-input-mib", .help = "largest scene file read, in MiB", .role = Role::Scene, .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.max_input_mib; }, whole<long long>(1, 1 << 20)));
  t.push_back(row<long long>(
      {.names = "--max-texture-mib",
       .help = "memory all the scene's textures may take, in MiB; past it a texture is not used",
       .role = Role::Scene,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.max_texture_mib; }, whole<long long>(1, 1 << 20)));
  t.push_back(row<std::optional<long long>>(
      {.names = "--max-memory-mib",
       .help = "memory the scene, its accelerator and the image may take, in MiB (default: the memory available "
               "less a tenth); a render estimated above it is refused",
       .role = Role::Local,
       .group = G::Scene},
      [](RenderArgs & a) -> auto& { return a.scene.max_memory_mib; }, whole<long long>(1, 1 << 30)));

  // The image.
  t.push_back(row<int>(
      {.names = "--width", .key = "width", .help = "image width in pixels"},
      [](RenderArgs & a) -> auto& { return a.settings.width; }, whole<int>(1, 16384)));
  t.push_back(row<int>(
      {.names = "--height", .key = "height", .help = "image height in pixels"},
      [](RenderArgs & a) -> auto& { return a.settings.height; }, whole<int>(1, 16384)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--eye,-v", .key = "eye", .help = "camera position x,y,z (default: frame the scene from the front)"},
      [](RenderArgs & a) -> auto& { return a.eye; }, vector(VecKind::Point)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--look,-l", .key = "look", .help = "point the camera looks at, x,y,z"},
      [](RenderArgs & a) -> auto& { return a.look; }, vector(VecKind::Point)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--up", .key = "up", .help = "camera up vector x,y,z (default 0,1,0)"},
      [](RenderArgs & a) -> auto& { return a.up; }, vector(VecKind::Direction)));
  t.push_back(row<std::optional<float>>(
      {.names = "--fov", .key = "fov", .help = "vertical field of view in degrees (default 53.13)"},
      [](RenderArgs & a) -> auto& { return a.fov; }, real<float>(kMinFovDegrees, kMaxFovDegrees)));
  t.push_back(row<std::optional<double>>(
      {.names = "--aperture",
       .key = "aperture",
       .help = "depth of field: the radius of a thin lens, in scene units (default 0: a pinhole, all sharp)"},
      [](RenderArgs & a) -> auto& { return a.aperture; }, real<double>(0.0, 1e6)));
  t.push_back(row<std::optional<double>>(
      {.names = "--focus-distance",
       .key = "focus_distance",
       .help = "with --aperture: the distance of the plane in focus along the view (default: the look-at point's)"},
      [](RenderArgs & a) -> auto& { return a.focus_distance; }, real<double>(0.0, 1e12, LowEnd::Open)));
  t.push_back(row<Integrator>(
      {.names = "--integrator",
       .key = "integrator",
       .help = "what a pixel is made of: ao (the study's workload: direct light, ambient occlusion, every surface "
               "diffuse), whitted (mirrors and glass from the MTL, hard shadows) or path (path tracing: every "
               "material, emissive triangles as area lights, soft shadows, indirect light)"},
      [](RenderArgs & a) -> auto& { return a.integrator; }, choice<Integrator>(kIntegratorNames, "integrator")));
  t.push_back(row<int>(
      {.names = "--max-depth",
       .key = "max_depth",
       .help = "whitted: reflections and refractions followed; path: bounces per path",
       .applies = kLit},
      [](RenderArgs & a) -> auto& { return a.settings.max_depth; }, whole<int>(0, 64)));
  t.push_back(row<std::optional<int>>(
      {.names = "--spp",
       .key = "spp",
       .help = "samples per pixel (default " + std::to_string(kDefaultPathSpp) +
               " for path, 1 through the pixel centre for ao and whitted)"},
      [](RenderArgs & a) -> auto& { return a.spp; }, whole<int>(1, 1 << 20)));
  t.push_back(row<std::optional<double>>(
      {.names = "--noise-threshold",
       .help = "adaptive sampling: a 4x4 block of pixels stops taking samples once each pixel's noise estimate is "
               "below this (default " +
               number_text(kDefaultNoiseThreshold) + ", 0 with --denoise; 0 gives every pixel --spp samples)",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.noise_threshold; }, real<double>(0.0, 1.0)));
  t.push_back(row<std::optional<int>>(
      {.names = "--min-spp",
       .help = "adaptive sampling: samples every pixel takes before it may stop (default " +
               std::to_string(RenderSettings{}.min_spp) + ")",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.min_spp; }, whole<int>(2, 1 << 20)));
  t.push_back(row<std::optional<Vec3>>(
      {.names = "--env",
       .help = "radiance r,g,b of a uniform environment, or the --env-map's scale (default black, 1,1,1 with "
               "--env-map; white when the scene has no light)",
       .applies = kLit},
      [](RenderArgs & a) -> auto& { return a.env; }, vector(VecKind::Radiance)));
  t.push_back(row<std::string>(
      {.names = "--aov",
       .help = "also write these layers into the .exr output: albedo and normal of the first hit, samples (each "
               "pixel's sample count), and with --denoise noisy (the image before denoising) and variance (of each "
               "pixel's mean); comma-separated",
       .applies = kPath,
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.aov; }, name_codec(false)));
  t.push_back(toggle(
      {.names = "--denoise",
       .help = "denoise the image (NFOR, a feature-guided regression on the albedo, normal and "
               "distance of the first surface that is not a mirror or glass); --aov noisy,variance "
               "keep what it started from",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.denoise; }));
  t.push_back(row<LightSampling>(
      {.names = "--light-sampling",
       .help = names_of<LightSampling>(kLightSamplingNames) +
               " (mis: emitter samples and BSDF samples combined; bsdf: BSDF samples only)",
       .applies = kPath},
      [](RenderArgs & a) -> auto& { return a.settings.light_sampling; },
      choice<LightSampling>(kLightSamplingNames, "light sampling")));
  t.push_back(row<int>(
      {.names = "--frames",
       .help = "render an image sequence of this many frames: -o NAME.png gives NAME-0000.png ..."},
      [](RenderArgs & a) -> auto& { return a.frames; }, whole<int>(1, 1'000'000)));
  t.push_back(row<double>(
      {.names = "--orbit",
       .help = "degrees the camera turns about the look point (around --up) over the --frames sequence"},
      [](RenderArgs & a) -> auto& { return a.orbit; }, real<double>(-1e6, 1e6)));
  t.push_back(row<std::optional<double>>(
      {.names = "--checkpoint",
       .help = "rewrite the output every this many seconds while samples accumulate",
       .applies = kPath,
       .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.checkpoint; }, real<double>(0.0, 1e9, LowEnd::Open)));
  t.push_back(row<int>(
      {.names = "--ao", .help = "ambient-occlusion rays per hit, 0 = off", .applies = kAo},
      [](RenderArgs & a) -> auto& { return a.settings.ao_samples; }, whole<int>(0, 4096)));
  t.push_back(row<std::optional<double>>(
      {.names = "--ao-distance", .help = "maximum distance of AO rays (default: unbounded)", .applies = kAo},
      [](RenderArgs & a) -> auto& { return a.ao_distance; }, real<double>(0.0, 1e30, LowEnd::Open)));
  t.push_back(row<float>(
      {.names = "--ambient", .help = "ambient light strength", .applies = kAo},
      [](RenderArgs & a) -> auto& { return a.settings.ambient; }, real<float>(0.0, 1e6)));
  t.push_back(row<float>(
      {.names = "--exposure", .key = "exposure", .help = "tone-mapping exposure of .png and .ppm outputs"},
      [](RenderArgs & a) -> auto& { return a.settings.exposure; }, real<float>(0.0, 1e6, LowEnd::Open)));
  t.push_back(row<uint32_t>(
      {.names = "--seed", .help = "seed of the sample patterns"},
      [](RenderArgs & a) -> auto& { return a.settings.seed; }, whole<uint32_t>(0, 4294967295LL)));

  // The work: how it is cut, which ranks must agree on.
  t.push_back(row<Strategy>(
      {.names = "--sched",
       .help = "how tiles are handed to threads: " + names_of<Strategy>(kStrategyNames),
       .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.sched.strategy; }, choice<Strategy>(kStrategyNames, "strategy")));
  t.push_back(row<int>(
      {.names = "--tile", .help = "tile edge in pixels for the atomic and tbb strategies", .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.sched.tile; }, whole<int>(1, 4096)));
  t.push_back(row<int>(
      {.names = "--block", .help = "pixels per row block for the queue strategy", .role = Role::Work},
      [](RenderArgs & a) -> auto& { return a.sched.block; }, whole<int>(1, 1 << 20)));

  // This process's means: the same image from each.
  t.push_back(row<ExrPixel>(
      {.names = "--exr",
       .help = "pixel type of .exr outputs (linear radiance, no tone mapping): half or float",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.exr; }, choice<ExrPixel>(kExrPixelNames, "pixel type")));
  t.push_back(row<std::optional<AccelKind>>(
      {.names = "--accel",
       .help = "accelerator: " + names_of<AccelKind>(kAccelKindNames) + " (default " +
               std::string(name_of<AccelKind>(kAccelKindNames, AccelOptions{}.kind)) + ", the fastest)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.accel; }, choice<AccelKind>(kAccelKindNames, "accelerator")));
  t.push_back(row<std::optional<BuildQuality>>(
      {.names = "--build-quality",
       .help = "bvh8 and embree: " + names_of<BuildQuality>(kBuildQualityNames) +
               " (high: spatial splits, a slower build for faster closest hits; default high for a path render of "
               "at least 16 pixel samples per triangle, else medium, and medium in tracer view)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.build_quality; }, choice<BuildQuality>(kBuildQualityNames, "quality")));
  t.push_back(row<BvhSplit>(
      {.names = "--bvh-split",
       .help = "BVH split: " + names_of<BvhSplit>(kBvhSplitNames) + " (the study's)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.split; }, choice<BvhSplit>(kBvhSplitNames, "split")));
  t.push_back(row<Strategy>(
      {.names = "--build-sched,--build",
       .help = "how the BVH build forks: seq, async, queue or tbb (the strategies of --sched but atomic, which hands "
               "out tiles)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.strategy; }, choice<Strategy>(kStrategyNames, "strategy")));
  t.push_back(row<int>(
      {.names = "--max-leaf", .help = "SAH BVH: largest leaf", .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.max_leaf; }, whole<int>(1, 16)));
  t.push_back(row<int>(
      {.names = "--bins", .help = "SAH BVH: bins per axis", .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.bins; }, whole<int>(4, 32)));
  t.push_back(row<float>(
      {.names = "--traversal-cost",
       .help = "SAH BVH: cost of a node step relative to a triangle test",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.bvh.traversal_cost; }, real<float>(0.0, 100.0, LowEnd::Open)));
  t.push_back(row<SimdUse>(
      {.names = "--simd",
       .help = "SIMD kernels: auto, or off (scalar traversal: --accel bvh by default)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.simd; }, choice<SimdUse>(kSimdUseNames, "SIMD use")));
  t.push_back(row<SimdTarget>(
      {.names = "--simd-target",
       .help =
           "bvh8 and the denoiser: " + names_of<SimdTarget>(kSimdTargetNames) + " (a narrower target than the CPU's)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.simd_target; }, choice<SimdTarget>(kSimdTargetNames, "target")));
  t.push_back(tristate(
      {.names = "--packets",
       .help = "trace rays together: each hit's AO rays as one bundle (bvh, bvh8, embree), primary rays and shadow "
               "rays per 4x4-pixel packet (bvh8, embree); same image (default: on where the accelerator can)",
       .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.packets; }, true));
  t.push_back(tristate(
      {.names = "--no-packets",
       .help = "trace every ray alone (same image, slower)",
       .role = Role::Local,
       .excludes = "--packets"},
      [](RenderArgs & a) -> auto& { return a.packets; }, false));
  t.push_back(row<std::optional<int>>(
      {.names = "--threads", .help = "worker threads (default: all hardware threads)", .role = Role::Local},
      [](RenderArgs & a) -> auto& { return a.threads; }, whole<int>(1, 1024)));
  for (Setting& s : t) {
    if (!s.applies.is_all()) s.help = s.applies.names(", ") + ": " + s.help;
  }
  return t;
}

// Rules that tie several flags together; each row's own range is its check().
void check_combinations(const RenderArgs& a) {
  const AccelOptions accel = accel_options_for(a);
  if (a.packets == true && !traces_rays_together(accel.kind)) {
    throw UsageError("--packets: needs --accel bvh, bvh8 or embree (the accelerators with packet kernels)");
  }
  if (a.count && accel.kind != AccelKind::Bvh8) {
    throw UsageError("--count: only the 8-wide BVH counts its traversal (--accel bvh8, the default)");
  }
  if (a.bvh.strategy == Strategy::Atomic) {
    throw UsageError("--build-sched: atomic hands out tiles; a build forks with seq, async, queue or tbb");
  }
  aovs_for(a);
}

}  // namespace

const std::span<const Setting> settings_table() {
  static const std::vector<Setting> table = make_table();
  return table;
}

const Setting& setting(std::string_view flag) {
  for (const Setting& s : settings_table()) {
    if (s.flag() == flag) return s;
  }
  throw std::logic_error("no setting " + std::string(flag));
}

void add_settings(CLI::App& app, RenderArgs& args, std::initializer_list<SettingGroup> groups) {
  const RenderArgs defaults;
  for (const Setting& s : settings_table()) {
    if (std::find(groups.begin(), groups.end(), s.group) == groups.end()) continue;
    // A bad value is the parser's error: one line naming the flag, exit 2.
    const auto parse = [&args, &s](const std::string& text) {
      try {
        s.parse(args, text);
      } catch (const UsageError& e) {
        throw CLI::ValidationError(e.what());
      }
    };
    CLI::Option* option = nullptr;
    if (s.toggle) {
      option = app.add_flag_function(
          s.names, [parse](int64_t) { parse(""); }, s.help);
    } else if (s.repeatable) {
      option = app.add_option_function<std::vector<std::string>>(
          s.names,
          [parse](const std::vector<std::string>& v) {
            for (const std::string& t : v) parse(t);
          },
          s.help);
    } else {
      option = app.add_option_function<std::string>(s.names, parse, s.help);
      if (const std::optional<std::string> d = s.text(defaults)) option->default_str(*d);
    }
    if (!s.excludes.empty()) option->excludes(s.excludes);
  }
}

void check_settings(const RenderArgs& a) {
  const RenderArgs defaults;
  for (const Setting& s : settings_table()) {
    s.check(a, s.flag());
    // A flag that is not given until set (an optional, a toggle, a name) is refused for an
    // integrator that would ignore it; one with a default value only says so in its help.
    if (!s.applies.has(a.integrator) && s.text(a) && !s.text(defaults)) {
      throw UsageError(s.flag() + ": only for --integrator " + s.applies.names(" or "));
    }
  }
  check_combinations(a);
}

void follow_integrator(RenderArgs& a, const RenderArgs& launched) {
  const RenderArgs defaults;
  for (const Setting& s : settings_table()) {
    if (!s.applies.has(a.integrator)) {
      s.copy(a, defaults);
    } else if (s.key.empty() && !s.applies.is_all()) {
      s.copy(a, launched);
    }
  }
}

bool same_settings(const RenderArgs& a, const RenderArgs& b, std::initializer_list<Role> roles,
                   std::initializer_list<std::string_view> except) {
  for (const Setting& s : settings_table()) {
    if (std::find(roles.begin(), roles.end(), s.role) == roles.end()) continue;
    if (std::find(except.begin(), except.end(), s.flag()) != except.end()) continue;
    if (s.text(a) != s.text(b)) return false;
  }
  return true;
}

std::string shell_quote(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("_./,=:+-@%").find(c) != std::string::npos;
  });
  if (plain) return word;
  std::string out = "'";
  for (const char c : word) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string render_command(const RenderArgs& a) {
  const RenderArgs defaults;
  std::string out = "tracer render";
  for (const Setting& s : settings_table()) {
    const std::optional<std::string> text = s.text(a);
    if (!text || text == s.text(defaults)) continue;
    if (s.toggle) {
      out += " " + s.flag();
    } else if (s.repeatable) {
      std::istringstream words(*text);
      for (std::string w; words >> w;) out += " " + s.flag() + " " + shell_quote(w);
    } else {
      out += " " + s.flag() + " " + shell_quote(*text);
    }
  }
  return out;
}

std::string settings_lines(const RenderArgs& a, std::initializer_list<Role> roles) {
  std::string out;
  for (const Setting& s : settings_table()) {
    if (std::find(roles.begin(), roles.end(), s.role) == roles.end()) continue;
    const std::optional<std::string> text = s.text(a);
    out += s.flag() + " " + (!text ? "(not given)" : s.toggle ? "on" : *text) + "\n";
  }
  return out;
}

}  // namespace tracer::driver
