#pragma once
// Helpers of the numerical-stability stress suite: scenes as plain SceneInput or JSON text,
// renders, NaN/Inf counts, and noise-aware image comparisons.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "api/scene_loader.h"
#include "renderer/render/render.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_input.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {

inline RenderSettings settings(int w, int h, int spp, int max_depth = -1, uint64_t seed = 0) {
  RenderSettings s;
  s.width = w;
  s.height = h;
  s.spp = spp;
  s.max_depth = max_depth;
  s.seed = seed;
  return s;
}


// Loads JSON scene text with the public loader (asserting it is valid) and renders it.
inline RenderResult render_json(const std::string& json, const RenderSettings* override_settings = nullptr) {
  const api::LoadResult loaded = api::load_scene(json);
  if (!loaded.ok()) {
    std::string all;
    for (const auto& e : loaded.errors) all += e.to_string() + "\n";
    ADD_FAILURE() << "scene does not load:\n" << all;
    return {};
  }
  const auto scene = Scene::build(loaded.request->scene);
  return render(*scene, override_settings ? *override_settings : loaded.request->settings);
}

// Pixels (channels) that are NaN or Inf in the image, plus samples the film dropped as such.
inline int64_t nonfinite_count(const RenderResult& r) {
  int64_t n = int64_t(r.stats.nonfinite_samples);
  for (float v : r.image.rgb)
    if (!std::isfinite(v)) ++n;
  for (float v : r.variance.rgb)
    if (!std::isfinite(v)) ++n;
  return n;
}

inline double channel_mean(const Image& img, int c) {
  double s = 0.0;
  const size_t n = size_t(img.width) * img.height;
  for (size_t i = 0; i < n; ++i) s += img.rgb[3 * i + c];
  return n ? s / double(n) : 0.0;
}

// Mean of all channels and pixels and the standard error of that mean (from the film's
// per-pixel variance of the mean).
struct MeanAndError {
  double mean = 0.0, stderr_of_mean = 0.0;
};
inline MeanAndError image_mean(const RenderResult& r, int x0 = 0, int y0 = 0, int x1 = -1, int y1 = -1) {
  if (x1 < 0) x1 = r.image.width;
  if (y1 < 0) y1 = r.image.height;
  double sum = 0.0, var = 0.0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      for (int c = 0; c < 3; ++c) {
        sum += r.image.pixel(x, y)[c];
        var += r.variance.pixel(x, y)[c];
        ++n;
      }
  return {sum / n, std::sqrt(var) / n};
}

// Compares two renders of the same picture block by block: every block mean of `b` must lie
// within k combined standard errors (plus a small relative slack for the box filter of slightly
// shifted geometry) of the same block of `a`. Returns the number of blocks that do not.
struct BlockComparison {
  int blocks = 0, bad = 0;
  double worst_sigma = 0.0;
  std::string first_bad;
};
inline BlockComparison compare_blocks(const RenderResult& a, const RenderResult& b, int block, double k,
                                      double rel_slack = 0.0) {
  BlockComparison cmp;
  for (int by = 0; by + block <= a.image.height; by += block)
    for (int bx = 0; bx + block <= a.image.width; bx += block)
      for (int c = 0; c < 3; ++c) {
        double ma = 0, mb = 0, va = 0, vb = 0;
        for (int y = by; y < by + block; ++y)
          for (int x = bx; x < bx + block; ++x) {
            ma += a.image.pixel(x, y)[c];
            mb += b.image.pixel(x, y)[c];
            va += a.variance.pixel(x, y)[c];
            vb += b.variance.pixel(x, y)[c];
          }
        const double n = double(block) * block;
        ma /= n;
        mb /= n;
        const double sigma = std::sqrt(va + vb) / n;
        const double tol = k * sigma + rel_slack * std::max(std::abs(ma), 1e-3);
        const double z = std::abs(ma - mb) / std::max(sigma, 1e-12);
        ++cmp.blocks;
        cmp.worst_sigma = std::max(cmp.worst_sigma, z);
        if (!(std::abs(ma - mb) <= tol)) {
          if (cmp.bad++ == 0)
            cmp.first_bad = "block (" + std::to_string(bx) + "," + std::to_string(by) + ") channel " +
                            std::to_string(c) + ": " + std::to_string(ma) + " vs " + std::to_string(mb) +
                            " (sigma " + std::to_string(sigma) + ")";
        }
      }
  return cmp;
}

// Scene-building helpers shared with the renderer tests.
inline ObjectDesc quad(const vec3& origin, const vec3& u, const vec3& v, uint32_t material,
                       const Spectrum& emission = Spectrum(0.f)) {
  return quad_object(origin, u, v, material, emission);
}
inline ObjectDesc sphere(const vec3& center, float radius, uint32_t material,
                         const Spectrum& emission = Spectrum(0.f)) {
  return sphere_object(center, radius, material, emission);
}

inline ObjectDesc box(const vec3& lo, const vec3& hi, uint32_t material) {
  ObjectDesc o;
  o.shape = box_mesh(lo, hi);
  o.material = material;
  return o;
}

// A box of six quads, faces outward, its corners turned by `rotation` about `lo` (each face's
// corner and edges rotated and rounded on their own, so neighbouring faces share their edges only
// to float rounding, as a user's hand-made box does).
inline std::vector<ObjectDesc> quad_box(const vec3& lo, const vec3& hi, uint32_t material,
                                        const glm::mat3& rotation = glm::mat3(1.f)) {
  const vec3 e = hi - lo;
  const vec3 x(e.x, 0.f, 0.f), y(0.f, e.y, 0.f), z(0.f, 0.f, e.z);
  const vec3 faces[6][3] = {{vec3(0.f), z, y}, {x, y, z}, {vec3(0.f), x, z},
                            {y, z, x},         {vec3(0.f), y, x}, {z, x, y}};
  std::vector<ObjectDesc> out;
  for (const auto& f : faces)
    out.push_back(quad(lo + rotation * f[0], rotation * f[1], rotation * f[2], material));
  return out;
}

// Unit-radius UV sphere as a triangle mesh (counter-clockwise from outside), optional smooth
// normals.
inline MeshDesc uv_sphere_mesh(const vec3& center, float radius, int rings, int segments, bool normals) {
  MeshDesc m;
  for (int i = 0; i <= rings; ++i) {
    const float theta = kPi * float(i) / float(rings);
    for (int j = 0; j <= segments; ++j) {
      const float phi = 2.f * kPi * float(j) / float(segments);
      const vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(center + radius * n);
      if (normals) m.normals.push_back(n);
    }
  }
  const int row = segments + 1;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * row + j), b = a + 1, c = a + uint32_t(row), d = c + 1;
      if (i != 0) m.indices.insert(m.indices.end(), {a, b, c});
      if (i != rings - 1) m.indices.insert(m.indices.end(), {b, d, c});
    }
  return m;
}

}  // namespace penumbra::test
