// One tile of an image: the integrator the settings name, chosen once per tile, through the one
// pixel-sample loop (render/pixel_samples.hpp). Templated on the accelerator so the per-ray path
// has no virtual call.
#pragma once

#include "render/ao.hpp"
#include "render/path.hpp"
#include "render/whitted.hpp"

namespace tracer {

template <class Accel>
RayCounts render_tile(const Accel& accel, const PassContext& ctx, const Tile& tile) {
  RayCounts counts;
  switch (ctx.settings.integrator) {
    case Integrator::Ao:
      render_pixels(AoIntegrator{}, accel, ctx, tile, counts);
      break;
    case Integrator::Whitted:
      render_pixels(WhittedIntegrator{}, accel, ctx, tile, counts);
      break;
    case Integrator::Path:
      render_pixels(PathIntegrator{}, accel, ctx, tile, counts);
      break;
  }
  return counts;
}

}  // namespace tracer
