// The exact-t test after traversal (scene/exact_t_check.h): a ray that leaves a plain mesh and
// re-hits it at t <= 0 in Embree's unfiltered traversal must get the true next hit, from
// intersect and intersect_packet alike, exactly the hit of a scene whose meshes filter in
// traversal; occlusion must not see the re-hit; and the coincident-triangle detector that
// decides between the two must find duplicated triangles and nothing else.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "renderer/embree/ray_access.h"
#include "renderer/scene/exact_t_check.h"
#include "renderer/scene/scene.h"
#include "renderer/shapes/triangle_mesh.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

// Boxes of Embree triangles: a box of quads' face pairs would be traced as parallelograms
// (shapes/parallelogram_pairs.h), which this test is not about.
ObjectDesc box(const vec3& lo, const vec3& hi, uint32_t material) {
  ObjectDesc o;
  o.shape = box_mesh_of_triangles(lo, hi);
  o.material = material;
  return o;
}

// A large tilted quad of four triangles (object 0) whose plane passes close to the world origin, inside a box
// (object 1). Embree computes a triangle's plane distance from its first vertex translated to
// the ray origin, with an error of order eps times that vertex's distance (~1000 here), far
// above the distance from the plane of a float point near the origin (docs/design-notes.md):
// so Embree gets the sign of t wrong for many rays leaving such points. `coincident_elsewhere`
// adds two copies of a small triangle in a corner, which makes every mesh filter in traversal.
const vec3 kQuadOrigin(-1000.f, -1000.f, 300.f), kQuadU(2000.f, 100.f, -250.f), kQuadV(150.f, 2000.f, -400.f);

SceneInput tilted_quad_in_box(bool coincident_elsewhere) {
  SceneInput in;
  in.camera = camera_looking({0.f, 0.f, 0.f}, {0.f, 0.f, -1.f}, 40.f);
  in.materials = {MaterialParams{}};
  // The quad as a mesh of four triangles around its centre: a quad shape, and a mesh whose
  // triangles pair into parallelograms, are traced by the parallelogram test
  // (shapes/parallelogram.h), not as Embree triangles.
  ObjectDesc quad;
  quad.shape = MeshDesc{{kQuadOrigin, kQuadOrigin + kQuadU, kQuadOrigin + kQuadU + kQuadV,
                         kQuadOrigin + kQuadV, kQuadOrigin + 0.5f * (kQuadU + kQuadV)},
                        {4, 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0}};
  in.objects = {quad, box(vec3(-1500.f), vec3(1500.f), 0)};
  if (coincident_elsewhere) {
    MeshDesc tri;
    tri.positions = {{1400.f, 1400.f, 1400.f}, {1410.f, 1400.f, 1400.f}, {1400.f, 1410.f, 1400.f}};
    tri.indices = {0, 1, 2};
    ObjectDesc o;
    o.shape = tri;
    in.objects.push_back(o);
    in.objects.push_back(o);
  }
  return in;
}

// Rays from points of the quad's plane within 1 of the world origin (the exact point rounded to
// float) in random directions; kept are those whose exact t on the triangle Embree reports is
// <= 0, while Embree's unfiltered closest hit is that quad anyway: a re-hit.
std::vector<Ray> rays_that_rehit(const Scene& scene, int wanted) {
  const TriangleMesh& mesh = *scene.object(0).shape->triangle_mesh();
  const dvec3 o0(kQuadOrigin), u(kQuadU), v(kQuadV);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<Ray> out;
  for (int tried = 0; int(out.size()) < wanted && tried < 100000; ++tried) {
    // Solve o0 + s u + t v = (x, y, .) for s, t, in double.
    const double x = 2 * u01(rng) - 1, y = 2 * u01(rng) - 1;
    const double det = u.x * v.y - v.x * u.y;
    const double s = ((x - o0.x) * v.y - v.x * (y - o0.y)) / det;
    const double t = (u.x * (y - o0.y) - (x - o0.x) * u.y) / det;
    const vec3 o(o0 + s * u + t * v);
    const double z = 2 * u01(rng) - 1, phi = 2 * M_PI * u01(rng), r = std::sqrt(1 - z * z);
    const vec3 d(vec3(dvec3(r * std::cos(phi), r * std::sin(phi), z)));
    const Ray ray{o, d, 0.f};
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRayHit rh = embree_ray_hit(ray);
    rtcIntersect1(scene.embree_scene(), &ctx, &rh);
    if (rh.hit.geomID == 0 && !mesh.ahead_of_ray(rh.hit.primID, o, d, 0.f)) out.push_back(ray);
  }
  return out;
}

