// Warnings grouped by kind, as every importer reports them: one line per kind with a count and
// the first place, not one line per occurrence.
#pragma once

#include <functional>
#include <iostream>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "base/text.hpp"

namespace tracer {

// Receives non-fatal problems (a missing MTL or texture), one line per kind of problem with a
// count and the first place; the default prints to stderr.
using WarningSink = std::function<void(const std::string&)>;

inline void default_warning(const std::string& message) { std::cerr << "tracer: warning: " << message << "\n"; }

// Groups warnings by kind (the text with its quoted names and numbers left out), so 80,000
// undefined material names make one line with a count and the first place, not 80,000 lines.
class WarningLog {
 public:
  void add(const std::string& message) {
    const std::string key = kind_of(message);
    auto [it, inserted] = index_.try_emplace(key, entries_.size());
    if (inserted) entries_.push_back({message, 0});
    ++entries_[it->second].count;
  }
  void flush(const std::string& name, const WarningSink& sink) const {
    for (const Entry& e : entries_) {
      std::string line = name + ": " + escaped(e.first);
      if (e.count > 1) line += " (" + std::to_string(e.count) + " times; the first shown)";
      sink(line);
    }
  }

 private:
  static std::string kind_of(std::string_view message) {
    std::string key;
    char quote = 0;
    for (char c : message) {
      if (quote) {
        if (c == quote) quote = 0, key += c;
        continue;
      }
      if (c == '\'' || c == '"') quote = c;
      if (c >= '0' && c <= '9') {
        if (key.empty() || key.back() != '#') key += '#';
        continue;
      }
      key += c;
    }
    return key;
  }
  struct Entry {
    std::string first;
    size_t count;
  };
  std::vector<Entry> entries_;
  std::unordered_map<std::string, size_t> index_;
};

}  // namespace tracer
