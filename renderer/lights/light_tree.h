#pragma once
// Many-light selection by where the shading point is: a bounding volume hierarchy over the
// lights that have a place in space (area, sphere, mesh and point lights), each node bounding
// its lights' positions, emitted power and the cone of directions they emit into. A light is
// chosen by walking down from the root, at each node picking a child with probability
// proportional to an upper estimate of what the child's lights can deliver to the point
// (power x a bound of the emission cosine / squared distance). Conty Estevez and Kulla 2018,
// "Importance Sampling of Many Lights with Adaptive Tree Splitting"; the node importance and the
// split cost as pbrt-v4's BVHLightSampler (section 12.6.3). The importance is conservative: it is
// zero only where none of a node's lights can send light to the point (but for points within a
// hair, 1e-5 of the scene's scale, of a panel's plane: LightTreeNode::behind_at), so choosing by
// it stays unbiased; and where an area light gets no choice, the path integrator's BSDF-sampled
// rays that reach it count with MIS weight 1.
//
// The tree is built binary by the split cost, then collapsed to nodes of up to eight children
// whose importances are computed together in SIMD lanes: a choice among 64 lights evaluates two
// nodes instead of twelve children one by one.
//
// The receiving surface's normal enters as pbrt-v4's does, |cos| of the angle to the node less
// the angle the node subtends (either side: light may arrive through a transmitting surface); a
// zero normal (a point in free space) leaves that factor out.
#include <cstdint>
#include <utility>
#include <vector>

#include "renderer/lights/light_bounds.h"

namespace penumbra {

// Up to kWide children's bounds, by field, as the importance kernel reads them; an unused slot
// has phi 0 (importance 0, never chosen).
struct alignas(32) LightTreeNode {
  static constexpr int kWide = 8;
  float cx[kWide], cy[kWide], cz[kWide];
  float radius[kWide], radius2[kWide];  // the child's box's bounding sphere
  float inv_d2_floor[kWide];            // 1 / half its diagonal's length
  float ax[kWide], ay[kWide], az[kWide];  // its normals' axis
  float cos_o[kWide], sin_o[kWide], cos_e[kWide];
  float phi[kWide];
  float two_sided[kWide], all_directions[kWide];  // 1 or 0
  // Normals all one way (cos_o = 1: panels) and one-sided: 1, and where along the axis from the
  // centre a point is behind or in every emitter's plane: at or below -(sum |axis_i| x half
  // extent_i), plus a slack of 1e-5 of the box's size and distance from the origin (hit points
  // on a panel itself lie in its plane only to their rounding). Such points are out of reach
  // even inside the bounding sphere. (Gaps that thin are below any renderer's ray offset,
  // Mitsuba's is 1e-4.)
  float one_way[kWide], behind_at[kWide];
  int32_t child[kWide];  // >= 0: a node; < 0: the light -1 - child
  int32_t parent = -1, parent_slot = -1;

  LightTreeNode();
  void set(int slot, const LightBounds& b, int32_t child_or_light);
};

// Each slot's importance at p, on a surface of normal n: phi x cos(theta') x cos(theta_i') /
// d^2, where theta' is the smallest angle any of the slot's emission directions can make with
// the direction to p (importance 0 when no emission direction reaches p), theta_i' the smallest
// angle between n (either side) and a direction into the slot's bounding sphere (0 also where
// all of a slot's normals point one way and p lies behind or in every one of its planes), and d^2 the
// squared distance to the box centre, kept from below at half the box's diagonal (pbrt-v4's
// LightBounds::Importance). n = 0: no theta_i' factor. Finite, >= 0. Every SIMD clone gives the
// same bits (no contraction).
void light_tree_importance(const LightTreeNode& node, const vec3& p, const vec3& n, float* out);

// One light's importance at p, n (light_tree_importance with it alone in a node): for tests.
float light_importance(const LightBounds& b, const vec3& p, const vec3& n = vec3(0.f));

class LightTree {
 public:
  LightTree() = default;
  // Over `lights`: lights[k] bounds light ids[k] (the scene's light index, >= 0). Lights with
  // phi <= 0, empty bounds or bounds near the end of the float range (whose centre or size is
  // not finite) are left out (never chosen, pmf 0).
  LightTree(const std::vector<LightBounds>& lights, const std::vector<int>& ids);

  bool empty() const { return nodes_.empty(); }
  // Number of lights in the tree.
  size_t size() const { return light_count_; }

  // The light chosen for point p with surface normal n (0 for none) by u in [0, 1): its id, its
  // probability in *pmf; -1 (and *pmf 0) when no light in the tree can reach p.
  int choose(const vec3& p, const vec3& n, float u, float* pmf) const;
  // choose() for count points at once (light[k], pmf[k] for p[k], n[k], u[k]): the same choices
  // and bits. The tree is walked a level at a time over all of them, so the walks, each a
  // chain of dependent arithmetic, overlap.
  void choose_many(size_t count, const vec3* p, const vec3* n, const float* u, int* light, float* pmf) const;
  // Probability that choose(p, n, u) returns light `id` for u uniform in [0, 1) (0 for a light
  // that is not in the tree or cannot reach p); the same bits choose() reports.
  float pmf(const vec3& p, const vec3& n, int id) const;

 private:
  struct Binary {
    LightBounds bounds;
    int32_t second = -1;  // interior: the second child (the first follows the node)
    int32_t light = -1;   // leaf: the light id
  };
  static int build_binary(std::vector<Binary>& out, std::vector<std::pair<LightBounds, int>>& lights,
                          size_t begin, size_t end, int depth);
  int collapse(const std::vector<Binary>& binary, int root, int parent, int parent_slot);

  std::vector<LightTreeNode> nodes_;
  std::vector<std::pair<int32_t, int32_t>> slot_of_;  // per light id: (node, slot), node -1 if absent
  size_t light_count_ = 0;
};

}  // namespace penumbra
