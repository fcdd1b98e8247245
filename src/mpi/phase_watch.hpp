// A deadline on the phase a rank is in, kept by a thread of its own: a rank blocked in MPI while
// waiting for another that stopped (SIGSTOP, a hung node, a start-up that never ends) says so and
// ends with exit code 1, and mpirun then ends the job, instead of every rank waiting forever.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace tracer::mpi {

class PhaseWatch {
 public:
  PhaseWatch();
  ~PhaseWatch();
  PhaseWatch(const PhaseWatch&) = delete;
  PhaseWatch& operator=(const PhaseWatch&) = delete;

  // From now the phase must end, or progress(), within `seconds`; past that, `message` is written
  // to stderr and the process exits with code 1.
  void arm(const std::string& message, double seconds);
  // The phase moved on: its deadline starts again, `seconds` from now.
  void progress(double seconds);
  // While held (by any thread: holds count), the deadline does not run: this rank is busy with
  // its own work (rendering a tile), not waiting for another. The last release() starts it
  // again, `seconds` from then.
  void hold();
  void release(double seconds);
  void disarm();

 private:
  void run();
  std::mutex mutex_;
  std::condition_variable changed_;
  std::chrono::steady_clock::time_point deadline_;
  double seconds_ = 0.0;  // the bound last set, for a deadline started again
  int holds_ = 0;
  std::string message_;
  bool armed_ = false, stopping_ = false;
  std::thread thread_;
};

// This process's rank and the job's size as the launcher gives them (before MPI_Init), for
// messages; "?" where it gives none.
std::string launcher_rank_text();

}  // namespace tracer::mpi
