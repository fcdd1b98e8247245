#include "frontend/memory_estimate.hpp"

#include <string>

#include "base/errors.hpp"
#include "base/memory_limit.hpp"
#include "denoise/nfor.hpp"
#include "frontend/render_options.hpp"

namespace tracer::frontend {

uint64_t memory_limit(const SceneArgs& args) {
  return args.max_memory_mib ? uint64_t(*args.max_memory_mib) << 20 : default_memory_limit();
}

uint64_t film_bytes(const RenderArgs& args) {
  const RenderSettings settings = settings_for(args);
  const Aovs aovs = aovs_for(args);
  const uint64_t layers = uint64_t(aovs.albedo) + uint64_t(aovs.normal) + uint64_t(aovs.samples) +
                          uint64_t(aovs.noisy) + uint64_t(aovs.variance);
  const uint64_t per_pixel = kFilmBytesPerPixel + (adaptive(settings) ? kHalvesBytesPerPixel : 0) +
                             layers * kLayerBytesPerPixel + (args.denoise ? kDenoiseBytesPerPixel : 0);
  return uint64_t(settings.width) * uint64_t(settings.height) * per_pixel +
         (args.denoise ? denoise::nfor_peak_bytes(settings.width, settings.height) : 0);
}

void check_film_fits(const RenderArgs& args, uint64_t limit) {
  const uint64_t bytes = film_bytes(args);
  if (bytes <= limit) return;
  std::string what = "--width " + std::to_string(args.settings.width) + " --height " +
                     std::to_string(args.settings.height) + (args.aov.empty() ? "" : " --aov " + args.aov) +
                     (args.denoise ? " --denoise" : "") + ": the image's film";
  if (!args.aov.empty()) what += " and layers";
  if (args.denoise) what += " and the denoiser's";
  if (adaptive(settings_for(args))) what += " (with adaptive sampling's, --noise-threshold)";
  throw UsageError(memory_refusal(what, bytes, limit));
}

void check_render_fits(const Scene& scene, const AccelOptions& options, const RenderArgs& args, uint64_t limit) {
  const uint64_t scene_bytes = scene.memory_bytes();
  const uint64_t accel_bytes = uint64_t(scene.size()) * build_bytes_per_triangle(options.kind, options.quality);
  const uint64_t bytes = scene_bytes + accel_bytes + film_bytes(args);
  if (bytes <= limit) return;
  throw InputError(memory_refusal(scene.source + ": its " + std::to_string(scene.size()) + " triangles (" +
                                      format_bytes(scene_bytes) + "), their accelerator (about " +
                                      format_bytes(accel_bytes) + ") and the image together",
                                  bytes, limit));
}

}  // namespace tracer::frontend
