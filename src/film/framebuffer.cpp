#include "film/framebuffer.hpp"

#include <algorithm>
#include <cstdint>

namespace tracer {

uint32_t Framebuffer::min_samples() const {
  uint32_t m = UINT32_MAX;
  for (uint32_t n : samples_) m = std::min(m, n);
  return samples_.empty() ? 0u : m;
}

uint32_t Framebuffer::max_samples() const {
  uint32_t m = 0;
  for (uint32_t n : samples_) m = std::max(m, n);
  return m;
}

}  // namespace tracer
