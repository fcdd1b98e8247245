// What the viewer shows: the display image (denoised when the state asks for it), tone-mapped,
// encoded and published as the newest frame for every event stream.
#include <vector>

#include "base/stopwatch.hpp"
#include "denoise/nfor.hpp"
#include "io/image_io.hpp"
#include "view/view_session.hpp"

namespace tracer::view {

namespace {

// Frames of a pass in progress (tiles refined so far) come at most this often.
constexpr auto kProgressInterval = std::chrono::milliseconds(200);
constexpr int kJpegQuality = 88;

}  // namespace

bool ViewSession::denoise_display(const Job& job, bool last_pass) {
  // At most a third of the time goes to denoising; the last pass's image always is.
  if (!last_pass && display_denoised_ && ms_since(denoised_at_) * 1e-3 < 2e-3 * denoise_ms_) return true;
  const auto t0 = Clock::now();
  std::vector<Vec3> image;
  try {
    image = denoise::nfor(*features_, denoiser_, &interrupt_,
                          {.simd = launched_.simd_target});  // a change stops it within a tile
  } catch (const Cancelled&) {
    return false;
  }
  denoise_ms_ = ms_since(t0);
  denoised_at_ = Clock::now();
  {
    const std::lock_guard lock(display_mu_);
    if (display_generation_ != job.generation || !display_) return true;
    const int w = display_->width();
    for (int y = 0; y < display_->height(); ++y) {
      for (int x = 0; x < w; ++x) display_->set(x, y, image[size_t(y) * size_t(w) + size_t(x)]);
    }
    display_image_ = tonemap(*display_, exposure_);
    display_spp_ = film_done_;
    display_denoised_ = true;
    display_awaits_denoise_ = false;
  }
  publish_display(true);
  return true;
}

void ViewSession::publish_display(bool force) {
  std::unique_lock publish(publish_mu_, std::defer_lock);
  if (force) {
    publish.lock();
  } else if (Clock::now() - last_publish_ < kProgressInterval || !publish.try_lock()) {
    return;
  }
  auto meta = std::make_shared<Frame>();
  Image8 image;
  {
    const std::lock_guard lock(display_mu_);
    if (!display_) return;
    image = display_image_;
    meta->generation = display_generation_;
    meta->spp = display_spp_;
    meta->spp_target = display_target_;
    meta->pass_fraction = pass_fraction_;
    meta->complete = display_spp_ >= display_target_ && pass_fraction_ == 0.0 && !display_awaits_denoise_;
    meta->denoised = display_denoised_;
    meta->frame_ms = last_pass_ms_;
    if (accum_seconds_ > 0.0) {
      meta->msamples_per_s = double(accum_samples_) / accum_seconds_ * 1e-6;
      meta->mrays_per_s = double(accum_rays_) / accum_seconds_ * 1e-6;
    }
  }
  const bool lossless = meta->complete;
  publish_locked(std::move(image), std::move(meta), lossless);
}

void ViewSession::publish_image(Image8 image, std::shared_ptr<Frame> meta, bool lossless) {
  const std::lock_guard publish(publish_mu_);
  publish_locked(std::move(image), std::move(meta), lossless);
}

void ViewSession::publish_locked(Image8 image, std::shared_ptr<Frame> meta, bool lossless) {
  meta->width = image.width;
  meta->height = image.height;
  // The finished image exactly (PNG: what `tracer render` writes); JPEG while it refines.
  meta->mime = lossless ? "image/png" : "image/jpeg";
  meta->bytes = lossless ? encode_png(image) : encode_jpeg(image, kJpegQuality);
  frames_.publish(std::move(meta));
  last_publish_ = Clock::now();
}

}  // namespace tracer::view
