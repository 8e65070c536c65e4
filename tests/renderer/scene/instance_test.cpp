// Instancing (shapes/instance.h): copies of a mesh placed by Embree instances must be what the
// same mesh transformed by hand is: the same hits (point, distance, normals, uv, material), hit
// points within their error bounds, no self-intersection of rays spawned from a copy, and the
// same rendered image.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "renderer/core/frame.h"
#include "renderer/embree/device.h"
#include "renderer/embree/ray_access.h"
#include "renderer/sampling/sampling.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/make_shape.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

// A convex faceted sphere (latitude-longitude grid) of radius r around c, counter-clockwise seen
// from outside, with smooth normals and optional uvs.
MeshDesc faceted_sphere(const vec3& c, float r, bool uvs, int rings = 10, int segments = 20) {
  MeshDesc m;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segments; ++j) {
      const double theta = M_PI * i / rings, phi = 2 * M_PI * j / segments;
      const dvec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      m.positions.push_back(vec3(dvec3(c) + double(r) * n));
      m.normals.push_back(vec3(n));
      if (uvs) m.uvs.push_back(vec2(float(j) / segments, float(i) / rings));
    }
  auto at = [&](int i, int j) { return uint32_t(i * (segments + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      if (i > 0) m.indices.insert(m.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j)});
      if (i < rings - 1) m.indices.insert(m.indices.end(), {at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
    }
  return m;
}

glm::dmat3 rotation(dvec3 axis, double degrees) {
  axis = glm::normalize(axis);
  const double a = degrees * M_PI / 180, c = std::cos(a), s = std::sin(a), t = 1 - c;
  const double x = axis.x, y = axis.y, z = axis.z;
  glm::dmat3 m;
  m[0] = {t * x * x + c, t * x * y + s * z, t * x * z - s * y};
  m[1] = {t * x * y - s * z, t * y * y + c, t * y * z + s * x};
  m[2] = {t * x * z + s * y, t * y * z - s * x, t * z * z + c};
  return m;
}

InstanceTransform make(const glm::dmat3& linear, const dvec3& translation) {
  return InstanceTransform{glm::mat3(linear), vec3(translation)};
}

// Translation, rotation with uniform scale, non-uniform scale with shear, and a mirror.
std::vector<InstanceTransform> varied_transforms() {
  glm::dmat3 shear(1.0);
  shear[1][0] = 0.6;  // x += 0.6 y
  const glm::dmat3 mirror = glm::dmat3(glm::dvec3(-1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1));
  return {make(glm::dmat3(1.0), {2.6, 0, 0}),
          make(0.7 * rotation({1, 2, 3}, 70), {-2.4, 0.9, 0.4}),
          make(shear * glm::dmat3(glm::dvec3(1.5, 0, 0), glm::dvec3(0, 0.5, 0), glm::dvec3(0, 0, 1.1)),
               {0.2, -2.3, 0.1}),
          make(rotation({0, 1, 0}, 35) * mirror, {0.1, 2.4, -0.3})};
}

// The mesh transformed by hand in double precision: positions as points, normals by the
// inverse transpose (as api/ applies a mesh's own transform).
MeshDesc transformed(const MeshDesc& mesh, const InstanceTransform& t) {
  const glm::dmat3 a(t.linear);
  const glm::dmat3 normal = glm::transpose(glm::inverse(a));
  MeshDesc out = mesh;
  for (vec3& p : out.positions) p = vec3(a * dvec3(p) + dvec3(t.translation));
  for (vec3& n : out.normals) n = vec3(glm::normalize(normal * dvec3(n)));
  return out;
}

struct Pair {
  SceneInput instanced, by_hand;
};

// Material 0: the mesh and its copies; the hand-made copies get material k + 1 (the same
// parameters), so a test can tell which copy a hit is on.
Pair scene_pair(const MeshDesc& mesh, const std::vector<InstanceTransform>& transforms,
               const vec3& velocity = vec3(0.f)) {
  Pair p;
  SceneInput base;
  base.camera = camera_looking({0, 0, 9}, {0, 0, 0}, 40.f);
  if (velocity != vec3(0.f)) {
    base.camera.shutter_open = 0.f;
    base.camera.shutter_close = 1.f;
  }
  base.materials = {DiffuseParams{}};
  ObjectDesc o;
  o.shape = mesh;
  o.velocity = velocity;
  base.objects = {o};
  p.instanced = base;
  p.instanced.instances = {InstancesDesc{0, transforms}};
  p.by_hand = base;
  for (size_t k = 0; k < transforms.size(); ++k) {
    ObjectDesc copy;
    copy.shape = transformed(mesh, transforms[k]);
    // Rigid motion carried through the linear part: A (p + v t) + b = (A p + b) + (A v) t.
    copy.velocity = transforms[k].linear * velocity;
    copy.material = uint32_t(k + 1);
    p.by_hand.materials.push_back(DiffuseParams{});
    p.by_hand.objects.push_back(copy);
  }
  return p;
}

vec3 random_target(std::mt19937& rng, const std::vector<InstanceTransform>& transforms) {
  std::uniform_real_distribution<float> u(-1.2f, 1.2f);
  std::uniform_int_distribution<size_t> pick(0, transforms.size());
  const size_t k = pick(rng);
  const vec3 local(u(rng), u(rng), u(rng));
  return k == transforms.size() ? local : transforms[k].linear * local + transforms[k].translation;
}

TEST(InstanceBuild, CountsCopiesAndBoundsCoverThem) {
  const auto transforms = varied_transforms();
  const Pair p = scene_pair(faceted_sphere(vec3(0.f), 1.f, true), transforms);
  const auto scene = Scene::build(p.instanced);
  ASSERT_EQ(scene->object_count(), 1u);
  ASSERT_EQ(scene->instance_count(), transforms.size());
  const auto reference = Scene::build(p.by_hand);
  // The bounds cover the copies written out: a copy's are its mesh's box transformed, so a
  // rotated copy's reach a little further than its own vertices (at most a factor sqrt(3) of
  // the copies' extent here, which is below 2).
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(scene->bounds().lo[i], reference->bounds().lo[i]) << i;
    EXPECT_GE(scene->bounds().hi[i], reference->bounds().hi[i]) << i;
    EXPECT_GT(scene->bounds().lo[i], reference->bounds().lo[i] - 1.5f) << i;
    EXPECT_LT(scene->bounds().hi[i], reference->bounds().hi[i] + 1.5f) << i;
  }
}

