// The viewer's state as its page reads and writes it: the fields are the settings table's rows
// that have a viewer key (frontend/settings_table.hpp), read and checked as the command line's are,
// plus the page's own (its denoise toggle, a pixel to focus at).
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <optional>

#include "frontend/render_args.hpp"
#include "math/vec.hpp"

namespace tracer::view {

// The largest image the viewer renders, per side. At 4096 x 4096 its buffers take ~750 MB (the
// film of sums and counts, 268 MB; its displayed copy, 268 MB; a download's snapshot while one is
// made, 268 MB at most; the 8-bit image, 50 MB; measured 724 MB), 181 MB at 2048 x 2048.
inline constexpr int kMaxViewSide = 4096;

// What a change sets: the render flags, the page's denoise toggle, and a pixel to focus at.
struct StateFields {
  frontend::RenderArgs args;
  bool denoise = true;
  std::optional<Vec2> focus_at;
};

// Reads `change` (a JSON object of the table's viewer fields, denoise and focus_at) into `fields`,
// each checked as its flag is. A switch of integrator drops the flags that do not apply to the new
// one and takes those that do as launched (`launched`: the command's own). Throws UsageError
// naming the field for an unknown field, a wrong type or a value out of range.
void read_change(const nlohmann::json& change, StateFields& fields, const frontend::RenderArgs& launched);

// The table's viewer fields of `args`, as read_change() takes them (an unset one is null).
nlohmann::json state_fields(const frontend::RenderArgs& args);

nlohmann::json vec_json(Vec3 v);

}  // namespace tracer::view
