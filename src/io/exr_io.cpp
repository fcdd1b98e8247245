#include "io/exr_io.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <vector>

#include "base/errors.hpp"
#include "base/read_input.hpp"

namespace tracer {
namespace {

// OpenEXR writes through a stream; this one keeps the bytes in memory, so the file itself is
// written atomically like every other output (write_file_atomic).
class MemoryStream : public Imf::OStream {
 public:
  MemoryStream() : Imf::OStream("memory") {}
  void write(const char c[], int n) override {
    if (pos_ + size_t(n) > bytes_.size()) bytes_.resize(pos_ + size_t(n));
    std::memcpy(bytes_.data() + pos_, c, size_t(n));
    pos_ += size_t(n);
  }
  uint64_t tellp() override { return pos_; }
  void seekp(uint64_t pos) override { pos_ = size_t(pos); }
  std::string take() { return std::move(bytes_); }

 private:
  std::string bytes_;
  size_t pos_ = 0;
};

template <class T>
void add_channels(Imf::Header& header, Imf::FrameBuffer& frame, std::vector<T>& planes, int w, int h,
                  Imf::PixelType type, const std::string& prefix = "",
                  const std::array<const char*, 3>& names = {"R", "G", "B"}) {
  const size_t n = size_t(w) * size_t(h);
  for (int c = 0; c < 3; ++c) {
    if (!names[c]) continue;  // a layer of fewer channels
    const std::string name = prefix.empty() ? std::string(names[c]) : prefix + "." + names[c];
    header.channels().insert(name, Imf::Channel(type));
    frame.insert(name, Imf::Slice(type, reinterpret_cast<char*>(planes.data() + size_t(c) * n), sizeof(T),
                                  sizeof(T) * size_t(w)));
  }
}

// The image as three planes of T. A value beyond T's range (a half holds 65504 at most) or not
// finite is written as the largest finite value of its sign (NaN as 0) and counted: no output
// holds an infinity.
template <class T>
std::vector<T> planar(const Framebuffer& fb, size_t& clamped) {
  const float largest = std::is_same_v<T, half> ? float(HALF_MAX) : std::numeric_limits<float>::max();
  const auto finite = [&](float v) {
    if (std::fabs(v) <= largest) return T(v);
    ++clamped;
    return T(std::isnan(v) ? 0.0f : std::copysign(largest, v));
  };
  const size_t n = size_t(fb.width()) * size_t(fb.height());
  std::vector<T> planes(3 * n);
  for (int y = 0; y < fb.height(); ++y) {
    for (int x = 0; x < fb.width(); ++x) {
      const Vec3 p = fb.radiance(x, y);
      const size_t i = size_t(y) * size_t(fb.width()) + size_t(x);
      planes[i] = finite(p.x);
      planes[n + i] = finite(p.y);
      planes[2 * n + i] = finite(p.z);
    }
  }
  return planes;
}

}  // namespace

std::string encode_exr(const Framebuffer& fb, ExrPixel pixel, const std::vector<ExrLayer>& layers, size_t* clamped) {
  size_t beyond = 0;
  try {
    Imf::Header header(fb.width(), fb.height());
    header.compression() = Imf::ZIP_COMPRESSION;
    Imf::FrameBuffer frame;
    // One set of planes per layer, kept alive until the pixels are written.
    std::vector<std::vector<half>> halves(1 + layers.size());
    std::vector<std::vector<float>> floats(1 + layers.size());
    for (size_t l = 0; l <= layers.size(); ++l) {
      const Framebuffer& image = l == 0 ? fb : *layers[l - 1].image;
      const std::string prefix = l == 0 ? "" : layers[l - 1].name;
      const std::array<const char*, 3> names =
          l == 0 ? std::array<const char*, 3>{"R", "G", "B"} : layers[l - 1].channels;
      if (pixel == ExrPixel::Half) {
        halves[l] = planar<half>(image, beyond);
        add_channels(header, frame, halves[l], fb.width(), fb.height(), Imf::HALF, prefix, names);
      } else {
        floats[l] = planar<float>(image, beyond);
        add_channels(header, frame, floats[l], fb.width(), fb.height(), Imf::FLOAT, prefix, names);
      }
    }
    MemoryStream stream;
    {
      Imf::OutputFile file(stream, header);
      file.setFrameBuffer(frame);
      file.writePixels(fb.height());
    }
    if (clamped) *clamped = beyond;
    return stream.take();
  } catch (const std::exception& e) {
    throw InputError(std::string("EXR encoding failed: ") + e.what());
  }
}

namespace {

// OpenEXR reads through a stream; this one reads bytes already in memory (read once, by
// read_input, with its limits), so the header can be checked before any pixel is decoded.
class MemoryIStream : public Imf::IStream {
 public:
  explicit MemoryIStream(std::string_view bytes) : Imf::IStream("memory"), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (pos_ + size_t(n) > bytes_.size()) throw std::runtime_error("the file ends early");
    std::memcpy(c, bytes_.data() + pos_, size_t(n));
    pos_ += size_t(n);
    return pos_ < bytes_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override { pos_ = size_t(pos); }

