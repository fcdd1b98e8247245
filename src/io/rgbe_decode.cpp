#include "io/rgbe_decode.hpp"

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "base/text.hpp"

namespace tracer {
namespace {

class Reader {
 public:
  Reader(std::string_view bytes, const std::string& path) : bytes_(bytes), path_(path) {}
  bool at_end() const { return pos_ >= bytes_.size(); }
  std::string_view line() {
    const size_t end = bytes_.find('\n', pos_);
    if (end == std::string_view::npos) fail("the header has no end");
    const std::string_view l = bytes_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return l;
  }
  uint8_t byte() {
    if (pos_ >= bytes_.size()) fail("truncated: the pixels end before the image does");
    return uint8_t(bytes_[pos_++]);
  }
  [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": " + what); }

 private:
  std::string_view bytes_;
  const std::string& path_;
  size_t pos_ = 0;
};

Vec3 rgbe_to_rgb(const uint8_t c[4]) {
  if (c[3] == 0) return Vec3{0.0f};
  const float f = std::ldexp(1.0f, int(c[3]) - (128 + 8));
  return {float(c[0]) * f, float(c[1]) * f, float(c[2]) * f};
}

}  // namespace

RgbeImage decode_rgbe(std::string_view bytes, const std::string& path,
                      void (*check_size)(const std::string&, long long, long long), CancelFlag cancel) {
  Reader in(bytes, path);
  const std::string_view magic = in.line();
  if (magic != "#?RADIANCE" && magic != "#?RGBE") in.fail("cannot read environment map: not a Radiance HDR file");
  for (std::string_view l = in.line(); !trim(l).empty(); l = in.line()) {
    if (l.substr(0, 7) == "FORMAT=" && trim(l.substr(7)) != "32-bit_rle_rgbe") {
      in.fail("cannot read environment map: format " + in_quotes(l.substr(7)) + " (only 32-bit_rle_rgbe is read)");
    }
  }
  long long h = 0, w = 0;
  {
    const std::string resolution(in.line());
    char yflag[3] = {}, xflag[3] = {};
    int consumed = 0;
    if (std::sscanf(resolution.c_str(), "%2s %lld %2s %lld%n", yflag, &h, xflag, &w, &consumed) != 4 ||
        std::string(yflag) != "-Y" || std::string(xflag) != "+X" || size_t(consumed) != resolution.size()) {
      in.fail("cannot read environment map: resolution line " + in_quotes(resolution) +
              " (only '-Y height +X width' is read)");
    }
  }
  check_size(path, w, h);
  RgbeImage image;
  image.width = int(w);
  image.height = int(h);
  std::vector<uint8_t> scanline(size_t(w) * 4);
  bool flat = w < 8 || w >= 32768;  // run-length scanlines exist only for these widths
  for (long long y = 0; y < h; ++y) {
    if ((y & 15) == 0) throw_if_cancelled(cancel);
    uint8_t head[4] = {in.byte(), in.byte(), in.byte(), in.byte()};
    if (!flat && (head[0] != 2 || head[1] != 2 || (head[2] & 0x80))) flat = true;  // an old flat file
    if (flat) {
      // This scanline's first pixel is the four bytes just read.
      image.texels.push_back(rgbe_to_rgb(head));
      for (long long x = 1; x < w; ++x) {
        const uint8_t c[4] = {in.byte(), in.byte(), in.byte(), in.byte()};
        image.texels.push_back(rgbe_to_rgb(c));
      }
      continue;
    }
    if (((long long)(head[2]) << 8 | head[3]) != w) in.fail("corrupt scanline " + std::to_string(y) + ": wrong width");
    for (int c = 0; c < 4; ++c) {
      for (long long x = 0; x < w;) {
        uint8_t count = in.byte();
        const bool run = count > 128;
        if (run) count = uint8_t(count - 128);
        if (count == 0 || x + count > w) in.fail("corrupt scanline " + std::to_string(y) + ": a run past its end");
        if (run) {
          const uint8_t value = in.byte();
          for (int k = 0; k < count; ++k) scanline[size_t(x++) * 4 + size_t(c)] = value;
        } else {
          for (int k = 0; k < count; ++k) scanline[size_t(x++) * 4 + size_t(c)] = in.byte();
        }
      }
    }
    for (long long x = 0; x < w; ++x) image.texels.push_back(rgbe_to_rgb(&scanline[size_t(x) * 4]));
  }
  return image;
}

}  // namespace tracer
