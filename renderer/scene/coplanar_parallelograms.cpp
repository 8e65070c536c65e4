#include "renderer/scene/coplanar_parallelograms.h"

#include <algorithm>
#include <bit>
#include <map>
#include <utility>

namespace penumbra {
namespace {

// Marks, of every two parallelograms of a plane from different objects whose boxes overlap in
// the plane's two axes (a, b), the one of the lower object: the one that wins their tie
// (embree/ray_access.h, tie_wins; an object's Embree geometry id is its index). Only the winner
// must not be skipped: a skipped loser would lose anyway. A sweep along a, comparing each box
// with those still open there.
void mark_overlaps(std::vector<PlacedParallelogram>& plane, int a, int b, std::vector<bool>* mark) {
  std::vector<size_t> order(plane.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t x, size_t y) {
    return plane[x].shape->bounds.lo[a] < plane[y].shape->bounds.lo[a];
  });
  std::vector<size_t> open;
  for (size_t i : order) {
    const Bounds3& box = plane[i].shape->bounds;
    std::erase_if(open, [&](size_t j) { return plane[j].shape->bounds.hi[a] < box.lo[a]; });
    for (size_t j : open) {
      const Bounds3& other = plane[j].shape->bounds;
      if (plane[j].object != plane[i].object && other.lo[b] <= box.hi[b] && box.lo[b] <= other.hi[b])
        (*mark)[plane[j].object < plane[i].object ? j : i] = true;
    }
    open.push_back(i);
  }
}

}  // namespace

void thicken_coplanar_parallelograms(const std::vector<PlacedParallelogram>& all) {
  std::map<std::pair<int, uint32_t>, std::vector<PlacedParallelogram>> planes;
  for (const PlacedParallelogram& p : all)
    if (const int k = p.shape->flat_axis(); k >= 0)
      planes[{k, std::bit_cast<uint32_t>(p.shape->origin[k] + 0.f)}].push_back(p);
  for (auto& [plane, members] : planes) {
    if (members.size() < 2) continue;
    std::vector<bool> mark(members.size(), false);
    mark_overlaps(members, (plane.first + 1) % 3, (plane.first + 2) % 3, &mark);
    for (size_t i = 0; i < members.size(); ++i)
      if (mark[i]) members[i].shape->thicken();
  }
}

}  // namespace penumbra
