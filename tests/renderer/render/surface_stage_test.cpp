// The wavefront driver's surface stages (renderer/render/surface_stage.h) against path_scatter,
// the scalar step they repeat in SIMD lanes: for real hits on a floor and ball of each stage's
// model, Lambertian, rough conductors, rough plastics and rough dielectrics of several
// roughnesses and iors, smooth plastics and dielectrics of several iors and a mirror (front and
// back side, at every depth around the roulette depth, with the sampler's corner values), every
// result must be path_scatter's to the bit: whether the path goes on, its new state and how
// many sampler values it took, its shadow ray and contribution, and the ray count. The lights:
// two quads and an environment (area lights with MIS), a point and a directional light (deltas),
// and an emitting sphere and an emitting box mesh, which have no kernel (their own
// Light::sample per lane); in a second scene an environment map and a moving quad light (also
// sampled by their own code).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "renderer/materials/plastic.h"
#include "renderer/render/lane_bsdfs.h"
#include "renderer/render/surface_stage.h"
#include "renderer/render/path_step.h"
#include "renderer/sampling/sobol_batch.h"
#include "renderer/scene/scene.h"
#include "tests/renderer/render/render_test_util.h"
#include "tests/renderer/textures/texture_test_util.h"

namespace penumbra::test {
namespace {

template <class T>
bool same_bits(const T& a, const T& b) {
  return std::memcmp(&a, &b, sizeof(T)) == 0;
}

// Hands out a lane's prefetched values in order, as PrefetchedSampler does: a 1D value is x[j],
// a 2D one (x[j], y[j]).
class ListSampler {
 public:
  ListSampler(const float* x, const float* y, const float* z) : x_(x), y_(y), z_(z) {}
  float get_1d() { return x_[used_++]; }
  vec2 get_2d() {
    const int j = used_++;
    return vec2(x_[j], y_[j]);
  }
  // A pair starts at dimension 0 or 2 (BounceSamples::kBouncePairs): its 1D value is z[0] or z[1].
  void get_1d_2d(float* u1, vec2* u2) {
    EXPECT_TRUE(used_ == 0 || used_ == 2) << "a pair at dimension " << used_;
    *u1 = z_[used_ / 2];
    *u2 = vec2(x_[used_ + 1], y_[used_ + 1]);
    used_ += 2;
  }
  int used() const { return used_; }