TEST(InstanceBuild, RefusesWhatCannotBeCopied) {
  SceneInput in;
  in.camera = camera_looking({0, 0, 5}, {0, 0, 0}, 40.f);
  in.materials = {DiffuseParams{}};
  ObjectDesc sphere;
  sphere.shape = SphereDesc{vec3(0.f), 1.f};
  ObjectDesc light;
  light.shape = faceted_sphere(vec3(0.f), 1.f, false);
  light.emission = Spectrum(1.f);
  in.objects = {sphere, light};
  const std::vector<InstanceTransform> one{InstanceTransform{}};
  in.instances = {InstancesDesc{0, one}};
  EXPECT_THROW(Scene::build(in), SceneBuildError);  // not a mesh
  in.instances = {InstancesDesc{1, one}};
  EXPECT_THROW(Scene::build(in), SceneBuildError);  // emits
  in.instances = {InstancesDesc{2, one}};
  EXPECT_THROW(Scene::build(in), SceneBuildError);  // no such object
}

// Every ray sees the same surface in both scenes: same material (which copy), primitive,
// distance, point, normals and uv. Motion: copies of a moving mesh move with A v.
void check_same_hits(const Pair& p, const std::vector<InstanceTransform>& transforms, float time) {
  const auto a = Scene::build(p.instanced);
  const auto b = Scene::build(p.by_hand);
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
  int both = 0, disagree = 0;
  for (int i = 0; i < 20000; ++i) {
    const vec3 dir = square_to_uniform_sphere({u01(rng), u01(rng)});
    const vec3 target = random_target(rng, transforms);
    const Ray ray{target - 12.f * dir, dir, time};
    SurfaceHit ha, hb;
    const bool hit_a = a->intersect(ray, &ha), hit_b = b->intersect(ray, &hb);
    if (hit_a != hit_b) {
      ++disagree;  // only a ray through a shared edge or a silhouette can, by rounding
      continue;
    }
    if (!hit_a) continue;
    // The copy hit in `a`: its mesh object is 0; which copy follows from the point.
    const uint32_t copy_b = hb.object;  // 0 = the mesh where it stands, k + 1 = copy k
    if (ha.primitive != hb.primitive) {
      ++disagree;
      continue;
    }
    ++both;
    EXPECT_EQ(ha.object, 0u);
    // Embree intersects the copy in its own space, so its barycentrics round differently; the
    // difference grows as the ray grazes the triangle (1 / |cos|).
    const float grazing = 1.f / std::max(std::abs(glm::dot(dir, hb.ng)), 0.01f);
    const float scale = (1.f + glm::length(hb.p)) * grazing;
    ASSERT_NEAR(ha.t, hb.t, 2e-5f * (ha.t + 1.f) * grazing) << "copy " << copy_b;
    ASSERT_LT(glm::length(ha.p - hb.p), 2e-5f * scale) << "copy " << copy_b;
    ASSERT_GT(glm::dot(ha.ng, hb.ng), 0.99999f) << "copy " << copy_b;
    // Shading normals: the copy interpolates and then transforms (as pbrt-v4 and Mitsuba 3
    // instances do), the hand-made mesh transforms each vertex normal and then interpolates.
    // Under a rotation, uniform scale or mirror the two are the same; under the sheared,
    // non-uniform copy (object 3 here) they differ by the curvature within a triangle.
    const glm::mat3 m = copy_b == 0 ? glm::mat3(1.f) : transforms[copy_b - 1].linear;
    const glm::mat3 gram = glm::transpose(m) * m;
    const bool similarity = std::abs(gram[0][1]) + std::abs(gram[0][2]) + std::abs(gram[1][2]) < 1e-5f &&
                            std::abs(gram[0][0] - gram[1][1]) + std::abs(gram[0][0] - gram[2][2]) < 1e-5f;
    ASSERT_GT(glm::dot(ha.ns, hb.ns), similarity ? 0.99999f : 0.99f) << "copy " << copy_b;
    // uv: both 0 here (no textures, ShapeContext::need_uv); InstanceHit checks a copy's uv.
    ASSERT_NEAR(ha.uv.x, hb.uv.x, 2e-5f * grazing);
    ASSERT_NEAR(ha.uv.y, hb.uv.y, 2e-5f * grazing);
  }
  EXPECT_GT(both, 5000);
  EXPECT_LE(disagree, both / 1000) << "of " << both;
}

