// The grammar of a number that is a whole word: a flag's value (frontend/parse.hpp, the settings
// table) and a field of views.tsv. std::from_chars over all of the word: an optional '-', digits,
// a point, an exponent, inf and nan; no '+', no spaces, no hex, nothing after. It differs on
// purpose from the two file grammars: OBJ coordinates (importers/obj_numbers.hpp) and MTL values
// (base/number_prefix.hpp) take a number's prefix as tinyobjloader does, because real exporters
// glue text to numbers; a value typed on a command line or in a table has no such excuse.
#pragma once

#include <charconv>
#include <string_view>
#include <system_error>

namespace tracer {

enum class WholeNumber { Ok, NotANumber, OutOfRange };

// `text` read whole as a T (an integer or floating type); OutOfRange for a number beyond T.
template <class T>
WholeNumber read_whole_number(std::string_view text, T& out) {
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  if (text.empty() || ptr != text.data() + text.size()) return WholeNumber::NotANumber;
  if (ec == std::errc::result_out_of_range) return WholeNumber::OutOfRange;
  return ec == std::errc{} ? WholeNumber::Ok : WholeNumber::NotANumber;
}

}  // namespace tracer
