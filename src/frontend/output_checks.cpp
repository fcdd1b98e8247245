#include "frontend/output_checks.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "base/errors.hpp"
#include "io/image_io.hpp"

namespace tracer::frontend {

namespace fs = std::filesystem;

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return fs::weakly_canonical(fs::absolute(a), ec) == fs::weakly_canonical(fs::absolute(b), ec);
}

void check_outputs(const RenderArgs& a) {
  image_format_for(a.output, "-o");
  if (!a.scene.scene.empty() && a.scene.scene != "-" && same_file(a.output, a.scene.scene)) {
    throw UsageError("-o: '" + a.output + "' is the input scene");
  }
  check_writable(a.output);
  if (a.stats_json.empty() || a.stats_json == "-") return;
  if (!a.scene.scene.empty() && a.scene.scene != "-" && same_file(a.stats_json, a.scene.scene)) {
    throw UsageError("--stats-json: '" + a.stats_json + "' is the input scene");
  }
  // Against every name the frames expand to, not the literal -o: frame 1 of `-o fr.png` is fr-0001.png.
  for (int frame = 0; frame < a.frames; ++frame) {
    const std::string image = frame_output(a.output, frame, a.frames);
    if (same_file(a.stats_json, image)) {
      throw UsageError("--stats-json: '" + a.stats_json + "' is also " +
                       (a.frames > 1 ? "frame " + std::to_string(frame) + "'s image (-o " + a.output + ")"
                                     : std::string("the -o image")));
    }
  }
  check_writable(a.stats_json);
}

void check_outputs_against_inputs(const RenderArgs& a) {
  for (int frame = 0; frame < a.frames; ++frame) check_output(frame_output(a.output, frame, a.frames), "-o");
  if (!a.stats_json.empty() && a.stats_json != "-") check_output(a.stats_json, "--stats-json");
}

std::string frame_output(const std::string& output, int frame, int frames) {
  if (frames <= 1) return output;
  const fs::path p(output);
  // At least four digits, and as many as the last frame needs, so names sort in frame order.
  const int digits = std::max(4, int(std::to_string(frames - 1).size()));
  char number[24];
  std::snprintf(number, sizeof number, "-%0*d", digits, frame);
  return (p.parent_path() / (p.stem().string() + number + p.extension().string())).string();
}

}  // namespace tracer::frontend
