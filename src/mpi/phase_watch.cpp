#include "mpi/phase_watch.hpp"

#include <cstdio>
#include <cstdlib>

namespace tracer::mpi {

PhaseWatch::PhaseWatch() : thread_([this] { run(); }) {}

PhaseWatch::~PhaseWatch() {
  {
    const std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void PhaseWatch::arm(const std::string& message, double seconds) {
  {
    const std::lock_guard lock(mutex_);
    message_ = message;
    armed_ = true;
    deadline_ = std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
  }
  changed_.notify_all();
}

void PhaseWatch::progress(double seconds) {
  const std::lock_guard lock(mutex_);
  deadline_ = std::chrono::steady_clock::now() +
              std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

void PhaseWatch::disarm() {
  const std::lock_guard lock(mutex_);
  armed_ = false;
}

void PhaseWatch::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (!armed_) {
      changed_.wait(lock);
      continue;
    }
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline_ + std::chrono::milliseconds(500)) {
      // Woken far past the deadline: this process was itself stopped (SIGSTOP, a suspended VM),
      // and blames no other rank for it; the deadline starts again.
      deadline_ = now + std::chrono::seconds(2);
      continue;
    }
    if (now >= deadline_) {
      const std::string line = message_ + "\n";
      std::fputs(line.c_str(), stderr);  // one write: the ranks' lines do not interleave
      std::fflush(stderr);
      std::_Exit(1);
    }
    changed_.wait_until(lock, deadline_);
  }
}

std::string launcher_rank_text() {
  const char* rank = std::getenv("OMPI_COMM_WORLD_RANK");
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  return std::string(rank ? rank : "?") + " of " + (size ? size : "?");
}

}  // namespace tracer::mpi
