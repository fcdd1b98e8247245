// What reads the settings table: the flags it registers, the checks, the viewer's integrator
// switch, the copied command and the lines ranks compare.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <sstream>

#include "base/errors.hpp"
#include "frontend/render_options.hpp"
#include "frontend/settings_table.hpp"

namespace tracer::frontend {

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

// Rules that tie several flags together; each row's own range is its check().
void check_combinations(const RenderArgs& a) {
  const AccelOptions accel = accel_options_for(a);
  if (a.packets == true && !traces_rays_together(accel.kind)) {
    throw UsageError("--packets: needs --accel bvh, bvh8 or embree (the accelerators with packet kernels)");
  }
  if (a.streams == true && (a.packets == false || a.simd == SimdUse::Off)) {
    throw UsageError("--streams: traces rays together, which --no-packets and --simd off turn off");
  }
  if (a.streams == true && !traces_streams(accel.kind)) {
    throw UsageError("--streams: needs --accel bvh8 or embree (the accelerators with stream kernels)");
  }
  if (a.count && accel.kind != AccelKind::Bvh8) {
    throw UsageError("--count: only the 8-wide BVH counts its traversal (--accel bvh8, the default)");
  }
  if (a.min_spp && a.spp && *a.min_spp > *a.spp) {
    throw UsageError("--min-spp " + std::to_string(*a.min_spp) + ": above --spp " + std::to_string(*a.spp) +
                     " (adaptive sampling's minimum cannot exceed the samples a pixel gets)");
  }
  if (a.bvh.strategy == Strategy::Atomic) {
    throw UsageError("--build-sched: atomic hands out tiles; a build forks with seq, async, queue or tbb");
  }
  aovs_for(a);
}

}  // namespace

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
      // One value each time it is given: `--light 0,1,0 scene.obj` leaves the scene to the
      // positional argument (CLI11 would take every following word).
      option->expected(1)->allow_extra_args(false)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
    } else {
      option = app.add_option_function<std::string>(s.names, parse, s.help);
      if (const std::optional<std::string> d = s.text(defaults)) option->default_str(*d);
    }
    if (!s.excludes.empty()) option->excludes(s.excludes);
    if (!s.value_name.empty()) option->type_name(s.value_name);
  }
}

std::string parse_error_text(const std::string& message) {
  static constexpr std::string_view kAtMost = ": At Most 1 required but received ";
  if (const size_t at = message.find(kAtMost); at != std::string::npos) {
    return message.substr(0, at) + ": given " + message.substr(at + kAtMost.size()) + " times; it takes one value";
  }
  return message;
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
    // As check_settings refuses them: only a flag that is off until given is dropped.
    if (!s.applies.has(a.integrator)) {
      if (!s.text(defaults)) s.copy(a, defaults);
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

}  // namespace tracer::frontend
