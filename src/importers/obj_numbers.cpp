#include "importers/obj_numbers.hpp"

#include <fast_float/fast_float.h>

#include <charconv>
#include <cmath>
#include <cstdint>

#include "base/text.hpp"

namespace tracer {

[[noreturn]] void fail_at(const std::string& name, uint64_t line, const std::string& what) {
  throw InputError(name + ":" + std::to_string(line) + ": " + what);
}

float parse_coordinate(std::string_view tok, const std::string& name, uint64_t line) {
  std::string_view digits = tok;
  if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
  double value = 0;
  const auto r = fast_float::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (r.ec != std::errc{} || r.ptr != digits.data() + digits.size()) {
    fail_at(name, line, "malformed number " + in_quotes(tok));
  }
  if (std::isfinite(value)) {
    const float f = float(value);
    if (std::fabs(f) <= kMaxCoordinate) return f;
    fail_at(name, line,
            "number out of range " + in_quotes(tok) + " (coordinates must lie within +-" + kMaxCoordinateText + ")");
  }
  // fast_float reads digits beyond double's range as infinity; "inf" and "nan" are words.
  const char first = digits[digits.front() == '-' ? 1 : 0];
  if ((first >= '0' && first <= '9') || first == '.') fail_at(name, line, "number out of range " + in_quotes(tok));
  fail_at(name, line, "non-finite coordinate " + in_quotes(tok));
}

long long parse_index(std::string_view part, std::string_view tok, const std::string& name, uint64_t line) {
  const char* p = part.data();
  const char* const e = p + part.size();
  if (e - p > 1 && *p == '+' && p[1] != '-' && p[1] != '+') ++p;
  long long index = 0;
  if (const char* q = p; parse_plain_index(q, e, index) && q == e) return index;
  const auto [ptr, ec] = std::from_chars(p, e, index);
  if (p == e || ec != std::errc{} || ptr != e) fail_at(name, line, "malformed face index " + in_quotes(tok));
  return index;
}

}  // namespace tracer
