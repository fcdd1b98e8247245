#include "mpi/tile_server.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <thread>

namespace tracer::mpi {

namespace {

// Kinds of message within a pass (see pass_tag()).
constexpr int kRequest = 0;  // int32 {thread}: send me a tile
constexpr int kResult = 1;   // int32 tile, then its pixels' sums (three floats each, row by row), then
                             // with adaptive sampling their halves' sums (as many again)
constexpr int kDone = 2;     // int32 {thread}: this thread has sent everything, the pass is over for it
constexpr int kKinds = 3;
constexpr uint32_t kPassSlots = 4096;  // tags repeat after this many passes; far apart by then
constexpr int kTagFailure = 1;         // a rank's error message, whenever it happens
constexpr int kTagAnswer = 16;         // + thread: rank 0's answer, a tile index or -1 when none is left,
                                       // with masks then the tile's blocks (ActivePixels::window_blocks)
constexpr int kTagPassBase = 2048;     // above every answer tag (threads are at most 1024); the
                                       // largest tag, 2048 + 3 * 4096, is within the 32767 MPI promises

// Waiting by polling rather than in a blocking call: Open MPI spins in blocking calls, which would
// take a core from the render threads. The pause doubles while nothing comes, from 20 us to 1 ms:
// every thread of another rank keeps a request in flight, so a late answer is rarely waited for,
// and a waking poll costs its core a few microseconds (at a steady 20 us, 2 ranks x 1 thread on
// two cores rendered 1.2x slower than one process).
class Backoff {
 public:
  void reset() { us_ = 20; }
  void pause() {
    std::this_thread::sleep_for(std::chrono::microseconds(us_));
    us_ = std::min(us_ * 2, 1000);
  }

