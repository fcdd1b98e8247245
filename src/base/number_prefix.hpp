// The number at the start of a token, as the common OBJ/MTL readers (tinyobjloader's
// tryParseDouble) delimit it: [sign] digits [. digits] [(e|E) [sign] digits], or [sign] . digits
// [exponent]. Real exporters glue letters to numbers (`0.0000c`); such readers take the number and
// drop the rest, and so does tracer, with a warning.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>

namespace tracer {

// The length of the number that starts `tok`, or 0 if none does. An exponent marker must be
// followed by digits (`1e` and `1e+` are no numbers, as in tinyobjloader), and at least one
// digit must stand before or after the point (unlike tinyobjloader, `.` alone is no number).
inline size_t number_prefix_length(std::string_view tok) {
  const auto digit = [&](size_t i) { return i < tok.size() && tok[i] >= '0' && tok[i] <= '9'; };
  size_t i = 0;
  if (i < tok.size() && (tok[i] == '+' || tok[i] == '-')) ++i;
  size_t digits = 0;
  while (digit(i)) ++i, ++digits;
  if (i < tok.size() && tok[i] == '.') {
    ++i;
    while (digit(i)) ++i, ++digits;
  }
  if (digits == 0) return 0;
  if (i < tok.size() && (tok[i] == 'e' || tok[i] == 'E')) {
    size_t j = i + 1;
    if (j < tok.size() && (tok[j] == '+' || tok[j] == '-')) ++j;
    if (!digit(j)) return 0;
    while (digit(j)) ++j;
    i = j;
  }
  return i;
}

// Whether `tok` spells infinity or not-a-number (`nan`, `-inf`, `Infinity`, ...): words a reader
// must refuse rather than read as zero.
inline bool is_non_finite_word(std::string_view tok) {
  if (!tok.empty() && (tok.front() == '+' || tok.front() == '-')) tok.remove_prefix(1);
  const auto starts = [&](std::string_view word) {
    if (tok.size() < word.size()) return false;
    for (size_t i = 0; i < word.size(); ++i) {
      if ((tok[i] | 0x20) != word[i]) return false;
    }
    return true;
  };
  return starts("nan") || starts("inf");
}

// The value of a number_prefix_length() prefix, correctly rounded; a value beyond double's range
// reads as infinity and one below it as zero.
inline double number_prefix_value(std::string_view number) {
  if (!number.empty() && number.front() == '+') number.remove_prefix(1);
  double value = 0;
  const auto [ptr, ec] = std::from_chars(number.data(), number.data() + number.size(), value);
  if (ec == std::errc::result_out_of_range) {
    // from_chars leaves `value` unset here: the sign and magnitude from strtod.
    value = std::strtod(std::string(number).c_str(), nullptr);
  }
  return value;
}

}  // namespace tracer
