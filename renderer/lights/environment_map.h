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
#include <vector>

#include "renderer/lights/environment_light.h"
#include "renderer/sampling/distribution_2d.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

class EnvironmentMap final : public EnvironmentLight {
 public:
  // Negative and non-finite texels count as 0; an image of one row is constant in v.
  explicit EnvironmentMap(const EnvironmentMapDesc& desc);

  bool sample(const vec3& ref, float time, const vec2& u, LightSample* out) const override;
  // In three stages over all n: every sample's row, then every column, then the rest.
  void sample_many(size_t n, const vec3* refs, const float* times, const vec2* u, LightSample* out,
                   bool* ok) const override;
  // Like ConstantEnvironment: the radiance integral over the sphere onto the scene's bounding
  // disc, (integral of L over directions) * pi r^2.
  float power(float scene_radius) const override;
  Spectrum radiance(const vec3& dir) const override;
  float pdf(const vec3& dir) const override;
  Spectrum radiance_and_pdf(const vec3& dir, float* pdf) const override;
  bool prefers_many() const override { return true; }
  // In two stages: every direction's lat-long coordinates, then every texel lookup and density.
  void radiance_and_pdf_many(size_t n, const vec3* dirs, const uint8_t* want_pdf, Spectrum* radiance,
                             float* pdf) const override;

  // Integral of the (scaled) luminance over the sphere of directions; 4 pi L for a constant map.
  double luminance_integral() const { return integral_; }
  // Nothing to emit (every texel black, or scale 0): the scene build leaves such a map out.
  bool is_black() const { return !(integral_ > 0.0); }

  // The lat-long coordinates of a map-space unit direction, u in [0, 1], v in [0, 1], and back.
  static vec2 direction_to_uv(const vec3& d);
  static vec3 uv_to_direction(const vec2& uv);

 private:
  // Bilinear lookup at (u, v), as Mitsuba's EnvironmentMapEmitter::eval_spectrum.
  Spectrum lookup(const vec2& uv) const;
  // sample() from the point st of the distribution's cell (density pdf_cell) on: the bilinear
  // warp within the cell, the direction, its radiance and density.
  bool sample_in_cell(const vec2& st, float pdf_cell, LightSample* out) const;
  struct CellPoint;
  struct Corners;
  // The same from the point's place in its cell and the cell's corners.
  bool sample_in_cell(const CellPoint& q, Corners c, float pdf_cell, LightSample* out) const;
  // pdf() of the map-space direction d whose lat-long coordinates are uv.
  float pdf_local(const vec3& d, const vec2& uv) const;
  // The distribution's cell holding st (cell coordinates, u from texel x's centre) and st's place
  // within it, each in [0, 1]: where the bilinear warp starts and where its density is read.
  struct CellPoint {
    int x, y;
    float fx, fy;
  };
  CellPoint cell_point(const vec2& st) const;
  // Cell (x, y)'s corners: luminance x sin(theta) of texels x, x + 1 in rows y, y + 1.
  struct Corners {
    float w00, w10, w01, w11;
  };
  Corners corners(int x, int y) const;
  const Spectrum& texel(int x, int y) const { return texels_[size_t(y) * size_t(width_) + size_t(x)]; }

  int width_ = 1, height_ = 2;      // height >= 2: rows are samples from pole to pole
  std::vector<Spectrum> texels_;  // times scale
  glm::mat3 to_world_{1.f}, to_local_{1.f};
  // Cell (x, y) of the distribution spans texels x, x + 1 and rows y, y + 1; in u it starts at
  // texel x's centre, half a texel right of the cell's own coordinate.
  Distribution2D distribution_;
  std::vector<float> row_sin_;  // sin(theta) of each texel row (poles: see the constructor)
  float half_texel_ = 0.f;
  double integral_ = 0.0;
  bool uniform_sampling_ = false;
};

}  // namespace penumbra
