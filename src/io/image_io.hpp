// Writing images and other outputs atomically: a temporary file in the target directory, then
// rename, so no failed or interrupted run leaves a truncated file behind.
#pragma once

#include <string>
#include <string_view>

#include "film/tone_map.hpp"
#include "io/exr_io.hpp"

namespace tracer {

enum class ImageFormat { Png, Ppm, Exr };

// From the path's extension (.png, .ppm or .exr, any case); throws UsageError naming `flag` otherwise.
ImageFormat image_format_for(const std::string& path, const std::string& flag = "-o");

// The bytes of a PNG file of `image` (what write_image writes); of a baseline JPEG of it at
// `quality` 1-100 (the viewer's frames: a fifth of the PNG's bytes, encoded several times faster).
std::string encode_png(const Image8& image);
std::string encode_jpeg(const Image8& image, int quality);

// Encodes and writes; throws InputError("PATH: cannot write: reason") on failure.
void write_image(const std::string& path, const Image8& image);

// Writes a render in the format the path names: PNG and PPM tone-mapped with `exposure`, EXR as
// linear radiance (half or float), no tone mapping.
// `layers` (AOVs) go into an EXR beside the radiance. Returns how many EXR values were beyond the
// pixel type's range or not finite, and so written as its largest value (encode_exr).
size_t write_render(const std::string& path, const Framebuffer& fb, float exposure, ExrPixel exr_pixel,
                    const std::vector<ExrLayer>& layers = {});

// Writes bytes to `path`. A regular file (or none) is replaced atomically through a temporary file
// in its directory and a rename; a symbolic link is followed and its target replaced so; a device
// node or FIFO (/dev/stdout, /dev/null) is written into, never replaced. Throws InputError on
// failure, UsageError when the target is a file this run read as input.
void write_file_atomic(const std::string& path, std::string_view bytes);

// Removes the temporary file of a write_file_atomic() in progress, if any. Async-signal-safe: for a
// signal handler that ends the process in the middle of a write.
void remove_pending_temp_file();

// Checks up front that `path` (followed through symbolic links) can be written: its directory
// exists and is writable, or it is a writable device or FIFO; throws InputError.
void check_writable(const std::string& path);

// check_writable(), and that `path` is no file this run has read (check_not_an_input): for every
// output of a command, once its inputs are loaded, so nothing is written when one collides.
void check_output(const std::string& path, const std::string& flag);

// Where a write to `path` lands: symbolic links followed (the target may not exist yet).
std::string resolve_output(const std::string& path);

// Reads a PNG or PPM written by write_image (tests), which stays writable by this run
// (read_back()); throws InputError.
Image8 read_image(const std::string& path);
// The same from bytes in memory, and the size alone from the header (refused past
// kMaxImagePixels); both throw InputError naming `path`.
Image8 decode_image(std::string_view bytes, const std::string& path);
ImageSize image8_size(std::string_view bytes, const std::string& path);

}  // namespace tracer
