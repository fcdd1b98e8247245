#include "io/read_input.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

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

}  // namespace

std::string read_input(const std::string& path, CancelFlag cancel) {
  const bool stdin_input = path == "-";
  const std::string name = stdin_input ? "<stdin>" : path;
  const int fd = stdin_input ? STDIN_FILENO : ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
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
  std::string bytes;
  if (S_ISREG(st.st_mode)) bytes.reserve(size_t(st.st_size));
  constexpr size_t kChunk = 1 << 20;
  for (;;) {
    throw_if_cancelled(cancel);
    // A pipe or FIFO may stay silent: wait in slices, so a cancel is seen whichever thread
    // took the signal. A regular file is always ready.
    pollfd pfd{fd, POLLIN, 0};
    const int ready = ::poll(&pfd, 1, 100);
    if (ready == 0 || (ready < 0 && errno == EINTR)) continue;
    const size_t old = bytes.size();
    bytes.resize(old + kChunk);
    const ssize_t n = ::read(fd, bytes.data() + old, kChunk);
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
  return bytes;
}

}  // namespace tracer
