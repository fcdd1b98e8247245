#include "io/image_compare.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "base/errors.hpp"
#include "io/image_io.hpp"

namespace tracer {

ImageDifference compare_images(const std::string& a, const std::string& b) {
  const bool exr_a = image_format_for(a, "compare") == ImageFormat::Exr;
  const bool exr_b = image_format_for(b, "compare") == ImageFormat::Exr;
  if (exr_a != exr_b) throw UsageError("compare: both images must be EXR (linear) or both PNG/PPM (display)");
  ImageDifference d;
  d.linear = exr_a;
  double sum = 0.0;
  size_t n = 0;
  const auto add = [&](double x, double y) {
    const double e = x - y;
    sum += e * e;
    d.max_abs = std::max(d.max_abs, std::fabs(e));
    ++n;
  };
  const auto check_size = [&](int wa, int ha, int wb, int hb) {
    if (wa != wb || ha != hb) {
      throw UsageError("compare: sizes differ (" + std::to_string(wa) + "x" + std::to_string(ha) + " and " +
                       std::to_string(wb) + "x" + std::to_string(hb) + ")");
    }
    d.width = wa;
    d.height = ha;
  };
  if (d.linear) {
    const Framebuffer fa = read_exr(a), fb = read_exr(b);
    check_size(fa.width(), fa.height(), fb.width(), fb.height());
    for (int y = 0; y < fa.height(); ++y) {
      for (int x = 0; x < fa.width(); ++x) {
        const Vec3 p = fa.radiance(x, y), q = fb.radiance(x, y);
        for (int c = 0; c < 3; ++c) add(p[c], q[c]);
      }
    }
  } else {
    const Image8 ia = read_image(a), ib = read_image(b);
    check_size(ia.width, ia.height, ib.width, ib.height);
    for (size_t i = 0; i < ia.rgb.size(); ++i) add(ia.rgb[i] / 255.0, ib.rgb[i] / 255.0);
  }
  d.rmse = n > 0 ? std::sqrt(sum / double(n)) : 0.0;
  if (!d.linear) d.psnr_db = d.rmse > 0.0 ? 20.0 * std::log10(1.0 / d.rmse) : std::numeric_limits<double>::infinity();
  return d;
}

}  // namespace tracer