 private:
  const float* x_;
  const float* y_;
  const float* z_;
  int used_ = 0;
};

// A tilted floor: no component of its normal is 0 or 1, so the shading frame's arithmetic is
// all exercised.
const vec3 kFloorOrigin(-2.f, -0.3f, 2.f), kFloorU(4.f, 0.5f, 0.3f), kFloorV(0.2f, 0.4f, -4.f);
// And a ball of the same material, for normals in every direction (hit from outside and inside).
const vec3 kBallCentre(0.3f, 1.2f, -0.2f);
constexpr float kBallRadius = 0.6f;

// The floor and ball's material for a stage's model (`roughness` of a conductor or a rough
// plastic, `ior` of a plastic).
MaterialParams stage_material(StageModel model, float roughness, float ior) {
  switch (model) {
    case StageModel::kLambert:
      return DiffuseParams{Spectrum(0.7f, 0.5f, 0.3f)};
    case StageModel::kRoughConductor:
      return ConductorParams{Spectrum(0.9f, 0.6f, 0.3f), roughness};
    case StageModel::kSmoothPlastic:
      return PlasticParams{Spectrum(0.2f, 0.4f, 0.8f), ior, 0.f};
    case StageModel::kRoughPlastic:
      return PlasticParams{Spectrum(0.7f, 0.15f, 0.1f), ior, roughness};
    case StageModel::kRoughDielectric:
      return DielectricParams{ior, roughness, Spectrum(0.2f, 0.f, 0.5f)};
    case StageModel::kSmoothConductor:
      return ConductorParams{Spectrum(0.9f, 0.6f, 0.3f), 0.f};
    case StageModel::kSmoothDielectric:
      return DielectricParams{ior, 0.f, Spectrum(0.2f, 0.f, 0.5f)};
    case StageModel::kMetallicRoughness:
      return MetallicRoughnessParams{Spectrum(0.8f, 0.5f, 0.3f), 0.5f, roughness};
  }
  return DiffuseParams{};
}

// The lights of floor_scene: none; quads, a sphere, a mesh, point and directional lights in a
// constant environment; or an environment map and a moving quad light.
enum class Lights { kNone, kMixed, kMapAndMovingQuad };

SceneInput floor_scene(bool lights, const MaterialParams& material) {
  SceneInput in;
  in.camera = camera_looking({0, 2, 4}, {0, 0, 0}, 40.f);
  in.materials = {material, DiffuseParams{Spectrum(0.f)}};
  in.objects = {quad_object(kFloorOrigin, kFloorU, kFloorV, 0),
                sphere_object(kBallCentre, kBallRadius, 0)};
  if (lights) {
    in.environment = Spectrum(0.2f, 0.3f, 0.4f);
    // Two quad lights of different power and orientation, one seen from below the floor too.
    in.objects.push_back(quad_object({-0.5f, 2, -0.5f}, {1, 0, 0}, {0, 0, 1}, 1, Spectrum(5.f)));
    in.objects.push_back(
        quad_object({1.5f, -1, 1}, {0, 0, -2}, {0, 1.5f, 0}, 1, Spectrum(1.f, 2.f, 3.f)));
    in.objects.push_back(sphere_object({2.f, 2.5f, -1.5f}, 0.3f, 1, Spectrum(3.f, 3.f, 2.f)));
    ObjectDesc box;
    box.shape = box_mesh({-2.5f, 1.8f, 1.f}, {-2.f, 2.2f, 1.4f});
    box.material = 1;
    box.emission = Spectrum(2.f, 1.f, 0.5f);
    in.objects.push_back(box);
    in.lights = {PointLightDesc{{-1, 1, 1}, Spectrum(2.f)},
                 DirectionalLightDesc{{-0.3f, -1.f, -0.2f}, Spectrum(0.8f, 0.6f, 0.4f)}};
  }
  return in;
}

SceneInput floor_scene(Lights lights, const MaterialParams& material) {
  if (lights != Lights::kMapAndMovingQuad) return floor_scene(lights == Lights::kMixed, material);
  SceneInput in = floor_scene(false, material);
  // A map with a bright patch (its sampling far from uniform) over a dim gradient.
  EnvironmentMapDesc map;
  map.width = 32;
  map.height = 16;
  auto rgb = std::make_shared<std::vector<float>>();
  for (int y = 0; y < map.height; ++y)
    for (int x = 0; x < map.width; ++x)
      for (int c = 0; c < 3; ++c)
        rgb->push_back((x > 20 && x < 24 && y > 3 && y < 6) ? 40.f + float(c)
                                                               : 0.05f * float(x + y + c));
  map.rgb = std::move(rgb);
  map.scale = 0.7f;
  in.environment_map = map;
  ObjectDesc moving = quad_object({-0.5f, 2, -0.5f}, {1, 0, 0}, {0, 0, 1}, 1, Spectrum(5.f));
  moving.velocity = vec3(0.3f, 0.f, 0.1f);
  in.objects.push_back(moving);
  in.camera.shutter_close = 1.f;  // (without a shutter interval nothing moves)
  return in;
}

struct Lane {
  PathState state;
  SurfaceHit hit;
  float x[BounceSamples::kBounce], y[BounceSamples::kBounce], z[2];
};

// Rays onto the floor from above and below, from random points, with random path states and
// sampler values (a tenth of them set to the concentric map's centre and other edges).
std::vector<Lane> floor_hits(const Scene& scene, size_t count, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<Lane> lanes;
  while (lanes.size() < count) {
    vec3 from, to;
    const float pick = u(rng);
    if (pick < 0.5f) {  // the floor, from above (mostly) or below
      const float side = u(rng) < 0.7f ? 1.f : -1.f;
      to = kFloorOrigin + (0.05f + 0.9f * u(rng)) * kFloorU + (0.05f + 0.9f * u(rng)) * kFloorV;
      from = to + vec3(4.f * u(rng) - 2.f, side * (0.2f + 3.f * u(rng)), 4.f * u(rng) - 2.f);
    } else {  // the ball, from outside or from inside
      const vec3 d = glm::normalize(vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f));
      to = kBallCentre + kBallRadius * d;
      const vec3 e = vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f);
      from = pick < 0.8f ? to + 2.f * d + e : kBallCentre + 0.5f * kBallRadius * e;
    }
    Lane lane;
    lane.state = PathState(Ray{from, glm::normalize(to - from), u(rng)});
    if (!scene.intersect(lane.state.ray, &lane.hit) || lane.hit.object > 1) continue;
    lane.state.beta = Spectrum(u(rng), u(rng), u(rng)) * (u(rng) < 0.2f ? 0.02f : 1.f);
    lane.state.eta = u(rng) < 0.5f ? 1.f : 1.5f;
    lane.state.depth = 1 + int(rng() % 8);
    lane.state.prev_pdf = u(rng);
    lane.state.prev_delta = u(rng) < 0.5f;
    for (int j = 0; j < BounceSamples::kBounce; ++j) {
      lane.x[j] = u(rng);
      lane.y[j] = u(rng);
    }
    lane.z[0] = u(rng);
    lane.z[1] = u(rng);
    if (lanes.size() % 10 == 3) lane.x[3] = lane.y[3] = 0.5f;  // the disk's centre
    if (lanes.size() % 10 == 5) lane.x[1] = lane.y[1] = 0.5f;
    if (lanes.size() % 10 == 7) lane.x[3] = 0.f, lane.y[3] = 0.5f;
    if (lanes.size() % 10 == 9) lane.x[3] = lane.y[3] = 0.f;
    lanes.push_back(lane);
  }
  return lanes;
}

struct Coverage {
  int staged = 0, fallback = 0, alive = 0, dead = 0, shadows = 0, back = 0, ball = 0, delta = 0;
  int delta_lights = 0;  // staged lanes whose chosen light is a point or directional light
  int own_code_lights = 0;  // staged lanes whose chosen light has no kernel
  int kernel_lights[5] = {};  // staged lanes by their chosen light's StagedLights::Kind
  int textured_lights = 0;  // staged lanes whose chosen light is a textured quad
};

