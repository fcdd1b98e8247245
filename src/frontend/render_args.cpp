#include "frontend/render_args.hpp"

#include <CLI/CLI.hpp>

#include "frontend/settings_table.hpp"

namespace tracer::frontend {

CLI::Option* file_option(CLI::Option* option) {
  return option->check(CLI::Validator(
      [](const std::string& s) { return s.empty() ? std::string("an empty file name") : std::string(); }, "FILE"));
}

void add_output_options(CLI::App& app, RenderArgs& a, const std::string& writer, const std::string& stats) {
  file_option(app.add_option("-o,--output", a.output,
                             "output image: .png or .ppm (tone-mapped), .exr (linear radiance)" + writer))
      ->capture_default_str();
  app.add_flag("--stats", a.stats, "print " + stats);
  file_option(app.add_option("--stats-json", a.stats_json,
                             "write the statistics as JSON to this file ('-': standard output)" + writer));
  app.add_flag("-q,--quiet", a.quiet, "no progress bar, no loader warnings");
}

void add_render_options(CLI::App& app, RenderArgs& a) {
  add_settings(app, a, {SettingGroup::Scene, SettingGroup::Render});
}

void validate(const RenderArgs& a) { check_settings(a); }

}  // namespace tracer::frontend
