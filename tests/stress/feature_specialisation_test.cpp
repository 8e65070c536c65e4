// "Skip what a scene doesn't need": the integrator instantiation chosen from the scene's feature
// mask gives bit-identical images to the generic (all features compiled in) integrator, on
// scenes covering the feature combinations; zero velocities and a zero aperture count as absent.
#include <gtest/gtest.h>

#include <cstring>

#include "renderer/render/camera_sample.h"
#include "renderer/render/integrator.h"
#include "renderer/render/render.h"
#include "renderer/sampling/sampler.h"
#include "renderer/scene/scene.h"
#include "renderer/render/thin_lens_camera.h"
#include "tests/stress/stress_util.h"

namespace penumbra::test {
namespace {

// The render loop of renderer/render.cpp (same sampler dimensions, same accumulation order and
// precision), with the generic integrator.
Image render_generic(const Scene& scene, const RenderSettings& s) {
  const ThinLensCamera camera(scene.camera(), s.width, s.height);
  const IntegrateFn integrate = select_generic_integrator(s.integrator);
  const IntegratorSettings is{s.max_depth, s.rr_depth};
  Image img(s.width, s.height);
  PathCounters counters;
  Sampler sampler(s.seed, sampler_cmj_bits(s));
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      double sum[3] = {0, 0, 0};
      int n = 0;
      for (int i = 0; i < s.spp; ++i) {
        sampler.start_pixel_sample(x, y, uint32_t(i));
        const CameraSample cs = take_camera_sample(sampler, scene.features().lens, scene.features().motion);
        const CameraRay cr = camera.generate_ray(vec2(float(x), float(y)) + cs.film, cs.lens, cs.time);
        const Spectrum L = integrate(scene, is, Ray{cr.origin, cr.direction, cr.time}, sampler, counters, nullptr);
        if (!is_finite(L)) continue;
        for (int c = 0; c < 3; ++c) sum[c] += double(L[c]);
        ++n;
      }
      for (int c = 0; c < 3; ++c) img.pixel(x, y)[c] = n ? float(sum[c] / n) : 0.f;
    }
  return img;
}

struct FeatureScene {
  const char* name;
  SceneInput input;
};

std::vector<FeatureScene> feature_scenes() {
  std::vector<FeatureScene> scenes;
  SceneInput base;
  base.camera = CameraDesc{{0, 1, 3}, {0, 0.4f, 0}, {0, 1, 0}, 40.f, 0.f, 3.f, 0.f, 0.f};
  base.materials = {DiffuseParams{Spectrum(0.7f)}, ConductorParams{Spectrum(0.9f), 0.2f},
                    PlasticParams{Spectrum(0.2f, 0.4f, 0.8f), 1.5f, 0.1f}};
  base.objects = {quad({-2, 0, 2}, {4, 0, 0}, {0, 0, -4}, 0), sphere({-0.5f, 0.4f, 0}, 0.4f, 1),
                  box({0.2f, 0, -0.3f}, {0.8f, 0.6f, 0.3f}, 2)};

  SceneInput area = base;
  area.objects.push_back(quad({-0.3f, 2, 0.3f}, {0, 0, -0.6f}, {0.6f, 0, 0}, 0, Spectrum(8.f)));
  scenes.push_back({"opaque, area light", area});

  SceneInput point = base;
  point.lights = {PointLightDesc{{1, 2, 1}, Spectrum(5.f)}, DirectionalLightDesc{{0.2f, -1, 0.1f}, Spectrum(1.f)}};
  scenes.push_back({"opaque, point and directional", point});

  SceneInput env = base;
  env.environment = Spectrum(0.5f, 0.6f, 0.8f);
  scenes.push_back({"opaque, environment", env});

  SceneInput glass = area;
  glass.materials.push_back(DielectricParams{1.5f, 0.f, Spectrum(0.f)});
  glass.materials.push_back(DielectricParams{1.5f, 0.3f, Spectrum(0.f)});
  glass.objects.push_back(sphere({0, 0.3f, 0.8f}, 0.3f, 3));
  glass.objects.push_back(sphere({0.7f, 0.9f, 0.2f}, 0.2f, 4));
  scenes.push_back({"glass", glass});

  SceneInput absorbing = glass;
  absorbing.materials[3] = DielectricParams{1.5f, 0.f, Spectrum(2.f, 0.5f, 0.1f)};
  absorbing.environment = Spectrum(0.2f);
  scenes.push_back({"absorbing glass, environment", absorbing});

  SceneInput motion_lens = absorbing;
  motion_lens.camera.aperture_radius = 0.05f;
  motion_lens.camera.shutter_close = 1.f;
  motion_lens.objects[1].velocity = vec3(0.3f, 0, 0);
  motion_lens.objects[2].acceleration = vec3(0, 0.5f, 0);
  scenes.push_back({"everything, motion and lens", motion_lens});

  SceneInput dark = base;  // no light at all
  scenes.push_back({"no lights", dark});
  return scenes;
}

TEST(FeatureSpecialisation, BitIdenticalToGenericIntegrator) {
  std::vector<uint32_t> masks;
  for (const FeatureScene& fs : feature_scenes())
    for (IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed}) {
      const auto scene = Scene::build(fs.input);
      RenderSettings s = settings(16, 12, 16, 8, 5);
      s.integrator = kind;
      const RenderResult specialised = render(*scene, s);
      const Image generic = render_generic(*scene, s);
      EXPECT_EQ(nonfinite_count(specialised), 0) << fs.name;
      ASSERT_EQ(specialised.image.rgb.size(), generic.rgb.size());
      EXPECT_EQ(std::memcmp(specialised.image.rgb.data(), generic.rgb.data(), generic.rgb.size() * sizeof(float)), 0)
          << fs.name << (kind == IntegratorKind::kPath ? " path" : " distributed");
      masks.push_back(integrator_feature_mask(scene->features(), kind));
      SceneFeatures every;
      every.motion = every.lens = every.transmission = every.absorption = every.lights =
          every.mis_lights = every.environment = every.textures = true;
      const uint32_t all = integrator_feature_mask(every, kind);
      EXPECT_EQ(select_integrator(kind, scene->features()) == select_generic_integrator(kind),
                masks.back() == all)
          << fs.name;
    }
  std::sort(masks.begin(), masks.end());
  EXPECT_GE(std::unique(masks.begin(), masks.end()) - masks.begin(), 5) << "scenes must cover several instantiations";
}