// The stage on floor_hits of the scene `in` (its objects 0 and 1 the floor and the ball),
// against path_scatter; `lights`: whether it has lights.
Coverage expect_stage_matches_scene(const SceneInput& in, bool lights, uint32_t seed,
                                    StageModel model) {
  const auto scene = Scene::build(in);
  const StagedLights staged_lights(*scene);
  IntegratorSettings settings;
  settings.max_depth = 16;
  settings.rr_depth = 4;
  const bool next_event = !scene->light_sampler().empty();
  EXPECT_EQ(next_event, lights);
  const std::vector<Lane> lanes = floor_hits(*scene, 2000, seed);
  SurfaceStage stage(*scene, model);
  EXPECT_TRUE(stage.takes(0));
  EXPECT_TRUE(stage.takes(1));
  // The lanes in the driver's arrays: slot k's hit in hits[k], its path live[k] (paths in
  // another order than slots), its sampler values in column hit_of[k] of dimension-major
  // arrays (columns in a third order). Queued last slot first, in chunks as the driver hands
  // them over, so that a result put in the lane's place instead of its slot's shows, and so does
  // a chunk written over another. The flags start at 2, so a lane the stage did not deliver shows.
  const size_t n = lanes.size();
  std::vector<uint32_t> live(n), hit_of(n), slots(n);
  std::vector<PathState> states(n);
  std::vector<SurfaceHit> hits(n);
  std::vector<float> xs(BounceSamples::kBounce * n), ys(BounceSamples::kBounce * n), zs(2 * n);
  for (size_t k = 0; k < n; ++k) {
    live[k] = uint32_t(n - 1 - k);
    hit_of[k] = uint32_t((k * 7 + 3) % n);
    slots[k] = uint32_t(n - 1 - k);
    states[live[k]] = lanes[k].state;
    hits[k] = lanes[k].hit;
    for (int d = 0; d < BounceSamples::kBounce; ++d) {
      xs[size_t(d) * n + hit_of[k]] = lanes[k].x[d];
      ys[size_t(d) * n + hit_of[k]] = lanes[k].y[d];
    }
    zs[hit_of[k]] = lanes[k].z[0];
    zs[n + hit_of[k]] = lanes[k].z[1];
  }
  EXPECT_EQ(std::gcd(size_t(7), n), 1u);  // hit_of a permutation
  stage.start(n);
  for (size_t c = 0; c < n; c += 128)
    stage.add_many(std::min<size_t>(128, n - c), slots.data() + c, live.data(), hit_of.data(),
                   states.data(), hits.data(), xs.data(), ys.data(), zs.data(), n, next_event);
  stage.compute(settings, next_event);
  EXPECT_EQ(stage.size(), n);

  std::vector<Sampler::Cursor> cursors(n, Sampler::Cursor{0, 100});
  std::vector<uint8_t> goes_on_of(n, 2), has_shadow_of(n, 2);
  std::vector<ShadowQuery> shadows(n);
  std::vector<uint32_t> unstaged;
  const uint64_t delivered_rays =
      stage.deliver(live.data(), states.data(), cursors.data(), goes_on_of.data(),
                    has_shadow_of.data(), shadows.data(), &unstaged);
  std::vector<uint8_t> is_unstaged(n, 0);
  for (const uint32_t lane : unstaged) is_unstaged[lane] = 1;

  Coverage cover;
  uint64_t scatter_rays = 0;
  for (size_t lane = 0; lane < stage.size(); ++lane) {
    const size_t k = stage.slot(lane);
    PathState s = lanes[k].state;
    SurfaceHit hit = lanes[k].hit;
    ListSampler sampler(lanes[k].x, lanes[k].y, lanes[k].z);
    PathCounters counters;
    ShadowQuery shadow;
    bool has_shadow = false;
    const bool goes_on = path_scatter<false, kFeatureAll>(*scene, settings, s, hit, sampler,
                                                          counters, &shadow, &has_shadow);
    const PathState& staged = states[live[k]];
    if (is_unstaged[lane]) {
      ++cover.fallback;
      EXPECT_EQ(goes_on_of[k], 2);  // left to the caller
      EXPECT_EQ(has_shadow_of[k], 2);
      continue;
    }
    ++cover.staged;
    scatter_rays += counters.rays;
    if (next_event) {
      LightSample ls;
      float pmf;
      const int chosen = scene->mis_light_sampler().choose(lanes[k].z[0], hit.p, hit.ng, &pmf);
      if (chosen >= 0) {  // (-1: no light reaches the point, a light tree's choice)
        const Light& light = scene->mis_light(chosen);
        cover.delta_lights += light.sample(hit.p, 0.f, vec2(0.5f), &ls) && ls.is_delta;
        cover.own_code_lights += staged_lights.kind[size_t(chosen)] == StagedLights::kOwnCode;
        ++cover.kernel_lights[staged_lights.kind[size_t(chosen)]];
        cover.textured_lights += staged_lights.kind[size_t(chosen)] == StagedLights::kQuad &&
                                 staged_lights.quads[size_t(staged_lights.index[size_t(chosen)])].texture;
      }
    }
    cover.back += glm::dot(lanes[k].state.ray.direction, hit.ng) > 0.f;
    cover.ball += hit.object == 1;
    SCOPED_TRACE("lane " + std::to_string(lane));
    EXPECT_EQ(has_shadow_of[k], has_shadow ? 1 : 0);
    EXPECT_EQ(goes_on_of[k], goes_on ? 1 : 0);
    if (has_shadow_of[k] != has_shadow || goes_on_of[k] != goes_on) continue;
    if (has_shadow) {
      ++cover.shadows;
      const ShadowQuery& q = shadows[k];
      EXPECT_TRUE(same_bits(q.ray.origin, shadow.ray.origin));
      EXPECT_TRUE(same_bits(q.ray.direction, shadow.ray.direction));
      EXPECT_TRUE(same_bits(q.ray.t_max, shadow.ray.t_max));
      EXPECT_TRUE(same_bits(q.ray.time, shadow.ray.time));
      EXPECT_TRUE(same_bits(q.contribution, shadow.contribution));
    }
    if (!goes_on) {
      ++cover.dead;
      continue;
    }
    ++cover.alive;
    cover.delta += s.prev_delta;
    EXPECT_EQ(cursors[live[k]].dimension, 100u + uint64_t(sampler.used()));
    EXPECT_TRUE(same_bits(staged.beta, s.beta));
    EXPECT_TRUE(same_bits(staged.prev_pdf, s.prev_pdf));
    EXPECT_EQ(staged.prev_delta, s.prev_delta);
    EXPECT_TRUE(same_bits(staged.prev_p, s.prev_p));
    EXPECT_TRUE(same_bits(staged.ray.origin, s.ray.origin));
    EXPECT_TRUE(same_bits(staged.ray.direction, s.ray.direction));
    EXPECT_TRUE(same_bits(staged.ray.time, s.ray.time));
    EXPECT_TRUE(same_bits(staged.ray.t_max, s.ray.t_max));
    EXPECT_EQ(staged.depth, s.depth);
    EXPECT_TRUE(same_bits(staged.eta, s.eta));
    EXPECT_TRUE(same_bits(staged.radiance, s.radiance));
  }
  // The next-event rays the staged lanes counted, as path_scatter counts them.
  EXPECT_EQ(delivered_rays, scatter_rays);
  return cover;
}

