#include "view/view_state.hpp"

#include <nlohmann/json.hpp>

#include "base/errors.hpp"
#include "frontend/parse.hpp"
#include "frontend/settings_table.hpp"

namespace tracer::view {

namespace {

Vec2 vec2_field(const std::string& key, const nlohmann::json& value) {
  if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number())
    throw UsageError(key + ": expected [x, y], got " + value.dump());
  const double x = value[0].get<double>(), y = value[1].get<double>();
  if (!(std::fabs(x) <= 1e6 && std::fabs(y) <= 1e6))
    throw UsageError(key + ": " + value.dump() + " is outside [-1e6, 1e6]");
  return {float(x), float(y)};
}

}  // namespace

nlohmann::json vec_json(Vec3 v) { return nlohmann::json::array({v.x, v.y, v.z}); }

void read_change(const nlohmann::json& change, StateFields& s, const frontend::RenderArgs& launched) {
  if (!change.is_object()) throw UsageError("expected a JSON object of fields to change, got " + change.dump());
  const Integrator integrator = s.args.integrator;
  for (const auto& [key, value] : change.items()) {
    if (key == "focus_at") {
      s.focus_at = vec2_field(key, value);
      continue;
    }
    if (key == "denoise") {
      if (!value.is_boolean()) throw UsageError("denoise: expected true or false, got " + value.dump());
      s.denoise = value.get<bool>();
      continue;
    }
    const frontend::Setting* row = nullptr;
    std::string keys;
    for (const frontend::Setting& r : frontend::settings_table()) {
      if (r.key.empty()) continue;
      if (r.key == key) row = &r;
      keys += r.key + ", ";
    }
    if (!row) throw UsageError("unknown field '" + key + "' (" + keys + "focus_at, denoise)");
    // The viewer's own bound on a side first, so every width past it gets the same error.
    if ((key == "width" || key == "height") && value.is_number_integer()) {
      const auto side = value.get<long long>();
      frontend::check_range(key, side, 1, kMaxViewSide);
    }
    row->read_json(s.args, value);
    row->check(s.args, key);
  }
  if (s.args.integrator != integrator) frontend::follow_integrator(s.args, launched);
}

nlohmann::json state_fields(const frontend::RenderArgs& args) {
  nlohmann::json out = nlohmann::json::object();
  for (const frontend::Setting& r : frontend::settings_table()) {
    if (!r.key.empty()) out[r.key] = r.json(args);
  }
  return out;
}

}  // namespace tracer::view
