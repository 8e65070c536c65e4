// Which parallelograms get thick boxes (scene/coplanar_parallelograms.h): of two objects'
// parallelograms that overlap in one axis plane, the lower object's; nothing else.
#include <gtest/gtest.h>

#include <vector>

#include "renderer/scene/coplanar_parallelograms.h"

namespace penumbra::test {
namespace {

bool thick(const Parallelogram& q) {
  const Parallelogram flat(QuadDesc{q.origin, q.u, q.v});
  return q.bounds.lo.y < flat.bounds.lo.y && q.bounds.hi.y > flat.bounds.hi.y;
}

// A square in the plane y = `y` from (x, z) to (x + size, z + size).
Parallelogram square(float x, float z, float size, float y = 0.f) {
  return Parallelogram(QuadDesc{vec3(x, y, z), vec3(size, 0.f, 0.f), vec3(0.f, 0.f, size)});
}

TEST(CoplanarParallelograms, OnlyTheTieWinnerOfOverlappingObjectsIsThick) {
  std::vector<Parallelogram> q = {
      square(0.f, 0.f, 10.f),       // 0: a floor, object 0
      square(2.f, 2.f, 1.f),        // 1: a box bottom on it, object 3
      square(20.f, 0.f, 1.f),       // 2: object 4, in the plane but clear of everything
      square(2.f, 2.f, 1.f, 1.f),   // 3: object 5, above the floor (another plane)
      square(30.f, 0.f, 1.f),       // 4: object 6 and
      square(31.f, 0.f, 1.f),       // 5: object 6, one mesh's neighbours sharing an edge
      square(40.f, 0.f, 1.f),       // 6: object 8, a duplicate of
      square(40.f, 0.f, 1.f),       // 7: object 7
  };
  const uint32_t objects[] = {0, 3, 4, 5, 6, 6, 8, 7};
  std::vector<PlacedParallelogram> placed;
  for (size_t i = 0; i < q.size(); ++i) placed.push_back({&q[i], objects[i]});
  thicken_coplanar_parallelograms(placed);
  const bool expected[] = {true, false, false, false, false, false, false, true};
  for (size_t i = 0; i < q.size(); ++i) EXPECT_EQ(thick(q[i]), expected[i]) << i;
}

// Planes are told apart by their coordinate, -0 and +0 alike; tilted parallelograms have none.
TEST(CoplanarParallelograms, PlanesAreAxisPlanesAtOneCoordinate) {
  std::vector<Parallelogram> q = {square(0.f, 0.f, 1.f, 0.f), square(0.f, 0.f, 1.f, -0.f),
                                  square(0.f, 0.f, 1.f, 1e-7f),
                                  Parallelogram(QuadDesc{vec3(0.f), vec3(1.f, 0.1f, 0.f), vec3(0.f, 0.f, 1.f)})};
  std::vector<PlacedParallelogram> placed = {{&q[0], 1}, {&q[1], 0}, {&q[2], 2}, {&q[3], 3}};
  thicken_coplanar_parallelograms(placed);
  EXPECT_FALSE(thick(q[0]));
  EXPECT_TRUE(thick(q[1]));
  EXPECT_FALSE(thick(q[2]));
  EXPECT_FALSE(thick(q[3]));
}

}  // namespace
}  // namespace penumbra::test
