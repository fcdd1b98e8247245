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

namespace {
std::chrono::steady_clock::time_point after(double seconds) {
  return std::chrono::steady_clock::now() +
         std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}
}  // namespace

void PhaseWatch::arm(const std::string& message, double seconds) {
  {
    const std::lock_guard lock(mutex_);
    message_ = message;
    armed_ = true;
    seconds_ = seconds;
    deadline_ = after(seconds);
  }
  changed_.notify_all();
}

void PhaseWatch::progress(double seconds) {
  const std::lock_guard lock(mutex_);
  seconds_ = seconds;
  deadline_ = after(seconds);
}

void PhaseWatch::hold() {
  const std::lock_guard lock(mutex_);
  ++holds_;
}

void PhaseWatch::release(double seconds) {
  {
    const std::lock_guard lock(mutex_);
    if (--holds_ > 0) return;
    seconds_ = seconds;
    deadline_ = after(seconds);
  }
  changed_.notify_all();
}

void PhaseWatch::disarm() {
  const std::lock_guard lock(mutex_);
  armed_ = false;
}

void PhaseWatch::run() {
  std::unique_lock lock(mutex_);
  while (!stopping_) {
    if (!armed_ || holds_ > 0) {
      changed_.wait(lock);
      continue;
    }
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline_ + std::chrono::milliseconds(500)) {
      // Woken far past the deadline: this process was itself stopped or descheduled (SIGSTOP, a
      // suspended VM, an oversubscribed machine), and blames no other rank for it; the whole
      // bound starts again, since the others may have moved on (a round ended) while it was away.
      deadline_ = after(seconds_);
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
