#include "io/environment_io.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfStdIO.h>
#include <stb_image.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>

#include "base/read_input.hpp"

namespace tracer {

namespace {

void check_size(const std::string& path, long long w, long long h) {
  if (w < 2 || h < 1) throw InputError(path + ": an environment map needs at least 2 x 1 texels");
  if (uint64_t(w) * uint64_t(h) > kMaxEnvironmentTexels || w > 65536 || h > 65536) {
    throw InputError(path + ": environment map of " + std::to_string(w) + " x " + std::to_string(h) +
                     " texels is larger than the 16384 x 8192 allowed");
  }
}

EnvironmentMap read_exr_map(const std::string& path, float rotation, CancelFlag cancel) {
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
    std::vector<float> planes(3 * size_t(w) * size_t(h));
    Imf::FrameBuffer frame;
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) {
      char* base = reinterpret_cast<char*>(planes.data() + size_t(c) * size_t(w) * size_t(h));
      base -= (ptrdiff_t(window.min.x) + ptrdiff_t(window.min.y) * ptrdiff_t(w)) * ptrdiff_t(sizeof(float));
      frame.insert(names[c], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * size_t(w)));
    }
    file.setFrameBuffer(frame);
    file.readPixels(window.min.y, window.max.y);
    const size_t n = size_t(w) * size_t(h);
    std::vector<Vec3> texels(n);
    for (size_t i = 0; i < n; ++i) texels[i] = {planes[i], planes[n + i], planes[2 * n + i]};
    return EnvironmentMap(int(w), int(h), std::move(texels), rotation);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read EXR: " + e.what());
  }
}

EnvironmentMap read_hdr_map(const std::string& path, float rotation, CancelFlag cancel) {
  const std::string bytes = read_input(path, cancel, kMaxEnvironmentTexels * 4 + (uint64_t(1) << 20));
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int size = int(std::min<size_t>(bytes.size(), size_t(INT32_MAX)));
  int w = 0, h = 0, channels = 0;
  if (!stbi_is_hdr_from_memory(data, size) || !stbi_info_from_memory(data, size, &w, &h, &channels)) {
    throw InputError(path + ": cannot read environment map: not a Radiance HDR file");
  }
  check_size(path, w, h);
  const std::unique_ptr<float, void (*)(void*)> pixels(stbi_loadf_from_memory(data, size, &w, &h, &channels, 3),
                                                       stbi_image_free);
  if (!pixels) throw InputError(path + ": cannot read environment map: " + stbi_failure_reason());
  std::vector<Vec3> texels(size_t(w) * size_t(h));
  for (size_t i = 0; i < texels.size(); ++i)
    texels[i] = {pixels.get()[3 * i], pixels.get()[3 * i + 1], pixels.get()[3 * i + 2]};
  return EnvironmentMap(w, h, std::move(texels), rotation);
}

}  // namespace

EnvironmentMap load_environment_map(const std::string& path, float rotation_degrees, CancelFlag cancel) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".exr") return read_exr_map(path, rotation_degrees, cancel);
  if (ext == ".hdr") return read_hdr_map(path, rotation_degrees, cancel);
  throw InputError(path + ": an environment map must be .exr or .hdr");
}

}  // namespace tracer