// Zero velocities, zero acceleration and a zero aperture (given explicitly, through the loader)
// are the same scene as without those fields: same features, same image, bit for bit.
TEST(FeatureSpecialisation, ZeroVelocityAndApertureCountAsAbsent) {
  const std::string head = R"({"version": 1, "render": {"width": 16, "height": 16, "spp": 8},
    "materials": {"m": {"type": "diffuse", "color": [0.6, 0.6, 0.6]}},
    "lights": [{"type": "point", "position": [1, 2, 1], "intensity": [5, 5, 5]}],)";
  const std::string plain = head + R"(
    "camera": {"position": [0, 1, 3], "look_at": [0, 0.4, 0], "fov": 40},
    "objects": [{"type": "sphere", "center": [0, 0.4, 0], "radius": 0.4, "material": "m"},
                {"type": "quad", "origin": [-2, 0, 2], "u": [4, 0, 0], "v": [0, 0, -4], "material": "m"}]})";
  const std::string zeros = head + R"(
    "camera": {"position": [0, 1, 3], "look_at": [0, 0.4, 0], "fov": 40, "aperture_radius": 0,
               "focus_distance": 2, "shutter": [0, 1]},
    "objects": [{"type": "sphere", "center": [0, 0.4, 0], "radius": 0.4, "material": "m",
                 "velocity": [0, 0, 0], "acceleration": [0, 0, 0]},
                {"type": "quad", "origin": [-2, 0, 2], "u": [4, 0, 0], "v": [0, 0, -4], "material": "m",
                 "velocity": [0, 0, 0]}]})";
  const api::LoadResult a = api::load_scene(plain), b = api::load_scene(zeros);
  ASSERT_TRUE(a.ok() && b.ok()) << (b.errors.empty() ? "" : b.errors[0].to_string());
  const auto sa = Scene::build(a.request->scene), sb = Scene::build(b.request->scene);
  EXPECT_FALSE(sb->features().motion);
  EXPECT_FALSE(sb->features().lens);
  for (IntegratorKind kind : {IntegratorKind::kPath, IntegratorKind::kDistributed})
    EXPECT_EQ(integrator_feature_mask(sa->features(), kind), integrator_feature_mask(sb->features(), kind));
  EXPECT_EQ(render(*sa, a.request->settings).image.rgb, render(*sb, b.request->settings).image.rgb);
}

}  // namespace
}  // namespace penumbra::test
