#include "frontend/render_driver.hpp"

#include <chrono>

#include "denoise/nfor.hpp"
#include "frontend/output_checks.hpp"
#include "frontend/render_args.hpp"
#include "frontend/render_options.hpp"
#include "io/image_io.hpp"
#include "scene/camera.hpp"

namespace tracer::frontend {

std::vector<std::vector<SampleRange>> rounds_of(const RenderSettings& settings, bool round_per_pass) {
  const std::vector<SampleRange> passes = sample_passes(settings);
  if (!round_per_pass) return {passes};
  std::vector<std::vector<SampleRange>> rounds;
  for (const SampleRange& p : passes) rounds.push_back({p});
  return rounds;
}

DriveResult drive_render(const Scene& scene, const CameraSpec& camera, const RenderSettings& settings,
                         const FrameSequence& seq, const DriveOptions& options, const RenderRound& render_round,
                         const std::function<void(const std::string&)>& warn) {
  using Clock = std::chrono::steady_clock;
  DriveResult result;
  bool warned_black = false, warned_clamped = false;
  for (int frame = 0; frame < seq.frames; ++frame) {
    const std::string output = frame_output(seq.output, frame, seq.frames);
    std::optional<Framebuffer> fb, albedo, normal;
    std::optional<FeatureFilm> features;
    if (options.holds_image) fb.emplace(settings.width, settings.height);
    if (options.holds_image && seq.denoise) features.emplace(settings.width, settings.height);
    if (fb && adaptive(settings)) fb->keep_halves();
    if (options.holds_image && seq.aovs.albedo) albedo.emplace(settings.width, settings.height);
    if (options.holds_image && seq.aovs.normal) normal.emplace(settings.width, settings.height);
    const Camera cam(frame_camera(camera, frame, seq.frames, seq.orbit_degrees), settings.width, settings.height);
    PassContext ctx{&scene, cam, settings, fb ? &*fb : nullptr};
    ctx.albedo = albedo ? &*albedo : nullptr;
    ctx.normal = normal ? &*normal : nullptr;
    ctx.features = features ? &*features : nullptr;
    std::vector<ExrLayer> layers;
    if (albedo) layers.push_back({"albedo", &*albedo, {"R", "G", "B"}});
    if (normal) layers.push_back({"normal", &*normal, {"X", "Y", "Z"}});
    std::optional<Framebuffer> counts;
    if (fb && seq.aovs.samples) {
      counts.emplace(settings.width, settings.height);
      layers.push_back({"samples", &*counts, {"Y", nullptr, nullptr}});
    }
    std::optional<Framebuffer> denoised, variance;
    if (features) {
      denoised.emplace(settings.width, settings.height);
      if (seq.aovs.noisy) layers.push_back({"noisy", &*fb, {"R", "G", "B"}});
      if (seq.aovs.variance) {
        variance.emplace(settings.width, settings.height);
        layers.push_back({"variance", &*variance, {"R", "G", "B"}});
      }
    }
    // `final_image`: a whole pass or more; a stop's partial image is written as it is.
    const auto write = [&](bool final_image = true) {
      if (counts) {
        for (int y = 0; y < fb->height(); ++y) {
          for (int x = 0; x < fb->width(); ++x) counts->set(x, y, Vec3{float(fb->samples(x, y))});
        }
      }
      // --denoise: the denoised image, unless the write is a stop's partial one or a stop comes
      // while denoising; then the noisy image, and the stop says so (every sample was taken).
      const Framebuffer* image = &*fb;
      result.not_denoised = features.has_value();
      if (features && final_image) {
        const auto start = Clock::now();
        try {
          const std::vector<Vec3> d =
              denoise::nfor(*features, *options.denoiser, options.cancel, {.simd = seq.denoise_simd});
          for (int y = 0; y < fb->height(); ++y) {
            for (int x = 0; x < fb->width(); ++x) denoised->set(x, y, d[size_t(y) * size_t(fb->width()) + size_t(x)]);
          }
          if (variance) {
            for (int y = 0; y < fb->height(); ++y) {
              for (int x = 0; x < fb->width(); ++x) variance->set(x, y, features->variance_of_mean(x, y));
            }
          }
          image = &*denoised;
          result.not_denoised = false;
        } catch (const Cancelled&) {  // written noisy, below
        }
        result.denoise_ms += std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      }
      const size_t clamped = write_render(output, *image, settings.exposure, seq.exr, layers);
      if (clamped > 0 && !warned_clamped) {
        warn(output + ": " + std::to_string(clamped) + " pixel values beyond the " +
             (seq.exr == ExrPixel::Half ? "half EXR's range (65504; --exr float holds up to 3.4e38)"
                                        : "float EXR's range") +
             " or not finite, written as its largest value");
        warned_clamped = true;
      }
    };
    auto last_write = Clock::now();
    uint32_t done = 0;
    for (const std::vector<SampleRange>& round : rounds_of(settings, options.round_per_pass)) {
      if (!render_round(ctx, round)) {
        result.stopped = true;
        result.output = output;
        if (!fb) return result;
        // A path render stopped after its first pass is a complete image, only noisier.
        // --save-partial: unfinished tiles black, if any tile finished at all.
        // (With adaptive sampling the passes finished: pixels that stopped earlier hold fewer.)
        result.samples = adaptive(settings) ? done : fb->min_samples();
        if (result.samples > 0 || (seq.save_partial && fb->max_samples() > 0)) {
          write(/*final_image=*/false);
          result.wrote_partial = true;
        }
        return result;
      }
      done = round.back().first + round.back().count;
      const bool checkpoint_due =
          seq.checkpoint_seconds && done < uint32_t(settings.spp) &&
          std::chrono::duration<double>(Clock::now() - last_write).count() >= *seq.checkpoint_seconds;
      if (fb && checkpoint_due) {
        write();
        ++result.checkpoints;
        last_write = Clock::now();
      }
    }
    if (!fb) continue;
    write();
    if (!warned_black && looks_black(*fb, settings.exposure)) {
      warn(output + ": " + black_image_warning(settings, scene));
      warned_black = true;
    }
    if (is_cancelled(options.cancel)) {  // arrived during the write, which is never torn
      result.stopped = result.stopped_after_write = true;
      result.output = output;
      return result;
    }
  }
  return result;
}

}  // namespace tracer::frontend
