#include "io/image_io.hpp"

#include <fcntl.h>
#include <stb_image.h>
#include <stb_image_write.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <climits>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "base/errors.hpp"
#include "base/read_input.hpp"

namespace tracer {

namespace fs = std::filesystem;

namespace {

// The temporary file of the atomic write in progress, for remove_pending_temp_file(), which a
// signal handler may call: a fixed buffer and an atomic flag, nothing that allocates or locks.
char g_pending_temp[4096];
std::atomic<bool> g_pending{false};

class PendingTemp {
 public:
  explicit PendingTemp(const std::string& path) {
    if (path.size() < sizeof g_pending_temp) {
      std::memcpy(g_pending_temp, path.c_str(), path.size() + 1);
      g_pending.store(true);
    }
  }
  ~PendingTemp() { g_pending.store(false); }
};

}  // namespace

ImageFormat image_format_for(const std::string& path, const std::string& flag) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".png") return ImageFormat::Png;
  if (ext == ".ppm") return ImageFormat::Ppm;
  if (ext == ".exr") return ImageFormat::Exr;
  throw UsageError(flag + ": unsupported image extension '" + ext + "' in '" + path + "' (use .png, .ppm or .exr)");
}

// Where a write to `path` lands: symbolic links followed to the file they name (which may not
// exist yet). Throws InputError on a link loop.
std::string resolve_output(const std::string& path) {
  struct stat existing {};
  if (::stat(path.c_str(), &existing) == 0) {
    // A device or FIFO is opened by the name given: /dev/stdout's link names "pipe:[N]", which
    // only the kernel can follow.
    if (!S_ISREG(existing.st_mode)) return path;
    char real[PATH_MAX];
    if (::realpath(path.c_str(), real)) return real;
  }
  std::string at = path;
  for (int hops = 0; hops < 40; ++hops) {
    struct stat st {};
    if (::lstat(at.c_str(), &st) != 0 || !S_ISLNK(st.st_mode)) return at;
    std::string target(size_t(st.st_size > 0 ? st.st_size : 4096) + 1, '\0');
    const ssize_t n = ::readlink(at.c_str(), target.data(), target.size());
    if (n < 0) throw InputError(path + ": cannot write: " + std::strerror(errno));
    target.resize(size_t(n));
    const fs::path link(at);
    at = target.front() == '/' ? target : (link.parent_path() / target).string();
  }
  throw InputError(path + ": cannot write: too many levels of symbolic links (a link loop?)");
}

namespace {

// A device node, FIFO or socket: written into, never replaced (/dev/stdout, /dev/null, a pipe).
bool is_special(const std::string& resolved) {
  struct stat st {};
  return ::stat(resolved.c_str(), &st) == 0 && !S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode);
}

void write_all(int fd, std::string_view bytes, const std::string& path) {
  size_t written = 0;
  while (written < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw InputError(path + ": cannot write: " + std::strerror(errno));
    }
    written += size_t(n);
  }
}

}  // namespace

void check_writable(const std::string& path) {
  const std::string target = resolve_output(path);
  std::error_code ec;
  if (fs::is_directory(target, ec)) throw InputError(path + ": cannot write: is a directory");
  if (is_special(target)) {
    if (::access(target.c_str(), W_OK) != 0) throw InputError(path + ": cannot write: " + std::strerror(errno));
    return;
  }
  fs::path dir = fs::path(target).parent_path();
  if (dir.empty()) dir = ".";
  if (!fs::is_directory(dir, ec))
    throw InputError(path + ": cannot write: directory '" + dir.string() + "' does not exist");
  if (::access(dir.c_str(), W_OK) != 0) throw InputError(path + ": cannot write: " + std::strerror(errno));
}

void check_output(const std::string& path, const std::string& flag) {
  check_not_an_input(path, flag);  // stat() follows links: the identity of what would be written
  check_writable(path);
}

