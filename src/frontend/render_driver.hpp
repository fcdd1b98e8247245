// The one render driver both binaries call: the frames of --frames (the camera orbiting), the
// passes of each frame (grouped in rounds), checkpoints between them, the final write of every
// frame with its black-image warning, and what a stop leaves. How a round of passes is rendered
// is the caller's: tile loops on this machine, or tiles handed out to the ranks of an MPI job.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "base/errors.hpp"
#include "io/exr_io.hpp"
#include "parallel/executor.hpp"
#include "render/render_image.hpp"
#include "scene/scene.hpp"

namespace tracer::frontend {

// The --aov layers: first-hit albedo and shading normal; each pixel's sample count (where
// adaptive sampling stopped); with --denoise, the image before denoising and the variance of
// each pixel's mean.
struct Aovs {
  bool albedo = false, normal = false, samples = false, noisy = false, variance = false;
};

struct FrameSequence {
  std::string output;  // one frame: this name; N frames: NAME-0000.EXT ... (frame_output)
  int frames = 1;
  double orbit_degrees = 0.0;
  std::optional<double> checkpoint_seconds;  // rewrite the output this often while passes add up
  ExrPixel exr = ExrPixel::Half;
  bool save_partial = false;                   // on a stop, write finished tiles of a frame with no complete pass
  Aovs aovs;                                   // --aov: layers written into the EXR beside the radiance
  bool denoise = false;                        // --denoise: every image written is denoise::nfor's of the film
  SimdTarget denoise_simd = SimdTarget::Auto;  // the widest target the denoiser's kernels may use
};

// Renders the passes of `round` of the frame `ctx` describes into ctx.framebuffer (null on a rank
// that holds no image); false when stopped before the round finished.
using RenderRound = std::function<bool(const PassContext& ctx, const std::vector<SampleRange>& round)>;

struct DriveResult {
  int checkpoints = 0;
  // Stopped (the cancel flag): the frame's output, the samples per pixel it got, and whether an
  // image was written (complete passes, or --save-partial's finished tiles).
  bool stopped = false;
  bool stopped_after_write = false;  // the stop came during a frame's final write
  std::string output;
  uint32_t samples = 0;
  bool wrote_partial = false;
  double denoise_ms = 0.0;    // --denoise: time spent denoising, every write included
  bool not_denoised = false;  // --denoise: the last image written is the noisy one (a stop came first)
};

// How this process takes part in a render.
struct DriveOptions {
  bool holds_image = true;     // keeps the image and writes it (false on the worker ranks of an MPI job)
  bool round_per_pass = true;  // each pass a round of its own (checkpoints, Ctrl-C after the first
                               // pass), else one round of every pass
  CancelFlag cancel = nullptr;
  const Executor* denoiser = nullptr;  // runs the denoiser (needed with FrameSequence::denoise)
};

// Drives every frame. `warn` receives one-line warnings.
DriveResult drive_render(const Scene& scene, const CameraSpec& camera, const RenderSettings& settings,
                         const FrameSequence& frames, const DriveOptions& options, const RenderRound& render_round,
                         const std::function<void(const std::string&)>& warn);

// The rounds of passes of a frame (sample_passes, grouped as drive_render says).
std::vector<std::vector<SampleRange>> rounds_of(const RenderSettings& settings, bool round_per_pass);

}  // namespace tracer::frontend
