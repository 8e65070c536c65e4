#pragma once
// Adaptive sampling (render.noise_threshold): how many samples each pixel gets.
//
// The image error we minimise is relMSE = mean over pixels of s_i^2 / n_i, where s_i is pixel i's
// relative standard deviation of one sample (Film::relative_deviation) and n_i its sample count.
// For a fixed total of samples the minimum is at n_i proportional to s_i (Neyman's optimal
// allocation of a stratified sample, Neyman 1934, with pixels as strata; Lagrange multipliers or
// Cauchy-Schwarz). Taking n_i = s_i * mean(s) / t^2 makes that relMSE equal to t^2, so the
// threshold t is the relative RMS error the image aims for.
//
// A pixel's count is decided by its neighbours' deviations (and the image-wide scale without its
// own term), never by its own samples: a count that depends on the values it averages biases the
// mean (adaptive_sampling.cpp, docs/stability-and-features.md).
//
// Not the per-pixel rule "stop a pixel once its own relative error is below t" (Cycles): that
// gives every pixel n_i = s_i^2 / t^2, i.e. relMSE * mean(n) = mean(s^2), exactly what uniform
// sampling gets, and measured no better than uniform on our reference scenes
// (docs/stability-and-features.md). Noisy pixels still get more samples here, but in proportion
// to their deviation, not its square.
#include <cstdint>
#include <vector>

namespace penumbra {

struct AdaptiveLimits {
  float threshold;  // target relative RMS error of the image (> 0)
  int min_samples;  // every pixel gets at least these (the first estimate is made at this count)
  int max_samples;  // and at most these (render.spp)
};

// deviation: per-pixel s_i, row-major width x height; +inf where not yet estimable. Returns each
// pixel's sample limit in [min_samples, max_samples].
std::vector<uint32_t> adaptive_sample_limits(const std::vector<double>& deviation, int width,
                                             int height, const AdaptiveLimits& limits);

}  // namespace penumbra
