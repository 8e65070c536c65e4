#pragma once
// An environment light from an equirectangular (latitude-longitude) HDR image, matching
// Mitsuba 3's `envmap` so references compare (src/emitters/envmap.cpp):
//  - mapping: map-space direction (x, y, z) <-> u = atan2(x, -z) / 2 pi (mod 1), v = acos(y) / pi;
//  - lookup: bilinear between texels, with texel x's centre at u = (x + 0.5) / width (wrapping
//    around the seam) and row y at v = y / (height - 1): the first and last rows sit on the poles;
//  - sampling: by importance, in proportion to luminance times sin(theta) (the Jacobian of the
//    lat-long map), combined with BSDF sampling by MIS in the integrator. The density is
//    piecewise bilinear over the texel grid, as Mitsuba's: a cell (between four texels) is chosen
//    from a piecewise-constant distribution of the cells' integrals (pbrt-v4 §A.5), then a point
//    within it from the bilinear interpolant of its corners' luminance x sin(theta) (pbrt-v4
//    SampleBilinear, §A.3.2) -- the shape of the bilinear radiance itself, so a cell half lit by
//    the sun's edge gets its samples where the light is.
//  - MIS compensation (Karlik, Sik, Vevoda, Skrivan and Krivanek 2019, "MIS compensation:
//    optimizing sampling techniques in multiple importance sampling"; pbrt-v4's
//    ImageInfiniteLight compensatedDistribution): an integrator that weighs light against BSDF
//    sampling by MIS everywhere (the path integrator) samples the map in proportion to
//    max(L - mean L, 0) instead, from a twin made by compensated(). Where the map is dimmer than
//    its mean, BSDF sampling, which the MIS weights then give all of it, covers it well; the
//    light samples all go where the map is bright, so a sun is no longer a Bernoulli mixture of
//    sun and sky samples. The distributed integrator keeps the full density: its diffuse lobes
//    see direct light only through light sampling.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <memory>
#include <mutex>
#include <vector>

#include "renderer/core/arc_tangent.h"
#include "renderer/lights/environment_light.h"
#include "renderer/sampling/distribution_2d.h"
#include "renderer/sampling/sampling.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

class EnvironmentMap final : public EnvironmentLight {
 public:
  // Negative and non-finite texels count as 0; an image of one row is constant in v.
  explicit EnvironmentMap(const EnvironmentMapDesc& desc);
  // The same map (its texels shared, not copied) sampled in proportion to max(L - mean L, 0) x
  // sin(theta), for MIS-compensated light sampling (see above); nullptr where that would change
  // nothing (a map sampled uniformly, or one that emits nothing).
  std::unique_ptr<EnvironmentMap> compensated() const;

  bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const override;
  // In stages over chunks of samples: every sample's row, then every column, then the cells'
  // loads, the warp within the cells in SIMD lanes, and the radiance lookups. sample() is this
  // on one sample.
  void sample_many(size_t n, const vec3* refs, const float* times, const vec2* u, LightSample* out,
                   bool* ok) const override;
  // Like ConstantEnvironment: the radiance integral over the sphere onto the scene's bounding
  // disc, (integral of L over directions) * pi r^2.
  float power(float scene_radius) const override;
  Spectrum radiance(const vec3& dir) const override;
  float pdf(const vec3& dir) const override;
  Spectrum radiance_and_pdf(const vec3& dir, float* pdf) const override;
  bool prefers_many() const override { return true; }
  void prepare_sampling() const override {
    if (!is_black() && !uniform_sampling_) distribution();
  }
  // Whether the sampling table has been built (by a sample, a density or prepare_sampling; a
  // radiance lookup alone builds nothing): for tests and memory accounting.
  bool sampling_table_built() const { return table_built_.load(std::memory_order_acquire); }
  // The sampling table (built now if it was not): for tests.
  const Distribution2D& sampling_table() const { return distribution(); }
  // A compensated map with nothing above its mean (a constant one) has no density anywhere: it
  // is left to BSDF sampling, as a constant environment is.
  bool left_to_bsdf_sampling() const override { return sampled_nowhere_; }
  // In two stages over chunks: every direction's lat-long coordinates, cell and texels in SIMD
  // lanes, then every texel lookup and density. radiance(), pdf() and radiance_and_pdf() are
  // this on one direction.
  void radiance_and_pdf_many(size_t n, const vec3* dirs, const uint8_t* want_pdf, Spectrum* radiance,
                             float* pdf) const override;

  // Integral of the (scaled) luminance over the sphere of directions; 4 pi L for a constant map.
  double luminance_integral() const { return integral_; }
  // Nothing to emit (every texel black, or scale 0): the scene build leaves such a map out.
  bool is_black() const { return !(integral_ > 0.0); }

  // Where a bilinear lookup at (u, v) in [0, 1]^2 reads: texels x0 and x1 (wrapping at the seam)
  // of rows y0 and y0 + 1, with weights tx and ty.
  struct TexelSpot {
    int x0, x1, y0;
    float tx, ty;
  };
  static TexelSpot texel_spot(float u, float v, int width, int height);
  // The sampling distribution's cell holding (s, t) in [0, 1]^2 (cell coordinates: s starts at
  // texel 0's centre) and the point's place within it, each in [0, 1]: where the bilinear warp
  // starts and where its density is read. NaN is read at cell 0.
  struct CellPoint {
    int x, y;
    float fx, fy;
  };
  static CellPoint cell_point(float s, float t, int width, int height);

