#include "cli/bench_run.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <numeric>
#include <thread>

#include "accel/accelerator.hpp"
#include "render/render_image.hpp"
#include "scene/camera.hpp"

namespace tracer::cli {
namespace {

using Clock = std::chrono::steady_clock;

// Stops a render after `seconds` through the scheduler's cancel flag.
class Watchdog {
 public:
  Watchdog(std::atomic<bool>& flag, double seconds) : flag_(flag) {
    thread_ = std::thread([this, seconds] {
      std::unique_lock lock(m_);
      if (!cv_.wait_for(lock, std::chrono::duration<double>(seconds), [this] { return done_; })) flag_ = true;
    });
  }
  ~Watchdog() {
    {
      std::lock_guard lock(m_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }

 private:
  std::atomic<bool>& flag_;
  std::mutex m_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace

double kbest_mean(std::vector<double> v, int best) {
  std::sort(v.begin(), v.end());
  const size_t k = std::min<size_t>(size_t(best), v.size());
  return k ? std::accumulate(v.begin(), v.begin() + long(k), 0.0) / double(k) : 0.0;
}

Cell run_cell(const CellJob& job, const std::function<void(int)>& on_run) {
  const Variant& v = job.variant;
  Cell cell;
  cell.variant = v.name;
  cell.triangles = job.scene.instanced_size();
  std::vector<double> builds, renders;
  const auto cell_start = Clock::now();
  for (int run = 0; run < job.runs && !cell.timed_out; ++run) {
    // The cap bounds the whole cell: later runs are skipped once it is spent, and a run still
    // going at the cap is stopped (the cell times out only if no run finished).
    const double left = job.max_seconds - std::chrono::duration<double>(Clock::now() - cell_start).count();
    if (run > 0 && left <= 0) break;
    on_run(run);
    AccelOptions ao;
    ao.kind = v.accel;
    ao.quality = v.quality;
    ao.bvh.split = v.split;
    ao.bvh.strategy = v.build;
    ao.bvh.threads = job.threads;
    const Accelerator accel = build_accelerator(job.scene, ao);
    RenderSettings rs;
    rs.width = job.width;
    rs.height = job.height;
    rs.ao_samples = job.ao;
    rs.integrator = job.integrator;
    rs.spp = job.integrator == Integrator::Path ? job.spp : 1;
    rs.packets = v.packets && job.integrator == Integrator::Ao;
    rs.streams = rs.packets && v.streams;
    Framebuffer fb(job.width, job.height);
    PassContext ctx{&job.scene, Camera(job.camera, job.width, job.height), rs, &fb};
    ctx.samples = {0, uint32_t(rs.spp)};  // one pass: the timing has no pass overhead
    std::atomic<bool> stop{false};
    RenderMonitor control;
    control.cancel = &stop;
    SchedOptions so;
    so.strategy = v.sched;
    so.threads = job.threads;
    const auto t0 = Clock::now();
    bool finished;
    {
      Watchdog watchdog(stop, std::max(0.0, left - accel.build_ms / 1000.0));
      finished = render_image(accel, ctx, so, control);
    }
    const double render_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (!finished) {
      cell.timed_out = run == 0;
      break;
    }
    builds.push_back(accel.build_ms);
    renders.push_back(render_ms);
    cell.run_ms.push_back(accel.build_ms + render_ms);
    cell.rays = control.counts.load().total();
  }
  if (!cell.timed_out) {
    cell.build_ms = kbest_mean(builds, job.best);
    cell.render_ms = kbest_mean(renders, job.best);
    cell.total_ms = kbest_mean(cell.run_ms, job.best);
    cell.mrays = cell.render_ms > 0 ? double(cell.rays) / (cell.render_ms * 1e3) : 0;
  }
  return cell;
}

}  // namespace tracer::cli
