// The dynamic distribution of a pass's tiles over the ranks of an MPI job. Rank 0 answers
// requests one at a time from a counter its own render threads draw from too; every other
// rank's render threads ask it for their next tile, sending with each request the pass sums of
// the tile they just finished. No static split: a slow or busy node just asks less often.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "parallel/tiles.hpp"
#include "render/framebuffer.hpp"

namespace tracer::mpi {

// A rank reported an error mid-render (it then waits to be aborted).
struct RankFailed : std::runtime_error {
  RankFailed(int rank_, const std::string& what) : std::runtime_error(what), rank(rank_) {}
  int rank;
};

// Rank 0's side of one pass.
class TileServer {
 public:
  // `remote_threads`: the render threads of all other ranks, each of which asks until told the
  // pass is over.
  TileServer(const std::vector<Tile>& tiles, int remote_threads, int ranks);
  // The next tile for one of rank 0's own threads; thread-safe.
  std::optional<uint32_t> take();
  // Answers the other ranks until every one of their threads has been told the pass is over,
  // adding each tile they return into `fb` as the sum of `samples` samples per pixel. Throws
  // RankFailed.
  void serve(Framebuffer& fb, uint32_t samples);
  // Time spent handling requests (receiving, adding the tile, answering), and their number.
  double busy_ms() const { return busy_ms_; }
  uint64_t requests() const { return requests_; }
  // Tiles handed out per rank in this pass (rank 0's own included): read once rank 0's own
  // threads have finished.
  std::vector<uint64_t> tiles_per_rank() const {
    std::vector<uint64_t> v = tiles_per_rank_;
    v[0] = own_tiles_.load();
    return v;
  }

 private:
  const std::vector<Tile>& tiles_;
  int remote_threads_;
  std::atomic<uint32_t> next_{0};
  std::vector<uint64_t> tiles_per_rank_;
  std::atomic<uint64_t> own_tiles_{0};
  double busy_ms_ = 0;
  uint64_t requests_ = 0;
};

// Another rank's side of one pass: its render threads' round trips to rank 0, one at a time.
class TileClient {
 public:
  explicit TileClient(const std::vector<Tile>& tiles) : tiles_(tiles) {}
  // Sends the finished tile's sums (if any) and returns the next tile, or nothing when the pass
  // is over. Thread-safe; `idle_ms` gets the time spent waiting.
  std::optional<uint32_t> request(std::optional<uint32_t> finished, const Framebuffer* sums, double& idle_ms);
  // Tells rank 0 this rank cannot go on (then rank 0 aborts the job).
  static void report_failure(const std::string& message);

 private:
  const std::vector<Tile>& tiles_;
  std::mutex mutex_;
  std::vector<char> buffer_;
};

}  // namespace tracer::mpi
