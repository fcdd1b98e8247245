#include "view/view_state.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "base/errors.hpp"
#include "driver/render_options.hpp"

namespace tracer::view {

namespace {

std::string format_float(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", v);
  return text;
}

double number_field(const std::string& key, const nlohmann::json& value, double lo, double hi) {
  if (!value.is_number()) throw UsageError(key + ": expected a number, got " + value.dump());
  const double v = value.get<double>();
  if (!(v >= lo && v <= hi))
    throw UsageError(key + ": " + value.dump() + " is outside [" + format_float(lo) + ", " + format_float(hi) + "]");
  return v;
}

int int_field(const std::string& key, const nlohmann::json& value, int lo, int hi) {
  const double v = number_field(key, value, lo, hi);
  if (v != std::floor(v)) throw UsageError(key + ": expected a whole number, got " + value.dump());
  return int(v);
}

Vec3 vec_field(const std::string& key, const nlohmann::json& value) {
  if (!value.is_array() || value.size() != 3) throw UsageError(key + ": expected [x, y, z], got " + value.dump());
  Vec3 v;
  for (int i = 0; i < 3; ++i) v[i] = float(number_field(key, value[size_t(i)], -1e12, 1e12));
  return v;
}

Vec2 vec2_field(const std::string& key, const nlohmann::json& value) {
  if (!value.is_array() || value.size() != 2) throw UsageError(key + ": expected [x, y], got " + value.dump());
  return {float(number_field(key, value[0], -1e6, 1e6)), float(number_field(key, value[1], -1e6, 1e6))};
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

}  // namespace

std::string vec_text(Vec3 v) { return format_float(v.x) + "," + format_float(v.y) + "," + format_float(v.z); }

nlohmann::json vec_json(Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

void read_change(const nlohmann::json& change, StateFields& s, std::optional<double> noise_threshold,
                 std::optional<int> min_spp) {
  if (!change.is_object()) throw UsageError("expected a JSON object of fields to change, got " + change.dump());
  for (const auto& [key, value] : change.items()) {
    if (key == "eye") {
      s.args.eye = vec_text(vec_field(key, value));
    } else if (key == "look") {
      s.args.look = vec_text(vec_field(key, value));
    } else if (key == "up") {
      s.args.up = vec_text(vec_field(key, value));
    } else if (key == "fov") {
      s.args.fov = double(float(number_field(key, value, 1e-3, 179.0)));
    } else if (key == "aperture") {
      s.args.aperture = number_field(key, value, 0.0, 1e6);
    } else if (key == "focus_distance") {
      s.args.focus_distance = number_field(key, value, 1e-6, 1e12);
    } else if (key == "focus_at") {
      s.focus_at = vec2_field(key, value);
    } else if (key == "integrator") {
      if (!value.is_string()) throw UsageError("integrator: expected a name, got " + value.dump());
      s.args.integrator = value.get<std::string>();
      const bool path =
          parse_name<Integrator>(kIntegratorNames, s.args.integrator, "integrator", "integrator") == Integrator::Path;
      s.args.noise_threshold = path ? noise_threshold : std::nullopt;
      s.args.min_spp = path ? min_spp : std::nullopt;
    } else if (key == "spp") {
      s.args.spp = int_field(key, value, 1, 1 << 20);
    } else if (key == "max_depth") {
      s.args.settings.max_depth = int_field(key, value, 0, 64);
    } else if (key == "exposure") {
      s.args.settings.exposure = float(number_field(key, value, 0.0, 1e6));
    } else if (key == "width") {
      s.args.settings.width = int_field(key, value, 1, kMaxViewSide);
    } else if (key == "height") {
      s.args.settings.height = int_field(key, value, 1, kMaxViewSide);
    } else if (key == "denoise") {
      if (!value.is_boolean()) throw UsageError("denoise: expected true or false, got " + value.dump());
      s.denoise = value.get<bool>();
    } else {
      throw UsageError("unknown field '" + key +
                       "' (eye, look, up, fov, aperture, focus_distance, focus_at, integrator, spp, max_depth, "
                       "exposure, width, height, denoise)");
    }
  }
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

std::string render_command(const driver::RenderArgs& a, const std::vector<std::string>& user_flags,
                           const std::vector<std::string>& viewer_flags) {
  std::vector<std::string> dropped(std::begin(kStateFlags), std::end(kStateFlags));
  dropped.insert(dropped.end(), viewer_flags.begin(), viewer_flags.end());
  std::string out = "tracer render";
  for (size_t i = 0; i < user_flags.size(); ++i) {
    const std::string& t = user_flags[i];
    bool drop = t == "--denoise";  // a flag of no value: the toggle's, written below
    for (const std::string& flag : dropped) {
      if (t == flag) {
        drop = true;
        ++i;  // and its value
        break;
      }
      const bool is_short = flag.size() == 2;  // -v1,2,3 as well as -v=1,2,3
      if (starts_with(t, flag + "=") || (is_short && starts_with(t, flag) && t.size() > 2)) {
        drop = true;
        break;
      }
    }
    if (!drop) out += " " + shell_quote(t);
  }
  out += " --eye " + a.eye + " --look " + a.look + " --up " + a.up + " --fov " + format_float(*a.fov);
  // The shortest text that reads back as the same double: the command's camera is the view's.
  const auto shortest = [](double v) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, v).ptr;
    return std::string(text, end);
  };
  if (a.aperture && *a.aperture > 0.0) {
    out += " --aperture " + shortest(*a.aperture);
    if (a.focus_distance) out += " --focus-distance " + shortest(*a.focus_distance);
  }
  out += " --width " + std::to_string(a.settings.width) + " --height " + std::to_string(a.settings.height);
  out += " --integrator " + a.integrator + " --spp " + std::to_string(*a.spp);
  out += " --max-depth " + std::to_string(a.settings.max_depth) + " --exposure " + format_float(a.settings.exposure);
  if (a.noise_threshold) out += " --noise-threshold " + shortest(*a.noise_threshold);
  if (a.min_spp) out += " --min-spp " + std::to_string(*a.min_spp);
  if (a.denoise) out += " --denoise";
  return out;
}

}  // namespace tracer::view
