// How much memory this process may still take, and bytes written for a person. A load or a
// render that its estimate says will not fit is refused up front with one line naming the
// estimate and the limit, instead of being killed by the kernel (or std::bad_alloc) minutes in.
#pragma once

#include <cstdint>
#include <string>

namespace tracer {

// The least of: the machine's MemAvailable (/proc/meminfo), the address space left under
// RLIMIT_AS (ulimit -v), and the memory left under this process's cgroup limit (memory.max).
uint64_t available_memory_bytes();

// What --max-memory-mib defaults to: the available memory less a margin (a tenth of it, at least
// 256 MiB) for what no estimate counts (libraries, thread stacks, the allocator's slack).
uint64_t default_memory_limit();

// "4.70 GiB", "312 MiB", "12 KiB", "100 bytes".
std::string format_bytes(uint64_t bytes);

// The one-line message of a refusal: "`what`: about E needed, more than the memory limit of L
// (--max-memory-mib; ...)".
std::string memory_refusal(const std::string& what, uint64_t estimate, uint64_t limit);

}  // namespace tracer