Coverage expect_stage_matches_material(Lights which, uint32_t seed, StageModel model,
                                       const MaterialParams& material) {
  return expect_stage_matches_scene(floor_scene(which, material), which != Lights::kNone, seed,
                                    model);
}

Coverage expect_stage_matches_material(bool lights, uint32_t seed, StageModel model,
                                       const MaterialParams& material) {
  return expect_stage_matches_material(lights ? Lights::kMixed : Lights::kNone, seed, model,
                                       material);
}

Coverage expect_stage_matches_scatter(Lights lights, uint32_t seed, StageModel model,
                                      float roughness = 0.f, float ior = 1.5f) {
  return expect_stage_matches_material(lights, seed, model,
                                       stage_material(model, roughness, ior));
}

Coverage expect_stage_matches_scatter(bool lights, uint32_t seed, StageModel model,
                                      float roughness = 0.f, float ior = 1.5f) {
  return expect_stage_matches_scatter(lights ? Lights::kMixed : Lights::kNone, seed, model,
                                      roughness, ior);
}

TEST(SurfaceStage, LambertStepIsPathScatterToTheBitWithAreaDeltaAndOwnCodeLights) {
  const Coverage c = expect_stage_matches_scatter(true, 7, StageModel::kLambert);
  // Every branch of the step was taken: lanes on both sides, paths that die (roulette, the
  // disk's edge) and go on, shadow rays, lanes lit by delta lights and by the sphere and mesh
  // lights (sampled by their own code), none left to path_scatter.
  EXPECT_GT(c.staged, 1000);
  EXPECT_EQ(c.fallback, 0);
  EXPECT_GT(c.own_code_lights, 100);
  EXPECT_GT(c.delta_lights, 200);
  EXPECT_GT(c.alive, 500);
  EXPECT_GT(c.dead, 50);
  EXPECT_GT(c.shadows, 500);
  EXPECT_GT(c.back, 200);
  EXPECT_GT(c.ball, 500);
}

// An environment map and a moving quad light: every lane's light sampled by its own code.
TEST(SurfaceStage, LambertStepIsPathScatterToTheBitUnderAnEnvironmentMap) {
  const Coverage c = expect_stage_matches_scatter(Lights::kMapAndMovingQuad, 9, StageModel::kLambert);
  EXPECT_GT(c.staged, 1000);
  EXPECT_EQ(c.fallback, 0);
  EXPECT_EQ(c.own_code_lights, c.staged);
  EXPECT_GT(c.shadows, 500);
  EXPECT_GT(c.alive, 500);
  EXPECT_GT(c.back, 200);
}

// Quad lights with image textures (bilinear and nearest, negative and zero texels among random
// ones; RGB and grey) beside the mixed lights: their radiance is looked up in lanes
// (look_up_emission), and must be AreaLight::sample's to the bit.
TEST(SurfaceStage, LambertStepIsPathScatterToTheBitWithTexturedQuadLights) {
  TempFolder dir("surface_stage_emission");
  std::mt19937 rng(53);
  std::uniform_real_distribution<float> u(-0.3f, 2.f);
  std::vector<float> rgb(8 * 8 * 3), grey(4 * 4);
  for (float& c : rgb) c = u(rng);
  for (float& c : grey) c = u(rng);
  rgb[0] = rgb[1] = rgb[2] = 0.f;
  write_test_image(dir.file("rgb.exr"), 8, 8, 3, rgb);
  write_test_image(dir.file("grey.exr"), 4, 4, 1, grey);
  SceneInput in = floor_scene(true, DiffuseParams{Spectrum(0.7f, 0.5f, 0.3f)});
  auto textured = [&](ObjectDesc o, const std::string& name, TextureFilter filter) {
    ImageTextureDesc d;
    d.path = dir.file(name);
    d.colorspace = TextureColorspace::kLinear;
    d.filter = filter;
    o.emission_texture = d;
    return o;
  };
  in.objects.push_back(textured(quad_object({-1.5f, 2.2f, -0.5f}, {1.2f, 0, 0}, {0, 0.2f, 1.f}, 1,
                                            Spectrum(3.f, 2.f, 1.f)),
                                "rgb.exr", TextureFilter::kBilinear));
  in.objects.push_back(textured(quad_object({0.5f, 1.8f, 1.5f}, {0, 0, -1.f}, {1.f, 0.3f, 0}, 1,
                                            Spectrum(2.f)),
                                "grey.exr", TextureFilter::kNearest));
  const Coverage c = expect_stage_matches_scene(in, true, 57, StageModel::kLambert);
  EXPECT_GT(c.staged, 1000);
  EXPECT_EQ(c.fallback, 0);
  EXPECT_GT(c.textured_lights, 200);
  EXPECT_GT(c.shadows, 500);
  EXPECT_GT(c.alive, 500);
}

