// Reading an input file whole, once: regular files, pipes, FIFOs and "-" (standard input) alike.
// Every regular file read is remembered by identity (device and inode), so no output of the run
// can replace an input, whatever name either is given by.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>

#include "base/errors.hpp"

namespace tracer {

// The largest input read_input() accepts unless told otherwise: 4 GiB (a 5M-triangle OBJ is
// about 300 MiB). `tracer render --max-input-mib` raises it for a scene.
inline constexpr uint64_t kDefaultMaxInputBytes = uint64_t(4096) << 20;

// More bytes than the limit arrived: not a missing or unreadable file, so never only a warning.
class InputTooLarge : public InputError {
 public:
  using InputError::InputError;
};

// The bytes of `path` ("-": standard input). Throws InputError("PATH: cannot open: reason") with
// the real reason (no such file, permission denied, a symlink loop, a directory), InputTooLarge
// when more than `max_bytes` arrive (a file that never ends: /dev/zero, a runaway pipe), and Cancelled
// when `cancel` is set while opening or reading (a FIFO with no writer, a silent pipe).
std::string read_input(const std::string& path, CancelFlag cancel = nullptr,
                       uint64_t max_bytes = kDefaultMaxInputBytes);

// The bytes of an input, read-only: a regular file mapped into memory (its pages are the page
// cache's: no copy, and no fresh pages to fault in, which cost ~16 us each on a VM: Sponza's
// 5.6 MB in 3.4 ms instead of 25.8), anything else read. A regular file truncated by another
// process while mapped would fault; tracer's own outputs can never be one of its inputs.
class InputBytes {
 public:
  InputBytes() = default;
  explicit InputBytes(std::string bytes) : bytes_(std::move(bytes)) {}
  InputBytes(const char* mapping, size_t size) : mapping_(mapping), size_(size) {}
  ~InputBytes();
  InputBytes(InputBytes&& o) noexcept { *this = std::move(o); }
  InputBytes& operator=(InputBytes&& o) noexcept;
  InputBytes(const InputBytes&) = delete;
  InputBytes& operator=(const InputBytes&) = delete;
  std::string_view view() const { return mapping_ ? std::string_view(mapping_, size_) : std::string_view(bytes_); }
  // The bytes as a string: moved out when they were read, copied when mapped.
  std::string release() && { return mapping_ ? std::string(view()) : std::move(bytes_); }

 private:
  std::string bytes_;
  const char* mapping_ = nullptr;
  size_t size_ = 0;
};

// As read_input(), for a file that is no input of the run: one it wrote and reads back (tests),
// which it may write again.
std::string read_back(const std::string& path, uint64_t max_bytes = kDefaultMaxInputBytes);

// As read_input(), mapping a regular file instead of reading it.
InputBytes map_input(const std::string& path, CancelFlag cancel = nullptr, uint64_t max_bytes = kDefaultMaxInputBytes);

// Throws UsageError("FLAG: 'PATH' is an input of this run (INPUT)") when `path`, followed through
// symbolic links, is a regular file this process has read with read_input().
void check_not_an_input(const std::string& path, const std::string& flag);

}  // namespace tracer
