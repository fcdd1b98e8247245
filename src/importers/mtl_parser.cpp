#include "importers/mtl_parser.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "base/number_prefix.hpp"
#include "base/text.hpp"

namespace tracer {
namespace {

[[noreturn]] void fail_at(const std::string& name, size_t line, const std::string& what) {
  throw InputError(name + ":" + std::to_string(line) + ": " + what);
}

// Whether a token begins as a number does (a sign, a point, a digit), or spells a non-finite one:
// a colour's further values and an option's are read while tokens do, and number() refuses the
// malformed ones (`1e`, `0.6ex`), which tinyobjloader would read as zero.
bool starts_number(std::string_view tok) {
  size_t i = !tok.empty() && (tok[0] == '+' || tok[0] == '-') ? 1 : 0;
  if (i < tok.size() && tok[i] == '.') ++i;
  return (i < tok.size() && tok[i] >= '0' && tok[i] <= '9') || is_non_finite_word(tok);
}

// Lines whose statement had text after what it takes, and the lines before the first `newmtl`:
// harmless in the files of real exporters, said once per file, with the lines.
class LineList {
 public:
  void add(size_t line, std::string_view example) {
    if (count_++ == 0) first_ = std::string(example);
    if (lines_.size() < kShown) lines_.push_back(line);
  }
  size_t count() const { return count_; }
  std::string describe() const {
    std::string s = count_ == 1 ? "line " : "lines ";
    for (size_t i = 0; i < lines_.size(); ++i) s += (i ? ", " : "") + std::to_string(lines_[i]);
    if (count_ > lines_.size()) s += " and " + std::to_string(count_ - lines_.size()) + " more";
    return s + " (first: " + in_quotes(first_) + ")";
  }

 private:
  static constexpr size_t kShown = 8;
  size_t count_ = 0;
  std::vector<size_t> lines_;
  std::string first_;
};

class Statement {
 public:
  Statement(std::string_view rest, std::string_view keyword, const std::string& name, size_t line)
      : rest_(rest), keyword_(keyword), name_(name), line_(line) {}

  bool done() const { return trim(rest_).empty(); }
  std::string_view peek() const {
    std::string_view copy = rest_;
    return next_token(copy);
  }
  std::string_view token() { return next_token(rest_); }
  std::string_view rest() const { return trim(rest_); }
  // What was dropped: letters glued to a number, and text after what the statement takes.
  std::string_view ignored() const { return ignored_; }
  void ignore_rest() {
    if (!done() && ignored_.empty()) ignored_ = rest();
    rest_ = {};
  }

  // One number in [lo, hi]: the number that starts the token (letters glued to it are dropped,
  // as tinyobjloader drops them), refused where none does, and where it is not finite or out of
  // range: those would make the image wrong.
  float number(float lo, float hi) {
    const std::string_view tok = token();
    if (tok.empty()) fail("'" + std::string(keyword_) + "' needs a number");
    if (is_non_finite_word(tok))
      fail("'" + std::string(keyword_) + "' value " + in_quotes(tok) + " is not a finite number");
    const size_t length = number_prefix_length(tok);
    if (length == 0) fail("malformed number " + in_quotes(tok));
    if (length < tok.size() && ignored_.empty()) ignored_ = tok;
    const double value = number_prefix_value(tok.substr(0, length));
    if (!std::isfinite(value))
      fail("'" + std::string(keyword_) + "' value " + in_quotes(tok) + " is not a finite number");
    if (!(value >= double(lo) && value <= double(hi))) {
      char range[64];
      std::snprintf(range, sizeof range, "[%g, %g]", double(lo), double(hi));
      fail("'" + std::string(keyword_) + "' value " + in_quotes(tok) + " out of range " + range);
    }
    return float(value);
  }