TEST(SurfaceStage, LambertStepIsPathScatterToTheBitWithManyLights) {
  // Many quad, sphere and point lights, chosen by the light tree at each lane's point: each
  // kind's kernel runs once over the lanes, every lane reading its own light's constants.
  SceneInput in = floor_scene(true, DiffuseParams{Spectrum(0.7f, 0.5f, 0.3f)});
  for (int i = 0; i < 12; ++i) {
    const float x = -3.f + 0.5f * float(i);
    in.objects.push_back(quad_object({x, 1.5f + 0.1f * float(i % 3), -1.f + 0.2f * float(i % 4)}, {0.3f, 0, 0},
                                     {0, 0, 0.3f}, 1, Spectrum(1.f + 0.5f * float(i % 5))));
    in.objects.push_back(sphere_object({x, 0.6f + 0.1f * float(i % 4), -1.8f}, 0.05f + 0.02f * float(i % 3), 1,
                                       Spectrum(4.f + float(i % 3), 3.f, 2.f + float(i % 2))));
    in.lights.push_back(PointLightDesc{{x, 0.8f, 1.5f}, Spectrum(0.2f + 0.1f * float(i % 3))});
  }
  const auto scene = Scene::build(in);
  ASSERT_TRUE(scene->mis_light_sampler().spatial());
  const StagedLights staged(*scene);
  EXPECT_EQ(staged.quads.size(), 12u + 2u);  // (and the scene's own lights)
  EXPECT_EQ(staged.spheres.size(), 12u + 1u);
  EXPECT_EQ(staged.points.size(), 12u + 1u);
  const Coverage c = expect_stage_matches_scene(in, true, 61, StageModel::kLambert);
  EXPECT_GT(c.staged, 1000);
  EXPECT_EQ(c.fallback, 0);
  EXPECT_GT(c.kernel_lights[StagedLights::kQuad], 200);
  EXPECT_GT(c.kernel_lights[StagedLights::kSphere], 100);
  EXPECT_GT(c.kernel_lights[StagedLights::kPoint], 100);
  EXPECT_GT(c.shadows, 500);
}

TEST(SurfaceStage, LambertStepIsPathScatterToTheBitWithoutLights) {
  const Coverage c = expect_stage_matches_scatter(false, 11, StageModel::kLambert);
  EXPECT_EQ(c.fallback, 0);
  EXPECT_EQ(c.shadows, 0);
  EXPECT_GT(c.alive, 500);
  EXPECT_GT(c.dead, 50);
}

// A model with a lobe of its own towards lights, over roughnesses x iors with lights, then once
// without: every lane bitwise as path_scatter's (expect_stage_matches_scatter), and every
// branch of the step taken.
void expect_model_cases(StageModel model, std::initializer_list<float> roughnesses,
                        std::initializer_list<float> iors, uint32_t seed) {
  for (const float roughness : roughnesses) {
    for (const float ior : iors) {
      SCOPED_TRACE("roughness " + std::to_string(roughness) + " ior " + std::to_string(ior));
      const Coverage c = expect_stage_matches_scatter(true, seed, model, roughness, ior);
      EXPECT_GT(c.staged, 1000);
      EXPECT_EQ(c.fallback, 0);
      EXPECT_GT(c.own_code_lights, 100);  // the mesh light
      EXPECT_GT(c.kernel_lights[StagedLights::kSphere], 100);
      EXPECT_GT(c.delta_lights, 200);
      EXPECT_GT(c.alive, 300);
      EXPECT_GT(c.dead, 50);
      EXPECT_GT(c.back, 200);
      EXPECT_GT(c.ball, 500);
      // (Nearly a mirror, alpha 1.2e-4, where the NDF's values overflow: few light samples
      // count.)
      if (roughness > 0.05f) {
        EXPECT_GT(c.shadows, 100);
      }
      EXPECT_EQ(c.delta, 0);
    }
  }
  const Coverage c = expect_stage_matches_scatter(false, seed + 1, model, 0.4f, 1.5f);
  EXPECT_EQ(c.fallback, 0);
  EXPECT_EQ(c.shadows, 0);
  EXPECT_GT(c.alive, 300);
  EXPECT_GT(c.dead, 50);
  const Coverage m = expect_stage_matches_scatter(Lights::kMapAndMovingQuad, seed + 2, model, 0.4f, 1.5f);
  EXPECT_EQ(m.fallback, 0);
  EXPECT_EQ(m.own_code_lights, m.staged);
  EXPECT_GT(m.shadows, 100);
  EXPECT_GT(m.alive, 300);
}

TEST(SurfaceStage, RoughConductorStepIsPathScatterToTheBit) {
  expect_model_cases(StageModel::kRoughConductor, {0.011f, 0.1f, 0.35f, 0.8f, 1.f}, {1.5f}, 13);
}

TEST(SurfaceStage, RoughPlasticStepIsPathScatterToTheBit) {
  expect_model_cases(StageModel::kRoughPlastic, {0.011f, 0.15f, 0.5f, 1.f},
                     {1.f, 1.33f, 1.6f, 3.f}, 19);
}

// glTF's metallic-roughness model over metallic factors (the dielectric alone, a mix, the metal
// alone) and roughnesses (near the smooth limit to 1), under every kind of light, then without
// lights and under an environment map.
TEST(SurfaceStage, MetallicRoughnessStepIsPathScatterToTheBit) {
  uint32_t seed = 61;
  for (const float metallic : {0.f, 0.35f, 1.f}) {
    for (const float roughness : {0.12f, 0.4f, 1.f}) {
      SCOPED_TRACE("metallic " + std::to_string(metallic) + " roughness " +
                   std::to_string(roughness));
      const MetallicRoughnessParams mr{Spectrum(0.9f, 0.6f, 0.2f), metallic, roughness};
      const Coverage c =
          expect_stage_matches_material(Lights::kMixed, ++seed, StageModel::kMetallicRoughness, mr);
      EXPECT_GT(c.staged, 1000);
      EXPECT_EQ(c.fallback, 0);
      EXPECT_GT(c.own_code_lights, 100);
      EXPECT_GT(c.delta_lights, 200);
      EXPECT_GT(c.alive, 300);
      EXPECT_GT(c.dead, 50);
      EXPECT_GT(c.shadows, 300);
      EXPECT_GT(c.back, 200);
      EXPECT_GT(c.ball, 500);
      EXPECT_EQ(c.delta, 0);
      const Coverage none =
          expect_stage_matches_material(Lights::kNone, ++seed, StageModel::kMetallicRoughness, mr);
      EXPECT_EQ(none.shadows, 0);
      EXPECT_GT(none.alive, 300);
      const Coverage map = expect_stage_matches_material(Lights::kMapAndMovingQuad, ++seed,
                                                         StageModel::kMetallicRoughness, mr);
      EXPECT_EQ(map.own_code_lights, map.staged);
      EXPECT_GT(map.shadows, 300);
    }
  }
}

