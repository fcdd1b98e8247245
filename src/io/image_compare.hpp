// The difference between two images of the same size, as `tracer compare` reports it: RMSE over
// every pixel and channel, in linear radiance for two EXR files (the noise of a render against a
// reference) or in display values (0-1) for two PNG/PPM files, and the PSNR of the latter. Two EXR
// files can also be compared in display values, tone-mapped as `render` would write a PNG but not
// rounded to 8 bits: the measure of a noise benchmark whose images come from two renderers (the
// rounding alone adds ~0.0016 to an RMSE).
#pragma once

#include <optional>
#include <string>

namespace tracer {

struct ImageDifference {
  int width = 0, height = 0;
  bool linear = false;  // both EXR, no exposure: the RMSE is in linear radiance
  double rmse = 0.0;
  double max_abs = 0.0;               // the largest difference of any channel
  double mean_a = 0.0, mean_b = 0.0;  // each image's mean over pixels and channels, in the same values
  double psnr_db = 0.0;               // display images only (infinite when identical)
};

// `exposure`: compare two EXR files in display values at this exposure. Throws InputError naming
// the file that cannot be read, or UsageError when the formats differ (one EXR, one not), the
// sizes do, or an exposure is given for PNG/PPM files (already display values).
ImageDifference compare_images(const std::string& a, const std::string& b,
                               std::optional<float> exposure = std::nullopt);

}  // namespace tracer