TEST(InstanceIntersect, MatchesTheMeshTransformedByHand) {
  const auto transforms = varied_transforms();
  check_same_hits(scene_pair(faceted_sphere(vec3(0.1f, -0.2f, 0.f), 1.f, true), transforms), transforms,
                  0.f);
}

TEST(InstanceIntersect, MatchesByHandForAMovingMesh) {
  const auto transforms = varied_transforms();
  for (float time : {0.f, 0.35f, 1.f})
    check_same_hits(scene_pair(faceted_sphere(vec3(0.f), 1.f, true), transforms, vec3(0.4f, -0.2f, 0.1f)),
                    transforms, time);
}

// The copies built at the Embree level as Scene::build builds them, but with the mesh's uv
// computation on (ShapeContext::need_uv, which a scene sets only for textured materials), so a
// test sees Embree's barycentrics and the uv a copy reports.
struct DirectCopies {
  std::unique_ptr<Shape> mesh;
  std::vector<Instance> copies;
  EmbreeScene child, top;

  DirectCopies(const MeshDesc& m, const std::vector<InstanceTransform>& transforms) {
    ShapeContext ctx;
    ctx.need_uv = true;
    mesh = make_shape(m, ctx);
    const EmbreeGeometry geom = mesh->make_geometry(embree_device());
    child = make_instanced_scene(embree_device(), geom.get());
    top = EmbreeScene(rtcNewScene(embree_device()));
    rtcSetSceneFlags(top.get(), RTC_SCENE_FLAG_ROBUST);
    for (size_t k = 0; k < transforms.size(); ++k) {
      copies.emplace_back(*mesh, 0, transforms[k]);
      const EmbreeGeometry g = copies.back().make_geometry(embree_device(), child.get());
      rtcAttachGeometryByID(top.get(), g.get(), unsigned(k));
    }
    rtcCommitScene(top.get());
  }

  // The copy hit (or -1), its primitive and barycentrics, and the copy's rebuilt hit.
  int intersect(const Ray& ray, SurfaceHit* hit, uint32_t* prim, vec2* bary) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    RTCRayHit rh = embree_ray_hit(ray);
    rtcIntersect1(top.get(), &context, &rh);
    if (rh.hit.instID[0] == RTC_INVALID_GEOMETRY_ID) return -1;
    *prim = rh.hit.primID;
    *bary = vec2(rh.hit.u, rh.hit.v);
    copies[rh.hit.instID[0]].hit_geometry(ray, rh.ray.tfar, rh.hit.primID, *bary, hit);
    return int(rh.hit.instID[0]);
  }
};

