// What every tile of one pass of a render shares (PassContext): the scene, the camera, the
// settings, the films it adds to, and the samples the pass takes. (RenderArgs are the flags,
// RenderSettings what they make of the image, RenderMonitor what the caller watches and stops.)
#pragma once

#include <cstdint>

#include "film/convergence.hpp"
#include "film/feature_film.hpp"
#include "film/framebuffer.hpp"
#include "render/ray_counts.hpp"
#include "render/render_settings.hpp"
#include "scene/camera.hpp"
#include "scene/scene.hpp"

namespace tracer {

// The samples of each pixel one pass adds: [first, first + count).
struct SampleRange {
  uint32_t first = 0, count = 1;
};

// Everything one tile needs; shared read-only by all workers except the disjoint framebuffer pixels.
struct PassContext {
  const Scene* scene = nullptr;
  Camera camera;
  RenderSettings settings;
  Framebuffer* framebuffer = nullptr;
  SampleRange samples;  // this pass's samples (ao and whitted at one spp: the pixel centre)
  // path, --aov: where each sample's first hit adds its albedo and shading normal (for a
  // denoiser), summed and counted as the radiance is; null when not asked for.
  Framebuffer* albedo = nullptr;
  Framebuffer* normal = nullptr;
  // path, --denoise: the halves of radiance and the denoiser's features (null when not asked for).
  FeatureFilm* features = nullptr;
  // path with adaptive sampling: the pixels this pass samples (null: all of them).
  const ActivePixels* active = nullptr;
};

}  // namespace tracer
