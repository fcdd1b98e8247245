// The denoiser's inner loops over one tile and one neighbour offset, compiled once per SIMD
// target (filter_kernels.cpp, regression_kernels.cpp) and chosen at run time: NL-means patch distances, the weighted
// sums of an NL-means filter, and the sums of a weighted first-order regression. Everything runs offset by offset over
// a tile's pixels, a row of them a few SIMD vectors: the loops are flat, and a pixel's result depends on its
// neighbourhood only, not on the tiling or the thread.
#pragma once

#include "base/simd_dispatch.hpp"
#include "denoise/planes.hpp"

namespace tracer::denoise {

// Features of the regression, after the constant and the two screen coordinates: albedo (3),
// shading normal (3), distance along the path (1).
inline constexpr int kFeatures = 7;
inline constexpr int kDim = 3 + kFeatures;                  // regression unknowns per channel
inline constexpr int kGramEntries = kDim * (kDim + 1) / 2;  // X^T W X, upper triangle, row-major
inline constexpr int kRhsEntries = kDim * 3;                // X^T W Y, Y the three colour channels
inline constexpr int kRegressionEntries = kGramEntries + kRhsEntries;
inline constexpr int kTilePixels = kTileWidth * kTileHeight;

// The patch distance between each pixel p of the tile at (x0, y0) and q = p + (ox, oy), as
// Rousselle et al. 2012 define it for a noisy guide: per channel
//   ((g(p) - g(q))^2 - (v(p) + min(v(p), v(q)))) / (1e-10 + v(p) + v(q)),
// averaged over the channels and over the (2 patch + 1)^2 patch; `out` gets kTilePixels values,
// row-major. The weight of q at bandwidth k is exp(-max(0, d) / k^2).
struct PatchDistance {
  const Planes* guide;
  const Planes* variance;  // of the guide, channel by channel
  int x0, y0, ox, oy, patch;
  float* out;
};
void patch_distances(const PatchDistance& a, SimdDispatch simd);

// For every pixel p of the tile: adds w * image(q) to acc[c] (c < channels) and w to
// acc[channels], each a plane of kTilePixels, with w = exp(-max(0, distance) * inv_k2) * valid(q).
struct FilterStep {
  const Planes* image;
  const Planes* valid;
  int x0, y0, ox, oy;
  const float* distance;
  float inv_k2;
  float* acc;
};
void filter_step(const FilterStep& a, SimdDispatch simd);

// The weighted first-order regression of every pixel p of row `ty` of the tile at (x0, y0), at
// each bandwidth b < bandwidths: over the window's offsets q - p, the least squares of
//   image(q) ~ beta . X(q),  X = (1, ox * scale, oy * scale, features(q) - features(p)),
// weighted by w = exp(-max(0, distance) * inv_k2[b]) * valid(q); out[b] gets beta's first term
// (the model's value at p itself), clamped to be non-negative. The regressors but the constant
// are regularised by 1e-3 times the weights' sum, so that a feature that does not vary in the
// window gets a zero slope rather than a singular system; where the system is still not
// positive definite, the weighted mean stands. The sums are kept in registers, a row of X^T W X
// at a time, while the offsets go by.
struct RegressionRow {
  const Planes* image;     // 3 channels
  const Planes* features;  // kFeatures channels
  const Planes* valid;
  int x0, y0, ty, radius;
  float position_scale;    // 1 / radius, or 0 to leave the position out (kDim - 2 unknowns)
  const float* distances;  // the tile's: kTilePixels per offset, offsets row-major from (-r, -r)
  int bandwidths;
  float inv_k2[2];
  float* scratch;  // regression_scratch_floats(radius) floats, aligned for any SIMD target
  Planes* out[2];
};
void regression_row(const RegressionRow& a, SimdDispatch simd);
size_t regression_scratch_floats(int radius);

}  // namespace tracer::denoise
