// The exact-t test after traversal (scene/exact_t_check.h): a ray that leaves a plain mesh and
// re-hits it at t <= 0 in Embree's unfiltered traversal must get the true next hit, from
// intersect and intersect_packet alike, exactly the hit of a scene whose meshes filter in
// traversal; occlusion must not see the re-hit; and the coincident-triangle detector that
// decides between the two must find duplicated triangles and nothing else.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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

// A direction uniform on the sphere, in double before rounding.
vec3 random_direction(std::mt19937& rng) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double z = 2 * u01(rng) - 1, phi = 2 * M_PI * u01(rng), r = std::sqrt(1 - z * z);
  return vec3(dvec3(r * std::cos(phi), r * std::sin(phi), z));
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
    const vec3 d = random_direction(rng);
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

// ---- the early accept of candidates (embree_hit_certainly_ahead) ----

// A candidate hit as Embree's robust test reported it to a filter: the ray's tfar then is the
// candidate's t.
struct Candidate {
  uint32_t geom, prim;
  float t;
  vec3 ng, o, d;
};
struct RecordingContext {
  RTCIntersectContext embree;  // first: the filter casts Embree's pointer back
  std::vector<Candidate>* out;
};
// Records every candidate and rejects it, so that the traversal goes on and shows them all.
void record_every_candidate(const RTCFilterFunctionNArguments* args) {
  auto* ctx = reinterpret_cast<const RecordingContext*>(args->context);
  for_each_filter_lane(args, [&](unsigned n, unsigned i) {
    if (args->valid[i] == 0) return;
    ctx->out->push_back({RTCHitN_geomID(args->hit, n, i), RTCHitN_primID(args->hit, n, i),
                         RTCRayN_tfar(args->ray, n, i),
                         vec3(RTCHitN_Ng_x(args->hit, n, i), RTCHitN_Ng_y(args->hit, n, i),
                              RTCHitN_Ng_z(args->hit, n, i)),
                         embree_ray_origin(args->ray, n, i), embree_ray_direction(args->ray, n, i)});
    args->valid[i] = 0;
  });
}

// Every candidate of `rays`, traced one by one (rtcIntersect1) and in 16-wide occlusion packets
// (rtcOccluded16, as the renderer's shadow rays): the two use different kernels.
std::vector<Candidate> candidates_of(RTCScene scene, const std::vector<Ray>& rays) {
  std::vector<Candidate> out;
  RecordingContext ctx;
  rtcInitIntersectContext(&ctx.embree);
  ctx.embree.filter = record_every_candidate;
  ctx.out = &out;
  for (const Ray& ray : rays) {
    RTCRayHit rh = embree_ray_hit(ray);
    rtcIntersect1(scene, &ctx.embree, &rh);
  }
  for (size_t first = 0; first < rays.size(); first += 16) {
    alignas(64) int valid[16];
    alignas(64) RTCRay16 r;
    for (int k = 0; k < 16; ++k) {
      const size_t i = std::min(first + size_t(k), rays.size() - 1);
      valid[k] = first + size_t(k) < rays.size() ? -1 : 0;
      r.org_x[k] = rays[i].origin.x, r.org_y[k] = rays[i].origin.y, r.org_z[k] = rays[i].origin.z;
      r.dir_x[k] = rays[i].direction.x, r.dir_y[k] = rays[i].direction.y, r.dir_z[k] = rays[i].direction.z;
      r.tnear[k] = 0.f, r.tfar[k] = rays[i].t_max, r.time[k] = 0.f;
      r.mask[k] = 0xFFFFFFFFu, r.id[k] = 0, r.flags[k] = 0;
    }
    rtcOccluded16(valid, scene, &ctx.embree, &r);
  }
  return out;
}

// A bumpy height field of 48 x 48 cells (two triangles each, no pair a parallelogram) over a
// square of side `size` centred at `centre`.
MeshDesc bumpy_field(const vec3& centre, float size) {
  MeshDesc m;
  const int n = 48;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = (float(i) / n - 0.5f) * size, z = (float(j) / n - 0.5f) * size;
      const float y = 0.04f * size * std::sin(13.f * x / size) * std::cos(11.f * z / size) +
                      0.003f * size * float((i * 7 + j * 13) % 5);
      m.positions.push_back(centre + vec3(x, y, z));
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const uint32_t a = uint32_t(j * (n + 1) + i), b = a + 1, c = a + uint32_t(n + 1), d = c + 1;
      m.indices.insert(m.indices.end(), {a, c, b, b, c, d});
    }
  return m;
}

struct Tally {
  size_t candidates = 0, behind = 0, accepted = 0, ahead = 0, wrongly_accepted = 0;
};

// Checks every candidate of `rays` on `scene`'s plain meshes against the exact test.
Tally check_candidates(const Scene& scene, const std::vector<Ray>& rays) {
  Tally tally;
  for (const Candidate& c : candidates_of(scene.embree_scene(), rays)) {
    const TriangleMesh* mesh = scene.exact_t_check().plain_mesh(c.geom, RTC_INVALID_GEOMETRY_ID);
    if (!mesh) continue;
    ++tally.candidates;
    // Embree's normal is the unnormalised cross product of two edges (the predicate's scale).
    vec3 v[3];
    mesh->step_triangle(c.prim, 0, v);
    const float cross = glm::length(glm::cross(v[1] - v[0], v[2] - v[0]));
    EXPECT_GT(glm::length(c.ng), 0.25f * cross) << "prim " << c.prim;
    EXPECT_LT(glm::length(c.ng), 4.f * cross) << "prim " << c.prim;
    const bool exact = mesh->ahead_of_ray(c.prim, c.o, c.d, 0.f);
    const bool early = embree_hit_certainly_ahead(c.o, c.d, c.t, c.ng, mesh->bounds(), mesh->max_edge());
    tally.behind += !exact;
    tally.ahead += exact;
    tally.accepted += early;
    tally.wrongly_accepted += early && !exact;
  }
  return tally;
}

