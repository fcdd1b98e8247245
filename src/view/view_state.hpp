// The viewer's state as its page reads and writes it: a JSON change read field by field into the
// flags of `tracer render` (the same checks follow, in ViewSession::apply), the floats written so
// they parse back the same, and the `tracer render` command of a state, which the page copies.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <optional>
#include <string>
#include <vector>

#include "driver/render_args.hpp"
#include "math/vec.hpp"

namespace tracer::view {

// The largest image the viewer renders, per side. At 4096 x 4096 its buffers take ~750 MB (the
// film of sums and counts, 268 MB; its displayed copy, 268 MB; a download's snapshot while one is
// made, 268 MB at most; the 8-bit image, 50 MB; measured 724 MB), 181 MB at 2048 x 2048.
inline constexpr int kMaxViewSide = 4096;

// The flags of a `tracer render` command that the viewer's state sets, each taking one value. The
// viewer's "copy command" drops them from the user's own flags and writes the current ones.
inline constexpr const char* kStateFlags[] = {"--eye",
                                              "-v",
                                              "--look",
                                              "--up",
                                              "--fov",
                                              "--width",
                                              "--height",
                                              "--spp",
                                              "--integrator",
                                              "--max-depth",
                                              "--exposure",
                                              "-l",
                                              "--aperture",
                                              "--focus-distance",
                                              "--noise-threshold",
                                              "--min-spp"};

// The command line of `tracer render` for `args`: `user_flags` (the view command's own arguments)
// without the state's flags and the viewer's own (`viewer_flags`, each taking one value), then the
// state's, every value written so that it parses back to the same float. Shell-quoted.
std::string render_command(const driver::RenderArgs& args, const std::vector<std::string>& user_flags,
                           const std::vector<std::string>& viewer_flags);

// Quotes a word for a POSIX shell when it needs it.
std::string shell_quote(const std::string& word);

// x,y,z of floats, each written so it parses back to the same float; and as a JSON array.
std::string vec_text(Vec3 v);
nlohmann::json vec_json(Vec3 v);

// What a change sets: the render flags, the page's denoise toggle, and a pixel to focus at.
struct StateFields {
  driver::RenderArgs args;
  bool denoise = true;
  std::optional<Vec2> focus_at;
};

// Reads `change` (a JSON object of eye, look, up, fov, aperture, focus_distance, focus_at,
// integrator, spp, max_depth, exposure, width, height, denoise) into `fields`. A switch of
// integrator takes adaptive sampling's flags as launched (`noise_threshold`, `min_spp`) for path
// tracing and none for the others. Throws UsageError naming the field for an unknown field, a
// wrong type or a value out of range.
void read_change(const nlohmann::json& change, StateFields& fields, std::optional<double> noise_threshold,
                 std::optional<int> min_spp);

}  // namespace tracer::view
