#pragma once
// Next-event light choices and light samples over arrays, for the wavefront driver's SIMD
// stages: one path at a time a quad light's sample is a dependent chain of multiplies, a square
// root and two divisions; over arrays eight or sixteen paths go at once. Static quad lights (the
// emitters of most scenes; an image-textured one's radiance is then looked up for all the lanes
// on the light at once), point and directional lights have kernels (the stages'
// path integrator never chooses a constant environment: Light::left_to_bsdf_sampling). The
// values are the scalar code's to the bit: the kernels are LightSampler::choose, Quad::sample
// with AreaLight::sample, and PointLight::sample operation for operation, compiled without
// contraction into fused multiply-adds (renderer/CMakeLists.txt). Every other light (spheres,
// emitting meshes, moving quads, spot lights, environment maps) is `kOwnCode`: the
// stage calls its Light::sample lane by lane, with the lane's point, time and sampler values,
// and the rest of the step stays in the lanes.
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
  enum Kind : int32_t { kOwnCode, kQuad, kPoint, kDirectional };
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
  // Lights with kernels at most: more quad and point lights than this are all sampled lane by
  // lane (their kernels run over every lane once per light).
  static constexpr size_t kMaxStaged = 8;
  std::vector<QuadLight> quads;
  std::vector<PointSource> points;
  std::vector<DistantSource> distant;
  // Per light: its kind and its index in quads, points or distant.
  std::vector<int32_t> kind, index;
};

// LightSampler::choose of u[i] into light[i], i < n (`cdf`: its table of `lights` entries).
void choose_lights(const float* cdf, int32_t lights, size_t n, const float* u, int32_t* light);

// Quad::sample then AreaLight::sample from ref at (u_x, u_y), for the entries whose light is
// `id`; other entries keep what they hold. ok = whether the light gave a sample.
void quad_light_samples(const float* q_origin, const float* q_u, const float* q_v,
                        const float* q_n, float q_area, int32_t id, size_t n, const int32_t* light,
                        const float* ref_x, const float* ref_y, const float* ref_z,
                        const float* u_x, const float* u_y, int32_t* ok, float* wi_x, float* wi_y,
                        float* wi_z, float* distance, float* pdf, float* p_x, float* p_y,
                        float* p_z, float* e_x, float* e_y, float* e_z);

// PointLight::sample from ref for the entries whose light is `id` (pdf 1, a delta light);
// other entries keep what they hold.
void point_light_samples(const float* position, const float* intensity, int32_t id, size_t n,
                         const int32_t* light, const float* ref_x, const float* ref_y,
                         const float* ref_z, int32_t* ok, float* wi_x, float* wi_y, float* wi_z,
                         float* distance, float* pdf, float* p_x, float* p_y, float* p_z,
                         float* value_x, float* value_y, float* value_z);


}  // namespace penumbra
