#include "denoise/nfor.hpp"

#include <hwy/aligned_allocator.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <span>

#include "denoise/kernels.hpp"
#include "denoise/planes.hpp"

namespace tracer::denoise {

namespace {

using Floats = hwy::AlignedFreeUniquePtr<float[]>;

Floats zeros(size_t n) {
  Floats p = hwy::AllocateAligned<float>(n);
  std::fill(p.get(), p.get() + n, 0.0f);
  return p;
}

// body(x0, y0) for every tile of the image, on the executor; throws Cancelled once cancelled.
void for_tiles(int width, int height, const Executor& executor, CancelFlag cancel,
               const std::function<void(int, int)>& body) {
  const int columns = (width + kTileWidth - 1) / kTileWidth, rows = (height + kTileHeight - 1) / kTileHeight;
  const bool done = executor.for_each(
      size_t(columns) * size_t(rows),
      [&](size_t i) { body(int(i % size_t(columns)) * kTileWidth, int(i / size_t(columns)) * kTileHeight); }, cancel);
  if (!done) throw Cancelled();
}

// Calls f(x, y, idx) for the pixels of the tile at (x0, y0) inside a width x height image, idx
// the pixel's index in the tile's kernel planes.
template <class F>
void for_tile_pixels(int x0, int y0, int width, int height, F&& f) {
  for (int ty = 0; ty < kTileHeight && y0 + ty < height; ++ty) {
    for (int tx = 0; tx < kTileWidth && x0 + tx < width; ++tx) f(x0 + tx, y0 + ty, ty * kTileWidth + tx);
  }
}

struct Context {
  const Planes& valid;
  const Executor& executor;
  CancelFlag cancel;
  SimdDispatch simd;
};

// f(x, y) for every pixel of a width x height image, bands of kTileHeight rows on the executor;
// throws Cancelled once cancelled.
template <class F>
void for_pixels(const Context& cx, int width, int height, F&& f) {
  const int bands = (height + kTileHeight - 1) / kTileHeight;
  const bool done = cx.executor.for_each(
      size_t(bands),
      [&](size_t band) {
        const int y0 = int(band) * kTileHeight;
        for (int y = y0; y < std::min(y0 + kTileHeight, height); ++y) {
          for (int x = 0; x < width; ++x) f(x, y);
        }
      },
      cx.cancel);
  if (!done) throw Cancelled();
}

// NL-means: each channel of `image` averaged over the window of `radius`, weighted by the patch
// distances of `guide` (whose variance is `variance`) at bandwidth k.
Planes nl_means(const Context& cx, const Planes& image, const Planes& guide, const Planes& variance, int patch,
                int radius, float k) {
  const int w = image.width(), h = image.height(), channels = image.channels();
  Planes out(w, h, channels);
  for_tiles(w, h, cx.executor, cx.cancel, [&](int x0, int y0) {
    Floats acc = zeros(size_t(channels + 1) * kTilePixels), distance = zeros(kTilePixels);
    for (int oy = -radius; oy <= radius; ++oy) {
      for (int ox = -radius; ox <= radius; ++ox) {
        patch_distances({&guide, &variance, x0, y0, ox, oy, patch, distance.get()}, cx.simd);
        filter_step({&image, &cx.valid, x0, y0, ox, oy, distance.get(), 1.0f / (k * k), acc.get()}, cx.simd);
      }
    }
    for_tile_pixels(x0, y0, w, h, [&](int x, int y, int i) {
      const float weights = acc[size_t(channels * kTilePixels + i)];
      for (int c = 0; c < channels; ++c) out(c, x, y) = acc[size_t(c * kTilePixels + i)] / weights;
    });
  });
  return out;
}

// 5.2: `image` (3 channels) regressed per pixel on `features` over the window of `radius`, with
// NL-means weights from `guide` and its variance, at each bandwidth of `ks` (one or two).
std::vector<Planes> regress(const Context& cx, const Planes& image, const Planes& guide, const Planes& variance,
                            const Planes& features, int patch, int radius, std::span<const float> ks,
                            bool position = true) {
  const int w = image.width(), h = image.height(), bandwidths = int(ks.size());
  std::vector<Planes> out;
  for (size_t b = 0; b < ks.size(); ++b) out.emplace_back(w, h, 3);
  const int edge = 2 * radius + 1, offsets = edge * edge;
  for_tiles(w, h, cx.executor, cx.cancel, [&](int x0, int y0) {
    // The tile's distances for every offset first, then the sums row by row, so that a row's
    // sums stay in the L1 cache through the whole window.
    Floats distances = zeros(size_t(offsets) * kTilePixels);
    for (int o = 0; o < offsets; ++o) {
      patch_distances({&guide, &variance, x0, y0, o % edge - radius, o / edge - radius, patch,
                       distances.get() + size_t(o) * kTilePixels},
                      cx.simd);
    }
    Floats scratch = zeros(regression_scratch_floats(radius));
    RegressionRow row{&image,
                      &features,
                      &cx.valid,
                      x0,
                      y0,
                      0,
                      radius,
                      position ? 1.0f / float(radius) : 0.0f,
                      distances.get(),
                      bandwidths,
                      {},
                      scratch.get(),
                      {}};
    for (int b = 0; b < bandwidths; ++b) {
      row.inv_k2[b] = 1.0f / (ks[size_t(b)] * ks[size_t(b)]);
      row.out[b] = &out[size_t(b)];
    }
    for (row.ty = 0; row.ty < kTileHeight && y0 + row.ty < h; ++row.ty) regression_row(row, cx.simd);
  });
  return out;
}

float square(float x) { return x * x; }

// Each channel averaged over the 3x3 pixels around (those inside the image): a variance
// estimated from one difference per pixel, made steadier.
Planes box3(const Context& cx, const Planes& in) {
  const int w = in.width(), h = in.height();
  Planes out(w, h, in.channels());
  for_pixels(cx, w, h, [&](int x, int y) {
    for (int c = 0; c < in.channels(); ++c) {
      float sum = 0.0f;
      int n = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (x + dx < 0 || y + dy < 0 || x + dx >= w || y + dy >= h) continue;
          sum += in(c, x + dx, y + dy);
          ++n;
        }
      }
      out(c, x, y) = sum / float(n);
    }
  });
  return out;
}

