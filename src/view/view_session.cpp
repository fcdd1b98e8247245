#include "view/view_session.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "base/errors.hpp"
#include "base/stopwatch.hpp"
#include "frontend/render_options.hpp"
#include "frontend/scene_setup.hpp"
#include "frontend/settings_table.hpp"
#include "io/image_io.hpp"
#include "render/render_image.hpp"

namespace tracer::view {

namespace {

// A preview is sized to render within this; the full image follows it.
constexpr double kPreviewBudgetMs = 30.0;
// Changes closer together than this are a camera in motion: after its preview the renderer waits
// up to kMotionPause for the next change before starting the full image, leaving the cores to the
// browser (on the same machine, it decodes and draws the frames) rather than to a pass the next
// move would interrupt.
constexpr auto kMotionInterval = std::chrono::milliseconds(150);
constexpr auto kMotionPause = std::chrono::milliseconds(100);
double seconds_since(Clock::time_point t) { return ms_since(t) * 1e-3; }

// Whether a state's image is denoised: the toggle on (for path tracing) and the image within
// kMaxDenoisedPixels, whose denoiser planes take 2.8 GB (docs/VIEW.md).
constexpr int64_t kMaxDenoisedPixels = 2048 * 2048;
bool denoised(const frontend::RenderArgs& a) {
  return a.denoise && int64_t(a.settings.width) * int64_t(a.settings.height) <= kMaxDenoisedPixels;
}

}  // namespace

ViewSession::ViewSession(const Scene& scene, const Accelerator& accel, const frontend::RenderArgs& args)
    : scene_(scene),
      accel_(accel),
      sched_(frontend::sched_options_for(args)),
      args_(args),
      launched_(args),
      denoiser_(sched_.strategy, sched_.threads) {
  args_.denoise = denoise_ && args_.integrator == Integrator::Path;
  // Every state flag explicit, so the copied command says exactly what is shown; the job's camera
  // and settings are then derived from those explicit flags, as the command's will be.
  const CameraSpec camera = frontend::camera_for(scene_, args_);
  args_.eye = camera.eye;
  args_.look = camera.look;
  args_.up = camera.up;
  args_.fov = camera.fov_degrees;
  std::string note;
  const RenderSettings settings = frontend::settings_for(args_, scene_, note);
  args_.spp = settings.spp;
  job_ = {generation_,
          frontend::camera_for(scene_, args_),
          frontend::settings_for(args_, scene_, note),
          false,
          generation_,
          denoised(args_)};
  exposure_ = settings.exposure;
}

ViewSession::~ViewSession() { stop(); }

void ViewSession::start() {
  thread_ = std::thread([this] { render_loop(); });
}

void ViewSession::stop() {
  {
    const std::lock_guard lock(mu_);
    interrupt_.store(true);
    stop_.store(true);
  }
  cv_.notify_all();
  if (thread_.joinable()) thread_.join();
  frames_.close();
}

nlohmann::json ViewSession::apply(const nlohmann::json& change) {
  nlohmann::json result;
  bool exposure_changed = false;
  float exposure = 0.0f;
  {
    const std::lock_guard lock(mu_);
    StateFields fields{args_, denoise_, std::nullopt};
    read_change(change, fields, launched_);
    frontend::RenderArgs& a = fields.args;
    const bool denoise = fields.denoise;
    const std::optional<Vec2>& focus_at = fields.focus_at;
    // The toggle is path tracing's: another integrator renders without it, and a switch back
    // takes it again.
    a.denoise = denoise && a.integrator == Integrator::Path;
    // The same checks and the same derivation as `tracer render`'s (camera_for rejects a camera
    // looking at its own position or along its up vector).
    frontend::validate(a);
    std::string note;
    if (focus_at) {
      if (const std::optional<float> d = focus_distance_at(a, *focus_at)) {
        a.focus_distance = double(*d);
      } else {
        note = "nothing there to focus on: the focus stays";
      }
    }
    const CameraSpec camera = frontend::camera_for(scene_, a);
    std::string settings_note;
    const RenderSettings settings = frontend::settings_for(a, scene_, settings_note);
    exposure_changed = settings.exposure != job_.settings.exposure;
    exposure = settings.exposure;
    // The image's flags but the samples and the exposure (a film goes on with more samples; the
    // exposure tone-maps it) unchanged; adaptive sampling measures noise at the exposure, though,
    // so another one stops other pixels.
    const bool same_view = frontend::same_settings(a, args_, {frontend::Role::Image}, {"--spp", "--exposure"}) &&
                           (!adaptive(settings) || settings.exposure == job_.settings.exposure);
    const bool restart = !same_view || a.spp != args_.spp;
    const bool raised = same_view && *a.spp > *args_.spp;
    args_ = a;
    denoise_ = denoise;
    job_.settings.exposure = settings.exposure;
    if (restart) {
      const auto now = Clock::now();
      // Only the target changed: the new state may go on from the film (render_job says when).
      const uint64_t film_base = same_view ? job_.film_base : generation_ + 1;
      // A raised target lets the pass in progress finish, to go on from it.
      if (!raised) interrupt_.store(true);
      job_ = {++generation_, camera, settings, now - last_change_ < kMotionInterval, film_base, denoised(a)};
      last_change_ = now;
    }
    result = state_locked();
    if (!note.empty()) result["note"] = note;
  }
  cv_.notify_all();
  if (exposure_changed) {
    {
      const std::lock_guard lock(display_mu_);
      exposure_ = exposure;
      if (display_) display_image_ = tonemap(*display_, exposure_);
    }
    publish_display(true);
  }
  return result;
}

std::optional<float> ViewSession::focus_distance_at(const frontend::RenderArgs& a, Vec2 pixel) const {
  const int w = a.settings.width, h = a.settings.height;
  if (!(pixel.x >= 0.0f && pixel.x <= float(w) && pixel.y >= 0.0f && pixel.y <= float(h))) {
    throw UsageError("focus_at: " + std::to_string(pixel.x) + "," + std::to_string(pixel.y) + " lies outside the " +
                     std::to_string(w) + "x" + std::to_string(h) + " image");
  }
  const Camera camera(frontend::camera_for(scene_, a), w, h);
  Ray ray = camera.ray_through(pixel.x, pixel.y);
  Hit hit;
  const bool found = accel_.visit([&](const auto& accel) { return accel.intersect(ray, hit); });
  if (!found) return std::nullopt;
  return hit.t * dot(ray.dir, camera.forward());
}

nlohmann::json ViewSession::state() const {
  const std::lock_guard lock(mu_);
  return state_locked();
}

nlohmann::json ViewSession::state_locked() const {
  const CameraSpec& c = job_.camera;
  nlohmann::json state = state_fields(args_);
  // The camera as rendered, the lens as the command gives it, the focus as it falls.
  state["eye"] = vec_json(c.eye);
  state["look"] = vec_json(c.look);
  state["up"] = vec_json(c.up);
  state["fov"] = c.fov_degrees;
  state["aperture"] = args_.aperture.value_or(0.0);
  state["focus_distance"] = Camera(c, args_.settings.width, args_.settings.height).focus_distance();
  state["generation"] = generation_;
  state["denoise"] = denoise_;
  state["max_side"] = kMaxViewSide;
  state["command"] = frontend::render_command(args_);
  state["scene"] = scene_.source;
  state["triangles"] = scene_.size();
  state["scene_size"] = length(scene_.bounds.extent());
  state["accel"] = std::string(name_of<AccelKind>(kAccelKindNames, accel_.kind));
  return state;
}

std::optional<ViewSession::Snapshot> ViewSession::snapshot() const {
  uint64_t generation = 0;
  {
    const std::lock_guard lock(mu_);
    generation = generation_;
  }
  const std::lock_guard lock(display_mu_);
  if (!display_ || display_generation_ != generation) return std::nullopt;
  return Snapshot{display_image_, *display_, display_spp_};
}

void ViewSession::measured_cost(Integrator integrator, double seconds, uint64_t samples) {
  if (samples == 0) return;  // interrupted before any piece finished: says nothing
  double& ns = ns_per_sample_[size_t(integrator)];
  const double now = seconds * 1e9 / double(samples);
  // Up at once, down gently: a preview too small for a moment beats a frame that comes late.
  ns = now >= ns ? now : 0.5 * (ns + now);
}

void ViewSession::render_loop() {
  uint64_t finished = 0;  // the generation whose accumulation is complete
  while (true) {
    Job job;
    {
      std::unique_lock lock(mu_);
      cv_.wait(lock, [&] { return stop_.load() || job_.generation != finished; });
      if (stop_.load()) return;
      job = job_;
      interrupt_.store(false);
    }
    if (render_job(job)) finished = job.generation;
  }
}

bool ViewSession::render_preview(const Job& job, bool& skipped) {
  skipped = false;
  const RenderSettings& s = job.settings;
  const double ns = ns_per_sample_[size_t(s.integrator)];
  const double full_ms = ns * double(s.width) * double(s.height) * 1e-6;
  // Unmeasured: a quarter of each side; then whatever fits the budget, or no preview at all.
  const int scale = ns == 0.0 ? 4 : std::min(16, int(std::ceil(std::sqrt(full_ms / kPreviewBudgetMs))));
  if (scale <= 1) {
    skipped = true;
    return true;
  }
  Job small = job;
  small.settings.width = std::max(1, (s.width + scale - 1) / scale);
  small.settings.height = std::max(1, (s.height + scale - 1) / scale);
  small.settings.spp = 1;
  Framebuffer fb(small.settings.width, small.settings.height);
  PassContext ctx{&scene_, Camera(job.camera, small.settings.width, small.settings.height), small.settings, &fb};
  ctx.samples = {0, 1};
  // Only a stop ends a preview: it is short, and interrupting it for the next move's would leave
  // a fast-moving camera with no frame at all.
  RenderMonitor control;
  control.cancel = &stop_;
  const auto t0 = Clock::now();
  if (!render_image(accel_, ctx, sched_, control)) return false;
  const double seconds = seconds_since(t0);
  measured_cost(s.integrator, seconds, fb.pixel_count());
  auto meta = std::make_shared<Frame>();
  meta->generation = job.generation;
  meta->spp_target = uint32_t(s.spp);
  meta->preview = true;
  meta->frame_ms = seconds * 1e3;
  meta->msamples_per_s = double(fb.pixel_count()) / seconds * 1e-6;
  meta->mrays_per_s = double(control.rays_done.load()) / seconds * 1e-6;
  Image8 image;
  {
    const std::lock_guard lock(display_mu_);
    image = tonemap(fb, exposure_);
  }
  publish_image(std::move(image), std::move(meta), false);
  return !interrupt_.load();
}

bool ViewSession::render_job(const Job& job) {
  const RenderSettings& s = job.settings;
  const std::vector<SampleRange> passes = sample_passes(s);
  // A state that only raised the samples per pixel of the film's goes on from the film's last
  // pass, when the new schedule has a pass boundary there (so the image stays tracer render's).
  size_t first_pass = 0;
  if (film_ && film_base_ == job.film_base) {
    for (size_t p = 0; p < passes.size(); ++p) {
      if (passes[p].first + passes[p].count == film_done_) first_pass = p + 1;
    }
  }
  bool no_preview = first_pass > 0;
  if (first_pass == 0) {
    if (!render_preview(job, no_preview)) return false;
    if (job.in_motion) {
      std::unique_lock lock(mu_);
      if (cv_.wait_for(lock, kMotionPause, [&] { return stop_.load() || job_.generation != job.generation; })) {
        return false;
      }
    }
    film_.emplace(s.width, s.height);
    if (adaptive(s)) film_->keep_halves();
    if (job.denoise) {
      features_.emplace(s.width, s.height);
    } else {
      features_.reset();
    }
    film_done_ = 0;
  } else {
    const std::lock_guard lock(display_mu_);
    display_generation_ = job.generation;
    display_target_ = uint32_t(s.spp);
  }
  film_base_ = job.film_base;
  Framebuffer& fb = *film_;
  PassContext ctx{&scene_, Camera(job.camera, s.width, s.height), s, &fb};
  ctx.features = job.denoise ? &*features_ : nullptr;
  RenderMonitor control;
  const size_t tile_count = tiles_for(s.width, s.height, sched_).size();
  const auto t_start = Clock::now();
  size_t tiles_done = 0;
  for (size_t p = first_pass; p < passes.size(); ++p) {
    ctx.samples = passes[p];
    tiles_done = 0;
    // After the first pass, each finished tile refines the display at once (but for a denoised
    // state, whose display changes only by whole denoised passes); the first pass is shown whole
    // (the preview stands in for it meanwhile).
    control.on_tile = nullptr;
    if (p > 0 && !job.denoise) {
      control.on_tile = [&](const Tile& tile) {
        {
          const std::lock_guard lock(display_mu_);
          display_->copy_tile(fb, tile);
          tonemap_tile(*display_, exposure_, tile, display_image_);
          pass_fraction_ = double(++tiles_done) / double(tile_count);
        }
        publish_display(false);
      };
    }
    // A first pass quick enough to stand for the preview is not interrupted either.
    control.cancel = p == 0 && no_preview ? &stop_ : &interrupt_;
    const auto t_pass = Clock::now();
    const uint64_t samples_before = control.pixels_done.load();
    const bool finished = render_image(accel_, ctx, sched_, control);
    const double pass_seconds = seconds_since(t_pass);
    // An interrupted pass counts too: a camera that turned from the sky to the scene must not keep
    // the sky's cost, or every move would start a full image and be interrupted before a frame.
    measured_cost(s.integrator, pass_seconds, control.pixels_done.load() - samples_before);
    if (!finished) {
      film_.reset();  // part of a pass: no state can go on from it
      return false;
    }
    film_done_ = ctx.samples.first + ctx.samples.count;
    {
      const std::lock_guard lock(display_mu_);
      if (p == 0) {
        display_ = fb;
        display_image_ = tonemap(fb, exposure_);
        display_generation_ = job.generation;
        display_target_ = uint32_t(s.spp);
        display_denoised_ = false;
        display_awaits_denoise_ = job.denoise;
      }
      if (!display_denoised_) display_spp_ = film_done_;
      pass_fraction_ = 0.0;
      last_pass_ms_ = pass_seconds * 1e3;
      accum_seconds_ = seconds_since(t_start);
      accum_samples_ = control.counts.load().primary;  // samples taken: adaptive sampling skips some pixels
      accum_rays_ = control.rays_done.load();
    }
    if (p == 0 || !job.denoise) publish_display(true);
    // The camera rests here: a move in progress would have interrupted the pass (or, in motion,
    // the pause before the full image).
    if (job.denoise && !denoise_display(job, p + 1 == passes.size())) return false;
  }
  if (first_pass == passes.size()) {
    // The film already holds them all. A denoised state whose film's denoise a change
    // interrupted (the spp lowered to a pass boundary during it) denoises it now: the frame
    // shown so far is the noisy film, not this state's image.
    bool awaits_denoise = false;
    {
      const std::lock_guard lock(display_mu_);
      awaits_denoise = display_awaits_denoise_;
    }
    if (job.denoise && awaits_denoise) return denoise_display(job, true);
    publish_display(true);
  }
  return true;
}

}  // namespace tracer::view
