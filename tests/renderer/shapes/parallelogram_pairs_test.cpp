// Meshes traced as parallelograms (shapes/parallelogram_pairs.h): which meshes pair, that their
// hits report what the triangles' own hits would (triangle, point, uv, normals), that a scene
// converts exactly the meshes it should, and that the faces' exact edges neither leave a crack
// nor stand out of a convex fold as a lip that grazing rays hit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "renderer/scene/scene.h"
#include "renderer/shapes/parallelogram_pairs.h"
#include "renderer/shapes/triangle_mesh.h"
#include "tests/renderer/render/render_test_util.h"

namespace penumbra::test {
namespace {

glm::mat3 turn(float radians, const vec3& axis) {
  return glm::mat3(glm::rotate(glm::mat4(1.f), radians, glm::normalize(axis)));
}

// box_mesh with every vertex turned about `pivot` and rounded on its own, as a mesh file's are.
MeshDesc turned_box(const vec3& lo, const vec3& hi, const glm::mat3& rotation, const vec3& pivot) {
  MeshDesc m = box_mesh(lo, hi);
  for (vec3& p : m.positions) p = pivot + rotation * (p - pivot);
  return m;
}

TEST(ParallelogramPairs, PairsTheFacesOfBoxesTurnedAnyWay) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> sym(-1.f, 1.f);
  for (int i = 0; i < 200; ++i) {
    const float scale = std::pow(10.f, 3.f * sym(rng));
    const vec3 lo = vec3(sym(rng), sym(rng), sym(rng)) * scale;
    const vec3 hi = lo + (vec3(1.f) + 0.9f * vec3(sym(rng), sym(rng), sym(rng))) * scale;
    const MeshDesc m =
        turned_box(lo, hi, turn(3.f * sym(rng), vec3(sym(rng), sym(rng), 1.f)), lo);
    const FacePairs pairs = pair_into_parallelograms(m.positions, m.indices);
    ASSERT_EQ(pairs.shapes.size(), 6u) << i;
    for (size_t k = 0; k < 6; ++k) {
      const Parallelogram& q = pairs.shapes[k];
      EXPECT_TRUE(q.exact_edges);
      // Its normal is the first triangle's, and every corner of both triangles is one of its own.
      const uint32_t* tri = &m.indices[6 * k];
      const vec3 a = m.positions[tri[0]], b = m.positions[tri[1]], c = m.positions[tri[2]];
      EXPECT_GT(glm::dot(dvec3(glm::cross(b - a, c - a)), q.normal), 0.0) << i << " " << k;
      for (int j = 0; j < 6; ++j) {
        const vec3 p = m.positions[tri[j]];
        bool found = false;
        for (const vec3& corner : q.corners) found = found || corner == p;
        EXPECT_TRUE(found) << i << " " << k << " " << j;
      }
      // The test's origin is a corner to the bit; origin + u, + v and + u + v are the others to
      // within rounding.
      EXPECT_EQ(q.corners[0], q.origin);
      const vec3 spans[4] = {vec3(0.f), q.u, q.u + q.v, q.v};
      for (int j = 1; j < 4; ++j)
        EXPECT_LE(glm::length(q.origin + spans[j] - q.corners[j]), 1e-6f * glm::length(q.corners[j]) + 1e-6f * glm::length(q.u + q.v))
            << i << " " << k << " " << j;
    }
  }
}

TEST(ParallelogramPairs, VerticesSplitForTheirUvsStillPair) {
  const MeshDesc box = box_mesh(vec3(-1.f), vec3(1.f));
  MeshDesc split;
  for (uint32_t i : box.indices) {
    split.indices.push_back(uint32_t(split.positions.size()));
    split.positions.push_back(box.positions[i]);
  }
  EXPECT_EQ(pair_into_parallelograms(split.positions, split.indices).shapes.size(), 6u);
}

TEST(ParallelogramPairs, LeavesMeshesThatAreNotAllParallelograms) {
  const MeshDesc box = box_mesh(vec3(-1.f), vec3(1.f));
  auto pairs = [](const MeshDesc& m) {
    return pair_into_parallelograms(m.positions, m.indices).shapes.size();
  };
  ASSERT_EQ(pairs(box), 6u);
  // Four triangles around each face's centre.
  EXPECT_EQ(pairs(box_mesh_of_triangles(vec3(-1.f), vec3(1.f))), 0u);
  // An odd triangle count.
  MeshDesc odd = box;
  odd.indices.resize(odd.indices.size() - 3);
  EXPECT_EQ(pairs(odd), 0u);
  // One second triangle wound the other way round the shared edge.
  MeshDesc flipped = box;
  std::swap(flipped.indices[3 + 1], flipped.indices[3 + 2]);
  EXPECT_EQ(pairs(flipped), 0u);
  // One face a trapezoid: its fourth corner moved along an edge.
  MeshDesc trapezoid{{vec3(0, 0, 0), vec3(1, 0, 0), vec3(1.5f, 1, 0), vec3(0, 1, 0)}, {0, 1, 2, 0, 2, 3}};
  EXPECT_EQ(pairs(trapezoid), 0u);
  // The same with the corner off by far less than the edges' tolerance: a parallelogram.
  MeshDesc nearly{{vec3(0, 0, 0), vec3(1, 0, 0), vec3(1, 1, 1e-7f), vec3(0, 1, 0)}, {0, 1, 2, 0, 2, 3}};
  EXPECT_EQ(pairs(nearly), 1u);
  // ... and by more: not.
  MeshDesc bent{{vec3(0, 0, 0), vec3(1, 0, 0), vec3(1, 1, 1e-5f), vec3(0, 1, 0)}, {0, 1, 2, 0, 2, 3}};
  EXPECT_EQ(pairs(bent), 0u);
  // A sliver: edges 1e-4 radians apart.
  MeshDesc sliver{{vec3(0, 0, 0), vec3(1, 0, 0), vec3(2, 1e-4f, 0), vec3(1, 1e-4f, 0)}, {0, 1, 2, 0, 2, 3}};
  EXPECT_EQ(pairs(sliver), 0u);
  // Two triangles sharing only a corner.
  MeshDesc corner{{vec3(0, 0, 0), vec3(1, 0, 0), vec3(0, 1, 0), vec3(-1, 0, 0), vec3(0, -1, 0)},
                  {0, 1, 2, 0, 3, 4}};
  EXPECT_EQ(pairs(corner), 0u);
}

// A hit at (s, t) of a face pair against the triangle's own hit at the same point: the same
// triangle, point, uv and shading normal, to rounding.
TEST(ParallelogramPairs, HitsReportWhatTheTrianglesHitWould) {
  MeshDesc m = turned_box(vec3(-1.f, -0.5f, -2.f), vec3(1.5f, 0.5f, 1.f), turn(0.7f, {1, 2, 3}),
                          vec3(0.f));
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  for (size_t p = 0; p < m.positions.size(); ++p) {
    m.uvs.push_back(vec2(u01(rng), u01(rng)));
    m.normals.push_back(glm::normalize(m.positions[p] + vec3(0.1f, 0.f, 0.f)));
  }
  ShapeContext ctx;
  ctx.need_uv = true;
  TriangleMesh triangles(m, ctx), pairs(m, ctx);
  ASSERT_TRUE(pairs.trace_as_parallelograms());
  ASSERT_NE(triangles.triangle_mesh(), nullptr);
  ASSERT_EQ(pairs.triangle_mesh(), nullptr);
  const std::span<Parallelogram> faces = pairs.parallelograms();
  ASSERT_EQ(faces.size(), 6u);
  int seen[2] = {0, 0};
  for (int i = 0; i < 20000; ++i) {
    const uint32_t k = uint32_t(i % 6);
    const Parallelogram& q = faces[k];
    const float s = u01(rng), t = u01(rng);
    // The point in double, then which triangle holds it and its barycentrics there, solved from
    // the triangle's own corners.
    const dvec3 point = dvec3(q.origin) + double(s) * dvec3(q.u) + double(t) * dvec3(q.v);
    uint32_t prim = 0;
    vec2 bary(0.f);
    for (uint32_t tri = 2 * k; tri < 2 * k + 2; ++tri) {
      const dvec3 a(m.positions[m.indices[3 * tri]]), b(m.positions[m.indices[3 * tri + 1]]),
          c(m.positions[m.indices[3 * tri + 2]]);
      const dvec3 n = glm::cross(b - a, c - a);
      const double b1 = glm::dot(glm::cross(point - a, c - a), n) / glm::dot(n, n);
      const double b2 = glm::dot(glm::cross(b - a, point - a), n) / glm::dot(n, n);
      if (b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0) {
        prim = tri;
        bary = vec2(float(b1), float(b2));
      }
    }
    ++seen[prim - 2 * k];
    const Ray ray{vec3(point) + q.du, -q.du, 0.f};
    SurfaceHit expected, got;
    expected.primitive = prim;
    triangles.hit_geometry(ray, 1.f, prim, bary, &expected);
    got.primitive = k;
    pairs.hit_geometry(ray, 1.f, k, vec2(s, t), &got);
    ASSERT_EQ(got.primitive, prim) << i;
    EXPECT_EQ(got.ng, expected.ng) << i;
    EXPECT_LT(glm::length(got.p - expected.p), 1e-5f) << i;
    EXPECT_LT(glm::length(got.uv - expected.uv), 1e-5f) << i;
    EXPECT_LT(glm::length(got.ns - expected.ns), 1e-5f) << i;
    // Both error bounds cover the distance to the exact point.
    EXPECT_TRUE(glm::all(glm::lessThanEqual(glm::abs(dvec3(got.p) - point), dvec3(got.p_error) + 1e-7)));
    triangles.surface_derivatives(0.f, &expected);
    pairs.surface_derivatives(0.f, &got);
    EXPECT_EQ(got.dpdu, expected.dpdu) << i;
    EXPECT_EQ(got.dpdv, expected.dpdv) << i;
  }
  EXPECT_GT(seen[0], 8000);
  EXPECT_GT(seen[1], 8000);
}

SceneInput mesh_scene(const std::vector<ObjectDesc>& objects) {
  SceneInput in;
  in.camera = camera_looking({0.f, 3.f, 8.f}, {0.f, 0.f, 0.f}, 40.f);
  in.materials = {MaterialParams{}};
  in.objects = objects;
  return in;
}

ObjectDesc mesh_object(const MeshDesc& m) {
  ObjectDesc o;
  o.shape = m;
  return o;
}

// Static meshes of quads are traced as parallelograms, instanced ones too; moving and emitting
// ones, meshes of other triangles, meshes holding a face twice and meshes of more than kMaxFacePairs
// quads stay Embree triangles. A box standing on a floor shares the floor's plane: the floor,
// which wins their ties, gets a thick box (scene/coplanar_parallelograms.h).
TEST(ParallelogramPairs, SceneTracesTheMeshesItShouldAsParallelograms) {
  ObjectDesc floor = quad_object(vec3(-5.f, 0.f, 5.f), vec3(10.f, 0.f, 0.f), vec3(0.f, 0.f, -10.f), 0);
  ObjectDesc standing = mesh_object(turned_box(vec3(-1.f, 0.f, -1.f), vec3(1.f, 1.f, 1.f),
                                               turn(0.4f, {0, 1, 0}), vec3(0.f)));
  ObjectDesc moving = mesh_object(box_mesh(vec3(2.f), vec3(3.f)));
  moving.velocity = vec3(1.f, 0.f, 0.f);
  ObjectDesc emitting = mesh_object(box_mesh(vec3(-3.f), vec3(-2.f)));
  emitting.emission = Spectrum(1.f);
  ObjectDesc copied = mesh_object(box_mesh(vec3(4.f), vec3(5.f)));
  ObjectDesc fan = mesh_object(box_mesh_of_triangles(vec3(-5.f), vec3(-4.f)));
  MeshDesc twice_desc = box_mesh(vec3(6.f), vec3(7.f));
  twice_desc.indices.insert(twice_desc.indices.end(), twice_desc.indices.begin(),
                            twice_desc.indices.begin() + 6);
  ObjectDesc twice = mesh_object(twice_desc);
  // A grid of quads, one more than the limit.
  MeshDesc grid_desc;
  const int n = int(TriangleMesh::kMaxFacePairs) + 1;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= 1; ++j) grid_desc.positions.push_back(vec3(float(i), 8.f, float(j)));
  for (uint32_t i = 0; i < uint32_t(n); ++i)
    grid_desc.indices.insert(grid_desc.indices.end(), {2 * i, 2 * i + 1, 2 * i + 3, 2 * i, 2 * i + 3, 2 * i + 2});
  ObjectDesc grid = mesh_object(grid_desc);
  grid_desc.indices.resize(grid_desc.indices.size() - 6);  // at the limit
  ObjectDesc smaller_grid = mesh_object(grid_desc);
  SceneInput in = mesh_scene({floor, standing, moving, emitting, copied, fan, twice, grid, smaller_grid});
  in.camera.shutter_open = 0.f;
  in.camera.shutter_close = 1.f;
  in.instances = {InstancesDesc{4, {InstanceTransform{glm::mat3(1.f), vec3(0.f, 10.f, 0.f)}}}};
  const auto scene = Scene::build(in);
  auto traced_as_parallelograms = [&](uint32_t i) {
    return scene->object(i).shape->triangle_mesh() == nullptr;
  };
  EXPECT_TRUE(traced_as_parallelograms(0));  // a quad
  EXPECT_TRUE(traced_as_parallelograms(1));
  EXPECT_FALSE(traced_as_parallelograms(2));
  EXPECT_FALSE(traced_as_parallelograms(3));
  EXPECT_TRUE(traced_as_parallelograms(4));
  EXPECT_FALSE(traced_as_parallelograms(5));
  EXPECT_FALSE(traced_as_parallelograms(6));
  EXPECT_FALSE(traced_as_parallelograms(7));
  EXPECT_TRUE(traced_as_parallelograms(8));
  // The floor is thick, the standing box's bottom face (its one face in the plane y = 0) is not.
  auto thick = [](const Parallelogram& q) { return q.bounds.lo.y < 0.f && q.bounds.hi.y > 0.f; };
  EXPECT_TRUE(thick(const_cast<Shape&>(*scene->object(0).shape).parallelograms()[0]));
  int bottoms = 0;
  for (const Parallelogram& q : const_cast<Shape&>(*scene->object(1).shape).parallelograms())
    if (q.flat_axis() == 1 && q.origin.y == 0.f) {
      EXPECT_FALSE(thick(q));
      ++bottoms;
    }
  EXPECT_EQ(bottoms, 1);
}

