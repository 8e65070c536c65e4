#pragma once
// Piecewise-constant distributions on [0, 1) and [0, 1)^2, sampled by inverting their CDFs
// (pbrt-v4 §A.4-A.5, PiecewiseConstant1D / PiecewiseConstant2D). Used to sample an environment map
// in proportion to its luminance; reusable for anything tabulated on a grid.
//
// Robustness: negative or non-finite weights count as 0. A distribution whose weights are all
// zero still samples (uniformly) but reports pdf 0 for every point, so a caller that divides by
// the pdf must reject pdf == 0; nothing here divides by zero.
#include <cstddef>
#include <span>
#include <vector>

#include "renderer/core/math.h"

namespace penumbra {

class Distribution1D {
 public:
  Distribution1D() = default;
  // n = weights.size() >= 1 equal cells over [0, 1); cell i has density proportional to weights[i].
  explicit Distribution1D(std::span<const float> weights);

  size_t size() const { return func_.size(); }
  // Integral of the (cleaned) weights over [0, 1): their mean. 0 = nothing to sample.
  double integral() const { return integral_; }
  // x in [0, 1) with density pdf(x); *cell (if given) receives the cell x lies in.
  float sample(float u, float* pdf, int* cell = nullptr) const;
  // Density at x in [0, 1] (x == 1 counts as the last cell).
  float pdf(float x) const;
  // Density of cell i (constant over it).
  float cell_pdf(int i) const { return integral_ > 0.0 ? float(func_[size_t(i)] / integral_) : 0.f; }

 private:
  std::vector<float> func_;
  std::vector<float> cdf_;  // size n + 1, cdf_[0] = 0, cdf_[n] = 1
  double integral_ = 0.0;
};

class Distribution2D {
 public:
  Distribution2D() = default;
  // `weights` is row-major with `nu` cells per row and `nv` rows: the cell (i, j) covers
  // [i/nu, (i+1)/nu) x [j/nv, (j+1)/nv). A marginal distribution picks the row (v), then that
  // row's conditional distribution picks u.
  Distribution2D(std::span<const float> weights, int nu, int nv);

  int nu() const { return nu_; }
  int nv() const { return nv_; }
  // Integral of the weights over [0, 1)^2: their mean.
  double integral() const { return marginal_.integral(); }
  // A point of [0, 1)^2 with density *pdf (0 when the distribution is all zero).
  vec2 sample(const vec2& u, float* pdf) const;
  // Density at p in [0, 1]^2.
  float pdf(const vec2& p) const;

 private:
  int nu_ = 0, nv_ = 0;
  std::vector<Distribution1D> conditional_;  // one per row
  Distribution1D marginal_;                  // over rows, weighted by each row's integral
};

}  // namespace penumbra
