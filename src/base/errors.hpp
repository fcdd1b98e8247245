// The failures a user can cause or ask for, and the exit code of each (failure_of, the one place
// an exception becomes one). Every layer throws these; only the front ends (tracer, tracer-mpi)
// turn them into messages and exit codes.
#pragma once

#include <atomic>
#include <exception>
#include <stdexcept>
#include <string>

namespace tracer {

// Bad data: a missing/malformed scene file, an unwritable output. Exit code 1.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A bad flag or flag value. Exit code 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The user stopped the run (a signal) while it was loading or building; the CLI exits with
// 128 + the signal number. Thrown where the work checks its cancel flag.
class Cancelled : public std::runtime_error {
 public:
  Cancelled() : std::runtime_error("cancelled") {}
};

// What a front end reports for an exception: its kind, exit code and message. Cancelled's exit
// code is 128 + the signal that stopped the run; 130 (SIGINT's) here, which a front end that
// knows the signal replaces.
struct Failure {
  enum class Kind { Usage, Input, Cancelled, OutOfMemory, Internal };
  Kind kind;
  int exit_code;        // Usage 2; Input, OutOfMemory and Internal 1; Cancelled 130
  std::string message;  // what() ("out of memory" for std::bad_alloc)
};
// The Failure of `e` (std::current_exception() in a catch (...) block); any exception at all.
Failure failure_of(std::exception_ptr e);

// A cancel flag a long phase polls: set asynchronously (by a signal handler or a watchdog).
using CancelFlag = const std::atomic<bool>*;

inline bool is_cancelled(CancelFlag flag) { return flag && flag->load(std::memory_order_relaxed); }
inline void throw_if_cancelled(CancelFlag flag) {
  if (is_cancelled(flag)) throw Cancelled();
}

// The largest coordinate magnitude a scene, camera or light may have, and how it reads in
// messages. The watertight triangle test's distance is a product of three coordinate
// differences (an edge function, about d^2, times a distance d): past about 7e12 it overflows
// float and the triangle vanishes, so 1e12 leaves room for a camera a few times as far out.
inline constexpr float kMaxCoordinate = 1e12f;
inline constexpr const char* kMaxCoordinateText = "1e12";
// How far from the origin an automatically framed camera may stand (a very narrow --fov backs
// it off): rays from there still reach every vertex without overflow.
inline constexpr float kMaxCameraDistance = 4e12f;

}  // namespace tracer
