// The numbers of an OBJ line: coordinates (a fast path for the common "-12.3456", fast_float for
// the rest), face indices, and the error that names the file and line.
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "base/errors.hpp"

namespace tracer {

// Throws InputError("name:line: what").
[[noreturn]] void fail_at(const std::string& name, uint64_t line, const std::string& what);

// One number of a `v`, `vt` or `vn` line: a leading '+' is accepted, a value that underflows reads
// as zero, and anything that is not a finite number within +-kMaxCoordinate is an error.
float parse_coordinate(std::string_view tok, const std::string& name, uint64_t line);

// One index of a corner written plainly: an optional '-' and at most 18 digits; false (p
// unmoved) for anything else.
inline bool parse_plain_index(const char*& p, const char* end, long long& out) {
  const char* q = p;
  const bool negative = q != end && *q == '-';
  q += negative ? 1 : 0;
  uint64_t v = 0;  // unsigned: a longer run of digits wraps (and is refused below), never overflows
  const char* digits = q;
  for (; q != end && static_cast<unsigned>(*q - '0') < 10; ++q) v = v * 10 + uint64_t(*q - '0');
  if (q == digits || q - digits > 18) return false;
  out = negative ? -static_cast<long long>(v) : static_cast<long long>(v);
  p = q;
  return true;
}

// One index of a face corner: an optional sign and decimal digits (a '+' is accepted).
long long parse_index(std::string_view part, std::string_view tok, const std::string& name, uint64_t line);

inline bool is_blank(char c) { return c == ' ' || c == '\t'; }

// The common number of an OBJ, "-12.3456": at most 15 significant digits and no exponent, so the
// digits are exact in a double and one division by an exact power of ten rounds correctly (the
// value fast_float gives). Anything else, and a value outside +-kMaxCoordinate, returns false
// for the full parser to read (or to reject with its message).
inline bool parse_plain_decimal(const char*& p, const char* end, float& out) {
  static constexpr double kPow10[16] = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                        1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15};
  const char* q = p;
  const bool negative = q != end && *q == '-';
  q += negative ? 1 : 0;
  uint64_t mantissa = 0;
  int digits = 0, fraction = 0;
  for (; q != end && static_cast<unsigned>(*q - '0') < 10; ++q, ++digits) mantissa = mantissa * 10 + uint64_t(*q - '0');
  if (q != end && *q == '.') {
    for (++q; q != end && static_cast<unsigned>(*q - '0') < 10; ++q, ++digits, ++fraction) {
      mantissa = mantissa * 10 + uint64_t(*q - '0');
    }
  }
  if (digits == 0 || digits > 15 || (q != end && !is_blank(*q))) return false;
  const double value = double(mantissa) / kPow10[fraction];
  const float f = float(negative ? -value : value);
  if (std::fabs(f) > kMaxCoordinate) return false;
  out = f;
  p = q;
  return true;
}

}  // namespace tracer
