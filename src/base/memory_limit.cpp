#include "base/memory_limit.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace tracer {
namespace {

// A "Key:   123 kB" line of a /proc file, in bytes, or 0.
uint64_t proc_kib(const char* path, const std::string& key) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ":", 0) == 0) {
      uint64_t kib = 0;
      std::istringstream(line.substr(key.size() + 1)) >> kib;
      return kib * 1024;
    }
  }
  return 0;
}

// One number in a file ("max" and unreadable files: none).
uint64_t file_number(const std::string& path) {
  std::ifstream in(path);
  uint64_t v = 0;
  return in >> v ? v : UINT64_MAX;
}

// The cgroup v2 folder of this process ("0::/path" in /proc/self/cgroup).
std::string own_cgroup() {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("0::", 0) == 0) return "/sys/fs/cgroup" + line.substr(3);
  }
  return {};
}

}  // namespace

uint64_t available_memory_bytes() {
  uint64_t available = proc_kib("/proc/meminfo", "MemAvailable");
  if (available == 0) available = UINT64_MAX;
  rlimit as{};
  if (getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    const uint64_t mapped = proc_kib("/proc/self/status", "VmSize");
    available = std::min<uint64_t>(available, as.rlim_cur > mapped ? as.rlim_cur - mapped : 0);
  }
  // The cgroup's limit, or its parents' (a container's limit often sits one level up).
  for (std::string dir = own_cgroup(); dir.size() > std::string("/sys/fs/cgroup").size();
       dir = dir.substr(0, dir.rfind('/'))) {
    const uint64_t max = file_number(dir + "/memory.max"), used = file_number(dir + "/memory.current");
    if (max != UINT64_MAX && used != UINT64_MAX) available = std::min(available, max > used ? max - used : 0);
  }
  return available;
}

uint64_t default_memory_limit() {
  const uint64_t available = available_memory_bytes();
  const uint64_t margin = std::max<uint64_t>(available / 10, uint64_t(256) << 20);
  return available > margin ? available - margin : 0;
}

std::string format_bytes(uint64_t bytes) {
  char text[32];
  if (bytes >= (uint64_t(1) << 30)) {
    std::snprintf(text, sizeof text, "%.2f GiB", double(bytes) / double(uint64_t(1) << 30));
  } else if (bytes >= (uint64_t(1) << 20)) {
    std::snprintf(text, sizeof text, "%" PRIu64 " MiB", bytes >> 20);
  } else if (bytes >= 1024) {
    std::snprintf(text, sizeof text, "%" PRIu64 " KiB", bytes >> 10);
  } else {
    std::snprintf(text, sizeof text, "%" PRIu64 " bytes", bytes);
  }
  return text;
}

std::string memory_refusal(const std::string& what, uint64_t estimate, uint64_t limit) {
  return what + ": about " + format_bytes(estimate) + " needed, more than the memory limit of " + format_bytes(limit) +
         " (--max-memory-mib; by default the memory available less a margin)";
}

}  // namespace tracer
