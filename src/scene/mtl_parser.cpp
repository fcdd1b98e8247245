#include "scene/mtl_parser.hpp"

#include <charconv>
#include <cmath>

#include "base/text.hpp"

namespace tracer {
namespace {

[[noreturn]] void fail_at(const std::string& name, size_t line, const std::string& what) {
  throw InputError(name + ":" + std::to_string(line) + ": " + what);
}

bool is_number(std::string_view tok) {
  if (tok.empty()) return false;
  const char c = tok.front();
  return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

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

  // One number in [lo, hi]; `what` names the quantity in the message.
  float number(float lo, float hi) {
    const std::string_view tok = token();
    if (tok.empty()) fail("'" + std::string(keyword_) + "' needs a number");
    std::string_view digits = tok;
    if (digits.size() > 1 && digits.front() == '+' && digits[1] != '-' && digits[1] != '+') digits.remove_prefix(1);
    double value = 0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ptr != digits.data() + digits.size() || (ec != std::errc{} && ec != std::errc::result_out_of_range)) {
      fail("malformed number " + in_quotes(tok));
    }
    if (ec == std::errc::result_out_of_range && std::fabs(std::strtod(std::string(digits).c_str(), nullptr)) < 1.0) {
      value = 0.0;  // underflow: as good as zero
    } else if (ec == std::errc::result_out_of_range || !std::isfinite(value)) {
      fail("'" + std::string(keyword_) + "' value " + in_quotes(tok) + " is not a finite number");
    }
    if (!(value >= double(lo) && value <= double(hi))) {
      char range[64];
      std::snprintf(range, sizeof range, "[%g, %g]", double(lo), double(hi));
      fail("'" + std::string(keyword_) + "' value " + in_quotes(tok) + " out of range " + range);
    }
    return float(value);
  }

  // `K? r [g b]`: one value is grey; `K? xyz x [y z]` a CIE XYZ colour.
  Vec3 colour(float hi) {
    if (peek() == "spectral") fail("'" + std::string(keyword_) + " spectral' is not supported (tracer renders RGB)");
    const bool xyz = peek() == "xyz";
    if (xyz) token();
    // XYZ white (D65) reaches Z = 1.089 for RGB white: XYZ values may exceed the RGB range.
    const float limit = xyz ? 2.0f * hi : hi;
    float c[3];
    c[0] = number(0.0f, limit);
    int n = 1;
    while (n < 3 && !done()) c[n++] = number(0.0f, limit);
    if (n == 2) fail("'" + std::string(keyword_) + "' needs one value or three, got two");
    if (!done()) fail("'" + std::string(keyword_) + "' has more than three values");
    if (n == 1) c[1] = c[2] = c[0];
    if (!xyz) return {c[0], c[1], c[2]};
    // CIE XYZ (D65) to linear sRGB, clamped to what the range allows.
    const auto clamp = [hi](float v) { return std::fmin(std::fmax(v, 0.0f), hi); };
    return {clamp(3.2406f * c[0] - 1.5372f * c[1] - 0.4986f * c[2]),
            clamp(-0.9689f * c[0] + 1.8758f * c[1] + 0.0415f * c[2]),
            clamp(0.0557f * c[0] - 0.2040f * c[1] + 1.0570f * c[2])};
  }

  // `map_* [-option value...] file`: the options' values consumed, the file name returned (it may
  // hold spaces). `bump_multiplier` receives -bm.
  std::string texture(float* bump_multiplier) {
    while (peek().size() > 1 && peek().front() == '-' && !is_number(peek().substr(1))) {
      const std::string_view option = token();
      int values = 1;
      bool up_to_three = false;
      if (option == "-mm") values = 2;
      if (option == "-o" || option == "-s" || option == "-t") up_to_three = true;
      if (option == "-bm") {
        const float bm = number(-1e6f, 1e6f);
        if (bump_multiplier) *bump_multiplier = bm;
        continue;
      }
      if (up_to_three) {
        number(-1e6f, 1e6f);
        for (int i = 0; i < 2 && is_number(peek()) && !trim(rest_).empty() && has_more_than_one_token(); ++i) {
          number(-1e6f, 1e6f);
        }
        continue;
      }
      for (int i = 0; i < values; ++i) {
        if (token().empty()) fail("'" + std::string(keyword_) + "' option " + in_quotes(option) + " needs a value");
      }
    }
    const std::string_view file = rest();
    if (file.empty()) fail("'" + std::string(keyword_) + "' needs a file name");
    return std::string(file);
  }

  [[noreturn]] void fail(const std::string& what) const { fail_at(name_, line_, what); }

 private:
  // Whether a token follows the next one: the file name must be left after an option's values.
  bool has_more_than_one_token() const {
    std::string_view copy = rest_;
    next_token(copy);
    return !trim(copy).empty();
  }

  std::string_view rest_;
  std::string_view keyword_;
  const std::string& name_;
  size_t line_;
};

}  // namespace

std::vector<MtlMaterial> parse_mtl(std::string_view text, const std::string& name, CancelFlag cancel) {
  std::vector<MtlMaterial> materials;
  MtlMaterial* m = nullptr;
  bool has_kd = false, has_d = false;
  for_each_line(text, [&](std::string_view line, size_t line_no) {
    if (line_no % 4096 == 0) throw_if_cancelled(cancel);
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
      return;
    }
    const bool known = keyword == "Ka" || keyword == "Kd" || keyword == "Ks" || keyword == "Ke" || keyword == "Tf" ||
                       keyword == "Kt" || keyword == "Ns" || keyword == "Ni" || keyword == "d" || keyword == "Tr" ||
                       keyword == "illum" || keyword == "map_Kd" || keyword == "map_bump" || keyword == "bump" ||
                       keyword == "map_Bump";
    if (!known) return;  // statements the renderer does not use
    if (!m) st.fail("'" + std::string(keyword) + "' before any 'newmtl'");
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
      m->diffuse_map = st.texture(nullptr);
      // A texture with no Kd: tinyobjloader's and most viewers' grey, so the texture shows.
      if (!has_kd) m->kd = Vec3{0.6f};
      return;
    } else if (keyword == "map_bump" || keyword == "map_Bump" || keyword == "bump") {
      m->bump_map = st.texture(&m->bump_multiplier);
      return;
    } else {
      float value = 0.0f;
      if (keyword == "Ns") value = m->ns = st.number(0.0f, kMaxShininess);
      if (keyword == "Ni") value = m->ni = st.number(0.0f, kMaxIor);
      if (keyword == "d") {
        m->dissolve = st.number(0.0f, 1.0f);
        has_d = true;
      }
      if (keyword == "Tr") {
        value = st.number(0.0f, 1.0f);
        if (!has_d) m->dissolve = 1.0f - value;  // `d` wins where both are given
      }
      if (keyword == "illum") {
        value = st.number(0.0f, 10.0f);
        if (value != std::floor(value)) st.fail("'illum' takes a whole number from 0 to 10");
        m->illum = int(value);
      }
    }
    if (!st.done()) st.fail("'" + std::string(keyword) + "' has an extra value " + in_quotes(st.token()));
  });
  return materials;
}

}  // namespace tracer
