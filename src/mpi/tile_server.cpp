#include "mpi/tile_server.hpp"

#include <mpi.h>

#include <chrono>
#include <cstring>
#include <thread>

namespace tracer::mpi {

namespace {

constexpr int kTagRequest = 101;  // a thread's request for a tile, with the tile it finished
constexpr int kTagAssign = 102;   // rank 0's answer: a tile index, or -1 when the pass is over
constexpr int kTagFailure = 103;  // a rank's error message

// A request: the finished tile (or -1), then its pixels' sums (three floats each, row by row).
struct RequestHeader {
  int32_t finished;
};

}  // namespace

TileServer::TileServer(const std::vector<Tile>& tiles, int remote_threads, int ranks)
    : tiles_(tiles), remote_threads_(remote_threads), tiles_per_rank_(size_t(ranks), 0) {}

std::optional<uint32_t> TileServer::take() {
  const uint32_t t = next_.fetch_add(1, std::memory_order_relaxed);
  if (t >= tiles_.size()) return std::nullopt;
  own_tiles_.fetch_add(1, std::memory_order_relaxed);
  return t;
}

void TileServer::serve(Framebuffer& fb, uint32_t samples) {
  std::vector<char> buffer;
  int finished_threads = 0;
  while (finished_threads < remote_threads_) {
    int flag = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
    if (!flag) {
      // Polling rather than a blocking receive: Open MPI spins in blocking calls, which would
      // take a core from rank 0's own render threads. 50 us is far below a tile's time.
      std::this_thread::sleep_for(std::chrono::microseconds(50));
      continue;
    }
    const auto t0 = std::chrono::steady_clock::now();
    int bytes = 0;
    MPI_Get_count(&status, MPI_BYTE, &bytes);
    buffer.resize(size_t(bytes));
    MPI_Recv(buffer.data(), bytes, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (status.MPI_TAG == kTagFailure) throw RankFailed(status.MPI_SOURCE, std::string(buffer.begin(), buffer.end()));
    if (status.MPI_TAG != kTagRequest || size_t(bytes) < sizeof(RequestHeader)) continue;
    RequestHeader header;
    std::memcpy(&header, buffer.data(), sizeof header);
    if (header.finished >= 0 && size_t(header.finished) < tiles_.size()) {
      const Tile& t = tiles_[size_t(header.finished)];
      const size_t floats = size_t(t.pixel_count()) * 3;
      if (size_t(bytes) == sizeof header + floats * sizeof(float)) {
        const char* p = buffer.data() + sizeof header;
        for (int y = t.y0; y < t.y1; ++y) {
          for (int x = t.x0; x < t.x1; ++x) {
            float c[3];
            std::memcpy(c, p, sizeof c);
            p += sizeof c;
            fb.add(x, y, Vec3{c[0], c[1], c[2]}, samples);
          }
        }
      }
    }
    const uint32_t next = next_.fetch_add(1, std::memory_order_relaxed);
    const int32_t answer = next < tiles_.size() ? int32_t(next) : -1;
    if (answer < 0) {
      ++finished_threads;
    } else {
      ++tiles_per_rank_[size_t(status.MPI_SOURCE)];
    }
    MPI_Send(&answer, 1, MPI_INT32_T, status.MPI_SOURCE, kTagAssign, MPI_COMM_WORLD);
    busy_ms_ += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    ++requests_;
  }
}

std::optional<uint32_t> TileClient::request(std::optional<uint32_t> finished, const Framebuffer* sums,
                                            double& idle_ms) {
  const auto t0 = std::chrono::steady_clock::now();
  std::lock_guard lock(mutex_);
  const RequestHeader header{finished ? int32_t(*finished) : -1};
  buffer_.assign(reinterpret_cast<const char*>(&header), reinterpret_cast<const char*>(&header) + sizeof header);
  if (finished && sums) {
    const Tile& t = tiles_[*finished];
    for (int y = t.y0; y < t.y1; ++y) {
      for (int x = t.x0; x < t.x1; ++x) {
        const Vec3& v = sums->sums()[size_t(y - t.y0) * size_t(t.x1 - t.x0) + size_t(x - t.x0)];
        const float c[3] = {v.x, v.y, v.z};
        buffer_.insert(buffer_.end(), reinterpret_cast<const char*>(c), reinterpret_cast<const char*>(c) + sizeof c);
      }
    }
  }
  MPI_Send(buffer_.data(), int(buffer_.size()), MPI_BYTE, 0, kTagRequest, MPI_COMM_WORLD);
  int32_t answer = -1;
  MPI_Recv(&answer, 1, MPI_INT32_T, 0, kTagAssign, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
  idle_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (answer < 0) return std::nullopt;
  return uint32_t(answer);
}

void TileClient::report_failure(const std::string& message) {
  MPI_Send(message.data(), int(message.size()), MPI_BYTE, 0, kTagFailure, MPI_COMM_WORLD);
}

}  // namespace tracer::mpi
