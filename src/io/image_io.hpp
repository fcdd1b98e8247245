// Writing images and other outputs atomically: a temporary file in the target directory, then
// rename, so no failed or interrupted run leaves a truncated file behind.
#pragma once

#include <string>
#include <string_view>

#include "io/exr_io.hpp"
#include "render/framebuffer.hpp"

namespace tracer {

enum class ImageFormat { Png, Ppm, Exr };

// From the path's extension (.png, .ppm or .exr, any case); throws UsageError naming `flag` otherwise.
ImageFormat image_format_for(const std::string& path, const std::string& flag = "-o");

// Encodes and writes; throws InputError("PATH: cannot write: reason") on failure.
void write_image(const std::string& path, const Image8& image);

// Writes a render in the format the path names: PNG and PPM tone-mapped with `exposure`, EXR as
// linear radiance (half or float), no tone mapping.
void write_render(const std::string& path, const Framebuffer& fb, float exposure, ExrPixel exr_pixel);

// Writes bytes to path via temp file + rename; throws InputError on failure.
void write_file_atomic(const std::string& path, std::string_view bytes);

// Removes the temporary file of a write_file_atomic() in progress, if any. Async-signal-safe: for a
// signal handler that ends the process in the middle of a write.
void remove_pending_temp_file();

// Checks up front that `path`'s directory exists and is writable, so a long render does not end
// in an unwritable path; throws InputError.
void check_writable(const std::string& path);

// Reads a PNG or PPM written by write_image (tests, image comparison); throws InputError.
Image8 read_image(const std::string& path);

}  // namespace tracer
