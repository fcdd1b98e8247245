// One table per enum gives its values' names: what flags accept, what --help, --stats and the JSON
// print, and what error messages list.
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "base/errors.hpp"

namespace tracer {

template <class E>
struct EnumName {
  E value;
  std::string_view name;
};

template <class E>
std::string_view name_of(std::span<const EnumName<E>> table, E value) {
  for (const EnumName<E>& e : table) {
    if (e.value == value) return e.name;
  }
  return "?";
}

// "a, b, c": the accepted names, for help texts and messages.
template <class E>
std::string names_of(std::span<const EnumName<E>> table) {
  std::string out;
  for (const EnumName<E>& e : table) out += (out.empty() ? "" : ", ") + std::string(e.name);
  return out;
}

// The value named exactly `text` (names are lower case, and every flag reads them alike: "HIGH"
// is no more a quality than "PATH" an integrator), or a UsageError "FLAG: unknown WHAT 'text'
// (names)".
template <class E>
E parse_name(std::span<const EnumName<E>> table, std::string_view text, const std::string& flag,
             const std::string& what) {
  for (const EnumName<E>& e : table) {
    if (e.name == text) return e.value;
  }
  throw UsageError(flag + ": unknown " + what + " '" + std::string(text) + "' (" + names_of(table) + ")");
}

}  // namespace tracer
