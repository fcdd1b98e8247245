#include "cli/parse.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "base/errors.hpp"

namespace tracer::cli {

Vec3 parse_vec3(const std::string& flag, const std::string& text) {
  float v[3];
  int n = 0;
  size_t pos = 0;
  bool ok = true;
  while (ok) {
    const size_t comma = text.find(',', pos);
    const std::string part = text.substr(pos, comma == std::string::npos ? std::string::npos : comma - pos);
    if (n == 3) { ok = false; break; }
    const char* b = part.data();
    const char* e = b + part.size();
    const auto [ptr, ec] = std::from_chars(b, e, v[n]);
    if (part.empty() || ec != std::errc{} || ptr != e || !std::isfinite(v[n])) { ok = false; break; }
    ++n;
    if (comma == std::string::npos) break;
    pos = comma + 1;
  }
  if (!ok || n != 3) throw UsageError(flag + ": expected three finite numbers x,y,z, got '" + text + "'");
  return {v[0], v[1], v[2]};
}

void check_range(const std::string& flag, long long value, long long lo, long long hi) {
  if (value < lo || value > hi) {
    throw UsageError(flag + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " + std::to_string(value));
  }
}

void check_range_real(const std::string& flag, double value, double lo, double hi, bool lo_open) {
  const bool below = lo_open ? !(value > lo) : !(value >= lo);
  if (below || !(value <= hi) || !std::isfinite(value)) {
    std::ostringstream s;
    s << flag << ": must be " << (lo_open ? "above " : "at least ") << lo << " and at most " << hi << ", got " << value;
    throw UsageError(s.str());
  }
}

}  // namespace tracer::cli
