// Feature-guided denoising of a path-traced film: NFOR, after Bitterli et al. 2016, "Nonlinearly
// Weighted First-order Regression for Denoising Monte Carlo Renderings" (section numbers below
// are the paper's). The steps, each over tiles on the executor (docs/DENOISING.md has the why and
// the measurements of each choice):
//   5.1 the features (albedo, normal, distance, each in two halves) cross-prefiltered: each half
//       by NL-means weights computed on the other;
//   5.2 each half of the colour regressed on the other half's features by weighted first-order
//       least squares (the pixel's position among the regressors), with NL-means weights from
//       the other half's colour, at two bandwidths (k = 0.5 and 1);
//   5.3 per pixel, the bandwidth of least estimated error (the halves give the estimate),
//       the error maps and the choice smoothed by NL-means;
//   5.4 a second regression of the combined halves, guided by themselves.
// A pixel's result depends on its neighbourhood in the film alone: the same image whatever the
// tiles, threads, scheduler or ranks that rendered or denoised it.
#pragma once

#include <cstdint>
#include <vector>

#include "base/errors.hpp"
#include "base/simd_dispatch.hpp"
#include "film/feature_film.hpp"
#include "math/vec.hpp"
#include "parallel/executor.hpp"

namespace tracer::denoise {

// The filters' radii (docs/DENOISING.md measures the choice: a 3x3 patch and an 11x11 window
// gave lower error on the Cornell box at 4 and 16 spp than the paper's 7x7 and 19x19, at a
// third of the time).
struct NforOptions {
  int feature_patch = 1, feature_radius = 2;  // 5.1, at k = 0.5
  int patch = 1, radius = 5;                  // 5.2 and 5.4
  int error_patch = 1, error_radius = 3;      // 5.3: smoothing the error and choice maps
  bool second_pass = true;                    // 5.4
  SimdTarget simd = SimdTarget::Auto;         // the widest target its kernels may use (--simd-target)
};

// The bytes nfor() holds at its peak for a width x height film (the film itself not counted): the
// planes live at once in 5.4 (kPeakChannels, counted in nfor.cpp's order of steps), each padded
// to whole tiles and a border, and the result.
inline constexpr int kPeakChannels = 127;
uint64_t nfor_peak_bytes(int width, int height);

// The denoised radiance of every pixel of `film`, row-major. Throws Cancelled once `cancel` is
// set (checked between tiles).
std::vector<Vec3> nfor(const FeatureFilm& film, const Executor& executor, CancelFlag cancel = nullptr,
                       const NforOptions& options = {});

}  // namespace tracer::denoise
