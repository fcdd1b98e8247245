// The settings table (driver/settings_table.hpp): what it derives agrees with itself. A command it
// writes parses back to the same values; every flag that defines the image is in what the ranks
// compare; a flag given to an integrator that ignores it is refused by the table's own rows.
#include <gtest/gtest.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <sstream>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "frontend/render_args.hpp"
#include "frontend/settings_table.hpp"
#include "view/view_state.hpp"

namespace tracer {
namespace {

using frontend::RenderArgs;
using frontend::Setting;

// The words of a command line (no quoting needed: the test's values have no spaces).
std::vector<std::string> words_of(const std::string& command) {
  std::istringstream in(command);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// `command` ("tracer render ...") parsed by the flags the table registers.
RenderArgs parsed(const std::string& command) {
  std::vector<std::string> words = words_of(command);
  words.erase(words.begin(), words.begin() + 2);
  CLI::App app;
  RenderArgs args;
  frontend::add_render_options(app, args);
  std::vector<std::string> reversed(words.rbegin(), words.rend());
  app.parse(reversed);
  return args;
}

// A render with a value other than the default for many rows of every type.
RenderArgs unusual() {
  RenderArgs a;
  a.scene.scene = "scene.obj";
  a.scene.lights = {Vec3{1, 2, 3}, Vec3{-0.5f, 1e-3f, 7}};
  a.scene.no_scene_lights = true;
  a.scene.env_rotation = 12.5;
  a.scene.max_memory_mib = 4096;
  a.settings.width = 321;
  a.settings.height = 123;
  a.settings.max_depth = 3;
  a.settings.exposure = 0.7f;
  a.settings.seed = 4000000000u;
  a.settings.light_sampling = LightSampling::Bsdf;
  a.eye = Vec3{0.1f, 0.2f, 0.3f};
  a.look = Vec3{1.0f / 3.0f, 0, -2};
  a.up = Vec3{0, 0, 1};
  a.fov = 33.3f;
  a.aperture = 0.05;
  a.focus_distance = 2.5;
  a.spp = 7;
  a.noise_threshold = 0.02;
  a.min_spp = 4;
  a.env = Vec3{0.5f, 0.25f, 1};
  a.denoise = true;
  a.sched.strategy = Strategy::Queue;
  a.sched.block = 32;
  a.bvh.strategy = Strategy::Async;
  a.bvh.split = BvhSplit::Median;
  a.bvh.traversal_cost = 1.25f;
  a.accel = AccelKind::Bvh8;
  a.build_quality = BuildQuality::High;
  a.simd_target = SimdTarget::Avx2;
  a.packets = false;
  a.exr = ExrPixel::Float;
  a.threads = 3;
  return a;
}

void expect_same_rows(const RenderArgs& a, const RenderArgs& b) {
  for (const Setting& s : frontend::settings_table()) {
    EXPECT_EQ(s.text(a), s.text(b)) << s.flag();
  }
}

TEST(SettingsTable, TheCopiedCommandParsesBackToTheSameValues) {
  const RenderArgs a = unusual();
  const std::string command = frontend::render_command(a);
  SCOPED_TRACE(command);
  expect_same_rows(parsed(command), a);
  EXPECT_NO_THROW(frontend::validate(a));
}

TEST(SettingsTable, EveryFlagThatDefinesTheImageIsComparedBetweenRanks) {
  const std::string lines = frontend::settings_lines(unusual(), {frontend::Role::Image, frontend::Role::Work});
  for (const Setting& s : frontend::settings_table()) {
    const bool compared = s.role == frontend::Role::Image || s.role == frontend::Role::Work;
    EXPECT_EQ(lines.find("\n" + s.flag() + " ") != std::string::npos || lines.rfind(s.flag() + " ", 0) == 0, compared)
        << s.flag();
  }
  // Two renders that differ in one such flag differ in their lines.
  RenderArgs b = unusual();
  b.settings.max_depth = 4;
  EXPECT_NE(frontend::settings_lines(b, {frontend::Role::Image}),
            frontend::settings_lines(unusual(), {frontend::Role::Image}));
  EXPECT_FALSE(frontend::same_settings(b, unusual(), {frontend::Role::Image}));
  EXPECT_TRUE(frontend::same_settings(b, unusual(), {frontend::Role::Image}, {"--max-depth"}));
}

TEST(SettingsTable, EveryRowHasHelpAndItsIntegratorsSayWhereItApplies) {
  for (const Setting& s : frontend::settings_table()) {
    EXPECT_FALSE(s.help.empty()) << s.flag();
    EXPECT_EQ(s.flag().rfind("--", 0), 0u) << s.names;
    if (!s.applies.is_all()) {
      EXPECT_EQ(s.help.rfind(s.applies.names(", ") + ": ", 0), 0u) << s.flag();
    }
  }
}

TEST(SettingsTable, AFlagGivenToAnIntegratorThatIgnoresItIsRefused) {
  RenderArgs a;
  a.integrator = Integrator::Ao;
  a.denoise = true;
  try {
    frontend::validate(a);
    ADD_FAILURE() << "--denoise with ao accepted";
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "--denoise: only for --integrator path");
  }
  a.denoise = false;
  a.env = Vec3{1.0f};
  EXPECT_THROW(frontend::validate(a), UsageError);  // --env: path or whitted
  a.integrator = Integrator::Whitted;
  EXPECT_NO_THROW(frontend::validate(a));
  // A flag with a default value (--max-depth) only says so in its help.
  a.integrator = Integrator::Ao;
  a.env.reset();
  a.settings.max_depth = 2;
  EXPECT_NO_THROW(frontend::validate(a));
}

TEST(SettingsTable, ASwitchOfIntegratorDropsAndRestoresWhatAppliesToIt) {
  RenderArgs launched = unusual();
  RenderArgs a = launched;
  a.integrator = Integrator::Ao;
  frontend::follow_integrator(a, launched);
  EXPECT_FALSE(a.noise_threshold);
  EXPECT_FALSE(a.denoise);
  EXPECT_FALSE(a.env);
  EXPECT_EQ(a.settings.max_depth, 3);  // has a default: kept, as the page shows it
  EXPECT_NO_THROW(frontend::validate(a));
  a.integrator = Integrator::Path;
  frontend::follow_integrator(a, launched);
  expect_same_rows(a, launched);
}

TEST(SettingsTable, TheViewersStateReadsBackToTheSameValues) {
  const RenderArgs a = unusual();
  view::StateFields fields{RenderArgs{}, true, std::nullopt};
  fields.args.settings.width = 64;  // within the viewer's largest side
  view::read_change(view::state_fields(a), fields, a);
  for (const Setting& s : frontend::settings_table()) {
    if (!s.key.empty()) {
      EXPECT_EQ(s.text(fields.args), s.text(a)) << s.key;
    }
  }
}

TEST(SettingsTable, BadValuesAreNamedByTheFlagOrTheField) {
  const auto refused = [](const std::string& command) {
    try {
      parsed(command);
    } catch (const CLI::ParseError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused("tracer render --width 0"), "--width: must be between 1 and 16384, got 0");
  EXPECT_EQ(refused("tracer render --width 2.5"), "--width: expected a whole number, got '2.5'");
  EXPECT_EQ(refused("tracer render --fov x"), "--fov: expected a number, got 'x'");
  EXPECT_EQ(refused("tracer render --integrator ray"), "--integrator: unknown integrator 'ray' (ao, whitted, path)");
  EXPECT_EQ(refused("tracer render --up 1,2"), "--up: expected three numbers x,y,z, got '1,2'");
  view::StateFields fields;
  EXPECT_THROW(view::read_change(nlohmann::json{{"spp", 0}}, fields, RenderArgs{}), UsageError);
  try {
    view::read_change(nlohmann::json{{"spp", 0}}, fields, RenderArgs{});
  } catch (const UsageError& e) {
    EXPECT_EQ(std::string(e.what()), "spp: must be between 1 and 1048576, got 0");
  }
}

}  // namespace
}  // namespace tracer