void write_file_atomic(const std::string& path, std::string_view bytes) {
  check_writable(path);
  check_not_an_input(path, "output");
  const std::string target = resolve_output(path);
  if (is_special(target)) {
    int fd;
    while ((fd = ::open(target.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC)) < 0 && errno == EINTR) {
    }
    if (fd < 0) throw InputError(path + ": cannot write: " + std::strerror(errno));
    try {
      write_all(fd, bytes, path);
    } catch (...) {
      ::close(fd);
      throw;
    }
    ::close(fd);
    return;
  }
  std::string tmp = target + ".tmp-XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) throw InputError(path + ": cannot write: " + std::strerror(errno));
  const PendingTemp pending(tmp);
  ::fchmod(fd, 0644);
  try {
    write_all(fd, bytes, path);
  } catch (...) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  if (::close(fd) != 0 || std::rename(tmp.c_str(), target.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(tmp.c_str());
    throw InputError(path + ": cannot write: " + reason);
  }
}

void write_image(const std::string& path, const Image8& image) {
  if (image_format_for(path) == ImageFormat::Exr) {
    throw UsageError(path + ": an EXR holds linear radiance, not a tone-mapped image (write_render)");
  }
  std::string bytes;
  if (image_format_for(path) == ImageFormat::Ppm) {
    bytes = "P6\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n255\n";
    bytes.append(reinterpret_cast<const char*>(image.rgb.data()), image.rgb.size());
  } else {
    try {
      bytes = encode_png(image);
    } catch (const InputError& e) {
      throw InputError(path + ": " + e.what());
    }
  }
  write_file_atomic(path, bytes);
}

namespace {

void append_to_string(void* ctx, void* data, int size) {
  static_cast<std::string*>(ctx)->append(static_cast<const char*>(data), size_t(size));
}

}  // namespace

std::string encode_png(const Image8& image) {
  std::string bytes;
  if (!stbi_write_png_to_func(append_to_string, &bytes, image.width, image.height, 3, image.rgb.data(),
                              image.width * 3)) {
    throw InputError("PNG encoding failed");
  }
  return bytes;
}

std::string encode_jpeg(const Image8& image, int quality) {
  std::string bytes;
  if (!stbi_write_jpg_to_func(append_to_string, &bytes, image.width, image.height, 3, image.rgb.data(), quality)) {
    throw InputError("JPEG encoding failed");
  }
  return bytes;
}

void remove_pending_temp_file() {
  if (g_pending.load()) ::unlink(g_pending_temp);
}

size_t write_render(const std::string& path, const Framebuffer& fb, float exposure, ExrPixel exr_pixel,
                    const std::vector<ExrLayer>& layers) {
  size_t clamped = 0;
  if (image_format_for(path) == ImageFormat::Exr) {
    write_file_atomic(path, encode_exr(fb, exr_pixel, layers, &clamped));
  } else {
    write_image(path, tonemap(fb, exposure));
  }
  return clamped;
}

ImageSize image8_size(std::string_view bytes, const std::string& path) {
  int w = 0, h = 0, channels = 0;
  const int size = int(std::min<size_t>(bytes.size(), size_t(INT32_MAX)));
  if (!stbi_info_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), size, &w, &h, &channels)) {
    throw InputError(path + ": cannot read image: " + stbi_failure_reason());
  }
  check_image_size(path, w, h);
  return {w, h};
}

Image8 decode_image(std::string_view bytes, const std::string& path) {
  image8_size(bytes, path);
  int w = 0, h = 0, channels = 0;
  const int size = int(std::min<size_t>(bytes.size(), size_t(INT32_MAX)));
  // stb reads PNG and binary PPM; 16-bit PNGs come as 8 bits.
  unsigned char* data =
      stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), size, &w, &h, &channels, 3);
  if (!data) throw InputError(path + ": cannot read image: " + stbi_failure_reason());
  Image8 img;
  img.width = w;
  img.height = h;
  img.rgb.assign(data, data + size_t(w) * size_t(h) * 3);
  stbi_image_free(data);
  return img;
}

Image8 read_image(const std::string& path) { return decode_image(read_back(path), path); }

}  // namespace tracer
