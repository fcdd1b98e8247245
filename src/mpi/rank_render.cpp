#include "mpi/rank_render.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <thread>

#include "frontend/render_stats.hpp"
#include "frontend/signals.hpp"
#include "mpi/setup_agreement.hpp"
#include "parallel/parallel_pull.hpp"
#include "render/render_image.hpp"

namespace tracer::mpi {

namespace {

// Renders the passes of `round` of one tile, in order, into `fb` (rank 0's image, or a window for
// the tile) and, with --denoise, `features` (likewise).
RayCounts render_one(const Accelerator& accel, const PassContext& ctx, const std::vector<SampleRange>& round,
                     Framebuffer& fb, FeatureFilm* features, const Tile& tile) {
  PassContext c = ctx;
  c.framebuffer = &fb;
  c.features = features;
  RayCounts counts;
  for (const SampleRange& pass : round) {
    c.samples = pass;
    counts += render_tile_of(accel, c, tile).rays;
  }
  return counts;
}

std::string rank_list(const std::vector<int>& list) {
  std::string text;
  for (const int r : list) text += (text.empty() ? "" : ", ") + std::to_string(r);
  return text;
}

}  // namespace

RankRender::RankRender(const frontend::PreparedRender& setup, const frontend::RenderArgs& args,
                       const MpiSession& session, std::vector<uint64_t> threads, double rank_timeout,
                       PhaseWatch& watch_phase)
    : setup_(setup),
      args_(args),
      session_(session),
      threads_(std::move(threads)),
      my_threads_(int(threads_[size_t(session.rank())])),
      rank_timeout_(rank_timeout),
      watch_phase_(watch_phase),
      tiles_(tiles_for(setup.settings.width, setup.settings.height, setup.sched)),
      started_(Clock::now()),
      tiles_per_rank_(size_t(session.size()), 0) {
  watch_.floor_seconds = rank_timeout;
  if (session.root()) {
    progress_.emplace(!args.quiet, frontend::pixel_samples(setup.settings, args.frames), pixels_done_, rays_done_);
  }
}

void RankRender::count(const RayCounts& c, const Tile& t, uint32_t samples) {
  counts_.add(c);
  rays_done_.fetch_add(c.total(), std::memory_order_relaxed);
  pixels_done_.fetch_add(uint64_t(t.pixel_count()) * samples, std::memory_order_relaxed);
}

double RankRender::answer_bound() const { return 2.0 * std::max(rank_timeout_, 8.0 * slowest_tile_s_.load()); }

bool RankRender::render_round(const PassContext& ctx, const std::vector<SampleRange>& round) {
  ++round_serial_;
  const uint32_t samples = round.back().first + round.back().count - round.front().first;
  // Adaptive sampling (a round per pass then): every rank knows whether this pass decides which
  // pixels it samples; rank 0 decides from its image and sends each tile's part with the tile.
  const NoiseTarget target = noise_target(ctx.settings);
  const bool masks = target.threshold > 0.0f && round.front().first >= target.min_samples;
  if (session_.root()) {
    PassContext c = ctx;
    if (masks) {
      active_.update(*ctx.framebuffer, target, round.front().first);
      c.active = &active_;
    }
    serve_round(c, round, samples);
  } else {
    work_round(ctx, round, samples, masks);
  }
  return true;
}

void RankRender::serve_round(const PassContext& ctx, const std::vector<SampleRange>& round, uint32_t samples) {
  Framebuffer& fb = *ctx.framebuffer;
  TileServer server(tiles_, threads_, round_serial_, watch_, ctx.active);
  std::exception_ptr own_failure;
  std::thread own([&] {
    try {
      parallel_pull(
          my_threads_, [&] { return server.take(); },
          [&](const TileGrant& g) {
            const Tile& t = tiles_[g.tile];
            if (!g.reissued) {
              count(render_one(setup_.accel, ctx, round, fb, ctx.features, t), t, samples);
              server.own_done(g.tile);
              return;
            }
            // Taken back from a late rank: its copy may still come, so render apart.
            Framebuffer window(t);
            if (fb.has_halves()) window.keep_halves();
            std::optional<FeatureFilm> window_features;
            if (ctx.features) window_features.emplace(t);
            count(render_one(setup_.accel, ctx, round, window, window_features ? &*window_features : nullptr, t), t,
                  samples);
            server.commit(g.tile, window, fb, samples, window_features ? &*window_features : nullptr, ctx.features);
          });
    } catch (...) {
      own_failure = std::current_exception();
    }
  });
  try {
    server.serve(fb, samples, ctx.features);
  } catch (const RankFailed& e) {
    if (progress_) progress_->stop();
    say("tracer-mpi: error: rank " + std::to_string(e.rank) + " of " + std::to_string(session_.size()) + ": " +
        e.what() + "; no image written");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  own.join();
  if (own_failure) std::rethrow_exception(own_failure);  // main() reports it and aborts the job
  server_ms_ += server.busy_ms();
  served_ += server.messages();
  const std::vector<uint64_t> given = server.tiles_per_rank();
  for (size_t r = 0; r < given.size(); ++r) tiles_per_rank_[r] += given[r];
}

void RankRender::work_round(const PassContext& ctx, const std::vector<SampleRange>& round, uint32_t samples,
                            bool masks) {
  TileClient client(tiles_, round_serial_, masks);
  // Rank 0 answers a request at once, or, between rounds, once the round is in.
  watch_phase_.arm("tracer-mpi: error: rank " + std::to_string(session_.rank()) + " of " +
                       std::to_string(session_.size()) + ": rank 0 stopped answering (no answer within " +
                       std::to_string(int(answer_bound())) + " s); ending the job",
                   answer_bound());
  try {
    // Each thread renders its tiles into windows of its own and sends them back; its next
    // request is already in flight while it renders.
    std::atomic<int> thread_ids{0};
    parallel_run(my_threads_, [&] {
      TileClient::Worker worker(client, thread_ids.fetch_add(1));
      std::optional<uint32_t> finished;
      std::unique_ptr<Framebuffer> result;
      std::unique_ptr<FeatureFilm> features;  // --denoise: the tile's features, sent with its sums
      ActivePixels active;                    // this thread's tiles' blocks
      PassContext c = ctx;
      if (masks) c.active = &active;
      double idle = 0;
      while (const std::optional<uint32_t> next = worker.next(finished, result.get(), features.get(), idle)) {
        const Tile& t = tiles_[*next];
        result = std::make_unique<Framebuffer>(t);
        if (adaptive(ctx.settings)) result->keep_halves();
        if (args_.denoise) features = std::make_unique<FeatureFilm>(t);
        if (masks) active.set_window_blocks(ctx.settings.width, ctx.settings.height, t, worker.mask());
        const auto t0 = Clock::now();
        watch_phase_.hold();  // the time spent rendering is not time waiting for rank 0
        count(render_one(setup_.accel, c, round, *result, features.get(), t), t, samples);
        const double took = ms_since(t0) * 1e-3;
        for (double seen = slowest_tile_s_.load(); took > seen && !slowest_tile_s_.compare_exchange_weak(seen, took);) {
        }
        watch_phase_.release(answer_bound());
        finished = *next;
      }
      std::lock_guard lock(idle_mutex_);
      idle_ms_ += idle;
    });
  } catch (const std::exception& e) {
    TileClient::report_failure(e.what());
    for (;;) std::this_thread::sleep_for(std::chrono::seconds(1));  // rank 0 aborts the job
  }
}

void RankRender::report_late_ranks() {
  if (!session_.root()) return;
  if (!watch_.recovered.empty()) {
    say("tracer-mpi: warning: rank " + rank_list(watch_.recovered) + " of " + std::to_string(session_.size()) +
        " was late (a tile out for more than " + std::to_string(int(watch_.overdue_after())) +
        " s); its tiles were also rendered by others, the first copy kept");
  }
  if (!watch_.gone.empty()) {
    // The image is complete and written; the silent rank cannot join the statistics, so the
    // job ends here, with its runtime told to stop every rank.
    if (progress_) progress_->stop();
    say("tracer-mpi: error: rank " + rank_list(watch_.gone) + " of " + std::to_string(session_.size()) +
        " stopped answering (no tile back within " + std::to_string(int(watch_.overdue_after())) +
        " s); the other ranks rendered its tiles and the image was written; ending the job");
    frontend::install_immediate_stop_handlers(nullptr);  // the runtime's SIGTERM needs no second message
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
}

void RankRender::report_ranks(int checkpoints) {
  if (progress_) progress_->stop();
  const double render_ms = ms_since(started_);
  // Every rank answers once rank 0 has written the image.
  const double gather_bound = answer_bound() + 60.0;
  watch_phase_.arm("tracer-mpi: error: rank " + std::to_string(session_.rank()) + " of " +
                       std::to_string(session_.size()) + ": the ranks' statistics did not arrive within " +
                       std::to_string(int(gather_bound)) + " s (a rank stopped answering); ending the job",
                   gather_bound);
  const RayCounts own_counts = counts_.load();
  RayCounts total;
  for (const auto& [field, value] : {std::pair{&RayCounts::primary, own_counts.primary},
                                     {&RayCounts::shadow, own_counts.shadow},
                                     {&RayCounts::ao, own_counts.ao},
                                     {&RayCounts::secondary, own_counts.secondary}}) {
    for (uint64_t v : session_.all_gather(value)) total.*field += v;
  }
  const std::vector<uint64_t> rays = session_.all_gather(own_counts.total());
  const std::vector<uint64_t> idle_us = session_.all_gather(uint64_t(idle_ms_ * 1e3));
  const std::vector<uint64_t> render_us = session_.all_gather(uint64_t(render_ms * 1e3));
  watch_phase_.disarm();
  if (!session_.root()) return;
  const RenderSettings& settings = setup_.settings;
  nlohmann::json stats = frontend::render_stats(setup_.scene, settings, setup_.accel, setup_.sched, args_,
                                                setup_.load_ms, render_ms, total);
  uint64_t all_rays = 0;
  nlohmann::json ranks = nlohmann::json::array();
  for (int r = 0; r < session_.size(); ++r) {
    all_rays += rays[size_t(r)];
    ranks.push_back({{"rank", r},
                     {"threads", threads_[size_t(r)]},
                     {"tiles", tiles_per_rank_[size_t(r)]},
                     {"rays", rays[size_t(r)]},
                     {"idle_ms", double(idle_us[size_t(r)]) * 1e-3},
                     {"render_ms", double(render_us[size_t(r)]) * 1e-3}});
  }
  stats["ranks"] = ranks;
  stats["tiles_per_pass"] = tiles_.size();
  stats["passes"] = sample_passes(settings).size() * size_t(args_.frames);
  stats["rounds"] = round_serial_;  // rounds of tile distribution (one per pass with --checkpoint)
  stats["rays"]["total"] = all_rays;
  stats["mrays_per_s"] = render_ms > 0 ? double(all_rays) / (render_ms * 1e3) : 0.0;
  stats["checkpoints_written"] = checkpoints;
  stats["rank0_message_ms"] = server_ms_;
  stats["rank0_messages"] = served_;
  stats["rank0_us_per_message"] = served_ > 0 ? server_ms_ * 1e3 / double(served_) : 0.0;
  if (args_.stats) {
    frontend::print_stats(stats, setup_.accel);
    std::printf("rank 0       %.1f ms on %llu messages (%.1f us each)\n", server_ms_, (unsigned long long)served_,
                served_ > 0 ? server_ms_ * 1e3 / double(served_) : 0.0);
    for (const auto& r : ranks) {
      std::printf("rank %-6d %d threads, %llu tiles, %llu rays, idle %.1f ms\n", r["rank"].get<int>(),
                  r["threads"].get<int>(), (unsigned long long)r["tiles"].get<uint64_t>(),
                  (unsigned long long)r["rays"].get<uint64_t>(), r["idle_ms"].get<double>());
    }
  }
  frontend::write_stats_json(args_.stats_json, stats);
}

}  // namespace tracer::mpi
