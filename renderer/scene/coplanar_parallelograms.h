#pragma once
// Which parallelograms get thick boxes (Parallelogram::thicken). Two parallelograms of one axis
// plane whose areas overlap (a duplicate quad, a panel flush with a wall, a box standing on a
// floor) can tie exactly, and Embree skips a flat box whose entry distance is the ray's current
// hit, in an order that differs between packets and single rays. Thick boxes trace slower (a
// Cornell box with every quad thick: +7%; a floor of 40,000 tiles under two boxes: +27%), so
// only parallelograms whose boxes overlap one of another object in their plane get one, and of
// two such only the one that wins their tie. Faces of one mesh traced as parallelograms meet only
// along shared edges, which their exact edges give to one face (shapes/parallelogram.h); a mesh
// with coincident triangles is not so traced.
#include <cstdint>
#include <vector>

#include "renderer/shapes/parallelogram.h"

namespace penumbra {

struct PlacedParallelogram {
  Parallelogram* shape;
  uint32_t object;  // the scene object it belongs to
};

// Thickens every parallelogram that lies in an axis plane together with one of a higher object
// whose box overlaps its own in that plane.
void thicken_coplanar_parallelograms(const std::vector<PlacedParallelogram>& all);

}  // namespace penumbra
