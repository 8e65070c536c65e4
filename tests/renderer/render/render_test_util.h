#pragma once
// Scene construction helpers for render tests (scenes built as plain SceneInput, no JSON).
#include <cmath>
#include <memory>

#include "renderer/render/render.h"
#include "renderer/scene/scene.h"
#include "renderer/scene/scene_input.h"

namespace penumbra::test {

inline RenderSettings small_settings(int w, int h, int spp, int max_depth = -1) {
  RenderSettings s;
  s.width = w;
  s.height = h;
  s.spp = spp;
  s.max_depth = max_depth;
  return s;
}

inline RenderResult render_input(const SceneInput& input, const RenderSettings& settings) {
  const auto scene = Scene::build(input);
  return render(*scene, settings);
}

struct ImageStats {
  double mean[3] = {0, 0, 0};
  double min = INFINITY, max = -INFINITY;
  int nonfinite = 0;
};

inline ImageStats image_stats(const Image& img) {
  ImageStats st;
  const size_t n = size_t(img.width) * img.height;
  for (size_t i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) {
      const float v = img.rgb[3 * i + c];
      if (!std::isfinite(v)) {
        ++st.nonfinite;
        continue;
      }
      st.mean[c] += v / double(n);
      st.min = std::min(st.min, double(v));
      st.max = std::max(st.max, double(v));
    }
  return st;
}

// sum |a - b| / sum |b| over every channel of two images of one size (NaN if the sizes differ
// or b is black).
inline double relative_l1(const Image& a, const Image& b) {
  if (a.rgb.size() != b.rgb.size() || a.rgb.empty()) return NAN;
  double diff = 0, sum = 0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    diff += std::abs(double(a.rgb[i]) - double(b.rgb[i]));
    sum += std::abs(double(b.rgb[i]));
  }
  return sum > 0 ? diff / sum : NAN;
}

// Mean over a rectangle of pixels of one channel, and the standard error of that mean from the
// film's per-pixel variance estimates.
inline void region_mean(const RenderResult& r, int x0, int y0, int x1, int y1, int c, double* mean,
                        double* stderr_of_mean) {
  double sum = 0.0, var = 0.0;
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      sum += r.image.pixel(x, y)[c];
      var += r.variance.pixel(x, y)[c];
      ++n;
    }
  *mean = sum / n;
  *stderr_of_mean = std::sqrt(var) / n;
}

inline CameraDesc camera_looking(const vec3& from, const vec3& to, float fov, const vec3& up = {0, 1, 0}) {
  CameraDesc c;
  c.position = from;
  c.look_at = to;
  c.up = up;
  c.fov_degrees = fov;
  c.focus_distance = glm::length(to - from);
  return c;
}

inline ObjectDesc quad_object(const vec3& origin, const vec3& u, const vec3& v, uint32_t material,
                              const Spectrum& emission = Spectrum(0.f)) {
  ObjectDesc o;
  o.shape = QuadDesc{origin, u, v};
  o.material = material;
  o.emission = emission;
  return o;
}

// An axis-aligned box of 12 triangles, each face's four corners counter-clockwise seen from
// outside.
inline MeshDesc box_mesh(const vec3& lo, const vec3& hi) {
  MeshDesc m;
  for (int i = 0; i < 8; ++i)
    m.positions.push_back(vec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z));
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
  return m;
}

// The same box with each face as four triangles around its centre: they do not pair into
// parallelograms (shapes/parallelogram_pairs.h), so the box is traced as Embree's triangles.
inline MeshDesc box_mesh_of_triangles(const vec3& lo, const vec3& hi) {
  const MeshDesc quads = box_mesh(lo, hi);
  MeshDesc m;
  m.positions = quads.positions;
  for (size_t f = 0; f < quads.indices.size(); f += 6) {
    const uint32_t c[4] = {quads.indices[f], quads.indices[f + 1], quads.indices[f + 2],
                           quads.indices[f + 5]};
    const uint32_t centre = uint32_t(m.positions.size());
    m.positions.push_back(0.5f * (m.positions[c[0]] + m.positions[c[2]]));
    for (int k = 0; k < 4; ++k) m.indices.insert(m.indices.end(), {centre, c[k], c[(k + 1) % 4]});
  }
  return m;
}

inline ObjectDesc sphere_object(const vec3& center, float radius, uint32_t material,
                                const Spectrum& emission = Spectrum(0.f)) {
  ObjectDesc o;
  o.shape = SphereDesc{center, radius};
  o.material = material;
  o.emission = emission;
  return o;
}

// White furnace: a unit sphere of `material` inside a uniform environment of radiance 1.
inline SceneInput furnace_with_sphere(const MaterialParams& material) {
  SceneInput in;
  in.camera = camera_looking({0, 0, 4}, {0, 0, 0}, 30.f);
  in.environment = Spectrum(1.f);
  in.materials = {material};
  in.objects = {sphere_object({0, 0, 0}, 1.f, 0)};
  return in;
}

}  // namespace penumbra::test
