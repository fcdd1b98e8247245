#include "driver/render_driver.hpp"

#include <chrono>

#include "driver/output_checks.hpp"
#include "driver/render_args.hpp"
#include "driver/render_options.hpp"
#include "io/image_io.hpp"
#include "scene/camera.hpp"

namespace tracer::driver {

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
    if (options.holds_image) fb.emplace(settings.width, settings.height);
    if (fb && adaptive(settings)) fb->keep_halves();
    if (options.holds_image && seq.aovs.albedo) albedo.emplace(settings.width, settings.height);
    if (options.holds_image && seq.aovs.normal) normal.emplace(settings.width, settings.height);
    const Camera cam(frame_camera(camera, frame, seq.frames, seq.orbit_degrees), settings.width, settings.height);
    RenderContext ctx{&scene, cam, settings, fb ? &*fb : nullptr};
    ctx.albedo = albedo ? &*albedo : nullptr;
    ctx.normal = normal ? &*normal : nullptr;
    std::vector<ExrLayer> layers;
    if (albedo) layers.push_back({"albedo", &*albedo, {"R", "G", "B"}});
    if (normal) layers.push_back({"normal", &*normal, {"X", "Y", "Z"}});
    std::optional<Framebuffer> counts;
    if (fb && seq.aovs.samples) {
      counts.emplace(settings.width, settings.height);
      layers.push_back({"samples", &*counts, {"Y", nullptr, nullptr}});
    }
    const auto write = [&] {
      if (counts) {
        for (int y = 0; y < fb->height(); ++y) {
          for (int x = 0; x < fb->width(); ++x) counts->set(x, y, Vec3{float(fb->samples(x, y))});
        }
      }
      const size_t clamped = write_render(output, *fb, settings.exposure, seq.exr, layers);
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
          write();
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

}  // namespace tracer::driver