// The film's halves as planes: colour, the variance of each half's mean, and the features, with
// the distance scaled by its mean over the image so that every regressor is of order one. The
// colour is scaled too (by `colour_scale`, a power of two, so exactly) where its mean is far from
// one: its squares (variances, patch distances) would overflow float above about 1e19 and sink
// below the filters' epsilon in a dim image; NFOR is linear in the colour, so the result is
// scaled back.
struct Halves {
  std::array<Planes, 2> colour, variance, features;
  Planes feature_variance;  // of one half's mean, from the halves' difference, 3x3-averaged
  float colour_scale = 1.0f;
};

// The power of two by which the colour is multiplied: 1 while the mean colour lies within
// [2^-16, 2^16] (every ordinary render, whose bytes it keeps), else one that brings the mean to
// [1, 2) -- but never one that lifts the brightest value's square past float's range.
float colour_scale_of(double mean, double brightest) {
  if (!(mean > 0.0) || !std::isfinite(mean) || (mean >= 0x1p-16 && mean <= 0x1p16 && brightest <= 0x1p60)) {
    return 1.0f;
  }
  const int k = std::min(-std::ilogb(mean), 60 - std::ilogb(std::max(brightest, mean)));
  return std::ldexp(1.0f, std::clamp(k, -120, 120));
}

