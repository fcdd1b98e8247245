// The two kinds of failure a user can cause, with the exit codes the CLI maps them to. Every
// layer throws these; only the CLI turns them into messages and exit codes.
#pragma once

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

}  // namespace tracer
