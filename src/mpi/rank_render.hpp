// One rank's part of a tracer-mpi render: rank 0 serves each round's tiles (and renders some with
// its own threads), the others work them; then the late ranks are named and every rank's
// statistics gathered on rank 0.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "base/stopwatch.hpp"

#include "frontend/prepare_render.hpp"
#include "frontend/progress.hpp"
#include "mpi/mpi_session.hpp"
#include "mpi/phase_watch.hpp"
#include "mpi/tile_server.hpp"

namespace tracer::mpi {

class RankRender {
 public:
  // `threads`: every rank's render threads (agree_on_setup); `rank_timeout`: --rank-timeout.
  RankRender(const frontend::PreparedRender& setup, const frontend::RenderArgs& args, const MpiSession& session,
             std::vector<uint64_t> threads, double rank_timeout, PhaseWatch& watch_phase);

  // One round of tile distribution of the frame `ctx` (frontend::rounds_of): with --checkpoint one
  // pass, else every pass, each tile rendered whole and sent back once.
  bool render_round(const PassContext& ctx, const std::vector<SampleRange>& round);
  // Rank 0, after the last frame: names the ranks that were late, and ends the job (the image
  // written) if one stopped answering.
  void report_late_ranks();
  // Collective: every rank's tiles, rays and idle time on rank 0, which prints and writes the
  // statistics. `checkpoints`: the checkpoints written.
  void report_ranks(int checkpoints);

 private:
  void serve_round(const PassContext& ctx, const std::vector<SampleRange>& round, uint32_t samples);
  // `masks`: rank 0 sends the blocks of adaptive sampling's active pixels with each tile.
  void work_round(const PassContext& ctx, const std::vector<SampleRange>& round, uint32_t samples, bool masks);
  void count(const RayCounts& c, const Tile& t, uint32_t samples);
  // How long a worker waits on rank 0 before taking it for stopped: twice the time rank 0 gives a
  // late rank (overdue_after()) and the rendering of that rank's tiles.
  double answer_bound() const;

  const frontend::PreparedRender& setup_;
  const frontend::RenderArgs& args_;
  const MpiSession& session_;
  const std::vector<uint64_t> threads_;
  const int my_threads_;
  const double rank_timeout_;
  PhaseWatch& watch_phase_;
  const std::vector<Tile> tiles_;
  StallWatch watch_;
  Clock::time_point started_;
  AtomicRayCounts counts_;
  std::atomic<uint64_t> pixels_done_{0}, rays_done_{0};
  std::optional<frontend::ProgressBar> progress_;  // rank 0's, reading the two above
  std::atomic<double> slowest_tile_s_{0.0};        // this rank's slowest tile so far
  ActivePixels active_;                            // rank 0, adaptive sampling: this pass's pixels
  std::mutex idle_mutex_;
  double idle_ms_ = 0;                    // this rank's threads waiting for tiles
  double server_ms_ = 0;                  // rank 0: time spent on messages (requests, returned tiles, done)
  uint64_t served_ = 0;                   // rank 0: messages handled
  std::vector<uint64_t> tiles_per_rank_;  // rank 0: tiles handed to each rank
  uint32_t round_serial_ = 0;             // rounds over all frames, for their messages' tags
};

}  // namespace tracer::mpi
