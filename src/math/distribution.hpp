// Piecewise-constant distributions for importance sampling: 1D over [0, 1) in n equal cells, and
// 2D over [0, 1)^2 as a marginal over rows times each row's conditional (pbrt-v4's
// PiecewiseConstant1D/2D). Sampling inverts the CDF exactly, so sample() and pdf() agree.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "math/vec.hpp"

namespace tracer {

class Distribution1D {
 public:
  Distribution1D() = default;
  // Cells weighted by `weights` (negative and non-finite weights count as 0); all zero: uniform.
  explicit Distribution1D(const float* weights, size_t n) : cdf_(n + 1, 0.0), pdf_(n, 0.0f) {
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
      const double w = weights[i] > 0.0f && std::isfinite(weights[i]) ? double(weights[i]) : 0.0;
      sum += w;
      cdf_[i + 1] = sum;
    }
    integral_ = float(sum / double(n));
    for (size_t i = 0; i <= n; ++i) cdf_[i] = sum > 0.0 ? cdf_[i] / sum : double(i) / double(n);
    cdf_[n] = 1.0;
    for (size_t i = 0; i < n; ++i) pdf_[i] = float((cdf_[i + 1] - cdf_[i]) * double(n));
  }
  size_t size() const { return pdf_.size(); }
  // The mean weight: what the cells' weights integrate to over [0, 1).
  float integral() const { return integral_; }
  // Density at x in [0, 1) with respect to x.
  float pdf(float x) const { return pdf_[cell(x)]; }
  float cell_pdf(size_t i) const { return pdf_[i]; }
  // x in [0, 1) distributed as the weights, its cell, and its density; u uniform in [0, 1).
  float sample(float u, size_t& cell_out, float& pdf_out) const {
    const size_t n = pdf_.size();
    // The last cell whose CDF start is <= u (cells of zero weight have zero width: never chosen).
    const size_t i =
        std::min<size_t>(size_t(std::upper_bound(cdf_.begin(), cdf_.end(), double(u)) - cdf_.begin()) - 1, n - 1);
    cell_out = i;
    pdf_out = pdf_[i];
    const double width = cdf_[i + 1] - cdf_[i];
    const double t = width > 0.0 ? (double(u) - cdf_[i]) / width : 0.0;
    return std::min(float((double(i) + std::clamp(t, 0.0, 1.0)) / double(n)), 0x1.fffffep-1f);
  }

 private:
  size_t cell(float x) const { return std::min(size_t(std::max(x, 0.0f) * float(pdf_.size())), pdf_.size() - 1); }
  std::vector<double> cdf_;  // doubles: a 2k x 1k map's CDF summed in float would drift
  std::vector<float> pdf_;
  float integral_ = 0.0f;
};

class Distribution2D {
 public:
  Distribution2D() = default;
  // weights[y * width + x]: cell (x, y) of a width x height grid over [0, 1)^2. `on_row(y)` is
  // called before each row is built (a caller polls for cancellation there, and may throw).
  template <class OnRow = void (*)(size_t)>
  Distribution2D(
      const std::vector<float>& weights, size_t width, size_t height, OnRow&& on_row = [](size_t) {}) {
    rows_.reserve(height);
    std::vector<float> row_integrals(height);
    for (size_t y = 0; y < height; ++y) {
      on_row(y);
      rows_.emplace_back(weights.data() + y * width, width);
      row_integrals[y] = rows_.back().integral();
    }
    marginal_ = Distribution1D(row_integrals.data(), height);
  }
  bool empty() const { return rows_.empty(); }
  // A point of [0, 1)^2 and its density; (u1, u2) uniform.
  Vec2 sample(float u1, float u2, float& pdf) const {
    size_t row = 0, col = 0;
    float pdf_y = 0.0f, pdf_x = 0.0f;
    const float y = marginal_.sample(u2, row, pdf_y);
    const float x = rows_[row].sample(u1, col, pdf_x);
    pdf = pdf_x * pdf_y;
    return {x, y};
  }
  float pdf(Vec2 p) const {
    const size_t row = std::min(size_t(std::max(p.y, 0.0f) * float(rows_.size())), rows_.size() - 1);
    return marginal_.cell_pdf(row) * rows_[row].pdf(p.x);
  }

 private:
  std::vector<Distribution1D> rows_;
  Distribution1D marginal_;
};

}  // namespace tracer
