#include "io/image_compare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "base/errors.hpp"
#include "base/read_input.hpp"
#include "film/tone_map.hpp"
#include "io/image_io.hpp"

namespace tracer {

ImageDifference compare_images(const std::string& a, const std::string& b, std::optional<float> exposure) {
  const bool exr_a = image_format_for(a, "compare") == ImageFormat::Exr;
  const bool exr_b = image_format_for(b, "compare") == ImageFormat::Exr;
  if (exr_a != exr_b) throw UsageError("compare: both images must be EXR (linear) or both PNG/PPM (display)");
  if (exposure && !exr_a) throw UsageError("compare: --exposure tone-maps .exr images; PNG/PPM are display values");
  ImageDifference d;
  d.linear = exr_a && !exposure;
  const bool exr = exr_a;
  // Both read (within read_input's limits) and their sizes compared from the headers, before
  // either is decoded.
  const std::string bytes_a = read_input(a), bytes_b = read_input(b);
  const ImageSize sa = exr ? exr_size(bytes_a, a) : image8_size(bytes_a, a);
  const ImageSize sb = exr ? exr_size(bytes_b, b) : image8_size(bytes_b, b);
  if (!(sa == sb)) {
    throw UsageError("compare: sizes differ (" + std::to_string(sa.width) + "x" + std::to_string(sa.height) + " and " +
                     std::to_string(sb.width) + "x" + std::to_string(sb.height) + ")");
  }
  d.width = sa.width;
  d.height = sa.height;
  double sum = 0.0, sum_a = 0.0, sum_b = 0.0;
  size_t n = 0;
  const auto add = [&](double x, double y) {
    const double e = x - y;
    sum += e * e;
    sum_a += x;
    sum_b += y;
    d.max_abs = std::max(d.max_abs, std::fabs(e));
    ++n;
  };
  if (exr) {
    const Framebuffer fa = decode_exr(bytes_a, a), fb = decode_exr(bytes_b, b);
    // A NaN or infinity has no difference to measure: refused, naming the file and the count.
    for (const auto& [image, path] : {std::pair{&fa, &a}, {&fb, &b}}) {
      size_t bad = 0;
      for (int y = 0; y < image->height(); ++y) {
        for (int x = 0; x < image->width(); ++x) {
          const Vec3 p = image->radiance(x, y);
          for (int c = 0; c < 3; ++c) bad += std::isfinite(p[c]) ? 0 : 1;
        }
      }
      if (bad > 0) {
        throw InputError(*path + ": " + std::to_string(bad) +
                         " pixel values are not finite (NaN or infinity): no difference can be measured");
      }
    }
    for (int y = 0; y < fa.height(); ++y) {
      for (int x = 0; x < fa.width(); ++x) {
        const Vec3 p = fa.radiance(x, y), q = fb.radiance(x, y);
        for (int c = 0; c < 3; ++c) {
          if (exposure) {
            add(display_value(p[c], *exposure), display_value(q[c], *exposure));
          } else {
            add(p[c], q[c]);
          }
        }
      }
    }
  } else {
    const Image8 ia = decode_image(bytes_a, a), ib = decode_image(bytes_b, b);
    for (size_t i = 0; i < ia.rgb.size(); ++i) add(ia.rgb[i] / 255.0, ib.rgb[i] / 255.0);
  }
  d.rmse = n > 0 ? std::sqrt(sum / double(n)) : 0.0;
  d.mean_a = n > 0 ? sum_a / double(n) : 0.0;
  d.mean_b = n > 0 ? sum_b / double(n) : 0.0;
  if (!d.linear) d.psnr_db = d.rmse > 0.0 ? 20.0 * std::log10(1.0 / d.rmse) : std::numeric_limits<double>::infinity();
  return d;
}

}  // namespace tracer