TEST(SurfaceStage, SmoothPlasticStepIsPathScatterToTheBit) {
  for (const float ior : {1.f, 1.33f, 1.5f, 3.f}) {
    SCOPED_TRACE("ior " + std::to_string(ior));
    const Coverage c = expect_stage_matches_scatter(true, 29, StageModel::kSmoothPlastic, 0.f,
                                                    ior);
    EXPECT_GT(c.staged, 1000);
    EXPECT_GT(c.alive, 300);
    EXPECT_GT(c.dead, 50);
    EXPECT_GT(c.shadows, 300);
    // Both lobes chosen: the coating's mirror (a Dirac sample) and the base.
    if (ior > 1.f) {
      EXPECT_GT(c.delta, 10);
      EXPECT_LT(c.delta, c.alive - 100);
    }
  }
  const Coverage c = expect_stage_matches_scatter(false, 31, StageModel::kSmoothPlastic, 0.f);
  EXPECT_EQ(c.fallback, 0);
  EXPECT_GT(c.alive, 300);
}

// The rough coating's table lookup on lanes: the guess from sqrt(mu) and one correction each
// way give CoatingTables::interval's answer for every cosine (the nodes themselves and their
// neighbouring floats, where rounding decides, and cosines out of [0, 1]), so no lane of the
// tables in use falls back to the scalar step; and the interpolated value is the scalar's.
TEST(SurfaceStage, RoughCoatingTableLookupIsExactEverywhere) {
  for (const float ior : {1.f, 1.33f, 1.5f, 2.4f}) {
    for (const float roughness : {0.05f, 0.3f, 0.9f}) {
      CoatingTableCache cache;
      const PlasticParams params{Spectrum(0.5f), ior, roughness};
      const PlasticBsdf plastic(params, PlasticBsdf::tables_for(params, cache));
      const CoatingTables& tables = plastic.tables();
      ASSERT_TRUE(tables.square_nodes);
      lane::Params q{};
      q.c[0] = q.c[1] = q.c[2] = 0.5f;
      q.alpha = plastic.alpha();
      q.eta = ior;
      q.nodes = tables.nodes;
      q.tables = lane::Tables{tables.cosines.data(), tables.transmittance.data(), nullptr};
      std::vector<float> cosines = {-0.5f, -0.f, 0.f, 1.f, 1.5f, 1e-30f};
      for (int i = 0; i < tables.nodes; ++i) {
        const float c = tables.cosines[size_t(i)];
        cosines.insert(cosines.end(), {c, std::nextafter(c, -1.f), std::nextafter(c, 2.f),
                                       std::nextafter(std::nextafter(c, -1.f), -1.f)});
      }
      std::mt19937 rng(5);
      std::uniform_real_distribution<float> u(0.f, 1.f);
      for (int i = 0; i < 20000; ++i) cosines.push_back(u(rng) * u(rng));
      for (const float c : cosines) {
        Mask exact = -1;
        const float t = lane::RoughCoating::transmittance(q, c, &exact);
        ASSERT_EQ(exact, -1) << "cosine " << c;
        const float expected = plastic.external_transmittance(c);
        ASSERT_TRUE(same_bits(t, expected)) << "cosine " << c << ": " << t << " vs " << expected;
      }
    }
  }
}

TEST(SurfaceStage, RoughDielectricStepIsPathScatterToTheBit) {
  expect_model_cases(StageModel::kRoughDielectric, {0.011f, 0.2f, 0.6f, 1.f},
                     {0.7f, 1.33f, 1.5f, 2.4f}, 37);
}

TEST(SurfaceStage, MirrorAndSmoothDielectricStepsArePathScatterToTheBit) {
  // Dirac lobes only: no direct light is estimated there even with lights in the scene, and
  // the step takes the sampler's values from the first.
  for (const bool lights : {true, false}) {
    const Coverage c = expect_stage_matches_scatter(lights, 43, StageModel::kSmoothConductor);
    EXPECT_GT(c.staged, 1000);
    EXPECT_EQ(c.fallback, 0);
    EXPECT_EQ(c.shadows, 0);
    EXPECT_GT(c.alive, 300);
    EXPECT_GT(c.dead, 50);
    EXPECT_EQ(c.delta, c.alive);
    EXPECT_GT(c.back, 200);
    for (const float ior : {0.7f, 1.33f, 1.5f, 2.4f}) {
      SCOPED_TRACE("ior " + std::to_string(ior) + (lights ? " with lights" : ""));
      const Coverage d =
          expect_stage_matches_scatter(lights, 47, StageModel::kSmoothDielectric, 0.f, ior);
      EXPECT_GT(d.staged, 1000);
      EXPECT_EQ(d.fallback, 0);
      EXPECT_EQ(d.shadows, 0);
      EXPECT_GT(d.alive, 300);
      EXPECT_EQ(d.delta, d.alive);
      EXPECT_GT(d.back, 200);
    }
  }
}