void expect_same_hit(const SurfaceHit& a, const SurfaceHit& b, const char* what, size_t i) {
  EXPECT_EQ(a.object, b.object) << what << " ray " << i;
  EXPECT_EQ(a.primitive, b.primitive) << what << " ray " << i;
  EXPECT_EQ(std::memcmp(&a.t, &b.t, sizeof(float)), 0) << what << " ray " << i << ": " << a.t << " vs " << b.t;
  EXPECT_EQ(std::memcmp(&a.p, &b.p, sizeof(vec3)), 0) << what << " ray " << i;
}

TEST(ExactTCheck, ReHitIsTracedAgainToTheTrueNextHitSingleAndPacket) {
  const auto scene = Scene::build(tilted_quad_in_box(false));
  const auto filtered = Scene::build(tilted_quad_in_box(true));
  ASSERT_TRUE(scene->exact_t_check().enabled());
  ASSERT_FALSE(filtered->exact_t_check().enabled());
  const std::vector<Ray> rays = rays_that_rehit(*scene, 64);
  ASSERT_EQ(rays.size(), 64u);

  std::vector<SurfaceHit> single(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    ASSERT_TRUE(scene->intersect(rays[i], &single[i])) << i;
    // The true next hit: the box around, never the quad the ray leaves.
    EXPECT_EQ(single[i].object, 1u) << i;
    SurfaceHit reference;
    ASSERT_TRUE(filtered->intersect(rays[i], &reference)) << i;
    expect_same_hit(single[i], reference, "single", i);
  }
  for (size_t first = 0; first < rays.size(); first += Scene::kPacketSize) {
    const int count = int(std::min<size_t>(Scene::kPacketSize, rays.size() - first));
    for (bool coherent : {false, true}) {
      SurfaceHit hits[Scene::kPacketSize];
      bool found[Scene::kPacketSize];
      scene->intersect_packet(&rays[first], count, coherent, hits, found);
      for (int k = 0; k < count; ++k) {
        ASSERT_TRUE(found[k]) << first + k;
        expect_same_hit(hits[k], single[first + k], "packet", first + k);
      }
    }
  }
}

TEST(ExactTCheck, OcclusionDoesNotSeeTheSurfaceTheRayLeaves) {
  const auto scene = Scene::build(tilted_quad_in_box(false));
  const std::vector<Ray> rays = rays_that_rehit(*scene, 32);
  ASSERT_EQ(rays.size(), 32u);
  // Short of the box: nothing but the quad itself could block them.
  for (size_t i = 0; i < rays.size(); ++i)
    EXPECT_FALSE(scene->occluded(rays[i].origin, rays[i].direction, 50.f, 0.f)) << i;
  for (size_t first = 0; first < rays.size(); first += Scene::kPacketSize) {
    std::vector<Ray> shadow(rays.begin() + long(first), rays.begin() + long(first) + Scene::kPacketSize);
    for (Ray& r : shadow) r.t_max = 50.f;
    bool occluded[Scene::kPacketSize];
    scene->occluded_packet(shadow.data(), Scene::kPacketSize, occluded);
    for (int k = 0; k < Scene::kPacketSize; ++k) EXPECT_FALSE(occluded[k]) << first + k;
  }
}

std::unique_ptr<TriangleMesh> mesh(const MeshDesc& desc, const vec3& velocity = vec3(0.f)) {
  ShapeContext ctx;
  ctx.motion = ShapeMotion{Motion{velocity, vec3(0.f)}, 0.f, velocity == vec3(0.f) ? 0.f : 1.f};
  return std::make_unique<TriangleMesh>(desc, ctx);
}

bool coincident(const std::vector<std::unique_ptr<TriangleMesh>>& meshes) {
  std::vector<const TriangleMesh*> p;
  for (const auto& m : meshes) p.push_back(m.get());
  return has_coincident_triangles(p);
}