  // A whole number in [lo, hi]: the integer that starts the token (`illum 2.5` reads 2, as
  // tinyobjloader's atoi reads it).
  int whole_number(int lo, int hi) {
    const std::string_view tok = token();
    if (tok.empty()) fail("'" + std::string(keyword_) + "' needs a number");
    if (is_non_finite_word(tok))
      fail("'" + std::string(keyword_) + "' value " + in_quotes(tok) + " is not a finite number");
    const size_t sign = tok.front() == '+' || tok.front() == '-' ? 1 : 0;
    size_t end = sign;
    while (end < tok.size() && tok[end] >= '0' && tok[end] <= '9') ++end;
    if (end == sign) fail("malformed number " + in_quotes(tok));
    if (end < tok.size() && ignored_.empty()) ignored_ = tok;
    long long value = 0;
    const char* first = tok.data() + (tok.front() == '+' ? 1 : 0);
    const auto [ptr, ec] = std::from_chars(first, tok.data() + end, value);
    if (ec != std::errc{} || value < lo || value > hi) {
      fail("'" + std::string(keyword_) + "' value " + in_quotes(tok) + " out of range [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
    }
    return int(value);
  }

  // `K? r [g b]`: one value is grey (as the format says); `K? xyz x [y z]` a CIE XYZ colour.
  // Two values are an error (a missing number); what follows three is dropped.
  Vec3 colour(float hi) {
    if (peek() == "spectral") fail("'" + std::string(keyword_) + " spectral' is not supported (tracer renders RGB)");
    const bool xyz = peek() == "xyz";
    if (xyz) token();
    // XYZ white (D65) reaches Z = 1.089 for RGB white: XYZ values may exceed the RGB range.
    const float limit = xyz ? 2.0f * hi : hi;
    float c[3];
    c[0] = number(0.0f, limit);
    int n = 1;
    while (n < 3 && starts_number(peek())) c[n++] = number(0.0f, limit);
    if (n == 2) fail("'" + std::string(keyword_) + "' needs one value or three, got two");
    if (n == 1) c[1] = c[2] = c[0];
    if (!xyz) return {c[0], c[1], c[2]};
    // CIE XYZ (D65) to linear sRGB, clamped to what the range allows.
    const auto clamp = [hi](float v) { return std::fmin(std::fmax(v, 0.0f), hi); };
    return {clamp(3.2406f * c[0] - 1.5372f * c[1] - 0.4986f * c[2]),
            clamp(-0.9689f * c[0] + 1.8758f * c[1] + 0.0415f * c[2]),
            clamp(0.0557f * c[0] - 0.2040f * c[1] + 1.0570f * c[2])};
  }

  // `map_* [-option value...] file`: the options' values consumed, the file name (the rest of the
  // line: it may hold spaces) returned. An option is read as one only where more text follows it,
  // as tinyobjloader reads it. `-o`, `-s`, `-t` take one to three numbers and `-mm` one or two (the
  // format's counts; tinyobjloader always takes three and two); `bump_multiplier` receives -bm.
  std::string texture(float* bump_multiplier, LineList& unknown_options) {
    for (;;) {
      std::string_view after = rest_;
      const std::string_view option = next_token(after);
      const bool letter = option.size() > 1 && ((option[1] | 0x20) >= 'a' && (option[1] | 0x20) <= 'z');
      if (option.empty() || option.front() != '-' || !letter || trim(after).empty()) break;
      token();
      if (option == "-bm") {
        const float bm = number(-1e6f, 1e6f);
        if (bump_multiplier) *bump_multiplier = bm;
      } else if (option == "-o" || option == "-s" || option == "-t" || option == "-mm") {
        number(-1e6f, 1e6f);
        for (int i = option == "-mm" ? 1 : 2; i > 0 && starts_number(peek()) && more_than_one_token(); --i) {
          number(-1e6f, 1e6f);
        }
      } else {
        static constexpr std::string_view kOneWord[] = {"-blendu", "-blendv", "-cc",    "-clamp",     "-imfchan",
                                                        "-type",   "-texres", "-boost", "-colorspace"};
        bool known = false;
        for (std::string_view k : kOneWord) known = known || option == k;
        if (!known) unknown_options.add(line_, option);
        if (known || more_than_one_token()) token();  // its value (an unknown option's: assumed one)
      }
      if (done()) fail("'" + std::string(keyword_) + "' option " + in_quotes(option) + " leaves no file name");
    }
    const std::string_view file = rest();
    if (file.empty()) fail("'" + std::string(keyword_) + "' needs a file name");
    rest_ = {};
    return std::string(file);
  }

  [[noreturn]] void fail(const std::string& what) const { fail_at(name_, line_, what); }

 private:
  bool more_than_one_token() const {
    std::string_view copy = rest_;
    next_token(copy);
    return !trim(copy).empty();
  }

  std::string_view rest_;
  std::string_view keyword_;
  const std::string& name_;
  size_t line_;
  std::string_view ignored_;
};

bool is_known(std::string_view k) {
  static constexpr std::string_view kKnown[] = {"Ka",   "Kd",     "Ks",     "Ke",     "Tf",     "Kt",       "Ns",
                                                "Ni",   "d",      "Tr",     "illum",  "map_Kd", "map_bump", "map_Bump",
                                                "bump", "map_Ks", "map_Ns", "map_Ke", "norm"};
  for (std::string_view known : kKnown) {
    if (k == known) return true;
  }
  return false;
}

}  // namespace

MtlFile parse_mtl(std::string_view text, const std::string& name, CancelFlag cancel) {
  MtlFile out;
  std::vector<MtlMaterial>& materials = out.materials;
  MtlMaterial* m = nullptr;
  bool has_kd = false, has_d = false;
  LineList trailing, orphans, unknown_options;
  for_each_line(text, [&](std::string_view line, size_t line_no) {
    if (line_no % 4096 == 0) throw_if_cancelled(cancel);
    // A NUL ends the line's text, as for the C-string readers (it is no character of a name).
    if (const size_t nul = line.find('\0'); nul != std::string_view::npos) {
      trailing.add(line_no, line.substr(0, nul));
      line = line.substr(0, nul);
    }
    line = line.substr(0, line.find('#'));
    std::string_view rest = line;
    const std::string_view keyword = next_token(rest);
    if (keyword.empty()) return;
    Statement st(rest, keyword, name, line_no);
    if (keyword == "newmtl") {
      const std::string_view material = st.token();
      if (material.empty()) st.fail("'newmtl' needs a name");
      materials.push_back(MtlMaterial{});
      m = &materials.back();
      m->name = std::string(material);
      m->line = line_no;
      has_kd = has_d = false;
      st.ignore_rest();
      if (!st.ignored().empty()) trailing.add(line_no, trim(line));
      return;
    }
    if (!is_known(keyword)) return;  // statements the renderer does not use
    if (!m) {
      orphans.add(line_no, trim(line));
      return;
    }
    if (keyword == "Ka") {
      m->ka = st.colour(kMaxReflectance);
    } else if (keyword == "Kd") {
      m->kd = st.colour(kMaxReflectance);
      has_kd = true;
    } else if (keyword == "Ks") {
      m->ks = st.colour(kMaxReflectance);
    } else if (keyword == "Ke") {
      m->ke = st.colour(kMaxEmission);
    } else if (keyword == "Tf" || keyword == "Kt") {
      m->tf = st.colour(kMaxReflectance);
    } else if (keyword == "map_Kd") {
      m->diffuse_map = st.texture(nullptr, unknown_options);
      // A texture with no Kd: tinyobjloader's and most viewers' grey, so the texture shows.
      if (!has_kd) m->kd = Vec3{0.6f};
    } else if (keyword == "map_bump" || keyword == "map_Bump" || keyword == "bump") {
      m->bump_map = st.texture(&m->bump_multiplier, unknown_options);
    } else if (keyword == "map_Ks") {
      m->specular_map = st.texture(nullptr, unknown_options);
    } else if (keyword == "map_Ns") {
      m->shininess_map = st.texture(nullptr, unknown_options);
    } else if (keyword == "map_Ke") {
      m->emissive_map = st.texture(nullptr, unknown_options);
    } else if (keyword == "norm") {
      m->normal_map = st.texture(&m->normal_scale, unknown_options);
    } else if (keyword == "Ns") {
      m->ns = st.number(0.0f, kMaxShininess);
    } else if (keyword == "Ni") {
      m->ni = st.number(0.0f, kMaxIor);
    } else if (keyword == "d") {
      m->dissolve = st.number(0.0f, 1.0f);
      has_d = true;
    } else if (keyword == "Tr") {
      const float tr = st.number(0.0f, 1.0f);
      if (!has_d) m->dissolve = 1.0f - tr;  // `d` wins where both are given
    } else if (keyword == "illum") {
      m->illum = st.whole_number(0, 10);
    }
    st.ignore_rest();
    if (!st.ignored().empty()) trailing.add(line_no, trim(line));
  });
  if (trailing.count() > 0) out.warnings.push_back(name + ": ignored trailing text on " + trailing.describe());
  if (orphans.count() > 0) {
    out.warnings.push_back(name + ": statements before the first 'newmtl' ignored on " + orphans.describe());
  }
  if (unknown_options.count() > 0) {
    out.warnings.push_back(name + ": unknown texture options skipped with one value each on " +
                           unknown_options.describe());
  }
  if (materials.empty() && !trim(text).empty()) {
    out.warnings.push_back(name + ": defines no material (no 'newmtl'): is it an MTL file?");
  }
  return out;
}

}  // namespace tracer