  // The lat-long coordinates of a map-space unit direction, u in [0, 1], v in [0, 1], and back.
  static vec2 direction_to_uv(const vec3& d);
  // (Angles by inline arithmetic: atan2_inline, sincos_two_pi; theta = pi v, phi = 2 pi u.)
  static vec3 uv_to_direction(const vec2& uv);
  static vec3 uv_to_direction(float u, float sin_theta, float cos_theta);

 private:
  // Bilinear lookup at the texels `t` names, as Mitsuba's EnvironmentMapEmitter::eval_spectrum.
  Spectrum lookup(const TexelSpot& t) const;
  // Cell (x, y)'s corners: max(luminance - floor_, 0) x sin(theta) of texels x, x + 1 in rows
  // y, y + 1.
  struct Corners {
    float w00, w10, w01, w11;
  };
  Corners corners(int x, int y) const;
  // One corner weight: texel (x, y)'s max(luminance - floor_, 0) x its row's sin(theta).
  float corner(int x, int y) const;
  const float* texel_address(int x, int y) const {
    return texels_ + (size_t(y) * size_t(width_) + size_t(x)) * 3;
  }
  Spectrum texel(int x, int y) const {
    const float* t = texel_address(x, y);
    return Spectrum(t[0], t[1], t[2]);
  }
  // integral_ and max_luminance_ from the texels.
  void integrate_luminance();
  // The compensated twin of `full`: its texels shared, its density over max(L - floor, 0).
  EnvironmentMap(const EnvironmentMap& full, float floor);
  // The sampling distribution over the cells' corners (with floor_ subtracted), built on first
  // use (see build_distribution).
  const Distribution2D& distribution() const;
  void build_distribution() const;

  int width_ = 1, height_ = 2;      // height >= 2: rows are samples from pole to pole
  // The texels times scale, shared by the map and its compensated twin (and, where scale is 1
  // and they are clean, with the scene input's map); texels_ points into it.
  std::shared_ptr<const std::vector<float>> texel_store_;  // RGB per texel
  const float* texels_ = nullptr;
  // The luminance the sampling density leaves out: 0, or the map's mean for the compensated twin.
  float floor_ = 0.f;
  bool sampled_nowhere_ = false;
  glm::mat3 to_world_{1.f}, to_local_{1.f};
  // Cell (x, y) of the distribution spans texels x, x + 1 and rows y, y + 1; in u it starts at
  // texel x's centre, half a texel right of the cell's own coordinate.
  mutable std::once_flag distribution_built_;
  mutable std::atomic<bool> table_built_{false};
  mutable Distribution2D distribution_;
  std::vector<float> row_sin_;  // sin(theta) of each texel row (poles: see build_distribution)
  float half_texel_ = 0.f;
  double integral_ = 0.0;
  float max_luminance_ = 0.f;  // of the brightest texel
  bool uniform_sampling_ = false;
};

// Inline: the SIMD kernels of environment_map.cpp run them in their lanes.
inline vec2 EnvironmentMap::direction_to_uv(const vec3& d) {
  // theta = atan2(sin theta, cos theta) rather than acos(y): the same angle for a unit d, one
  // function for both coordinates, and no loss of digits near the poles.
  float u = atan2_inline(d.x, -d.z) * kInv2Pi;
  if (u < 0.f) u += 1.f;
  return vec2(u, atan2_inline(std::sqrt(d.x * d.x + d.z * d.z), d.y) * kInvPi);
}

inline vec3 EnvironmentMap::uv_to_direction(const vec2& uv) {
  float sin_theta, cos_theta;
  sincos_two_pi(0.5f * uv.y, &sin_theta, &cos_theta);  // theta = pi v
  return uv_to_direction(uv.x, sin_theta, cos_theta);
}

inline vec3 EnvironmentMap::uv_to_direction(float u, float sin_theta, float cos_theta) {
  float sin_phi, cos_phi;
  sincos_two_pi(u, &sin_phi, &cos_phi);  // phi = 2 pi u
  return vec3(sin_phi * sin_theta, cos_theta, -cos_phi * sin_theta);
}

// Where the bilinear lookup at (u, v) reads: texels x0, x1 of rows y0, y0 + 1, weights tx, ty
// (Mitsuba's EnvironmentMapEmitter::eval_spectrum: texel x's centre at u = (x + 0.5) / width,
// the seam wrapping; row y at v = y / (height - 1)). u and v are in [0, 1] here (from a
// direction or a sample; anything else, NaN included, is read at 0), so x0 is in
// [-1, width - 1] and wraps once at most.
inline EnvironmentMap::CellPoint EnvironmentMap::cell_point(float s, float t, int width, int height) {
  const int nu = width, nv = height - 1;
  const float sx = s >= 0.f ? s * float(nu) : 0.f, sy = t >= 0.f ? t * float(nv) : 0.f;
  const int cx = std::clamp(int(std::min(sx, float(nu))), 0, nu - 1);
  const int cy = std::clamp(int(std::min(sy, float(nv))), 0, nv - 1);
  return {cx, cy, std::clamp(sx - float(cx), 0.f, 1.f), std::clamp(sy - float(cy), 0.f, 1.f)};
}

inline EnvironmentMap::TexelSpot EnvironmentMap::texel_spot(float u, float v, int width, int height) {
  u = u >= 0.f && u <= 1.f ? u : 0.f;
  v = v >= 0.f && v <= 1.f ? v : 0.f;
  const float fx = u * float(width) - 0.5f;
  const float x_floor = std::floor(fx);
  int x0 = int(x_floor);
  x0 = x0 < 0 ? x0 + width : x0;
  const float fy = v * float(height - 1);
  const int y0 = std::min(int(fy), height - 2);
  return {x0, x0 + 1 == width ? 0 : x0 + 1, y0, fx - x_floor, fy - float(y0)};
}

}  // namespace penumbra