 private:
  std::string_view bytes_;
  size_t pos_ = 0;
};

// The data window's size, refused past kMaxImagePixels.
ImageSize window_size(const Imf::Header& header, const std::string& path) {
  const Imath::Box2i window = header.dataWindow();
  const long long w = (long long)window.max.x - window.min.x + 1, h = (long long)window.max.y - window.min.y + 1;
  check_image_size(path, w, h);
  return {int(w), int(h)};
}

}  // namespace

ImageSize exr_size(std::string_view bytes, const std::string& path) {
  try {
    MemoryIStream stream(bytes);
    Imf::InputFile file(stream);
    return window_size(file.header(), path);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read EXR: " + e.what());
  }
}

Framebuffer decode_exr(std::string_view bytes, const std::string& path, const ExrLayer& layer) {
  try {
    MemoryIStream stream(bytes);
    Imf::InputFile file(stream);
    const auto [w, h] = window_size(file.header(), path);
    const Imath::Box2i window = file.header().dataWindow();
    for (int c = 0; c < 3; ++c) {
      if (!layer.channels[c]) continue;
      const std::string name = layer.name.empty() ? layer.channels[c] : layer.name + "." + layer.channels[c];
      if (!file.header().channels().findChannel(name)) throw InputError(path + ": no channel " + name);
    }
    // Nothing is allocated for pixels the file does not hold (a header alone claims any size).
    if (!file.isComplete()) throw InputError(path + ": truncated: the file ends before its pixels do");
    std::vector<float> planes(3 * size_t(w) * size_t(h));
    Imf::FrameBuffer frame;
    for (int c = 0; c < 3; ++c) {
      if (!layer.channels[c]) continue;  // left 0
      const std::string name = layer.name.empty() ? layer.channels[c] : layer.name + "." + layer.channels[c];
      char* base = reinterpret_cast<char*>(planes.data() + size_t(c) * size_t(w) * size_t(h));
      base -= (ptrdiff_t(window.min.x) + ptrdiff_t(window.min.y) * ptrdiff_t(w)) * ptrdiff_t(sizeof(float));
      frame.insert(name, Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * size_t(w)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    Framebuffer fb(w, h);
    const size_t n = size_t(w) * size_t(h);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const size_t i = size_t(y) * size_t(w) + size_t(x);
        fb.set(x, y, Vec3{planes[i], planes[n + i], planes[2 * n + i]});
      }
    }
    return fb;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read EXR: " + e.what());
  }
}

Framebuffer read_exr(const std::string& path, const ExrLayer& layer) {
  return decode_exr(read_back(path), path, layer);
}

}  // namespace tracer
