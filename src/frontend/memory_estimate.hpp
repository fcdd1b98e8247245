// What a render will take in memory, estimated before it is allocated: the film and its layers
// from the flags (before the scene is read), then the scene as loaded and the accelerator's build.
// A render that will not fit is refused at once in one line naming the flags or the scene, the
// estimate and the limit (--max-memory-mib), instead of dying "out of memory" minutes in.
#pragma once

#include <cstdint>

#include "accel/accelerator.hpp"
#include "frontend/render_args.hpp"
#include "scene/scene.hpp"

namespace tracer::frontend {

// Per pixel, measured as the peak resident set of `tracer render --spp 1` at 4096 x 4096 less
// that at 64 x 64 (docs/RELIABILITY.md, "Memory"), rounded up: the film's sums and counts with
// the tone-mapped or EXR copy written at the end; adaptive sampling's half sums; each --aov layer
// with its EXR copy.
inline constexpr uint64_t kFilmBytesPerPixel = 26;
inline constexpr uint64_t kHalvesBytesPerPixel = 12;
inline constexpr uint64_t kLayerBytesPerPixel = 24;
// --denoise: the feature film (film/feature_film.hpp, 112 bytes) and the denoised copy, per
// pixel; the denoiser's planes are denoise::nfor_peak_bytes (padded: a thin image's are many
// times its pixels). Checked against the peak resident set of `tracer render --spp 1 --denoise`
// less that without, at 2048 x 2048 and at 1 x 16384 (docs/RELIABILITY.md, "Memory").
inline constexpr uint64_t kDenoiseBytesPerPixel = 136;

// The limit: --max-memory-mib, or the available memory less a margin (base/memory_limit.hpp).
uint64_t memory_limit(const SceneArgs& args);
// The film, its layers and adaptive sampling's buffers at the flags' size.
uint64_t film_bytes(const RenderArgs& args);
// Throws UsageError naming --width, --height and the layers when the film alone is above `limit`.
void check_film_fits(const RenderArgs& args, uint64_t limit);
// Throws InputError naming the scene when it, the accelerator `options` builds over it and the
// film are above `limit`.
void check_render_fits(const Scene& scene, const AccelOptions& options, const RenderArgs& args, uint64_t limit);

}  // namespace tracer::frontend
