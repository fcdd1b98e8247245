// The difference between two images of the same size, as `tracer compare` reports it: RMSE over
// every pixel and channel, in linear radiance for two EXR files (the noise of a render against a
// reference) or in display values (0-1) for two PNG/PPM files, and the PSNR of the latter.
#pragma once

#include <string>

namespace tracer {

struct ImageDifference {
  int width = 0, height = 0;
  bool linear = false;  // both EXR: the RMSE is in linear radiance
  double rmse = 0.0;
  double max_abs = 0.0;  // the largest difference of any channel
  double psnr_db = 0.0;  // display images only (infinite when identical)
};

// Throws InputError naming the file that cannot be read, or UsageError when the formats differ
// (one EXR, one not) or the sizes do.
ImageDifference compare_images(const std::string& a, const std::string& b);

}  // namespace tracer
