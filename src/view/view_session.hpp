// The viewer's renderer: one scene and accelerator, built once, and a view state (camera, integrator,
// samples, depth, exposure, size) that requests change. A thread renders the state as `tracer
// render` would (the same flags turned into the same camera and settings, the same passes of
// render_image) into a display image that refines pass by pass and tile by tile, and publishes
// frames. A change interrupts the pass in progress within a piece of a tile; while the full image
// would be slow, a reduced-resolution preview of the new state comes first.
#pragma once

#include <nlohmann/json_fwd.hpp>

#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "film/feature_film.hpp"
#include "film/tone_map.hpp"
#include "frontend/render_args.hpp"
#include "parallel/executor.hpp"
#include "view/frame_store.hpp"
#include "view/view_state.hpp"

namespace tracer::view {

class ViewSession {
 public:
  // `args`: the view command's flags (the state starts from them; the copied command says what
  // differs from a default render). The scene and accelerator must outlive the session.
  ViewSession(const Scene& scene, const Accelerator& accel, const frontend::RenderArgs& args);
  ~ViewSession();
  ViewSession(const ViewSession&) = delete;
  ViewSession& operator=(const ViewSession&) = delete;

  void start();
  // Interrupts the render and joins its thread; frames() is closed. Idempotent.
  void stop();

  // Applies a change: a JSON object of the settings table's viewer fields (eye, look, up as
  // [x, y, z], fov, aperture, focus_distance, integrator, spp, max_depth, exposure, width, height),
  // focus_at ([x, y]: focus on the surface at that pixel) and denoise (true or false: path tracing's image denoised
  // once the camera rests; on by default). Throws UsageError naming the field for an unknown field,
  // a wrong type or a bad value; then nothing changes. Returns the new state.
  nlohmann::json apply(const nlohmann::json& change);
  // The state: the fields above, "generation" (counts changes that restart the accumulation),
  // "command" (the render command of this state) and the scene's facts.
  nlohmann::json state() const;

  FrameStore& frames() { return frames_; }

  // The accumulated image as it is now (every finished tile of every finished pass), tone-mapped
  // or as radiance; nullopt before the first pass of the current state has finished.
  struct Snapshot {
    Image8 image;
    Framebuffer radiance{1, 1};
    uint32_t spp = 0;
  };
  std::optional<Snapshot> snapshot() const;

 private:
  struct Job {
    uint64_t generation = 0;
    CameraSpec camera;
    RenderSettings settings;
    bool in_motion = false;  // came soon after the change before it
    // The first state of a chain that changed only the samples per pixel: its film may go on.
    uint64_t film_base = 0;
    bool denoise = false;  // path tracing with the toggle on
  };
  void render_loop();
  bool render_job(const Job& job);
  // Renders and publishes the preview of a new state, unless the full image is quick enough
  // (`skipped`); false if stopped or changed meanwhile.
  bool render_preview(const Job& job, bool& skipped);
  void measured_cost(Integrator integrator, double seconds, uint64_t samples);
  // After a finished pass of a denoised state: denoises the film into the display when the pass
  // is the last or the denoiser has been idle twice as long as it last took; false if a change
  // interrupted it.
  bool denoise_display(const Job& job, bool last_pass);
  // Encodes the display and publishes it (`force`: now, else at most every progress interval);
  // call without display_mu_ held.
  void publish_display(bool force);
  void publish_image(Image8 image, std::shared_ptr<Frame> meta, bool lossless);
  void publish_locked(Image8 image, std::shared_ptr<Frame> meta, bool lossless);  // publish_mu_ held
  nlohmann::json state_locked() const;

  const Scene& scene_;
  // The distance along the view of the surface seen at image position `pixel` (a click that
  // sets the focus): nothing where the ray leaves the scene; UsageError off the image.
  std::optional<float> focus_distance_at(const frontend::RenderArgs& a, Vec2 pixel) const;
  const Accelerator& accel_;
  const SchedOptions sched_;

  // The state, guarded by mu_; a change bumps generation_ and sets interrupt_ under it.
  mutable std::mutex mu_;
  std::condition_variable cv_;
  frontend::RenderArgs args_;
  // The flags as launched: a switch of integrator takes those of the new one from here.
  const frontend::RenderArgs launched_;
  bool denoise_ = true;  // the page's toggle; applies to path tracing only
  Job job_;
  uint64_t generation_ = 1;
  std::chrono::steady_clock::time_point last_change_{};
  std::atomic<bool> interrupt_{false};  // ends the pass in progress: a change, or stop()
  std::atomic<bool> stop_{false};       // set once, by stop(); ends previews too

  // The display: what the page sees of the accumulation, guarded by display_mu_.
  mutable std::mutex display_mu_;
  std::optional<Framebuffer> display_;  // copied from the render's film as tiles finish
  Image8 display_image_;
  float exposure_ = 1.0f;
  uint64_t display_generation_ = 0;
  uint32_t display_spp_ = 0, display_target_ = 0;
  double pass_fraction_ = 0.0, last_pass_ms_ = 0.0;
  double accum_seconds_ = 0.0;  // rendering time of the state's accumulation so far
  uint64_t accum_samples_ = 0, accum_rays_ = 0;

  std::mutex publish_mu_;  // one publication at a time; progress frames skip when busy
  std::chrono::steady_clock::time_point last_publish_{};

  // The render thread's film: the state chain it belongs to and the samples per pixel it holds.
  std::optional<Framebuffer> film_;
  std::optional<FeatureFilm> features_;  // beside film_ for a denoised state
  uint64_t film_base_ = 0;
  uint32_t film_done_ = 0;
  Executor denoiser_;
  double denoise_ms_ = 0.0;  // the last denoising's time
  std::chrono::steady_clock::time_point denoised_at_{};
  bool display_denoised_ = false;        // the display holds a denoised image (guarded by display_mu_)
  bool display_awaits_denoise_ = false;  // a denoised state's noisy first pass: not its final frame

  // Nanoseconds per pixel sample of each integrator, measured: sizes the preview.
  std::array<double, 3> ns_per_sample_{0.0, 0.0, 0.0};

  FrameStore frames_;
  std::thread thread_;
};

}  // namespace tracer::view
