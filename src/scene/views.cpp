#include "scene/views.hpp"
#include "base/whole_number.hpp"

#include <charconv>
#include <cmath>
#include <filesystem>

#include "base/errors.hpp"
#include "base/read_input.hpp"
#include "base/text.hpp"
#include "scene/value_limits.hpp"

namespace tracer {
namespace {

std::vector<std::string> split_tabs(std::string_view line) {
  std::vector<std::string> fields;
  size_t pos = 0;
  for (;;) {
    const size_t tab = line.find('\t', pos);
    fields.emplace_back(line.substr(pos, tab == std::string_view::npos ? std::string_view::npos : tab - pos));
    if (tab == std::string_view::npos) return fields;
    pos = tab + 1;
  }
}

bool parse_number(std::string_view text, float& out) {
  return read_whole_number(text, out) == WholeNumber::Ok && std::isfinite(out);
}

Vec3 parse_field_vec3(const std::string& text, const std::string& where, const char* field) {
  float v[3];
  size_t pos = 0;
  for (int i = 0; i < 3; ++i) {
    const size_t comma = text.find(',', pos);
    const bool last = i == 2;
    if ((comma == std::string::npos) != last ||
        !parse_number(std::string_view(text).substr(pos, last ? std::string::npos : comma - pos), v[i]) ||
        std::fabs(v[i]) > kMaxCoordinate) {
      throw InputError(where + ": " + field + ": expected x,y,z (three finite numbers), got " + in_quotes(text));
    }
    pos = comma + 1;
  }
  return {v[0], v[1], v[2]};
}

}  // namespace

std::string default_views_path() {
  for (const char* p :
       {"../shared/scenes/views.tsv", "../../shared/scenes/views.tsv", "../../../shared/scenes/views.tsv"}) {
    if (std::filesystem::exists(p)) return p;
  }
  return "../shared/scenes/views.tsv";
}

std::optional<View> view_of_scene_file(const std::string& obj_path, std::string* problem) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path dir = fs::path(obj_path).parent_path();
  for (const fs::path& candidate : {dir / "views.tsv", dir / ".." / "views.tsv"}) {
    if (!fs::is_regular_file(candidate, ec)) continue;
    std::vector<View> views;
    try {
      views = load_views(candidate.string());
    } catch (const std::runtime_error& e) {
      if (problem && problem->empty()) *problem = e.what();
      continue;
    }
    for (const View& v : views) {
      if (fs::equivalent(v.obj, obj_path, ec)) return v;
    }
  }
  return std::nullopt;
}

std::vector<View> load_views(const std::string& path) {
  std::string text = read_input(path, nullptr, uint64_t(64) << 20);  // a views file is a few lines
  strip_bom(text);
  const std::filesystem::path dir = std::filesystem::path(path).parent_path();
  std::vector<View> views;
  for_each_line(text, [&](std::string_view line, size_t line_no) {
    const std::string where = path + ":" + std::to_string(line_no);
    if (trim(line).empty() || trim(line).front() == '#') return;
    const std::vector<std::string> f = split_tabs(line);
    if (line_no == 1 && !f.empty() && f[0] == "scene") return;  // the header
    if (f.size() < 7) {
      throw InputError(where +
                       ": expected 7 or 8 tab-separated fields (scene, obj, eye, look, up, fov, light, note), got " +
                       std::to_string(f.size()));
    }
    View v;
    v.name = f[0];
    if (v.name.empty()) throw InputError(where + ": empty view name");
    v.obj = (dir / f[1]).string();
    v.camera.eye = parse_field_vec3(f[2], where, "eye");
    v.camera.look = parse_field_vec3(f[3], where, "look");
    v.camera.up = parse_field_vec3(f[4], where, "up");
    if (!parse_number(f[5], v.camera.fov_degrees) || !(v.camera.fov_degrees >= kMinFovDegrees) ||
        v.camera.fov_degrees > kMaxFovDegrees) {
      throw InputError(where + ": fov: expected degrees in [" + format_number(kMinFovDegrees) + ", " +
                       format_number(kMaxFovDegrees) + "], got " + in_quotes(f[5]));
    }
    v.light = parse_field_vec3(f[6], where, "light");
    if (f.size() > 7) v.note = f[7];
    const Vec3 forward = v.camera.look - v.camera.eye;
    if (length(forward) == 0.0f || length(cross(forward, v.camera.up)) == 0.0f) {
      throw InputError(where + ": the camera's eye, look and up do not define a view");
    }
    for (const View& other : views) {
      if (other.name == v.name) throw InputError(where + ": view " + in_quotes(v.name) + " is defined twice");
    }
    views.push_back(std::move(v));
  });
  return views;
}

const View& find_view(const std::vector<View>& views, const std::string& name, const std::string& path,
                      const std::string& flag) {
  std::string names;
  for (const View& v : views) {
    if (v.name == name) return v;
    names += (names.empty() ? "" : ", ") + v.name;
  }
  throw UsageError(flag + ": no view called " + in_quotes(name) + " in " + path + " (" + names + ")");
}

void apply_view_light(Scene& scene, const View& view) {
  Light l;
  l.position = view.light;
  l.power = Vec3{scene.default_light_intensity()};
  scene.lights.assign(1, l);
}

}  // namespace tracer