TEST(ExactTCheck, CoincidentTrianglesAreFoundAndNothingElse) {
  const MeshDesc a = box_mesh({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f});
  std::vector<std::unique_ptr<TriangleMesh>> v;
  v.push_back(mesh(a));
  EXPECT_FALSE(coincident(v));  // one box: no two triangles alike
  v.push_back(mesh(a));
  EXPECT_TRUE(coincident(v));   // the same box twice

  // The same box with every triangle wound the other way and its corners listed from another
  // vertex: the same vertex sets.
  MeshDesc flipped = a;
  for (size_t t = 0; t < flipped.indices.size(); t += 3) {
    const uint32_t i0 = flipped.indices[t], i1 = flipped.indices[t + 1], i2 = flipped.indices[t + 2];
    flipped.indices[t] = i1, flipped.indices[t + 1] = i0, flipped.indices[t + 2] = i2;
  }
  v.clear();
  v.push_back(mesh(a));
  v.push_back(mesh(flipped));
  EXPECT_TRUE(coincident(v));

  // Within one mesh: a triangle listed twice.
  MeshDesc twice = a;
  twice.indices.insert(twice.indices.end(), a.indices.begin() + 6, a.indices.begin() + 9);
  v.clear();
  v.push_back(mesh(twice));
  EXPECT_TRUE(coincident(v));

  // Two boxes that touch along a face plane (sharing part of it) but no triangle.
  v.clear();
  v.push_back(mesh(a));
  v.push_back(mesh(box_mesh({0.6f, -0.3f, -0.6f}, {1.8f, 0.9f, 0.6f})));
  EXPECT_FALSE(coincident(v));
  // Boxes that share an edge (two vertices of a triangle), not a triangle.
  v.clear();
  v.push_back(mesh(a));
  v.push_back(mesh(box_mesh({0.6f, 0.6f, -0.6f}, {1.8f, 1.8f, 0.6f})));
  EXPECT_FALSE(coincident(v));
  // One ulp apart: not the same triangle.
  v.clear();
  v.push_back(mesh(a));
  v.push_back(mesh(box_mesh({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, std::nextafter(0.6f, 1.f)})));
  EXPECT_TRUE(coincident(v));  // the boxes still share their z = -0.6 face's triangles
  v.clear();
  v.push_back(mesh(a));
  v.push_back(mesh(box_mesh({-0.6f, -0.6f, std::nextafter(-0.6f, 0.f)},
                            {0.6f, 0.6f, std::nextafter(0.6f, 1.f)})));
  EXPECT_FALSE(coincident(v));
  // -0 and +0 are the same coordinate.
  v.clear();
  v.push_back(mesh(box_mesh({0.f, 0.f, 0.f}, {1.f, 1.f, 1.f})));
  v.push_back(mesh(box_mesh({-0.f, -0.f, -0.f}, {1.f, 1.f, 1.f})));
  EXPECT_TRUE(coincident(v));

  // Moving meshes coincide if they move alike (every Embree time step's vertices equal).
  v.clear();
  v.push_back(mesh(a, {1.f, 0.f, 0.f}));
  v.push_back(mesh(a, {1.f, 0.f, 0.f}));
  EXPECT_TRUE(coincident(v));
  v.clear();
  v.push_back(mesh(a, {1.f, 0.f, 0.f}));
  v.push_back(mesh(a, {0.f, 1.f, 0.f}));
  EXPECT_FALSE(coincident(v));
}

TEST(ExactTCheck, ScenesWithCoincidentTrianglesKeepTheGeometryFilter) {
  SceneInput in;
  in.camera = camera_looking({0.f, 0.f, 5.f}, {0.f, 0.f, 0.f}, 40.f);
  in.materials = {MaterialParams{}, MaterialParams{}};
  in.objects = {box({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f}, 0),
                box({-0.6f, -0.6f, -0.6f}, {0.6f, 0.6f, 0.6f}, 1)};
  EXPECT_FALSE(Scene::build(in)->exact_t_check().enabled());
  in.objects[1] = box({0.6f, -0.3f, -0.6f}, {1.8f, 0.9f, 0.6f}, 1);  // touching, no shared triangle
  EXPECT_TRUE(Scene::build(in)->exact_t_check().enabled());
}

}  // namespace
}  // namespace penumbra::test