 private:
  int us_ = 20;
};

}  // namespace

int pass_tag(uint32_t serial, int kind) { return kTagPassBase + int(serial % kPassSlots) * kKinds + kind; }

TileServer::TileServer(const std::vector<Tile>& tiles, const std::vector<uint64_t>& rank_threads, uint32_t pass_serial,
                       StallWatch& watch, const ActivePixels* active)
    : tiles_(tiles),
      rank_threads_(rank_threads),
      serial_(pass_serial),
      watch_(watch),
      active_(active),
      owner_(tiles.size(), 0),
      handed_(tiles.size()),
      in_(tiles.size(), 0),
      late_(rank_threads.size(), 0),
      done_(rank_threads.size(), 0),
      tiles_per_rank_(rank_threads.size(), 0) {
  for (const int r : watch_.gone) late_[size_t(r)] = 1;
}

std::optional<TileGrant> TileServer::take() {
  for (;;) {
    {
      const std::lock_guard lock(mutex_);
      if (next_ < tiles_.size()) {
        const uint32_t t = next_++;
        owner_[t] = 0;
        ++tiles_per_rank_[0];
        return TileGrant{t, false};
      }
      if (!reissue_.empty()) {
        const uint32_t t = reissue_.front();
        reissue_.pop_front();
        owner_[t] = 0;
        ++tiles_per_rank_[0];
        return TileGrant{t, true};
      }
      if (in_count_ == tiles_.size()) return std::nullopt;
    }
    // Tiles are still out with other ranks; one of them may come back to us.
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void TileServer::received(uint32_t t) {
  in_[t] = 1;
  ++in_count_;
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - handed_[t]).count();
  if (owner_[t] != 0) watch_.slowest_seconds = std::max(watch_.slowest_seconds, seconds);
}

void TileServer::own_done(uint32_t t) {
  const std::lock_guard lock(mutex_);
  if (!in_[t]) received(t);
}

void TileServer::add_pixel(Framebuffer& fb, int x, int y, Vec3 sum, Vec3 half, uint32_t samples) const {
  fb.add(x, y, sum, half, active_ && !active_->active(x, y) ? 0u : samples);
}

void TileServer::commit(uint32_t t, const Framebuffer& window, Framebuffer& fb, uint32_t samples,
                        const FeatureFilm* window_features, FeatureFilm* features) {
  // Under the mutex, as serve() adds the tiles other ranks return: one copy of a tile counts.
  const std::lock_guard lock(mutex_);
  if (in_[t]) return;
  const Tile& tile = tiles_[t];
  for (int y = tile.y0; y < tile.y1; ++y) {
    for (int x = tile.x0; x < tile.x1; ++x) add_pixel(fb, x, y, window.sum(x, y), window.half_sum(x, y), samples);
  }
  if (features && window_features) features->add_tile(*window_features, tile);
  received(t);
}

void TileServer::check_overdue(std::chrono::steady_clock::time_point now) {
  const double limit = watch_.overdue_after();
  for (uint32_t t = 0; t < next_; ++t) {
    const int r = owner_[t];
    if (in_[t] || r == 0 || late_[size_t(r)]) continue;
    if (std::chrono::duration<double>(now - handed_[t]).count() <= limit) continue;
    late_[size_t(r)] = 1;
    for (uint32_t u = 0; u < next_; ++u) {
      if (!in_[u] && owner_[u] == r) reissue_.push_back(u);
    }
  }
}

void TileServer::serve(Framebuffer& fb, uint32_t samples, FeatureFilm* features) {
  std::vector<char> buffer, answer_bytes;
  Backoff backoff;
  using Clock = std::chrono::steady_clock;
  auto last_check = Clock::now();
  auto all_in_since = Clock::time_point{};
  const auto finished = [&] {
    // Every tile in, and every rank still answering done.
    if (in_count_ != tiles_.size()) return false;
    for (size_t r = 1; r < rank_threads_.size(); ++r) {
      if (!late_[r] && done_[r] < rank_threads_[r]) return false;
    }
    return true;
  };
  for (;;) {
    {
      const std::lock_guard lock(mutex_);
      const auto now = Clock::now();
      if (finished()) break;
      if (std::chrono::duration<double>(now - last_check).count() > 0.05) {
        last_check = now;
        check_overdue(now);
        // Every tile is in but some rank has not said it is done: it holds no tile to be late
        // with, so it is late once it has been silent as long as a tile may be out.
        if (in_count_ == tiles_.size()) {
          if (all_in_since == Clock::time_point{}) all_in_since = now;
          if (std::chrono::duration<double>(now - all_in_since).count() > watch_.overdue_after()) {
            for (size_t r = 1; r < rank_threads_.size(); ++r) {
              if (done_[r] < rank_threads_[r]) late_[r] = 1;
            }
          }
        }
      }
    }
    // This pass's messages, and failures; a later pass's requests wait in the queue.
    int flag = 0;
    MPI_Status status;
    for (const int tag :
         {kTagFailure, pass_tag(serial_, kResult), pass_tag(serial_, kDone), pass_tag(serial_, kRequest)}) {
      MPI_Iprobe(MPI_ANY_SOURCE, tag, MPI_COMM_WORLD, &flag, &status);
      if (flag) break;
    }
    if (!flag) {
      backoff.pause();
      continue;
    }
    backoff.reset();
    const auto t0 = Clock::now();
    int bytes = 0;
    MPI_Get_count(&status, MPI_BYTE, &bytes);
    buffer.resize(size_t(bytes));
    MPI_Recv(buffer.data(), bytes, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    int32_t first = -1;
    if (size_t(bytes) >= sizeof first) std::memcpy(&first, buffer.data(), sizeof first);
    const int kind = status.MPI_TAG == kTagFailure ? -1 : (status.MPI_TAG - kTagPassBase) % kKinds;
    const auto source = size_t(status.MPI_SOURCE);
    if (kind == -1) throw RankFailed(status.MPI_SOURCE, std::string(buffer.begin(), buffer.end()));
    {
      const std::lock_guard lock(mutex_);
      switch (kind) {
        case kRequest: {
          // A late rank gets no more tiles: told the pass is over, it says it is done.
          int32_t answer = -1;
          if (!late_[source] && next_ < tiles_.size()) {
            answer = int32_t(next_++);
          } else if (!late_[source] && !reissue_.empty()) {
            answer = int32_t(reissue_.front());
            reissue_.pop_front();
          }
          if (answer >= 0) {
            owner_[size_t(answer)] = int(source);
            handed_[size_t(answer)] = Clock::now();
            ++tiles_per_rank_[source];
          }
          // The worker's receive is posted before its request is sent, so this send never waits
          // on it, masks included.
          answer_bytes.assign(reinterpret_cast<const char*>(&answer),
                              reinterpret_cast<const char*>(&answer) + sizeof answer);
          if (active_ && answer >= 0) {
            const std::vector<uint8_t> mask = active_->window_blocks(tiles_[size_t(answer)]);
            answer_bytes.insert(answer_bytes.end(), mask.begin(), mask.end());
          }
          MPI_Send(answer_bytes.data(), int(answer_bytes.size()), MPI_BYTE, status.MPI_SOURCE, kTagAnswer + first,
                   MPI_COMM_WORLD);
          break;
        }
        case kResult: {
          // The first copy of a tile counts; a late rank's copy of a reissued tile is dropped.
          if (first < 0 || size_t(first) >= tiles_.size() || in_[size_t(first)]) break;
          const Tile& t = tiles_[size_t(first)];
          const size_t plane = size_t(t.pixel_count()) * 3 * sizeof(float);
          const bool halves = fb.has_halves();
          const size_t feature_bytes =
              features ? size_t(t.pixel_count()) * FeatureFilm::kPixelFloats * sizeof(float) : 0;
          if (size_t(bytes) != sizeof first + plane * (halves ? 2 : 1) + feature_bytes) break;
          const char* p = buffer.data() + sizeof first;
          for (int y = t.y0; y < t.y1; ++y) {
            for (int x = t.x0; x < t.x1; ++x) {
              float c[3], h[3] = {0.0f, 0.0f, 0.0f};
              std::memcpy(c, p, sizeof c);
              if (halves) std::memcpy(h, p + plane, sizeof h);
              p += sizeof c;
              add_pixel(fb, x, y, Vec3{c[0], c[1], c[2]}, Vec3{h[0], h[1], h[2]}, samples);
            }
          }
          if (features) {
            FeatureFilm window(t);
            std::memcpy(window.data(), buffer.data() + sizeof first + plane * (halves ? 2 : 1), feature_bytes);
            features->add_tile(window, t);
          }
          received(uint32_t(first));
          break;
        }
        case kDone:
          ++done_[source];
          break;
        default:
          break;
      }
    }
    busy_ms_ += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    ++messages_;
  }
  // A late rank whose every thread still said it was done within the pass is back; one that did
  // not is gone for the rest of the job.
  const std::lock_guard lock(mutex_);
  for (size_t r = 1; r < rank_threads_.size(); ++r) {
    if (!late_[r] || watch_.is_gone(int(r))) continue;
    if (done_[r] >= rank_threads_[r]) {
      watch_.recovered.push_back(int(r));
    } else {
      watch_.gone.push_back(int(r));
    }
  }
}

TileClient::TileClient(const std::vector<Tile>& tiles, uint32_t pass_serial, bool masks)
    : tiles_(tiles), serial_(pass_serial) {
  for (const Tile& t : tiles) {
    answer_bytes_ = std::max(answer_bytes_, sizeof(int32_t) + (masks ? ActivePixels::window_block_count(t) : 0));
  }
}

TileClient::Worker::Worker(TileClient& client, int thread)
    : client_(client), thread_(thread), answer_(client.answer_bytes_) {}

TileClient::Worker::~Worker() {
  // Normally nothing is outstanding here; after an error, give up what is.
  std::lock_guard lock(client_.mutex_);
  for (MPI_Request* r : {&request_send_, &answer_recv_, &result_send_}) {
    if (*r == MPI_REQUEST_NULL) continue;
    int flag = 0;
    MPI_Test(r, &flag, MPI_STATUS_IGNORE);
    if (!flag) {
      MPI_Cancel(r);
      MPI_Request_free(r);
    }
  }
}

void TileClient::Worker::post_request() {
  std::lock_guard lock(client_.mutex_);
  if (request_send_ != MPI_REQUEST_NULL) MPI_Wait(&request_send_, MPI_STATUS_IGNORE);  // 8 bytes: long sent
  request_[0] = thread_;
  MPI_Irecv(answer_.data(), int(answer_.size()), MPI_BYTE, 0, kTagAnswer + thread_, MPI_COMM_WORLD, &answer_recv_);
  MPI_Isend(request_, 2, MPI_INT32_T, 0, pass_tag(client_.serial_, kRequest), MPI_COMM_WORLD, &request_send_);
}

void TileClient::Worker::complete(MPI_Request& r) {
  Backoff backoff;
  for (;;) {
    int flag = 0;
    {
      std::lock_guard lock(client_.mutex_);
      MPI_Test(&r, &flag, MPI_STATUS_IGNORE);
    }
    if (flag) return;
    backoff.pause();
  }
}

int32_t TileClient::Worker::wait_answer(double& idle_ms) {
  const auto t0 = std::chrono::steady_clock::now();
  complete(answer_recv_);
  idle_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  int32_t tile = -1;
  std::memcpy(&tile, answer_.data(), sizeof tile);
  return tile;
}

void TileClient::Worker::wait_send() { complete(result_send_); }

std::optional<uint32_t> TileClient::Worker::next(std::optional<uint32_t> finished, const Framebuffer* sums,
                                                 const FeatureFilm* features, double& idle_ms) {
  if (!started_) {
    post_request();
    started_ = true;
  }
  if (finished && sums) {
    wait_send();  // the previous result's buffer is free again
    const Tile& t = client_.tiles_[*finished];
    const int32_t index = int32_t(*finished);
    result_.assign(reinterpret_cast<const char*>(&index), reinterpret_cast<const char*>(&index) + sizeof index);
    for (const Vec3* plane : {sums->sums(), sums->has_halves() ? sums->half_sums() : nullptr}) {
      if (!plane) continue;  // no halves without adaptive sampling
      for (int y = t.y0; y < t.y1; ++y) {
        for (int x = t.x0; x < t.x1; ++x) {
          const Vec3& v = plane[size_t(y - t.y0) * size_t(t.x1 - t.x0) + size_t(x - t.x0)];
          const float c[3] = {v.x, v.y, v.z};
          result_.insert(result_.end(), reinterpret_cast<const char*>(c), reinterpret_cast<const char*>(c) + sizeof c);
        }
      }
    }
    if (features) {
      const char* f = reinterpret_cast<const char*>(features->data());
      result_.insert(result_.end(), f, f + features->float_count() * sizeof(float));
    }
    std::lock_guard lock(client_.mutex_);
    MPI_Isend(result_.data(), int(result_.size()), MPI_BYTE, 0, pass_tag(client_.serial_, kResult), MPI_COMM_WORLD,
              &result_send_);
  }
  const int32_t tile = wait_answer(idle_ms);
  if (tile < 0) {
    wait_send();
    std::lock_guard lock(client_.mutex_);
    if (request_send_ != MPI_REQUEST_NULL) MPI_Wait(&request_send_, MPI_STATUS_IGNORE);
    const int32_t me = thread_;
    MPI_Send(&me, 1, MPI_INT32_T, 0, pass_tag(client_.serial_, kDone), MPI_COMM_WORLD);
    return std::nullopt;
  }
  post_request();  // the next tile travels while this one renders
  return uint32_t(tile);
}

void TileClient::report_failure(const std::string& message) {
  MPI_Send(message.data(), int(message.size()), MPI_BYTE, 0, kTagFailure, MPI_COMM_WORLD);
}

}  // namespace tracer::mpi
