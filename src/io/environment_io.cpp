#include "io/environment_io.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStdIO.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>

#include "base/read_input.hpp"
#include "io/rgbe_decode.hpp"

namespace tracer {

namespace {

void check_size(const std::string& path, long long w, long long h) {
  if (w < 2 || h < 1) throw InputError(path + ": an environment map needs at least 2 x 1 texels");
  if (uint64_t(w) * uint64_t(h) > kMaxEnvironmentTexels || w > 65536 || h > 65536) {
    throw InputError(path + ": environment map of " + std::to_string(w) + " x " + std::to_string(h) +
                     " texels is larger than the 16384 x 8192 allowed");
  }
}

EnvironmentMap read_exr_map(const std::string& path, double rotation, CancelFlag cancel) {
  // Read whole first (an input like any other: its identity remembered, a FIFO cancellable).
  Imf::StdISStream stream;
  stream.str(read_input(path, cancel, kMaxEnvironmentTexels * 16 + (uint64_t(1) << 20)));
  try {
    Imf::InputFile file(stream);
    const Imath::Box2i window = file.header().dataWindow();
    const long long w = (long long)window.max.x - window.min.x + 1, h = (long long)window.max.y - window.min.y + 1;
    check_size(path, w, h);
    if (!file.header().channels().findChannel("R") || !file.header().channels().findChannel("G") ||
        !file.header().channels().findChannel("B")) {
      throw InputError(path + ": an environment map needs R, G and B channels");
    }
    // Nothing is allocated for pixels the file does not hold (a header alone claims any size).
    if (!file.isComplete()) throw InputError(path + ": truncated: the file ends before its pixels do");
    std::vector<Vec3> texels(size_t(w) * size_t(h));
    Imf::FrameBuffer frame;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      char* base = reinterpret_cast<char*>(texels.data()) + size_t(c) * sizeof(float);
      base -= (ptrdiff_t(window.min.x) + ptrdiff_t(window.min.y) * ptrdiff_t(w)) * ptrdiff_t(sizeof(Vec3));
      frame.insert(names[c], Imf::Slice(Imf::FLOAT, base, sizeof(Vec3), sizeof(Vec3) * size_t(w)));
    }
    file.setFrameBuffer(frame);
    // In bands of rows, so Ctrl-C is seen while a large map decodes.
    for (int y = window.min.y; y <= window.max.y; y += 64) {
      throw_if_cancelled(cancel);
      file.readPixels(y, std::min(y + 63, window.max.y));
    }
    return EnvironmentMap(int(w), int(h), std::move(texels), rotation, cancel);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read EXR: " + e.what());
  }
}

EnvironmentMap read_hdr_map(const std::string& path, double rotation, CancelFlag cancel) {
  const std::string bytes = read_input(path, cancel, kMaxEnvironmentTexels * 4 + (uint64_t(1) << 20));
  RgbeImage image = decode_rgbe(bytes, path, check_size, cancel);
  return EnvironmentMap(image.width, image.height, std::move(image.texels), rotation, cancel);
}

}  // namespace

EnvironmentMap load_environment_map(const std::string& path, double rotation_degrees, CancelFlag cancel) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".exr") return read_exr_map(path, rotation_degrees, cancel);
  if (ext == ".hdr") return read_hdr_map(path, rotation_degrees, cancel);
  throw InputError(path + ": an environment map must be .exr or .hdr");
}

}  // namespace tracer
