#pragma once
// Output layers (AOVs): what the integrator reports about a camera ray's first hit, and the film
// that averages it per pixel beside the beauty image (docs/output-layers.md).
#include <cstdint>
#include <vector>

#include "renderer/core/image.h"
#include "renderer/core/math.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {

// Depth of a pixel none of whose samples hit a surface: the value Cycles writes for the
// background in its Z pass, large and finite (an image never holds Inf).
inline constexpr float kBackgroundDepth = 1e10f;

// The first hit of one camera sample, filled by the integrator when asked (a null pointer costs
// the beauty render nothing but one compare per camera ray).
struct FirstHit {
  bool hit = false;
  Spectrum albedo{0.f};  // SurfaceBsdf::albedo(); for a miss the environment clamped to [0, 1]
  vec3 normal{0.f};      // shading normal facing the ray (0 for a miss)
  vec3 p{0.f};           // world position of the hit
};

// Per-pixel sums of the requested layers. Like Film, a box filter: a sample counts for its own
// pixel only, so each pixel is written by one tile and needs no lock.
class LayerFilm {
 public:
  // `outputs`: OutputLayerBit set; `view_origin`, `view_axis`: the camera's position and unit
  // forward direction, for z-depth.
  LayerFilm(int width, int height, uint32_t outputs, const vec3& view_origin, const vec3& view_axis);

  // Non-finite values are not recorded (a camera sample never produces them; defensive).
  void add_sample(int x, int y, const FirstHit& h) {
    Pixel& px = pixels_[size_t(y) * width_ + x];
    ++px.n;
    for (int c = 0; c < 3; ++c) {
      if (std::isfinite(h.albedo[c])) px.albedo[c] += h.albedo[c];
      if (std::isfinite(h.normal[c])) px.normal[c] += h.normal[c];
    }
    if (h.hit) {
      const float depth = glm::dot(h.p - view_origin_, view_axis_);
      if (std::isfinite(depth)) {
        px.depth += depth;
        ++px.hits;
      }
    }
  }

  // The requested layers in OutputLayerBit order: albedo and normal are the means over the
  // pixel's samples; depth is the mean over the samples that hit a surface (kBackgroundDepth
  // where none did), so a silhouette's depth is its surface's, not a blend with 1e10.
  std::vector<ImageLayer> resolve() const;

 private:
  struct Pixel {
    double albedo[3] = {0, 0, 0};
    double normal[3] = {0, 0, 0};
    double depth = 0;
    uint32_t n = 0;
    uint32_t hits = 0;
  };
  int width_, height_;
  uint32_t outputs_;
  vec3 view_origin_, view_axis_;
  std::vector<Pixel> pixels_;
};

}  // namespace penumbra
