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

// The value named `text` (case-insensitive), or a UsageError "FLAG: unknown WHAT 'text' (names)".
template <class E>
E parse_name(std::span<const EnumName<E>> table, std::string_view text, const std::string& flag,
             const std::string& what) {
  for (const EnumName<E>& e : table) {
    if (e.name.size() != text.size()) continue;
    bool same = true;
    for (size_t i = 0; i < text.size() && same; ++i) {
      const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? char(c - 'A' + 'a') : c; };
      same = lower(text[i]) == e.name[i];
    }
    if (same) return e.value;
  }
  throw UsageError(flag + ": unknown " + what + " '" + std::string(text) + "' (" + names_of(table) + ")");
}

}  // namespace tracer