// Embree traverses one BVH per kind of primitive, so a mesh of quads is converted only where
// that adds no BVH: beside other user geometry (a sphere here), or where no triangles stay.
// Beside triangles alone it stays triangles (a user geometry of its own cost a glTF scene 3%).
TEST(ParallelogramPairs, MeshesOfQuadsAddNoUserGeometryBesideTrianglesAlone) {
  const ObjectDesc box = mesh_object(box_mesh(vec3(-1.f), vec3(1.f)));
  const ObjectDesc fan = mesh_object(box_mesh_of_triangles(vec3(2.f), vec3(3.f)));
  const ObjectDesc ball = sphere_object(vec3(-3.f), 0.5f, 0);
  auto converted = [](const std::vector<ObjectDesc>& objects) {
    const auto scene = Scene::build(mesh_scene(objects));
    return scene->object(0).shape->triangle_mesh() == nullptr;
  };
  EXPECT_FALSE(converted({box, fan}));
  EXPECT_TRUE(converted({box, fan, ball}));
  EXPECT_TRUE(converted({box}));
  EXPECT_TRUE(converted({box, mesh_object(box_mesh(vec3(4.f), vec3(5.f)))}));
}

// Hits on an instanced copy of a mesh of quads name the triangle they lie in (the instance
// passes on the primitive the mesh reports), which surface_derivatives reads.
TEST(ParallelogramPairs, CopiesNameTheTriangleTheirHitsLieIn) {
  const MeshDesc box = box_mesh(vec3(-1.f), vec3(1.f));
  const glm::mat3 rotation = turn(0.6f, {1, 1, 0});
  const vec3 offset(10.f, 0.f, 0.f);  // the copy; the mesh itself stays out of the rays' way
  SceneInput in = mesh_scene({mesh_object(box)});
  in.camera = camera_looking(offset + vec3(0.f, 0.f, 8.f), offset, 40.f);
  in.instances = {InstancesDesc{0, {InstanceTransform{rotation, offset}}}};
  const auto scene = Scene::build(in);
  ASSERT_EQ(scene->object(0).shape->triangle_mesh(), nullptr);
  std::mt19937 rng(2);
  std::uniform_real_distribution<float> u01(0.f, 1.f);
  const glm::dmat3 inverse = glm::inverse(glm::dmat3(rotation));
  int checked = 0;
  for (int i = 0; i < 4000; ++i) {
    const vec3 target = offset + vec3(2.f * u01(rng) - 1.f, 2.f * u01(rng) - 1.f, 0.f) * 1.5f;
    const vec3 from = offset + vec3(0.f, 0.f, 8.f);
    SurfaceHit hit;
    if (!scene->intersect(Ray{from, glm::normalize(target - from), 0.f}, &hit)) continue;
    ASSERT_NE(hit.instance, SurfaceHit::kNotACopy) << i;
    // The point in the mesh's space, and the one triangle of the face that holds it by more
    // than rounding.
    const dvec3 local = inverse * (dvec3(hit.p) - dvec3(offset));
    int holding = -1, count = 0;
    for (uint32_t tri = 0; tri < box.indices.size() / 3; ++tri) {
      const dvec3 a(box.positions[box.indices[3 * tri]]), b(box.positions[box.indices[3 * tri + 1]]),
          c(box.positions[box.indices[3 * tri + 2]]);
      const dvec3 n = glm::cross(b - a, c - a);
      if (std::abs(glm::dot(local - a, glm::normalize(n))) > 1e-4) continue;
      const double b1 = glm::dot(glm::cross(local - a, c - a), n) / glm::dot(n, n);
      const double b2 = glm::dot(glm::cross(b - a, local - a), n) / glm::dot(n, n);
      if (b1 > 1e-4 && b2 > 1e-4 && b1 + b2 < 1.0 - 1e-4) {
        holding = int(tri);
        ++count;
      }
    }
    if (count != 1) continue;  // on an edge or the diagonal
    EXPECT_EQ(hit.primitive, uint32_t(holding)) << i;
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// A convex fold of two faces of one mesh whose corners are turned floats: rays aimed exactly at
// the shared edge from outside hit one face (no crack), and rays leaving one face near the edge
// at grazing angles, over the fold, hit nothing (no lip: with the quads' overlap of 1e-5 of an
// edge, the other face stands out of the fold by that much).
TEST(ParallelogramPairs, ConvexFoldsNeitherCrackNorStandOut) {
  const glm::mat3 r = turn(0.9f, {3, -1, 2});
  for (const float scale : {1e-3f, 1.f, 1e3f}) {
    // A roof: the edge from e0 to e1, one face down the +x side, the other down the -x side.
    const vec3 e0 = r * (vec3(0.f, 1.f, -1.f) * scale), e1 = r * (vec3(0.f, 1.f, 1.f) * scale);
    const vec3 f0 = r * (vec3(1.f, 0.f, -1.f) * scale), f1 = r * (vec3(1.f, 0.f, 1.f) * scale);
    const vec3 g0 = r * (vec3(-1.f, 0.f, -1.f) * scale), g1 = r * (vec3(-1.f, 0.f, 1.f) * scale);
    MeshDesc roof{{e0, e1, f0, f1, g0, g1}, {0, 1, 3, 0, 3, 2, 0, 4, 5, 0, 5, 1}};
    const auto scene = Scene::build(mesh_scene({mesh_object(roof)}));
    ASSERT_EQ(scene->object(0).shape->triangle_mesh(), nullptr) << scale;
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    int cracks = 0, lips = 0;
    for (int i = 0; i < 100000; ++i) {
      const vec3 p = e0 + u01(rng) * (e1 - e0);
      // From in front of both faces, aimed at the edge point. (A ray from behind one face's
      // plane through the edge grazes the fold's tip: it hits both faces or neither.)
      const float x = 2.f * u01(rng) - 1.f;
      const vec3 from = p + r * vec3(x, std::abs(x) + 0.05f + u01(rng), 2.f * u01(rng) - 1.f) * scale;
      const vec3 d = glm::normalize(p - from);
      SurfaceHit hit;
      if (!scene->intersect(Ray{from, d, 0.f}, &hit)) ++cracks;
      // From a point of the +x face near the edge, up the roof and over it at 1e-6..1e-2 rad.
      const float along = std::pow(10.f, -6.f + 4.f * u01(rng));
      const vec3 start = p + along * (f0 - e0);
      const vec3 n = r * glm::normalize(vec3(1.f, 1.f, 0.f));
      const vec3 up = glm::normalize(e0 - f0);
      const float elevation = std::pow(10.f, -6.f + 4.f * u01(rng));
      const vec3 dir = glm::normalize(up + elevation * n);
      const vec3 o = offset_ray_origin(start, gamma_bound(8) * abs_components(start), n, dir);
      if (scene->occluded(o, dir, kInfinity, 0.f)) ++lips;
    }
    EXPECT_EQ(cracks, 0) << scale;
    EXPECT_EQ(lips, 0) << scale;
  }
}

}  // namespace
}  // namespace penumbra::test