// The rebuilt world point lies within its error bound of the exact point: Embree's float
// barycentrics applied in double to the float vertices, then the float transform applied in
// double. Near the origin and far from it.
TEST(InstanceHit, PointWithinItsErrorBound) {
  for (const dvec3 far : {dvec3(0.0), dvec3(3e4, -1e4, 2e4)}) {
    std::vector<InstanceTransform> transforms = varied_transforms();
    for (auto& t : transforms) t.translation += vec3(far);
    const MeshDesc mesh = faceted_sphere(vec3(0.f), 1.f, false);
    const DirectCopies copies(mesh, transforms);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
    int checked = 0;
    for (int i = 0; i < 5000; ++i) {
      const vec3 dir = square_to_uniform_sphere({u01(rng), u01(rng)});
      const vec3 target = random_target(rng, transforms);
      SurfaceHit hit;
      uint32_t prim = 0;
      vec2 b;
      const int k = copies.intersect(Ray{target - 12.f * dir, dir, 0.f}, &hit, &prim, &b);
      if (k < 0) continue;
      const uint32_t* tri = &mesh.indices[3 * prim];
      // b0 as the mesh computes it, in float: the bound is that of the sum (pbrt-v4 6.8.4).
      const double b1 = b.x, b2 = b.y, b0 = 1.f - b.x - b.y;
      const dvec3 local = b0 * dvec3(mesh.positions[tri[0]]) + b1 * dvec3(mesh.positions[tri[1]]) +
                          b2 * dvec3(mesh.positions[tri[2]]);
      const dvec3 exact = glm::dmat3(transforms[size_t(k)].linear) * local + dvec3(transforms[size_t(k)].translation);
      for (int c = 0; c < 3; ++c)
        ASSERT_LE(std::abs(double(hit.p[c]) - exact[c]), double(hit.p_error[c]))
            << "copy " << k << " component " << c;
      // And the bound is not vacuous: within a few hundred ulps of the magnitude.
      ASSERT_LT(max_component(hit.p_error), 1e-4f * (1.f + max_component(glm::abs(hit.p))));
      ++checked;
    }
    EXPECT_GT(checked, 1000);
  }
}

