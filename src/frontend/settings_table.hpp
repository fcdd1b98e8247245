// The one table of a render's flags: for each, its names, type, range, default, help, the
// integrators it applies to and what it changes. The command lines (render, view, info,
// tracer-mpi), the checks, the viewer's JSON fields and state, the command the viewer copies and
// tracer-mpi's agreement fingerprint are all read from it: a new flag that changes the image is a
// row here and the code that uses its value (docs/ARCHITECTURE.md, "Adding a flag").
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "frontend/render_args.hpp"

namespace CLI {
class App;  // CLI11: only the files that add or parse flags include it (a heavy header)
}  // namespace CLI

namespace tracer::frontend {

// The integrators a flag applies to, a bit each.
class IntegratorSet {
 public:
  constexpr IntegratorSet(std::initializer_list<Integrator> list) {
    for (const Integrator i : list) bits_ |= uint8_t(1u << unsigned(i));
  }
  static constexpr IntegratorSet all() { return {Integrator::Ao, Integrator::Whitted, Integrator::Path}; }
  constexpr bool has(Integrator i) const { return (bits_ >> unsigned(i)) & 1u; }
  constexpr bool is_all() const { return bits_ == all().bits_; }
  // "path", "path or whitted": for help texts and messages.
  std::string names(std::string_view separator) const;

 private:
  uint8_t bits_ = 0;
};

// tracer info reads the scene's rows; render, view and tracer-mpi all of them.
enum class SettingGroup { Scene, Render };

// What a flag's value changes, which says who must agree on it.
enum class Role {
  Image,  // the image: tracer-mpi's ranks agree on it; the viewer restarts its render for it
  Work,   // how the work is cut into tiles and passes: the ranks agree on it, the image does not change
  Scene,  // what is loaded (the scene, its lights, limits): the ranks agree on the scene's checksum
  Local,  // this process's means (accelerator, threads, SIMD, output format): the image does not change
};

// One row of the table. The behaviour comes from the row's type (settings_table.cpp's makers:
// whole numbers, reals, names of an enum, x,y,z vectors, toggles, file names, lists).
struct Setting {
  std::string names;  // CLI11's: "--eye,-v"; a positional's name first: "scene,-m,--scene"
  std::string key;    // the viewer's JSON field, "" when the viewer does not set it
  std::string help;   // the integrators it applies to are prefixed from `applies`
  IntegratorSet applies = IntegratorSet::all();
  Role role = Role::Image;
  SettingGroup group = SettingGroup::Render;

  // The long flag: "--eye".
  std::string flag() const;
  // The value as a command line writes it (each float as the shortest text that reads back the
  // same), or nothing when the flag is not given (an unset optional, a toggle off, an empty name).
  std::function<std::optional<std::string>(const RenderArgs&)> text;
  // Throws UsageError, naming the value `name` (the flag, or the viewer's field), when the value
  // is outside the row's range.
  std::function<void(const RenderArgs&, const std::string& name)> check;
  // This row's value copied from `from` (the viewer keeps flags across a switch of integrator).
  std::function<void(RenderArgs&, const RenderArgs& from)> copy;
  // The value read from the command line's text (one word; a list's rows take each in turn).
  // Throws UsageError naming the flag.
  std::function<void(RenderArgs&, const std::string& text)> parse;
  // The viewer's field: read (checked by type; check() follows) and written. Null without a key.
  std::function<void(RenderArgs&, const nlohmann::json& value)> read_json;
  std::function<nlohmann::json(const RenderArgs&)> json;
  bool toggle = false;      // takes no value (--denoise)
  bool repeatable = false;  // given any number of times (--light)
  std::string excludes;     // a flag it may not be given with
  std::string value_name;   // what --help calls its value: INT, FLOAT, X,Y,Z, FILE, NAME
};

const std::span<const Setting> settings_table();
// The row of a long flag ("--spp"); throws std::logic_error for a flag not in the table.
const Setting& setting(std::string_view flag);

// Registers every row of `groups` as a flag of `app` writing into `args`.
void add_settings(CLI::App& app, RenderArgs& args, std::initializer_list<SettingGroup> groups);
// A command-line parse error's text as tracer prints it: CLI11's own words where they name the
// flag plainly, else ours ("--spp: given 2 times; it takes one value", not "At Most 1 required").
std::string parse_error_text(const std::string& cli11_message);
// Checks every row's range, then the rules that tie flags together; throws UsageError naming the
// flag. Changes nothing.
void check_settings(const RenderArgs& args);
// Rows that are off until given (an optional, a toggle, a name) and do not apply to
// args.integrator are reset, so check_settings() accepts the switch; rows that apply and the
// viewer does not set (no key) take their value from `launched`.
void follow_integrator(RenderArgs& args, const RenderArgs& launched);
// The `tracer render` command of `args`: every row whose value differs from a default render's,
// in the table's order, shell-quoted.
std::string render_command(const RenderArgs& args);
// "--flag value" a line for every row of `roles`, given or not: what ranks compare.
std::string settings_lines(const RenderArgs& args, std::initializer_list<Role> roles);

// Whether every row of `roles` but those of `except` (long flags) has the same value in a and b.
bool same_settings(const RenderArgs& a, const RenderArgs& b, std::initializer_list<Role> roles,
                   std::initializer_list<std::string_view> except = {});

// Quotes a word for a POSIX shell when it needs it.
std::string shell_quote(const std::string& word);

}  // namespace tracer::frontend