// Textured parameters, looked up per hit by the stage (add) as path_scatter looks them up: a
// colour texture and a roughness texture whose texels reach 0 (where a conductor's or a
// dielectric's lobe turns into the smooth model's Dirac delta, which the rough stage leaves to
// path_scatter: the only fallback lanes).
TEST(SurfaceStage, TexturedSurfacesArePathScatterToTheBit) {
  TempFolder dir("surface_stage_textures");
  std::mt19937 rng(41);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<float> colour(8 * 8 * 3), rough(8 * 8);
  for (float& c : colour) c = u(rng);
  for (size_t k = 0; k < rough.size(); ++k) rough[k] = k % 8 < 3 ? 0.f : u(rng);
  write_test_image(dir.file("colour.exr"), 8, 8, 3, colour);
  write_test_image(dir.file("rough.exr"), 8, 8, 1, rough);
  auto texture = [&](const std::string& name, TextureFilter filter) {
    ImageTextureDesc d;
    d.path = dir.file(name);
    d.colorspace = TextureColorspace::kLinear;
    d.filter = filter;
    return d;
  };
  const ImageTextureDesc c = texture("colour.exr", TextureFilter::kBilinear);
  const ImageTextureDesc r = texture("rough.exr", TextureFilter::kNearest);
  struct Case {
    const char* name;
    StageModel model;
    MaterialParams material;
    bool smooth_texels;  // whether some hits leave the stage's model
  };
  const Case cases[] = {
      {"diffuse", StageModel::kLambert, DiffuseParams{Spectrum(0.9f), c}, false},
      {"conductor", StageModel::kRoughConductor,
       ConductorParams{Spectrum(0.9f, 0.8f, 0.7f), 0.7f, c, r}, true},
      {"smooth plastic", StageModel::kSmoothPlastic, PlasticParams{Spectrum(1.f), 1.5f, 0.f, c},
       false},
      {"rough plastic", StageModel::kRoughPlastic, PlasticParams{Spectrum(0.8f), 1.5f, 0.3f, c},
       false},
      {"dielectric", StageModel::kRoughDielectric, DielectricParams{1.5f, 0.6f, Spectrum(0.f), r},
       true},
      {"metallic-roughness", StageModel::kMetallicRoughness,
       MetallicRoughnessParams{Spectrum(0.9f, 0.7f, 0.5f), 0.6f, 0.8f, c, r, r}, true},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    const Coverage cv = expect_stage_matches_material(true, 43, k.model, k.material);
    // (Three columns of eight texels are smooth: about two fifths of the hits fall back.)
    EXPECT_GT(cv.staged, k.smooth_texels ? 700 : 1000);
    EXPECT_GT(cv.shadows, 100);
    EXPECT_GT(cv.alive, 300);
    EXPECT_GT(cv.ball, k.smooth_texels ? 250 : 500);
    if (k.smooth_texels) {
      EXPECT_GT(cv.fallback, 400);
    } else {
      EXPECT_EQ(cv.fallback, 0);
    }
  }
}

// Normal-mapped surfaces (SurfaceBsdf's normal map: the model in the perturbed frame of the
// mapped normal for wi, the side conditions, the shadow terminator), every model with a stage,
// against path_scatter bit for bit. The map's texels are random, one of them (0.5, 0.5, 0.5)
// (no direction: the unperturbed normal), others steep (mirrored where they face away from wi).
TEST(SurfaceStage, NormalMappedSurfacesArePathScatterToTheBit) {
  TempFolder dir("surface_stage_normal_map");
  std::mt19937 rng(47);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<float> texels(8 * 8 * 3);
  for (float& t : texels) t = u(rng);
  for (int c = 0; c < 3; ++c) texels[size_t(3 * 9 + c)] = 0.5f;  // texel (1, 1)
  texels[3 * 20 + 2] = 0.5f;  // texel (4, 2): a normal in the tangent plane
  write_test_image(dir.file("normal.exr"), 8, 8, 3, texels);
  ImageTextureDesc map;
  map.path = dir.file("normal.exr");
  map.colorspace = TextureColorspace::kLinear;
  map.filter = TextureFilter::kNearest;
  struct Case {
    const char* name;
    StageModel model;
    MaterialParams material;
  };
  DiffuseParams diffuse{Spectrum(0.8f, 0.6f, 0.4f)};
  diffuse.normal_map = map;
  ConductorParams rough{Spectrum(0.9f, 0.8f, 0.7f), 0.5f};
  rough.normal_map = map;
  ConductorParams mirror{Spectrum(0.9f), 0.f};
  mirror.normal_map = map;
  PlasticParams coat{Spectrum(0.5f, 0.3f, 0.2f), 1.5f, 0.3f};
  coat.normal_map = map;
  PlasticParams glaze{Spectrum(0.2f, 0.4f, 0.6f), 1.5f, 0.f};
  glaze.normal_map = map;
  DielectricParams frosted{1.5f, 0.4f};
  frosted.normal_map = map;
  DielectricParams glass{1.5f, 0.f};
  glass.normal_map = map;
  MetallicRoughnessParams gltf{Spectrum(0.7f, 0.6f, 0.3f), 0.4f, 0.5f};
  gltf.normal_map = map;
  // A textured colour or roughness besides the map: the stages look those up in lanes
  // (look_up_textures) and the normal per hit.
  DiffuseParams wood = diffuse;
  wood.color_texture = map;
  PlasticParams tiles = coat;
  tiles.color_texture = map;
  DielectricParams etched = frosted;
  etched.roughness_texture = map;
  const Case cases[] = {
      {"diffuse, textured colour", StageModel::kLambert, wood},
      {"rough plastic, textured colour", StageModel::kRoughPlastic, tiles},
      {"rough dielectric, textured roughness", StageModel::kRoughDielectric, etched},
      {"diffuse", StageModel::kLambert, diffuse},
      {"rough conductor", StageModel::kRoughConductor, rough},
      {"mirror", StageModel::kSmoothConductor, mirror},
      {"rough plastic", StageModel::kRoughPlastic, coat},
      {"smooth plastic", StageModel::kSmoothPlastic, glaze},
      {"rough dielectric", StageModel::kRoughDielectric, frosted},
      {"smooth dielectric", StageModel::kSmoothDielectric, glass},
      {"metallic-roughness", StageModel::kMetallicRoughness, gltf},
  };
  for (const Case& k : cases) {
    SCOPED_TRACE(k.name);
    const Coverage cv = expect_stage_matches_material(true, 53, k.model, k.material);
    EXPECT_GT(cv.staged, 1000);
    EXPECT_GT(cv.alive, 200);  // (metals lose paths to the side conditions: 250-280)
    EXPECT_GT(cv.dead, 50);
    EXPECT_GT(cv.back, 200);
    EXPECT_GT(cv.ball, 500);
    const bool delta =
        k.model == StageModel::kSmoothConductor || k.model == StageModel::kSmoothDielectric;
    if (!delta) {
      EXPECT_GT(cv.shadows, 100);
    }
  }
}

