#pragma once
// Next-event light samples over arrays, for the wavefront driver's SIMD stages: one path at a
// time a quad or sphere light's sample is a dependent chain of multiplies, square roots and
// divisions; over arrays eight or sixteen paths go at once. Static quad lights (the emitters of
// most scenes; an image-textured one's radiance is then looked up for all the lanes on the light
// at once), static untextured sphere lights (lamps), point and directional lights have kernels
// (the stages' path integrator never chooses a constant environment:
// Light::left_to_bsdf_sampling). One pass of a kernel serves all the lanes of its kind, each
// lane reading its own light's constants (gathers): a scene of many lights, chosen by the
// light tree, costs one pass, not one per light. The values are the scalar code's to the bit: the
// kernels are Quad::sample with AreaLight::sample, sample_sphere (its arithmetic shared,
// shapes/sphere_sample.h) with AreaLight::sample, and PointLight::sample operation for
// operation, compiled without contraction into fused multiply-adds (renderer/CMakeLists.txt).
// Every other light (emitting meshes, moving or textured spheres, moving quads, spot lights,
// environment maps) is `kOwnCode`: the stage calls its Light::sample lane by lane, with the
// lane's point, time and sampler values, and the rest of the step stays in the lanes.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "renderer/core/lane.h"
#include "renderer/core/math.h"
#include "renderer/scene/scene.h"
#include "renderer/textures/image_texture.h"

namespace penumbra {

// The scene's lights as the kernels see them.
struct StagedLights {
  explicit StagedLights(const Scene& scene);

  // kOwnCode: no kernel; sampled lane by lane through Light::sample.
  enum Kind : int32_t { kOwnCode, kQuad, kPoint, kDirectional, kSphere };
  // A static quad light: what Quad::sample and AreaLight::sample read. A textured one's radiance
  // is `radiance` times its image's texel at the sample's uv, which is the sample's (u_x, u_y)
  // (Quad::sample); texture is null for an untextured one.
  struct QuadLight {
    int32_t light;
    float origin[3], u[3], v[3], n[3], area, radiance[3];
    const ImageSpectrumTexture* texture = nullptr;
  };
  // A point light (PointLight::sample) and a directional one (DirectionalLight::sample: its
  // sample is the same everywhere).
  struct PointSource {
    int32_t light;
    float position[3], intensity[3];
  };
  struct DistantSource {
    float wi[3], irradiance[3];
  };
  // A static, untextured sphere light: its centre as Sphere::center_at gives it, its radius and
  // radiance.
  struct SphereLight {
    int32_t light;
    float center[3], radius, radiance[3];
  };
  std::vector<QuadLight> quads;
  std::vector<PointSource> points;
  std::vector<DistantSource> distant;
  std::vector<SphereLight> spheres;
  // The lights' constants as rows of floats, one row per light of quads, spheres and points
  // (quad: origin, u, v, n, area, radiance; sphere: centre, radius, radiance; point: position,
  // intensity), kQuadRow, kSphereRow or kPointRow floats each, which LightRows copies into the
  // arrays of the lanes that chose them.
  static constexpr int32_t kQuadRow = 16, kSphereRow = 7, kPointRow = 6;
  std::vector<float> quad_table, sphere_table, point_table;
  // Per light: its kind and its index in quads, points, distant or spheres.
  std::vector<int32_t> kind, index;
};

// LightSampler::choose of u[i] into light[i], i < n (`cdf`: its table of `lights` entries).
void choose_lights(const float* cdf, int32_t lights, size_t n, const float* u, int32_t* light);

// The kernels below take, per entry i < n, the kind of its light (kind[i], -1 for no light) and
// its index among that kind's lights (slot[i]); the entries of their kind get the sample from
// ref at (s_x, s_y), the others keep what they hold (every lane computes a sample and discards
// what is not its own). ok = whether the light gave a sample;
// e = the sample point's error bound, n = its normal (0 for a point light), value = the
// radiance arriving (a textured quad's texel is multiplied in afterwards).
//
// (With many lights the constants come in arrays rather than as a table and an index per lane:
// GCC's generic tuning does not vectorise loads by a per-lane index, gathers being slow on many
// x86 cores; and every array is a parameter of its own, since GCC trusts __restrict only on
// parameters and without it the kernels, with their dozen outputs, stay scalar.)

// A kind's lights' constants for the kernels. With a few lights (kFewRows or fewer; most scenes
// have one of a kind) the kernel runs once per light, its constants as values, over the lanes
// that chose it; with more, fetch() copies each lane's light's row into one array per float and
// the kernel runs once over all of the kind's lanes.
class LightRows {
 public:
  static constexpr size_t kFewRows = 4;
  LightRows(const std::vector<float>& table, int32_t width, int32_t kind)
      : table_(table), width_(width), kind_(kind), fields_(size_t(width)) {}
  size_t rows() const { return table_.size() / size_t(width_); }
  const float* row(size_t r) const { return table_.data() + r * size_t(width_); }
  // Row slot[i] into fields[f][i] for the first n lanes whose kind is this one's (kind and
  // slot per lane, as StagedLights::kind and index of the lane's light); other lanes keep what
  // they hold.
  void fetch(size_t n, const int32_t* kind, const int32_t* slot);
  const float* operator[](size_t f) const { return fields_[f].data(); }

 private:
  const std::vector<float>& table_;
  int32_t width_, kind_;
  std::vector<std::vector<float>> fields_;
};

// Where a kernel writes each lane's sample (arrays of the stage's lanes).
struct LightSampleArrays {
  int32_t* ok;
  float *wi[3], *distance, *pdf, *p[3], *e[3], *n[3], *value[3];
};

// Quad::sample then AreaLight::sample from ref (three arrays) at s (two): the quads' rows are
// origin, u, v, normal, area, radiance.
void quad_light_samples(size_t n, const int32_t* kind, const int32_t* slot, LightRows& quads,
                        const float* const* ref, const float* const* s,
                        const LightSampleArrays& out);

// Sphere::sample (sample_sphere) then AreaLight::sample: the spheres' rows are centre, radius,
// radiance.
void sphere_light_samples(size_t n, const int32_t* kind, const int32_t* slot, LightRows& spheres,
                          const float* const* ref, const float* const* s,
                          const LightSampleArrays& out);

// PointLight::sample (pdf 1, a delta light): the lights' rows are position, intensity.
void point_light_samples(size_t n, const int32_t* kind, const int32_t* slot, LightRows& points,
                         const float* const* ref, const LightSampleArrays& out);

}  // namespace penumbra