// A copy reports the mesh's interpolated uv, and its geometric normal is that of the
// transformed triangle (front side turned round by the mirror).
TEST(InstanceHit, UvKeptAndNormalOfTheTransformedTriangle) {
  const auto transforms = varied_transforms();
  const MeshDesc mesh = faceted_sphere(vec3(0.f), 1.f, true);
  const DirectCopies copies(mesh, transforms);
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
  int checked = 0;
  for (int i = 0; i < 3000; ++i) {
    const vec3 dir = square_to_uniform_sphere({u01(rng), u01(rng)});
    SurfaceHit hit;
    uint32_t prim = 0;
    vec2 b;
    const int k = copies.intersect(Ray{random_target(rng, transforms) - 12.f * dir, dir, 0.f}, &hit, &prim, &b);
    if (k < 0) continue;
    const uint32_t* tri = &mesh.indices[3 * prim];
    const vec2 uv = (1.f - b.x - b.y) * mesh.uvs[tri[0]] + b.x * mesh.uvs[tri[1]] + b.y * mesh.uvs[tri[2]];
    ASSERT_NEAR(hit.uv.x, uv.x, 1e-6f);
    ASSERT_NEAR(hit.uv.y, uv.y, 1e-6f);
    const glm::dmat3 a(transforms[size_t(k)].linear);
    const dvec3 p0 = a * dvec3(mesh.positions[tri[0]]), p1 = a * dvec3(mesh.positions[tri[1]]),
                p2 = a * dvec3(mesh.positions[tri[2]]);
    const dvec3 n = glm::normalize(glm::cross(p1 - p0, p2 - p0));
    ASSERT_GT(glm::dot(dvec3(hit.ng), n), 1.0 - 1e-5) << "copy " << k;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// Normal maps follow dp/du and dp/dv (Scene::surface_derivatives): on a copy they are those of
// the mesh written out by hand, and without uvs still tangent to the copy.
TEST(InstanceHit, SurfaceDerivativesOfTheCopy) {
  const auto transforms = varied_transforms();
  for (const bool uvs : {true, false}) {
    const Pair p = scene_pair(faceted_sphere(vec3(0.f), 1.f, uvs), transforms);
    const auto a = Scene::build(p.instanced), b = Scene::build(p.by_hand);
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
    int checked = 0;
    for (int i = 0; i < 4000; ++i) {
      const vec3 dir = square_to_uniform_sphere({u01(rng), u01(rng)});
      const Ray ray{random_target(rng, transforms) - 12.f * dir, dir, 0.f};
      SurfaceHit ha, hb;
      if (!a->intersect(ray, &ha) || !b->intersect(ray, &hb) || ha.primitive != hb.primitive) continue;
      if (hb.object == 0) continue;  // the mesh itself
      ASSERT_NE(ha.instance, SurfaceHit::kNotACopy);
      a->surface_derivatives(0.f, &ha);
      b->surface_derivatives(0.f, &hb);
      ASSERT_LT(std::abs(glm::dot(glm::normalize(ha.dpdu), ha.ng)), 1e-3f);
      ASSERT_LT(std::abs(glm::dot(glm::normalize(ha.dpdv), ha.ng)), 1e-3f);
      if (uvs) {  // without uvs any tangent frame will do
        ASSERT_LT(glm::length(ha.dpdu - hb.dpdu), 1e-4f * (1.f + glm::length(hb.dpdu))) << hb.object;
        ASSERT_LT(glm::length(ha.dpdv - hb.dpdv), 1e-4f * (1.f + glm::length(hb.dpdv))) << hb.object;
      }
      ++checked;
    }
    EXPECT_GT(checked, 1000);
  }
}

struct SpawnCase {
  const char* name;
  float scale;
  vec3 offset;
  bool moving;
};

class InstanceSpawn : public ::testing::TestWithParam<SpawnCase> {};

// Rays spawned from a copy of a convex mesh, into the outer hemisphere, never hit that copy
// again: the error bound covers the transform and Embree's own mapping of the ray back into it.
TEST_P(InstanceSpawn, NoSelfHits) {
  const SpawnCase c = GetParam();
  std::vector<InstanceTransform> transforms;
  for (const InstanceTransform& t : varied_transforms())
    transforms.push_back(InstanceTransform{t.linear * c.scale, t.translation * c.scale * 3.f + c.offset});
  const Pair p = scene_pair(faceted_sphere(vec3(0.f), 1.f, false), transforms,
                           c.moving ? vec3(0.3f, 0.1f, 0.f) : vec3(0.f));
  SceneInput in = p.instanced;
  in.camera = camera_looking(c.offset + vec3(0, 0, 30) * c.scale, c.offset, 40.f);
  const auto scene = Scene::build(in);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u01(0.f, 0.99999994f);
  int hits = 0, self_hits = 0;
  for (int i = 0; i < 4000; ++i) {
    const float time = c.moving ? u01(rng) : 0.f;
    const size_t k = size_t(u01(rng) * transforms.size());
    const vec3 dir = square_to_uniform_sphere({u01(rng), u01(rng)});
    const vec3 local = (vec3(u01(rng), u01(rng), u01(rng)) - 0.5f) * 1.6f;
    const vec3 target = transforms[k].linear * local + transforms[k].translation;
    SurfaceHit hit;
    if (!scene->intersect(Ray{target - 40.f * c.scale * dir, dir, time}, &hit)) continue;
    if (glm::length(hit.p - transforms[k].translation) > 2.5f * c.scale) continue;  // another copy
    ++hits;
    const vec3 n = glm::dot(hit.ng, dir) < 0.f ? hit.ng : -hit.ng;
    const Frame frame(n);
    for (int j = 0; j < 4; ++j) {
      vec3 w = frame.to_world(square_to_cosine_hemisphere({u01(rng), u01(rng)}));
      if (j == 0) w = glm::normalize(frame.to_world(vec3(1.f, 0.f, 1e-4f)));  // grazing
      SurfaceHit again;
      if (scene->intersect(Ray{offset_ray_origin(hit.p, hit.p_error, hit.ng, w), w, time}, &again) &&
          glm::length(again.p - transforms[k].translation) < 2.5f * c.scale)
        ++self_hits;
    }
  }
  EXPECT_GT(hits, 1000);
  EXPECT_EQ(self_hits, 0) << "of " << hits * 4 << " spawned rays";
}

INSTANTIATE_TEST_SUITE_P(
    Scales, InstanceSpawn,
    ::testing::Values(SpawnCase{"unit", 1.f, vec3(0.f), false}, SpawnCase{"small", 1e-3f, vec3(0.f), false},
                      SpawnCase{"large", 1e3f, vec3(0.f), false},
                      SpawnCase{"far1e5", 1.f, vec3(1e5f, -2e5f, 1e5f), false},
                      SpawnCase{"moving", 1.f, vec3(0.f), true}),
    [](const auto& info) { return std::string(info.param.name); });

// The same picture: a lit stage with the mesh and its copies, rendered with the same seed, once
// instanced and once with the copies written out. Paths differ only where a rounding difference
// flips a decision, so the images agree to far below their noise.
TEST(InstanceRender, SameImageAsCopiesWrittenOut) {
  const auto transforms = varied_transforms();
  // Flat shaded (no vertex normals), so that even the sheared copy shades exactly as written
  // out; shading normals are compared in MatchesTheMeshTransformedByHand.
  MeshDesc mesh = faceted_sphere(vec3(0.f), 1.f, true);
  mesh.normals.clear();
  Pair p = scene_pair(mesh, transforms);
  for (SceneInput* in : {&p.instanced, &p.by_hand}) {
    in->materials[0] = PlasticParams{};
    in->materials.push_back(DiffuseParams{});
    ObjectDesc light = quad_object({-2, 4, -2}, {4, 0, 0}, {0, 0, 4}, uint32_t(in->materials.size() - 1));
    light.emission = Spectrum(4.f);
    in->objects.push_back(light);
    // No environment: its share in light selection follows the scene's bounds, which for a copy
    // are its mesh's box transformed, a little wider than the copy written out. That changes
    // the noise (both are unbiased), not what this test compares.
  }
  for (size_t k = 1; k <= transforms.size(); ++k) p.by_hand.materials[k] = PlasticParams{};
  const RenderSettings s = small_settings(48, 48, 16, 6);
  const RenderResult a = render_input(p.instanced, s), b = render_input(p.by_hand, s);
  double diff = 0.0, sum = 0.0;
  int differing = 0;
  for (size_t i = 0; i < a.image.rgb.size(); ++i) {
    ASSERT_TRUE(std::isfinite(a.image.rgb[i]));
    const double d = std::abs(double(a.image.rgb[i]) - b.image.rgb[i]);
    diff += d;
    sum += b.image.rgb[i];
    if (d > 1e-3 * (1.0 + b.image.rgb[i])) ++differing;
  }
  EXPECT_GT(sum, 0.0);
  EXPECT_LT(diff / sum, 2e-3) << differing << " values differ";
  EXPECT_LT(differing, int(a.image.rgb.size() / 100));
}

}  // namespace
}  // namespace penumbra::test