Halves halves_of(const Context& cx, const FeatureFilm& film) {
  using F = FeatureFilm;
  const int w = film.width(), h = film.height();
  Halves hv;
  for (int s = 0; s < 2; ++s) {
    hv.colour[size_t(s)] = Planes(w, h, 3);
    hv.variance[size_t(s)] = Planes(w, h, 3);
    hv.features[size_t(s)] = Planes(w, h, kFeatures);
  }
  // Per row, summed in row order afterwards: the same scales whatever the threads.
  std::vector<double> distance_sum(size_t(h), 0.0), colour_sum(size_t(h), 0.0), brightest(size_t(h), 0.0);
  std::vector<uint64_t> distance_count(size_t(h), 0), colour_count(size_t(h), 0);
  for_pixels(cx, w, h, [&](int x, int y) {
    const float n[2] = {film.get(x, y, 0, F::kCount), film.get(x, y, 1, F::kCount)};
    for (int s = 0; s < 2; ++s) {
      // A half without samples (one sample per pixel) takes the other's.
      const int from = n[s] > 0.0f ? s : 1 - s;
      const float count = n[from];
      if (count == 0.0f) continue;
      for (int c = 0; c < 3; ++c) {
        const float colour = film.get(x, y, from, F::kRadiance + c) / count;
        hv.colour[size_t(s)](c, x, y) = colour;
        if (std::isfinite(colour)) {
          colour_sum[size_t(y)] += double(std::fabs(colour));
          brightest[size_t(y)] = std::max(brightest[size_t(y)], double(std::fabs(colour)));
          ++colour_count[size_t(y)];
        }
        hv.features[size_t(s)](c, x, y) = film.get(x, y, from, F::kAlbedo + c) / count;
        hv.features[size_t(s)](3 + c, x, y) = film.get(x, y, from, F::kNormal + c) / count;
      }
      hv.features[size_t(s)](6, x, y) = film.get(x, y, from, F::kDepth) / count;
    }
    const float d = 0.5f * (hv.features[0](6, x, y) + hv.features[1](6, x, y));
    if (d > 0.0f && std::isfinite(d)) {
      distance_sum[size_t(y)] += double(d);
      ++distance_count[size_t(y)];
    }
  });
  double sum = 0.0, csum = 0.0, cmax = 0.0;
  uint64_t count = 0, ccount = 0;
  for (int y = 0; y < h; ++y) {
    sum += distance_sum[size_t(y)];
    count += distance_count[size_t(y)];
    csum += colour_sum[size_t(y)];
    ccount += colour_count[size_t(y)];
    cmax = std::max(cmax, brightest[size_t(y)]);
  }
  const float scale = count > 0 && sum > 0.0 ? float(double(count) / sum) : 1.0f;
  const float cs = colour_scale_of(ccount > 0 ? csum / double(ccount) : 0.0, cmax);
  hv.colour_scale = cs;
  Planes difference(w, h, kFeatures);
  for_pixels(cx, w, h, [&](int x, int y) {
    const float n[2] = {film.get(x, y, 0, F::kCount), film.get(x, y, 1, F::kCount)};
    for (int s = 0; s < 2; ++s) {
      for (int c = 0; c < 3; ++c) hv.colour[size_t(s)](c, x, y) *= cs;
    }
    for (int s = 0; s < 2; ++s) {
      for (int c = 0; c < 3; ++c) {
        // In double: the sums' squares overflow float long before the film's sums do. A sum of
        // squares that overflowed the film (a sample above 1.8e19) leaves the halves' difference.
        const double sum2 = film.get(x, y, s, F::kRadiance2 + c);
        double v;
        if (n[s] >= 2.0f && std::isfinite(sum2)) {
          const double total = film.get(x, y, s, F::kRadiance + c), m = n[s];
          v = std::max(0.0, (sum2 - total * total / m) / (m * (m - 1.0))) * double(cs) * double(cs);
        } else {
          // One sample in a half: its variance as the halves' difference tells it.
          v = double(square(hv.colour[0](c, x, y) - hv.colour[1](c, x, y))) * 0.5;
        }
        hv.variance[size_t(s)](c, x, y) = float(v);
      }
    }
    for (int s = 0; s < 2; ++s) hv.features[size_t(s)](6, x, y) *= scale;
    for (int c = 0; c < kFeatures; ++c) {
      difference(c, x, y) = square(hv.features[0](c, x, y) - hv.features[1](c, x, y)) * 0.5f;
    }
  });
  hv.feature_variance = box3(cx, difference);
  return hv;
}

// A guide for NL-means weights: the colour divided by the albedo (plus 0.02, for black surfaces
// and the sky), with its variance divided alike. Its patches compare the light arriving at two
// pixels, not the texture it lands on, so a pixel beside an albedo edge finds as many similar
// neighbours as one inside a flat square; the regression then carries the albedo across
// (tests/test_denoise.cpp, AnAlbedoEdgeStaysAnEdge: the edge's error was four times the
// inside's with the colour itself as the guide).
struct Guide {
  Planes colour, variance;
};
Guide demodulated(const Context& cx, const Planes& colour, const Planes& variance, const Planes& features) {
  const int w = colour.width(), h = colour.height();
  Guide g{Planes(w, h, 3), Planes(w, h, 3)};
  for_pixels(cx, w, h, [&](int x, int y) {
    for (int c = 0; c < 3; ++c) {
      const float inv = 1.0f / (std::max(features(c, x, y), 0.0f) + 0.02f);
      g.colour(c, x, y) = colour(c, x, y) * inv;
      g.variance(c, x, y) = variance(c, x, y) * inv * inv;
    }
  });
  return g;
}

}  // namespace

uint64_t nfor_peak_bytes(int width, int height) {
  return uint64_t(kPeakChannels) * Planes::floats_per_channel(width, height) * sizeof(float) +
         uint64_t(width) * uint64_t(height) * sizeof(Vec3);
}

