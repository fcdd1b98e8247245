// The dynamic distribution of a pass's tiles over the ranks of an MPI job. Rank 0 hands out
// tiles one request at a time from the counter its own render threads draw from too; every other
// rank's render threads ask it for tiles and send back what they rendered. Each such thread keeps
// one request in flight while it renders, so its next tile is usually there when it finishes (the
// round trip to rank 0 is hidden); no static split: a slow or busy node just asks less often.
#pragma once

#include <mpi.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "film/framebuffer.hpp"
#include "parallel/tiles.hpp"

namespace tracer::mpi {

// A rank reported an error mid-render (it then waits to be aborted).
struct RankFailed : std::runtime_error {
  RankFailed(int rank_, const std::string& what) : std::runtime_error(what), rank(rank_) {}
  int rank;
};

// Messages of pass `serial` (numbered over all frames) carry tags of their own: a rank that has
// moved on to the next pass may ask for its tiles while rank 0 still waits for another rank's
// last tile of this one, and that request must wait for the next pass, not end this one.
int pass_tag(uint32_t serial, int kind);

// Rank 0's side of one pass.
class TileServer {
 public:
  // `remote_threads`: the render threads of all other ranks; each says when it is done.
  TileServer(const std::vector<Tile>& tiles, int remote_threads, int ranks, uint32_t pass_serial);
  // The next tile for one of rank 0's own threads; thread-safe.
  std::optional<uint32_t> take();
  // Answers the other ranks' requests and adds the tiles they return into `fb` (as the sum of
  // `samples` samples per pixel) until every remote thread has said it is done. Throws
  // RankFailed.
  void serve(Framebuffer& fb, uint32_t samples);
  // Time spent handling messages (receiving, adding a tile, answering), and their number.
  double busy_ms() const { return busy_ms_; }
  uint64_t messages() const { return messages_; }
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
  uint32_t serial_;
  std::atomic<uint32_t> next_{0};
  std::vector<uint64_t> tiles_per_rank_;
  std::atomic<uint64_t> own_tiles_{0};
  double busy_ms_ = 0;
  uint64_t messages_ = 0;
};

// Another rank's side of one pass, shared by its render threads (MPI calls serialised by a
// mutex, never held while waiting).
class TileClient {
 public:
  TileClient(const std::vector<Tile>& tiles, uint32_t pass_serial) : tiles_(tiles), serial_(pass_serial) {}

  // One render thread's conversation with rank 0; `thread` numbers it within the rank.
  class Worker {
   public:
    Worker(TileClient& client, int thread);
    ~Worker();
    // The next tile to render, or nothing when the pass is over (then this thread is done and
    // has told rank 0). Sends `finished`'s sums first, if given. `idle_ms` gets the time spent
    // waiting for a tile.
    std::optional<uint32_t> next(std::optional<uint32_t> finished, const Framebuffer* sums, double& idle_ms);

   private:
    void post_request();
    // Polls `r` (under the client's lock, never held while waiting) until it completes.
    void complete(MPI_Request& r);
    int32_t wait_answer(double& idle_ms);
    void wait_send();
    TileClient& client_;
    int thread_;
    bool started_ = false;
    MPI_Request request_send_ = MPI_REQUEST_NULL, answer_recv_ = MPI_REQUEST_NULL, result_send_ = MPI_REQUEST_NULL;
    int32_t request_[2] = {0, 0}, answer_ = -1;
    std::vector<char> result_;
  };

  // Tells rank 0 this rank cannot go on (then rank 0 aborts the job).
  static void report_failure(const std::string& message);

 private:
  const std::vector<Tile>& tiles_;
  uint32_t serial_;
  std::mutex mutex_;
};

}  // namespace tracer::mpi
