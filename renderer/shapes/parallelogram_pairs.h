#pragma once
// A mesh's triangles as parallelograms: meshes made of quads (boxes, walls, floors, a modeller's
// quads triangulated on export) are traced by the parallelogram test (shapes/parallelogram.h),
// one primitive per face pair, instead of Embree's robust test on both triangles: a Cornell box
// with its two boxes so traced takes 0.89 of the time (docs/performance.md, session 28).
//
// Triangles 2k and 2k + 1 pair when they share an edge, wind the same way around it, and their
// four corners A, B, C, D (first triangle A B C, second A C D) form a parallelogram:
// A + C = B + D, to within a quarter of the test's edge tolerance. The parallelogram is
// B + s (C - B) + t (A - B): its corners lie within rounding (A, C) or that quarter (D) of the
// triangles' own, and it decides every hit within kEdgeTolerance of an edge by the side of the
// line through the triangles' own corners the ray passes (Parallelogram::use_exact_edges). So
// faces sharing corners close as triangles do, neither leaving a crack nor overlapping. Corners
// are compared by position, so vertices split for their uvs or normals still pair.
#include <array>
#include <cstdint>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/shapes/parallelogram.h"

namespace penumbra {

// Where a hit at (s, t) of face pair k lies in its triangles: triangle 2k (A, B, C) where
// s + t <= 1, else 2k + 1 (A, C, D), with barycentric weights in each triangle's own index
// order, so uvs and normals interpolate as they would on the triangle.
struct FacePairSlots {
  // The slot (0, 1, 2) of A, B, C in the first triangle's indices and of A, C, D in the second's.
  std::array<uint8_t, 3> first, second;

  // Triangle 0 or 1 of the pair, and its barycentrics (b0, b1, b2) in index order.
  int locate(float s, float t, float b[3]) const {
    if (s + t <= 1.f) {
      b[first[0]] = t;  // A
      b[first[1]] = 1.f - s - t;  // B
      b[first[2]] = s;  // C
      return 0;
    }
    // With D = A + C - B: B + s (C - B) + t (A - B) = (1 - s) A + (1 - t) C + (s + t - 1) D.
    b[second[0]] = 1.f - s;
    b[second[1]] = 1.f - t;
    b[second[2]] = s + t - 1.f;
    return 1;
  }
};

struct FacePairs {
  std::vector<Parallelogram> shapes;  // face pair k's parallelogram
  std::vector<FacePairSlots> slots;   // and where in its triangles a hit lies
};

// Every consecutive triangle pair of the mesh as a parallelogram, or nothing if any pair is not
// one (then the mesh stays triangles: one Embree geometry per shape). Pairs also have to be
// well shaped (the sine of the angle between their edges at least 1e-3), since the test's
// (s, t) are computed through the edges' dual vectors.
FacePairs pair_into_parallelograms(const std::vector<vec3>& positions,
                                   const std::vector<uint32_t>& indices);

}  // namespace penumbra
