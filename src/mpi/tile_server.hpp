// The dynamic distribution of a pass's tiles over the ranks of an MPI job. Rank 0 hands out
// tiles one request at a time from the counter its own render threads draw from too; every other
// rank's render threads ask it for tiles and send back what they rendered. Each such thread keeps
// one request in flight while it renders, so its next tile is usually there when it finishes (the
// round trip to rank 0 is hidden); no static split: a slow or busy node just asks less often.
#pragma once

#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "film/convergence.hpp"
#include "film/feature_film.hpp"
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

// What rank 0 knows of its peers' health over a whole job: how long the slowest tile took to come
// back, and which ranks stopped answering. A tile is overdue once it has been out longer than
// overdue_after(): its rank is then late, and its tiles are handed to others.
struct StallWatch {
  double floor_seconds = 10.0;  // --rank-timeout
  double slowest_seconds = 0;   // the longest any tile took from hand-out to its sums, so far
  // Never less than the floor, and 8 times the slowest tile seen: tiles of one image differ in
  // cost, and one thread's round trip covers up to two tiles (a request stays in flight while it
  // renders), so a rank is only called late when it is far slower than every tile so far.
  double overdue_after() const { return std::max(floor_seconds, 8.0 * slowest_seconds); }
  std::vector<int> gone;       // ranks that never answered again: excluded for the rest of the job
  std::vector<int> recovered;  // ranks that were late but came back within their pass
  bool is_gone(int rank) const { return std::find(gone.begin(), gone.end(), rank) != gone.end(); }
};

// A tile for one of rank 0's own threads: a fresh one (rendered straight into the image), or one
// taken back from a late rank (rendered into a window of its own and then commit()ed, so that
// whichever copy comes first counts, once).
struct TileGrant {
  uint32_t tile;
  bool reissued;
};

// Rank 0's side of one pass.
class TileServer {
 public:
  // `rank_threads[r]`: the render threads of rank r (rank 0's own not counted); each says when it
  // is done. `watch` carries what earlier passes learnt and learns from this one.
  // `active` (adaptive sampling, when this pass has decided): the pixels it samples, whose
  // blocks go with each tile handed out; the others take no samples.
  TileServer(const std::vector<Tile>& tiles, const std::vector<uint64_t>& rank_threads, uint32_t pass_serial,
             StallWatch& watch, const ActivePixels* active = nullptr);
  // The next tile for one of rank 0's own threads, or nothing when every tile of the pass is in;
  // waits while tiles are out with other ranks (one may be taken back). Thread-safe.
  std::optional<TileGrant> take();
  // One of rank 0's own fresh tiles is rendered.
  void own_done(uint32_t tile);
  // Adds a reissued tile's sums (a window, and with --denoise its features into `features`)
  // unless another copy came first.
  void commit(uint32_t tile, const Framebuffer& window, Framebuffer& fb, uint32_t samples,
              const FeatureFilm* window_features = nullptr, FeatureFilm* features = nullptr);
  // Answers the other ranks' requests and adds the tiles they return into `fb` (as the sum of
  // `samples` samples per pixel) and, with --denoise, their features into `features`, until
  // every tile is in and every rank still answering has said it is done. Throws RankFailed.
  void serve(Framebuffer& fb, uint32_t samples, FeatureFilm* features = nullptr);
  // Time spent handling messages (receiving, adding a tile, answering), and their number.
  double busy_ms() const { return busy_ms_; }
  uint64_t messages() const { return messages_; }
  // Tiles handed out per rank in this pass (rank 0's own included): read once rank 0's own
  // threads have finished.
  std::vector<uint64_t> tiles_per_rank() const { return tiles_per_rank_; }

 private:
  // Called under mutex_: marks tile t in (its sums added), and notes how long it was out.
  void received(uint32_t t);
  // Called under mutex_: adds one pixel's sums (and its half's) for the samples it took.
  void add_pixel(Framebuffer& fb, int x, int y, Vec3 sum, Vec3 half, uint32_t samples) const;
  // Called under mutex_: ranks holding overdue tiles become late, their tiles reissued.
  void check_overdue(std::chrono::steady_clock::time_point now);

  const std::vector<Tile>& tiles_;
  std::vector<uint64_t> rank_threads_;
  uint32_t serial_;
  StallWatch& watch_;
  const ActivePixels* active_;
  std::mutex mutex_;
  uint32_t next_ = 0;                                          // the next fresh tile
  std::vector<int> owner_;                                     // per tile: the rank it was last handed to
  std::vector<std::chrono::steady_clock::time_point> handed_;  // per tile: when
  std::vector<char> in_;                                       // per tile: its sums are added
  uint32_t in_count_ = 0;
  std::deque<uint32_t> reissue_;  // tiles taken back from late ranks
  std::vector<char> late_;        // per rank
  std::vector<uint64_t> done_;    // per rank: threads that said they are done
  std::vector<uint64_t> tiles_per_rank_;
  double busy_ms_ = 0;
  uint64_t messages_ = 0;
};

// Another rank's side of one pass, shared by its render threads (MPI calls serialised by a
// mutex, never held while waiting).
class TileClient {
 public:
  // `masks`: rank 0 sends each tile's blocks of adaptive sampling's active pixels with it.
  TileClient(const std::vector<Tile>& tiles, uint32_t pass_serial, bool masks);

  // One render thread's conversation with rank 0; `thread` numbers it within the rank.
  class Worker {
   public:
    Worker(TileClient& client, int thread);
    ~Worker();
    // The next tile to render, or nothing when the pass is over (then this thread is done and
    // has told rank 0). Sends `finished`'s sums first, if given. `idle_ms` gets the time spent
    // waiting for a tile.
    std::optional<uint32_t> next(std::optional<uint32_t> finished, const Framebuffer* sums, const FeatureFilm* features,
                                 double& idle_ms);
    // With masks: the blocks of the tile next() returned (ActivePixels::window_blocks()).
    const uint8_t* mask() const { return reinterpret_cast<const uint8_t*>(answer_.data() + sizeof(int32_t)); }

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
    int32_t request_[2] = {0, 0};
    std::vector<char> answer_;  // int32 tile (-1: none left), then with masks the tile's blocks
    std::vector<char> result_;
  };

  // Tells rank 0 this rank cannot go on (then rank 0 aborts the job).
  static void report_failure(const std::string& message);

 private:
  const std::vector<Tile>& tiles_;
  uint32_t serial_;
  size_t answer_bytes_ = sizeof(int32_t);  // the largest answer: a tile and its blocks
  std::mutex mutex_;
};

}  // namespace tracer::mpi