// The early accept must never pass a candidate whose exact t is <= 0 (a re-hit of the surface
// the ray leaves: a false shadow), and should settle most other candidates. The rays: from
// points of the large tilted quad near the world origin (Embree misjudges the sign of t for many
// of them, see rays_that_rehit), and from hit points of a bumpy field, rounded to float and not
// offset (re-hits of the triangle left and of its neighbours at both kinds of fold), in every
// direction, grazing ones included; the field at three scales and far from the origin.
TEST(ExactTCheck, EarlyAcceptNeverPassesAReHit) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  Tally total;
  auto add = [&](const Tally& t) {
    total.candidates += t.candidates, total.behind += t.behind, total.accepted += t.accepted;
    total.ahead += t.ahead, total.wrongly_accepted += t.wrongly_accepted;
  };
  {
    const auto scene = Scene::build(tilted_quad_in_box(false));
    ASSERT_TRUE(scene->exact_t_check().enabled());
    const std::vector<Ray> rays = rays_that_rehit(*scene, 400);
    ASSERT_EQ(rays.size(), 400u);
    const Tally t = check_candidates(*scene, rays);
    EXPECT_GE(t.behind, 400u);  // every ray's re-hit, from one kernel and the other
    add(t);
  }
  for (const auto& [centre, size] : {std::pair{vec3(0.f), 2.f}, std::pair{vec3(0.f), 2e-3f},
                                     std::pair{vec3(0.f), 2e3f}, std::pair{vec3(300.f, -40.f, 120.f), 2.f}}) {
    SceneInput in;
    in.camera = camera_looking(centre + vec3(0.f, size, 2.f * size), centre, 40.f);
    in.materials = {MaterialParams{}};
    ObjectDesc field;
    field.shape = bumpy_field(centre, size);
    in.objects = {field};
    const auto scene = Scene::build(in);
    ASSERT_TRUE(scene->exact_t_check().enabled());
    std::vector<Ray> rays;
    for (int k = 0; k < 3000; ++k) {
      // A hit point of the field, as the renderer's intersect computes it, without the spawn
      // offset: the hardest origin for the sign of t.
      const vec3 above = centre + size * vec3(u01(rng) - 0.5f, 1.f, u01(rng) - 0.5f);
      SurfaceHit hit;
      if (!scene->intersect(Ray{above, vec3(0.f, -1.f, 0.f), 0.f}, &hit)) continue;
      vec3 d = random_direction(rng);
      if (k % 3 == 0) {  // grazing: within about 1e-3 .. 1e-6 radians of the tangent plane
        const vec3 n = hit.ng;
        d = glm::normalize(d - glm::dot(d, n) * n) + n * (std::pow(10.f, -3.f - 3.f * u01(rng)) * (u01(rng) < 0.5f ? -1.f : 1.f));
      }
      rays.push_back(Ray{hit.p, d, 0.f});
      // And a ray from far above, whose candidates are ordinary hits.
      rays.push_back(Ray{above, glm::normalize(vec3(u01(rng) - 0.5f, -1.f, u01(rng) - 0.5f)), 0.f});
    }
    add(check_candidates(*scene, rays));
  }
  EXPECT_EQ(total.wrongly_accepted, 0u) << "of " << total.candidates << " candidates";
  // The data exercise the case, and the early accept does its job on the rest.
  EXPECT_GE(total.behind, 1000u);
  EXPECT_GT(double(total.accepted), 0.5 * double(total.ahead))
      << total.accepted << " accepted of " << total.ahead << " ahead";
  std::printf("candidates %zu, exact t <= 0: %zu, ahead %zu, accepted early %zu\n", total.candidates,
              total.behind, total.ahead, total.accepted);
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

// A mesh large enough that the triangles' hashes are computed in several blocks on threads:
// a duplicate anywhere is found, in the same mesh or across meshes, and a clean grid passes.
TEST(ExactTCheck, CoincidentTrianglesAreFoundInLargeMeshes) {
  MeshDesc grid;
  const uint32_t n = 120;  // 28,800 triangles
  for (uint32_t j = 0; j <= n; ++j)
    for (uint32_t i = 0; i <= n; ++i) grid.positions.emplace_back(float(i), 0.01f * float(i * j), float(j));
  for (uint32_t j = 0; j < n; ++j)
    for (uint32_t i = 0; i < n; ++i) {
      const uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      grid.indices.insert(grid.indices.end(), {a, b, d, a, d, c});
    }
  std::vector<std::unique_ptr<TriangleMesh>> v;
  v.push_back(mesh(grid));
  EXPECT_FALSE(coincident(v));
  for (const size_t t : {size_t(0), size_t(5000), grid.indices.size() / 3 - 1}) {
    MeshDesc dup = grid;  // triangle t listed again at the end
    dup.indices.insert(dup.indices.end(), grid.indices.begin() + 3 * t, grid.indices.begin() + 3 * t + 3);
    v.clear();
    v.push_back(mesh(dup));
    EXPECT_TRUE(coincident(v)) << t;
  }
  MeshDesc one;  // one triangle of the grid's middle, as a second mesh
  one.positions = grid.positions;
  one.indices.assign(grid.indices.begin() + 3 * 14000, grid.indices.begin() + 3 * 14001);
  v.clear();
  v.push_back(mesh(grid));
  v.push_back(mesh(one));
  EXPECT_TRUE(coincident(v));
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
