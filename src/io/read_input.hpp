// Reading an input file whole, once: regular files, pipes, FIFOs and "-" (standard input) alike.
#pragma once

#include <string>

#include "base/errors.hpp"

namespace tracer {

// The bytes of `path` ("-": standard input). Throws InputError("PATH: cannot open: reason") with
// the real reason (no such file, permission denied, a symlink loop, a directory), and Cancelled
// when `cancel` is set while reading.
std::string read_input(const std::string& path, CancelFlag cancel = nullptr);

}  // namespace tracer
