// Small helpers for reading line-oriented text (OBJ, MTL) and for quoting it in messages.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace tracer {

inline std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// The next space- or tab-separated token of `s`, removed from it.
inline std::string_view next_token(std::string_view& s) {
  s = trim(s);
  size_t end = 0;
  while (end < s.size() && s[end] != ' ' && s[end] != '\t') ++end;
  std::string_view tok = s.substr(0, end);
  s.remove_prefix(end);
  return tok;
}

// Control characters and bytes outside printable ASCII as C escapes, so a message quoting file
// content stays one readable line on any terminal.
inline std::string escaped(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n')
      out += "\\n";
    else if (c == '\r')
      out += "\\r";
    else if (c == '\t')
      out += "\\t";
    else if (c < 0x20 || c == 0x7f) {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02x", c);
      out += b;
    } else {
      out += ch;  // printable ASCII, and UTF-8 sequences left intact
    }
  }
  return out;
}

// A token for a message: escaped, at most 40 bytes, in single quotes.
inline std::string in_quotes(std::string_view tok) {
  return "'" + escaped(tok.substr(0, 40)) + (tok.size() > 40 ? "...'" : "'");
}

// A number for a message, in at most six significant digits ("1e+300", not 300 digits).
inline std::string format_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

// Calls fn(line, number) for every line, numbered from 1, split at "\n", "\r\n" and a lone "\r"
// (as the OBJ parser splits them, and as old Mac exporters end lines).
template <class Fn>
void for_each_line(std::string_view text, Fn&& fn) {
  size_t line_no = 0;
  size_t pos = 0;
  while (pos < text.size()) {
    size_t end = pos;
    while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
    fn(text.substr(pos, end - pos), ++line_no);
    if (end < text.size() && text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n') ++end;
    pos = end + 1;
  }
}

// A UTF-8 byte-order mark at the start of a text file is not content.
inline void strip_bom(std::string& text) {
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
}

}  // namespace tracer
