#include "base/read_input.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <mutex>
#include <vector>

namespace tracer {
namespace {

std::string reason(int err) {
  switch (err) {
    case ENOENT:
      return "no such file";
    case EACCES:
      return "permission denied";
    case ELOOP:
      return "too many levels of symbolic links (a link loop?)";
    case ENOTDIR:
      return "a component of the path is not a directory";
    case EISDIR:
      return "is a directory";
    case ENAMETOOLONG:
      return "file name too long";
    default:
      return std::strerror(err);
  }
}

// The regular files read so far: loaders may run on several threads (textures), so a mutex.
struct InputFile {
  dev_t dev;
  ino_t ino;
  std::string name;
};
std::mutex g_inputs_mutex;
std::vector<InputFile> g_inputs;

void remember_input(const struct stat& st, const std::string& name) {
  if (!S_ISREG(st.st_mode)) return;
  const std::lock_guard lock(g_inputs_mutex);
  for (const InputFile& f : g_inputs) {
    if (f.dev == st.st_dev && f.ino == st.st_ino) return;
  }
  g_inputs.push_back({st.st_dev, st.st_ino, name});
}

std::string mib(uint64_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

// How read_or_map() takes a file: mapped (else read into memory), and remembered as an input
// (else an output read back, which no later output may name).
struct ReadMode {
  bool map = false;
  bool remember = true;
};

InputBytes read_or_map(const std::string& path, CancelFlag cancel, uint64_t max_bytes, ReadMode mode) {
  const bool map = mode.map, remember = mode.remember;
  const bool stdin_input = path == "-";
  const std::string name = stdin_input ? "<stdin>" : path;
  if (path.empty()) throw InputError("an empty file name was given");
  int fd = STDIN_FILENO;
  if (!stdin_input) {
    // Opening a FIFO blocks until a writer comes; a signal interrupts the wait (no SA_RESTART),
    // and then the cancel flag says whether to stop or to wait on.
    while ((fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC)) < 0 && errno == EINTR) {
      throw_if_cancelled(cancel);
    }
  }
  if (fd < 0) throw InputError(name + ": cannot open: " + reason(errno));
  struct Closer {
    int fd;
    bool owned;
    ~Closer() {
      if (owned) ::close(fd);
    }
  } closer{fd, !stdin_input};
  struct stat st {};
  if (::fstat(fd, &st) != 0) throw InputError(name + ": cannot open: " + reason(errno));
  if (S_ISDIR(st.st_mode)) throw InputError(name + ": cannot open: is a directory");
  const auto too_large = [&] {
    return InputTooLarge(name + ": larger than " + mib(max_bytes) +
                         ", the limit for this input (docs/RELIABILITY.md: Limits)");
  };
  if (S_ISREG(st.st_mode) && uint64_t(st.st_size) > max_bytes) throw too_large();
  if (remember) remember_input(st, name);
  if (map && S_ISREG(st.st_mode) && st.st_size > 0) {
    void* mapping = ::mmap(nullptr, size_t(st.st_size), PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    if (mapping != MAP_FAILED) return InputBytes(static_cast<const char*>(mapping), size_t(st.st_size));
  }
  std::string bytes;
  // A regular file's size is known: one allocation, with a byte to spare for the read that sees
  // its end (growing past it would copy the whole file once more into fresh pages, and first
  // touches of pages are slow on a VM: 41 -> 22 ms for Sponza's 5.6 MB).
  if (S_ISREG(st.st_mode)) bytes.reserve(size_t(st.st_size) + 1);
  constexpr size_t kChunk = 1 << 20;
  for (;;) {
    throw_if_cancelled(cancel);
    // A pipe or FIFO may stay silent: wait in slices, so a cancel is seen whichever thread
    // took the signal. A regular file is always ready.
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, 100);
    if (ready == 0 || (ready < 0 && errno == EINTR)) continue;
    if (bytes.size() > max_bytes) throw too_large();
    const size_t old = bytes.size();
    const size_t chunk = bytes.capacity() > old ? std::min(kChunk, bytes.capacity() - old) : kChunk;
    bytes.resize(old + chunk);
    const ssize_t n = ::read(fd, bytes.data() + old, chunk);
    if (n < 0) {
      if (errno == EINTR) {
        bytes.resize(old);
        continue;
      }
      throw InputError(name + ": read error: " + reason(errno));
    }
    bytes.resize(old + size_t(n));
    if (n == 0) break;
  }
  if (bytes.size() > max_bytes) throw too_large();
  return InputBytes(std::move(bytes));
}

}  // namespace

InputBytes::~InputBytes() {
  if (mapping_) ::munmap(const_cast<char*>(mapping_), size_);
}

InputBytes& InputBytes::operator=(InputBytes&& o) noexcept {
  if (this != &o) {
    if (mapping_) ::munmap(const_cast<char*>(mapping_), size_);
    bytes_ = std::move(o.bytes_);
    mapping_ = std::exchange(o.mapping_, nullptr);
    size_ = std::exchange(o.size_, 0);
  }
  return *this;
}

std::string read_input(const std::string& path, CancelFlag cancel, uint64_t max_bytes) {
  return read_or_map(path, cancel, max_bytes, {.map = false}).release();
}

InputBytes map_input(const std::string& path, CancelFlag cancel, uint64_t max_bytes) {
  return read_or_map(path, cancel, max_bytes, {.map = true});
}

std::string read_back(const std::string& path, uint64_t max_bytes) {
  return read_or_map(path, nullptr, max_bytes, {.map = false, .remember = false}).release();
}

void check_not_an_input(const std::string& path, const std::string& flag) {
  struct stat st {};
  if (path.empty() || path == "-" || ::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return;
  const std::lock_guard lock(g_inputs_mutex);
  for (const InputFile& f : g_inputs) {
    if (f.dev == st.st_dev && f.ino == st.st_ino) {
      throw UsageError(flag + ": '" + path + "' is an input of this run (" + f.name + ")");
    }
  }
}

}  // namespace tracer