// Which of the scene's objects a stage of `model` takes, one digit per object.
std::string taken(const Scene& scene, StageModel model) {
  const SurfaceStage stage(scene, model);
  std::string digits;
  for (uint32_t o = 0; o < scene.object_count(); ++o) digits += stage.takes(o) ? '1' : '0';
  return digits;
}

TEST(SurfaceStage, TakesOnlyPlainSurfacesOfItsModel) {
  SceneInput in = floor_scene(false, DiffuseParams{Spectrum(0.5f)});
  in.materials.push_back(ConductorParams{Spectrum(0.9f), 0.3f});
  in.materials.push_back(ConductorParams{Spectrum(0.9f), 0.f});  // a mirror: a delta lobe
  in.objects.push_back(quad_object({-2, 1, 2}, {4, 0, 0}, {0, 0, -4}, 2));
  in.objects.push_back(quad_object({-2, 1.5f, 2}, {4, 0, 0}, {0, 0, -4}, 3));
  in.materials.push_back(PlasticParams{Spectrum(0.5f), 1.5f, 0.f});
  in.materials.push_back(PlasticParams{Spectrum(0.5f), 1.5f, 0.4f});
  in.materials.push_back(PlasticParams{Spectrum(0.5f), 0.8f, 0.4f});  // ior < 1: adaptive nodes
  for (uint32_t m = 4; m < 7; ++m)
    in.objects.push_back(quad_object({-2, 1.5f + 0.1f * float(m), 2}, {4, 0, 0}, {0, 0, -4}, m));
  const auto scene = Scene::build(in);
  // Objects: two Lambertian, a rough conductor, a mirror, a smooth and a rough plastic, a
  // plastic of ior < 1.
  EXPECT_EQ(taken(*scene, StageModel::kLambert), "1100000");
  EXPECT_EQ(taken(*scene, StageModel::kRoughConductor), "0010000");
  EXPECT_EQ(taken(*scene, StageModel::kSmoothConductor), "0001000");
  EXPECT_EQ(taken(*scene, StageModel::kSmoothPlastic), "0000100");
  EXPECT_EQ(taken(*scene, StageModel::kRoughPlastic), "0000010");
  EXPECT_EQ(taken(*scene, StageModel::kRoughDielectric), "0000000");
}

// Lights without a kernel (here an emitting sphere) are sampled by their own code in the lanes:
// the stages take their surfaces as under any other light.
TEST(SurfaceStage, TakesSurfacesLitOnlyByLightsWithoutAKernel) {
  SceneInput in = floor_scene(false, DiffuseParams{Spectrum(0.5f)});
  in.materials.push_back(ConductorParams{Spectrum(0.9f), 0.f});
  in.objects.push_back(quad_object({-2, 1, 2}, {4, 0, 0}, {0, 0, -4}, 2));
  in.objects.push_back(sphere_object({2.f, 2.5f, -1.5f}, 0.3f, 1, Spectrum(3.f)));
  const auto scene = Scene::build(in);
  ASSERT_FALSE(scene->mis_light_sampler().empty());
  // Objects: floor and ball (Lambertian), a mirror, the sphere light (black Lambertian).
  EXPECT_EQ(taken(*scene, StageModel::kLambert), "1101");
  EXPECT_EQ(taken(*scene, StageModel::kSmoothConductor), "0010");
}

TEST(SurfaceStage, TakesDielectricsThatRefractByTheirRoughness) {
  SceneInput in = floor_scene(false, DielectricParams{1.5f, 0.3f});
  in.materials.push_back(DielectricParams{1.5f, 0.f});     // smooth: Dirac lobes
  in.materials.push_back(DielectricParams{1.00001f, 0.3f});  // index-matched: invisible
  in.objects.push_back(quad_object({-2, 1, 2}, {4, 0, 0}, {0, 0, -4}, 2));
  in.objects.push_back(quad_object({-2, 1.5f, 2}, {4, 0, 0}, {0, 0, -4}, 3));
  const auto scene = Scene::build(in);
  // Objects: two rough dielectrics, a smooth one, an index-matched one.
  EXPECT_EQ(taken(*scene, StageModel::kRoughDielectric), "1100");
  EXPECT_EQ(taken(*scene, StageModel::kSmoothDielectric), "0010");
  EXPECT_EQ(taken(*scene, StageModel::kLambert), "0000");
}

}  // namespace
}  // namespace penumbra::test
