#pragma once
// The renderer's input: a scene as plain data, in world space, already validated.
// api/ produces it from JSON (applying object transforms) and places the origin at the camera
// position, computed in double precision, so single-precision rendering keeps its accuracy for
// scenes far from the JSON origin; tests may build it directly.
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "renderer/materials/material_params.h"
#include "renderer/core/math.h"
#include "renderer/core/pixel_window.h"
#include "renderer/scene/instance_input.h"
#include "renderer/textures/texture_desc.h"

namespace penumbra {

struct CameraDesc {
  vec3 position{0.f, 0.f, 1.f};
  vec3 look_at{0.f, 0.f, 0.f};
  vec3 up{0.f, 1.f, 0.f};
  float fov_degrees = 40.f;       // vertical field of view
  float aperture_radius = 0.f;    // thin lens (Cook et al. 1984); 0 = pinhole
  float focus_distance = 1.f;     // distance along the view direction that is in focus
  float shutter_open = 0.f;       // scene time units; open == close means no motion blur
  float shutter_close = 0.f;
};

struct SphereDesc {
  vec3 center{0.f};
  float radius = 1.f;
};
// Parallelogram origin + s*u + t*v, s,t in [0,1]; front side along cross(u, v).
struct QuadDesc {
  vec3 origin{0.f};
  vec3 u{1.f, 0.f, 0.f};
  vec3 v{0.f, 1.f, 0.f};
};
// Triangle mesh; counter-clockwise = front. `normals` is empty or one per position (shading).
struct MeshDesc {
  std::vector<vec3> positions;
  std::vector<uint32_t> indices;  // 3 per triangle
  std::vector<vec3> normals;
  // Empty or one per position. (0, 0) is an image's top-left corner (glTF and Mitsuba 3).
  std::vector<vec2> uvs;
};
using ShapeDesc = std::variant<SphereDesc, QuadDesc, MeshDesc>;

struct ObjectDesc {
  ShapeDesc shape;
  uint32_t material = 0;         // index into SceneInput::materials
  Spectrum emission{0.f};        // radiance leaving the front side; 0 = not a light
  // If set, the radiance at a point is `emission` times this texture there (at the hit's uv).
  std::optional<ImageTextureDesc> emission_texture{};
  // A cutout (glTF alphaMode MASK), triangle meshes only: the surface exists where
  // alpha_factor x the texture's value at the hit's uv is >= alpha_cutoff; elsewhere rays pass.
  std::optional<ImageTextureDesc> alpha_texture{};
  float alpha_factor = 1.f;
  float alpha_cutoff = 0.5f;
  // Rigid motion: position(t) = position(0) + velocity*t + 0.5*acceleration*t^2.
  vec3 velocity{0.f};
  vec3 acceleration{0.f};
};

struct PointLightDesc {
  vec3 position{0.f};
  Spectrum intensity{1.f};  // W/sr
};
struct DirectionalLightDesc {
  vec3 direction{0.f, -1.f, 0.f};  // the direction light travels
  Spectrum irradiance{1.f};        // W/m^2 on a surface facing the light
};
using LightDesc = std::variant<PointLightDesc, DirectionalLightDesc>;

// Whether a texel value is one an environment map's light keeps as it is, to the bit: +0 or a
// finite positive number, i.e. its bits lie below +infinity's (a sign bit, infinity and NaN lie
// at or above them; -0 is not clean). By the bits, branch-free, so loops over a map vectorise.
inline bool texel_is_clean(float v) { return std::bit_cast<uint32_t>(v) < 0x7f800000u; }
// What an environment map's light makes of a texel value: itself if finite and > 0, else +0.
inline float clean_texel(float v) { return texel_is_clean(v) ? v : 0.f; }

// An environment from an equirectangular (latitude-longitude) image, with Mitsuba 3's `envmap`
// conventions: in map space, direction (x, y, z) looks up u = atan2(x, -z) / 2 pi (mod 1),
// v = acos(y) / pi, so +y is the top row, +z the centre column, -z the left and right edges.
struct EnvironmentMapDesc {
  int width = 0;                // texels per row (>= 1)
  int height = 0;               // rows (>= 1)
  // width * height * 3 linear radiance values (RGB per texel), row 0 = top (+y). Shared, not
  // copied: a render scene reads them in place where it can (scale 1, every value finite and
  // >= 0, at least two rows), so an 8192 x 4096 map (400 MB) is held once, not once here and once
  // in the light; the api moves the decoded image's own buffer here.
  std::shared_ptr<const std::vector<float>> rgb;
  // Multiplies every texel. The api applies the scene's "scale" to the texels as it reads the
  // image and leaves 1 here, so the light can share them.
  float scale = 1.f;
  glm::mat3 to_world{1.f};      // orthogonal: map space -> world (a rotation, maybe a mirror)
  // For bench/environment_sampling_benchmark.cpp only: sample directions uniformly instead of
  // in proportion to the map (the api never sets it).
  bool uniform_sampling = false;
};

struct SceneInput {
  CameraDesc camera;
  Spectrum environment{0.f};  // constant radiance arriving from every direction at infinity
  std::optional<EnvironmentMapDesc> environment_map;  // if set, used instead of `environment`
  std::vector<MaterialParams> materials;
  std::vector<ObjectDesc> objects;
  std::vector<LightDesc> lights;
  std::vector<InstancesDesc> instances;  // copies of mesh objects (instance_input.h)
  TextureLimits texture_limits;  // applied again as the build decodes the textures' images
};

enum class IntegratorKind { kPath, kDistributed };

// Output layers (AOVs) a render may produce beside the beauty image, as bits of
// RenderSettings::outputs (docs/output-layers.md). The order of the bits is the order in which
// the layers are listed and written.
enum OutputLayerBit : uint32_t {
  kOutputAlbedo = 1u << 0,  // first-hit surface colour, RGB in [0, 1]
  kOutputNormal = 1u << 1,  // first-hit shading normal, world space, XYZ
  kOutputDepth = 1u << 2,   // first-hit z-depth along the camera's view axis, Z
};
inline constexpr int kOutputLayerCount = 3;
inline constexpr const char* kOutputLayerNames[kOutputLayerCount] = {"albedo", "normal", "depth"};
// With RenderSettings::denoise, the beauty image as rendered (unbiased, noisy) is kept as this
// extra layer after the requested ones, and the image becomes the denoised one.
inline constexpr const char* kNoisyLayerName = "noisy";

// The sampler's points (renderer/sampling/sampler.h, cmj.h). Correlated multi-jittered points need
// every pixel to take spp samples, a power of two: otherwise (adaptive sampling, another count)
// the render takes Sobol points whatever this says (api/ resolves the scene's "auto" and rejects
// "cmj" where it would not apply).
enum class SamplerKind { kCorrelatedMultiJitter, kSobol };

struct RenderSettings {
  int width = 256;
  int height = 256;
  int spp = 64;
  int max_depth = 8;      // path segments from the camera, Mitsuba 3 convention; -1 = unlimited
  int rr_depth = 5;       // Russian roulette starts at this depth (Mitsuba 3 default)
  IntegratorKind integrator = IntegratorKind::kPath;
  SamplerKind sampler = SamplerKind::kCorrelatedMultiJitter;
  uint64_t seed = 0;
  int threads = 0;        // 0 = all hardware threads
  int tile_size = 16;
  float noise_threshold = 0.f;  // adaptive sampling: stop pixels below this relative error; 0 = off
  double time_limit = 0.0;      // seconds; 0 = none
  uint32_t outputs = 0;         // OutputLayerBit set; 0 = the beauty image only
  // Denoise the finished image with Open Image Denoise, guided by albedo and normal layers
  // (rendered for it whether or not `outputs` asks for them); renderer/denoise/oidn_denoiser.h.
  bool denoise = false;
  // Render only these pixels of the width x height image (a tile of a frame split across
  // machines). Each pixel gets exactly the values the full render gives it with uniform
  // sampling; adaptive sampling decides within the window (docs/animation-and-windows.md).
  // Unset: the whole image. Must fit inside the image (api/ checks it).
  std::optional<PixelWindow> window;
  // How paths are advanced: a batch a bounce at a time with rays traced in packets
  // (renderer/render/wavefront_integrator.h), or one path at a time, one ray at a time
  // (integrator.h, the reference). Both give the same image.
  bool wavefront = true;
  // Path reuse (renderer/render/path_reuse.h): the paths of each path_reuse x path_reuse block
  // of pixels share their second vertices, one sample index at a time. 1 = off. The path
  // integrator's wavefront driver only, and not with motion blur, rr_depth 1 or max_depth 2.
  // At most kMaxPathReuse (api/ checks it).
  int path_reuse = 1;
  static constexpr int kMaxPathReuse = 4;
};

}  // namespace penumbra
