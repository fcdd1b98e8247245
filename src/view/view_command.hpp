// `tracer view`: loads the scene and builds the accelerator once, then serves the viewer on
// 127.0.0.1 (or --listen) until Ctrl-C, which stops it at once, mid-frame too (exit 130).
#pragma once

#include <string>

#include "frontend/render_args.hpp"

namespace tracer::view {

struct ViewArgs {
  frontend::RenderArgs render;
  std::string listen = "127.0.0.1";
  int port = 8421;
  bool width_given = false, height_given = false;
};

// The size the viewer renders when --width/--height are not given: fluid on two cores.
inline constexpr int kDefaultViewSide = 512;

int run_view(ViewArgs args);

}  // namespace tracer::view