std::vector<Vec3> nfor(const FeatureFilm& film, const Executor& executor, CancelFlag cancel, const NforOptions& o) {
  const int w = film.width(), h = film.height();
  Planes valid(w, h, 1);
  const Context cx{valid, executor, cancel, SimdDispatch::of(o.simd)};
  for_pixels(cx, w, h, [&](int x, int y) { valid(0, x, y) = 1.0f; });
  Halves hv = halves_of(cx, film);

  // 5.1: each half's features filtered with weights from the other's.
  constexpr float kFeatureK = 0.5f;
  const Planes features_a =
      nl_means(cx, hv.features[0], hv.features[1], hv.feature_variance, o.feature_patch, o.feature_radius, kFeatureK);
  const Planes features_b =
      nl_means(cx, hv.features[1], hv.features[0], hv.feature_variance, o.feature_patch, o.feature_radius, kFeatureK);

  Planes features(w, h, kFeatures);  // both halves
  for_pixels(cx, w, h, [&](int x, int y) {
    for (int c = 0; c < kFeatures; ++c) features(c, x, y) = 0.5f * (features_a(c, x, y) + features_b(c, x, y));
  });

  // 5.2: each half regressed on the other's features, weighted by the other's colour.
  constexpr float kBandwidths[2] = {0.5f, 1.0f};
  const Guide guide_b = demodulated(cx, hv.colour[1], hv.variance[1], features_b);
  const std::vector<Planes> est_a =
      regress(cx, hv.colour[0], guide_b.colour, guide_b.variance, features_b, o.patch, o.radius, kBandwidths);
  const Guide guide_a = demodulated(cx, hv.colour[0], hv.variance[0], features_a);
  const std::vector<Planes> est_b =
      regress(cx, hv.colour[1], guide_a.colour, guide_a.variance, features_a, o.patch, o.radius, kBandwidths);

  // 5.3: each bandwidth's error, estimated from the halves (each half's estimate against the
  // other half's colour, less that colour's variance and the estimates' own residual variance).
  Planes full(w, h, 3), full_variance(w, h, 3), error(w, h, 6);
  for_pixels(cx, w, h, [&](int x, int y) {
    for (int c = 0; c < 3; ++c) {
      const float ca = hv.colour[0](c, x, y), cb = hv.colour[1](c, x, y);
      const float va = hv.variance[0](c, x, y), vb = hv.variance[1](c, x, y);
      full(c, x, y) = 0.5f * (ca + cb);
      full_variance(c, x, y) = 0.25f * (va + vb);
      for (int b = 0; b < 2; ++b) {
        const float ea = est_a[size_t(b)](c, x, y), eb = est_b[size_t(b)](c, x, y);
        const float mse_a = square(cb - ea) - vb, mse_b = square(ca - eb) - va;
        error(3 * b + c, x, y) = 0.5f * (mse_a + mse_b) - 0.25f * square(eb - ea);
      }
    }
  });
  const Guide guide_full = demodulated(cx, full, full_variance, features);
  const Planes smooth_error =
      nl_means(cx, error, guide_full.colour, guide_full.variance, o.error_patch, o.error_radius, 1.0f);
  Planes choice(w, h, 3);
  for_pixels(cx, w, h, [&](int x, int y) {
    for (int c = 0; c < 3; ++c) choice(c, x, y) = smooth_error(c, x, y) < smooth_error(3 + c, x, y) ? 0.0f : 1.0f;
  });
  const Planes smooth_choice =
      nl_means(cx, choice, guide_full.colour, guide_full.variance, o.error_patch, o.error_radius, 1.0f);

  Planes combined(w, h, 3), combined_variance(w, h, 3);
  for_pixels(cx, w, h, [&](int x, int y) {
    for (int c = 0; c < 3; ++c) {
      const float t = smooth_choice(c, x, y);
      const float ra = est_a[0](c, x, y) + t * (est_a[1](c, x, y) - est_a[0](c, x, y));
      const float rb = est_b[0](c, x, y) + t * (est_b[1](c, x, y) - est_b[0](c, x, y));
      combined(c, x, y) = 0.5f * (ra + rb);
      combined_variance(c, x, y) = 0.25f * square(rb - ra);
    }
  });

  // 5.4: the combined halves regressed once more, guided by themselves: their variance from the
  // halves' difference, 3x3-averaged, and the screen position left out of the regressors (both
  // lowered the Cornell box's error at 4 and 16 spp, docs/DENOISING.md).
  const float kFinal[1] = {1.0f};
  const Guide guide_combined = demodulated(cx, combined, box3(cx, combined_variance), features);
  const Planes result = o.second_pass ? std::move(regress(cx, combined, guide_combined.colour, guide_combined.variance,
                                                          features, o.patch, o.radius, kFinal, false)[0])
                                      : std::move(combined);
  std::vector<Vec3> out(size_t(w) * size_t(h));
  const float unscale = 1.0f / hv.colour_scale;
  for_pixels(cx, w, h, [&](int x, int y) {
    out[size_t(y) * size_t(w) + size_t(x)] = Vec3{result(0, x, y), result(1, x, y), result(2, x, y)} * unscale;
  });
  return out;
}

}  // namespace tracer::denoise