#include <unistd.h>

#include <fstream>

namespace penumbra::test {
namespace {

int64_t resident_bytes() {
  std::ifstream statm("/proc/self/statm");
  int64_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * int64_t(sysconf(_SC_PAGESIZE));
}

// A copy costs a transform and Embree's instance record, not the mesh: 20,000 copies of a
// 20,000-triangle mesh (which alone takes about 2 MB in Embree) stay within a few hundred bytes
// each. The measured figure is what renderer/scene/memory_estimate.cpp assumes.
TEST(InstanceMemory, CopiesCostBytesNotTheMesh) {
  MeshDesc mesh = faceted_sphere(vec3(0.f), 1.f, false, 100, 100);
  ASSERT_GE(mesh.indices.size() / 3, 19000u);
  auto scene_with = [&](int copies) {
    SceneInput in;
    in.camera = camera_looking({0, 0, 5}, {0, 0, 0}, 40.f);
    in.materials = {DiffuseParams{}};
    ObjectDesc o;
    o.shape = mesh;
    in.objects = {o};
    std::vector<InstanceTransform> t(static_cast<size_t>(copies));
    for (int k = 0; k < copies; ++k) t[size_t(k)].translation = vec3(float(k % 200) * 3.f, float(k / 200) * 3.f, 0.f);
    in.instances = {InstancesDesc{0, t}};
    return in;
  };
  constexpr int kCopies = 20000;
  const SceneInput small_input = scene_with(1), big_input = scene_with(kCopies + 1);
  int64_t small = 0, big = 0;
  {
    const auto scene = Scene::build(small_input);
    small = resident_bytes();
  }
  {
    const auto scene = Scene::build(big_input);
    big = resident_bytes();
    ASSERT_EQ(scene->instance_count(), size_t(kCopies + 1));
  }
  const double per_copy = double(big - small) / kCopies;
  std::printf("resident bytes per copy: %.0f\n", per_copy);
  EXPECT_LT(per_copy, 2048.0);
}

}  // namespace
}  // namespace penumbra::test
