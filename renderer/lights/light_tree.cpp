#include "renderer/lights/light_tree.h"

#include <algorithm>
#include <cmath>

#include "renderer/core/simd_clones.h"

namespace penumbra {
namespace {

float surface_area(const Bounds3& b) {
  const vec3 d = glm::max(b.hi - b.lo, vec3(0.f));
  return 2.f * (d.x * d.y + d.y * d.z + d.z * d.x);
}

// The solid-angle measure of the directions a node's lights emit into (pbrt-v4's M_omega: the
// normals' cone widened by the emission spread theta_e), times its power, its box's area and
// the box's elongation across the split axis: the cost of a child in the surface area
// orientation heuristic (Conty Estevez and Kulla 2018, section 4.4).
float split_cost(const LightBounds& b, const Bounds3& parent, int axis) {
  const float theta_o = safe_acos(b.normals.cos_theta), theta_e = safe_acos(b.cos_theta_e);
  const float theta_w = std::min(theta_o + theta_e, kPi);
  const float sin_o = std::sin(theta_o);
  const float m_omega = 2.f * kPi * (1.f - std::cos(theta_o)) +
                        0.5f * kPi * (2.f * theta_w * sin_o - std::cos(theta_o - 2.f * theta_w) -
                                      2.f * theta_o * sin_o + std::cos(theta_o));
  const vec3 d = parent.hi - parent.lo;
  const float longest = std::max(d.x, std::max(d.y, d.z));
  const float kr = d[axis] > 0.f ? longest / d[axis] : 1.f;
  return b.phi * m_omega * kr * surface_area(b.bounds);
}

constexpr int kBuckets = 12;
constexpr int kMaxCostDepth = 40;  // deeper, the binary tree splits by count

int bucket_of(const LightBounds& b, int axis, float lo, float hi) {
  const float c = 0.5f * (b.bounds.lo[axis] + b.bounds.hi[axis]);
  const float f = float(kBuckets) * (c - lo) / (hi - lo);
  // (Compared before the conversion: a NaN or overflow, from coordinates near the float range,
  // must not reach int().)
  return f > 0.f ? (f < float(kBuckets) ? int(f) : kBuckets - 1) : 0;
}

}  // namespace

LightTreeNode::LightTreeNode() {
  for (int k = 0; k < kWide; ++k) {
    cx[k] = cy[k] = cz[k] = 0.f;
    radius[k] = radius2[k] = 0.f;
    inv_d2_floor[k] = kInfinity;
    ax[k] = ay[k] = 0.f;
    az[k] = 1.f;
    cos_o[k] = -1.f;
    sin_o[k] = cos_e[k] = phi[k] = 0.f;
    two_sided[k] = 0.f;
    all_directions[k] = 1.f;
    one_way[k] = behind_at[k] = 0.f;
    child[k] = -1;
  }
}

void LightTreeNode::set(int k, const LightBounds& b, int32_t child_or_light) {
  const vec3 centre = 0.5f * (b.bounds.lo + b.bounds.hi), diagonal = b.bounds.hi - b.bounds.lo;
  cx[k] = centre.x, cy[k] = centre.y, cz[k] = centre.z;
  radius2[k] = 0.25f * glm::dot(diagonal, diagonal);
  radius[k] = std::sqrt(radius2[k]);
  // (pbrt-v4 keeps d^2 from below at half the diagonal's length; a point light's 0 -> inf.)
  inv_d2_floor[k] = 1.f / (0.5f * glm::length(diagonal));
  ax[k] = b.normals.axis.x, ay[k] = b.normals.axis.y, az[k] = b.normals.axis.z;
  cos_o[k] = b.normals.cos_theta;
  sin_o[k] = safe_sqrt(1.f - cos_o[k] * cos_o[k]);
  cos_e[k] = b.cos_theta_e;
  phi[k] = b.phi > 0.f && std::isfinite(b.phi) ? b.phi : 0.f;
  two_sided[k] = b.two_sided ? 1.f : 0.f;
  all_directions[k] = b.normals.cos_theta <= -1.f ? 1.f : 0.f;
  one_way[k] = b.normals.cos_theta >= 1.f && !b.two_sided ? 1.f : 0.f;  // (two-sided: light leaves both ways)
  const float reach =
      0.5f * (std::fabs(ax[k]) * diagonal.x + std::fabs(ay[k]) * diagonal.y + std::fabs(az[k]) * diagonal.z);
  const float size = 1.f + std::max(std::fabs(centre.x), std::max(std::fabs(centre.y), std::fabs(centre.z))) +
                     std::max(diagonal.x, std::max(diagonal.y, diagonal.z));
  behind_at[k] = 1e-5f * size - reach;
  child[k] = child_or_light;
}

namespace {

// The importance of slot k of node n at point (px, py, pz) with normal (nx, ny, nz) (0: none):
// light_tree_importance's arithmetic, inlined into it and into the walk's kernels, whether their
// SIMD lanes run across a node's slots or across points (the same operations in the same order:
// the same bits).
[[gnu::always_inline]] inline float slot_importance(const LightTreeNode& n, int k, float px, float py,
                                                    float pz, float nx, float ny, float nz,
                                                    float no_normal) {
  // (Every field read here, unconditionally: a load under a condition becomes a masked load,
  // which keeps GCC from running the lanes across points and, across slots, left stale lanes
  // that cost FP assists, core/flush_denormals.h.)
  const float one_way = n.one_way[k], behind_at = n.behind_at[k], cos_e = n.cos_e[k];
  const float all_directions = n.all_directions[k], radius = n.radius[k];
  const float vx = px - n.cx[k], vy = py - n.cy[k], vz = pz - n.cz[k];
  const float dist2 = vx * vx + vy * vy + vz * vz;
  // 1 / d^2 with d^2 kept from below (1 / max(a, b) = min(1 / a, 1 / b)).
  const float inv_dist2 = 1.f / dist2;
  const float inv_d2 = std::min(inv_dist2, n.inv_d2_floor[k]);
  // The angles as (cos, sin) x d, so that one division serves them all: the axis's angle w
  // to the direction to p (cw, sw), the bounding sphere's half angle b (cb, sin b x d = radius).
  const float dot = n.ax[k] * vx + n.ay[k] * vy + n.az[k] * vz;
  const float cw = n.two_sided[k] != 0.f ? std::fabs(dot) : dot;
  const float sw = std::sqrt(std::max(0.f, dist2 - cw * cw));
  const float cb = std::sqrt(std::max(0.f, dist2 - n.radius2[k]));
  // w less the cone's angle o (cos(w - o), sin(w - o)) x d; w within o where sin(w - o) < 0
  // (both angles in [0, pi]). Then less b: cos(x - b) x d^2, clamped to 1 where x < b, as
  // pbrt-v4's cosSubClamped and sinSubClamped.
  const float cx = cw * n.cos_o[k] + sw * n.sin_o[k];
  const float sx = sw * n.cos_o[k] - cw * n.sin_o[k];
  // Inside the bounding sphere, or with normals every way, every direction reaches p.
  const bool inside = dist2 <= n.radius2[k];
  const bool full = sx < 0.f || cx > cb || inside || all_directions != 0.f;
  const float cos_p_open = (cx * cb + sx * radius) * inv_dist2;
  const float cos_p = full ? 1.f : cos_p_open;
  // The receiver: |cos| between its normal and the direction to the centre, less the sphere's
  // angle (1 inside it or without a normal).
  const float ci = std::fabs(nx * vx + ny * vy + nz * vz);
  const float si = std::sqrt(std::max(0.f, dist2 - ci * ci));
  const bool full_i = ci > cb || inside;
  const float cos_ip_open = (ci * cb + si * radius) * inv_dist2;
  const float cos_ip = std::max(full_i ? 1.f : cos_ip_open, no_normal);  // (no_normal: 1 or 0)
  const float importance = n.phi[k] * cos_p * cos_ip * inv_d2;
  // Behind or in the plane of every emitter of one direction (a Lambertian panel's own
  // points receive nothing from it either).
  const bool behind = one_way != 0.f && dot <= behind_at;
  return (!behind && cos_p > cos_e && importance > 0.f && importance < kInfinity) ? importance : 0.f;
}

// 1 for a zero normal (a point in free space), else 0 (a normal is unit or 0).
[[gnu::always_inline]] inline float no_normal(const vec3& n) {
  return n.x * n.x + n.y * n.y + n.z * n.z > 0.f ? 0.f : 1.f;
}

// Every slot's importance at one point.
[[gnu::always_inline]] inline void node_importance(const LightTreeNode& n, const vec3& p,
                                                   const vec3& normal, float* __restrict out) {
  const float none = no_normal(normal);
  for (int k = 0; k < LightTreeNode::kWide; ++k)
    out[k] = slot_importance(n, k, p.x, p.y, p.z, normal.x, normal.y, normal.z, none);
}

}  // namespace

PENUMBRA_SIMD_CLONES
void light_tree_importance(const LightTreeNode& n, const vec3& p, const vec3& normal,
                           float* __restrict out) {
  node_importance(n, p, normal, out);
}

float light_importance(const LightBounds& b, const vec3& p, const vec3& n) {
  LightTreeNode node;
  node.set(0, b, -1);
  float out[LightTreeNode::kWide];
  light_tree_importance(node, p, n, out);
  return out[0];
}

LightTree::LightTree(const std::vector<LightBounds>& lights, const std::vector<int>& ids) {
  std::vector<std::pair<LightBounds, int>> kept;
  int max_id = -1;
  for (size_t k = 0; k < lights.size() && k < ids.size(); ++k)
    if (ids[k] >= 0 && lights[k].phi > 0.f && std::isfinite(lights[k].phi) && !lights[k].bounds.empty() &&
        std::isfinite(glm::length(lights[k].bounds.hi - lights[k].bounds.lo)) &&
        std::isfinite(glm::length(lights[k].bounds.hi + lights[k].bounds.lo))) {
      kept.emplace_back(lights[k], ids[k]);
      max_id = std::max(max_id, ids[k]);
    }
  if (kept.empty()) return;
  light_count_ = kept.size();
  slot_of_.assign(size_t(max_id) + 1, {-1, -1});
  std::vector<Binary> binary;
  binary.reserve(2 * kept.size() - 1);
  build_binary(binary, kept, 0, kept.size(), 0);
  collapse(binary, 0, -1, -1);
}

int LightTree::build_binary(std::vector<Binary>& out, std::vector<std::pair<LightBounds, int>>& lights,
                            size_t begin, size_t end, int depth) {
  const int index = int(out.size());
  out.emplace_back();
  if (end - begin == 1) {
    out[size_t(index)].bounds = lights[begin].first;
    out[size_t(index)].light = lights[begin].second;
    return index;
  }
  LightBounds all;
  Bounds3 centres;
  for (size_t k = begin; k < end; ++k) {
    all = LightBounds::merge(all, lights[k].first);
    centres.extend(0.5f * (lights[k].first.bounds.lo + lights[k].first.bounds.hi));
  }
  // The cheapest of kBuckets - 1 planes on each axis by the orientation heuristic; half by
  // count where no plane separates the centres or the tree grows deep.
  float best = kInfinity;
  int best_axis = -1, best_plane = 0;
  for (int axis = 0; axis < 3 && depth < kMaxCostDepth; ++axis) {
    const float lo = centres.lo[axis], hi = centres.hi[axis];
    if (!(hi > lo) || !std::isfinite(hi - lo)) continue;
    LightBounds bucket[kBuckets];
    for (size_t k = begin; k < end; ++k) {
      LightBounds& b = bucket[bucket_of(lights[k].first, axis, lo, hi)];
      b = LightBounds::merge(b, lights[k].first);
    }
    for (int plane = 0; plane + 1 < kBuckets; ++plane) {
      LightBounds below, above;
      for (int i = 0; i <= plane; ++i) below = LightBounds::merge(below, bucket[i]);
      for (int i = plane + 1; i < kBuckets; ++i) above = LightBounds::merge(above, bucket[i]);
      if (!(below.phi > 0.f) || !(above.phi > 0.f)) continue;
      const float cost = split_cost(below, all.bounds, axis) + split_cost(above, all.bounds, axis);
      if (cost < best) best = cost, best_axis = axis, best_plane = plane;
    }
  }
  size_t mid = begin + (end - begin) / 2;
  bool split = false;
  if (best_axis >= 0) {
    const int axis = best_axis;
    const float lo = centres.lo[axis], hi = centres.hi[axis];
    const auto it = std::partition(lights.begin() + std::ptrdiff_t(begin), lights.begin() + std::ptrdiff_t(end),
                                   [&](const std::pair<LightBounds, int>& l) {
                                     return bucket_of(l.first, axis, lo, hi) <= best_plane;
                                   });
    const size_t at = size_t(it - lights.begin());
    if (at > begin && at < end) mid = at, split = true;
  }
  if (!split) {
    // By count along the centres' longest axis, so the halves are at least ordered in space.
    const vec3 d = centres.hi - centres.lo;
    const int axis = d.x >= d.y && d.x >= d.z ? 0 : (d.y >= d.z ? 1 : 2);
    std::nth_element(lights.begin() + std::ptrdiff_t(begin), lights.begin() + std::ptrdiff_t(mid),
                     lights.begin() + std::ptrdiff_t(end), [axis](const auto& a, const auto& b) {
                       return a.first.bounds.lo[axis] + a.first.bounds.hi[axis] <
                              b.first.bounds.lo[axis] + b.first.bounds.hi[axis];
                     });
  }
  build_binary(out, lights, begin, mid, depth + 1);
  const int second = build_binary(out, lights, mid, end, depth + 1);
  out[size_t(index)].bounds = all;
  out[size_t(index)].second = second;
  return index;
}

int LightTree::collapse(const std::vector<Binary>& binary, int root, int parent, int parent_slot) {
  // The node's children: the binary subtree's top, opened up (the brightest interior entry
  // first) until there are kWide entries or only leaves.
  std::vector<int> entries = {root};
  if (binary[size_t(root)].light < 0) {
    entries.clear();
    entries.push_back(root + 1);
    entries.push_back(binary[size_t(root)].second);
  }
  while (entries.size() < size_t(LightTreeNode::kWide)) {
    int open = -1;
    for (size_t e = 0; e < entries.size(); ++e) {
      const Binary& b = binary[size_t(entries[e])];
      if (b.light < 0 && (open < 0 || b.bounds.phi > binary[size_t(entries[size_t(open)])].bounds.phi))
        open = int(e);
    }
    if (open < 0) break;
    const int at = entries[size_t(open)];
    entries[size_t(open)] = at + 1;
    entries.insert(entries.begin() + open + 1, binary[size_t(at)].second);
  }
  const int index = int(nodes_.size());
  nodes_.emplace_back();
  nodes_[size_t(index)].parent = parent;
  nodes_[size_t(index)].parent_slot = parent_slot;
  for (size_t e = 0; e < entries.size(); ++e) {
    const Binary& b = binary[size_t(entries[e])];
    int32_t child;
    if (b.light >= 0) {
      child = -1 - b.light;
      slot_of_[size_t(b.light)] = {index, int32_t(e)};
    } else {
      child = collapse(binary, entries[e], index, int(e));
    }
    nodes_[size_t(index)].set(int(e), b.bounds, child);  // (nodes_ may have grown: index again)
  }
  return index;
}

namespace {

// choose_many walks up to this many points at once (its buffers are on the stack).
constexpr size_t kWalkChunk = 256;

// One level of a point's walk, given its node's importances in[slot x stride]: the slot *u
// selects, the interval [cum[slot - 1], cum[slot]) of the prefix sums that holds *u x total,
// found by counting the intervals that end at or below it (a slot of importance 0 has an empty
// interval and is never the one; rounding past the last interval falls to the last nonempty
// one). *u becomes its place within that interval and *pmf is multiplied by the slot's
// probability. Returns the slot, -1 where nothing reaches the point (*u and *pmf then as they
// were). Branch-free, so that a loop over the points runs in SIMD lanes: which slot it is is
// random, and a branch on it would be mispredicted half the time.
[[gnu::always_inline]] inline int walk_step(const float* __restrict in, size_t stride, float* __restrict u,
                                            float* __restrict pmf) {
  constexpr int kWide = LightTreeNode::kWide;
  float imp[kWide], cum[kWide];
  float total = 0.f;
  for (int s = 0; s < kWide; ++s) {
    imp[s] = in[size_t(s) * stride];
    cum[s] = total += imp[s];
  }
  const float target = *u * total;
  int count = 0, last = 0;
  for (int s = 0; s < kWide; ++s) {
    count += int(cum[s] <= target);
    last = imp[s] > 0.f ? s : last;
  }
  const int slot = count < kWide ? count : last;
  float below = 0.f, chosen = imp[0];
  for (int s = 1; s < kWide; ++s) {
    below = s == slot ? cum[s - 1] : below;
    chosen = s == slot ? imp[s] : chosen;
  }
  const bool found = total > 0.f;
  const float next_u = std::clamp((target - below) / chosen, 0.f, kOneMinusEpsilon);
  const float next_pmf = *pmf * (chosen / total);
  *u = found ? next_u : *u;
  *pmf = found ? next_pmf : *pmf;
  return found ? slot : -1;
}

// The moves of a level's a walking points (place j: point index[j] at node at[j], its u and
// probability u[j], prob[j]) to the slots chosen (slots[j]): a point that reaches a light or
// finds nothing stops (light and pmf by its index); the others, at their child, are packed to
// the front in order. Returns how many go on.
[[gnu::always_inline]] inline size_t walk_moves(const LightTreeNode* nodes, size_t a, int32_t* __restrict at,
                                                int32_t* __restrict index, float* __restrict u,
                                                float* __restrict prob, const int32_t* __restrict slots,
                                                float* __restrict pmf, int* __restrict light) {
  size_t walking = 0;
  for (size_t j = 0; j < a; ++j) {
    const int slot = slots[j];
    const size_t k = size_t(index[j]);
    const int32_t child = slot >= 0 ? nodes[size_t(at[j])].child[slot] : 0;
    if (slot < 0) {
      light[k] = -1;
      pmf[k] = 0.f;
    } else if (child < 0) {
      light[k] = -1 - child;
      pmf[k] = prob[j];
    } else {
      at[walking] = child, index[walking] = int32_t(k), u[walking] = u[j], prob[walking] = prob[j];
      ++walking;
    }
  }
  return walking;
}

// A level of the walks of the a points still walking (LightTree::choose_many; packed as
// walk_moves leaves them): each takes its step. Returns how many go on. In three passes: the
// importances of every point's node (in this function's SIMD width, across the node's slots)
// into `scratch` (a x kWide floats); every point's choice of a slot (in SIMD lanes across the
// points) into `slots`; then the moves to the chosen children. Each pass's work per point is a
// short chain independent of the other points', which the core overlaps (one pass per point
// was a chain of all, mostly waiting).
PENUMBRA_SIMD_CLONES
size_t light_tree_walk_level(const LightTreeNode* nodes, size_t a, int32_t* __restrict at,
                             int32_t* __restrict index, const vec3* p, const vec3* normal,
                             float* __restrict u, float* __restrict prob, float* __restrict pmf,
                             int* __restrict light, float* __restrict scratch, int32_t* __restrict slots) {
  for (size_t j = 0; j < a; ++j)
    node_importance(nodes[size_t(at[j])], p[index[j]], normal[index[j]], scratch + j * LightTreeNode::kWide);
  for (size_t j = 0; j < a; ++j) slots[j] = walk_step(scratch + j * LightTreeNode::kWide, 1, &u[j], &prob[j]);
  return walk_moves(nodes, a, at, index, u, prob, slots, pmf, light);
}

// The first level, where all m points are at the root (at[k] = 0, index[k] = k): the
// importances in SIMD lanes across the points, slot by slot (the root's fields the same in
// every lane), into `scratch` by slot (slot x m + k); then the choices and moves as
// light_tree_walk_level's.
PENUMBRA_SIMD_CLONES
size_t light_tree_walk_root(const LightTreeNode* nodes, size_t m, int32_t* __restrict at,
                            int32_t* __restrict index, const vec3* p, const vec3* normal,
                            float* __restrict u, float* __restrict prob, float* __restrict pmf,
                            int* __restrict light, float* __restrict scratch, int32_t* __restrict slots) {
  const LightTreeNode& root = nodes[0];
  // The points by coordinate (GCC does not vectorise the vec3s' stride-3 loads).
  constexpr size_t kMax = kWalkChunk;  // m's bound (choose_many's chunks)
  float px[kMax], py[kMax], pz[kMax], nx[kMax], ny[kMax], nz[kMax];
  float none[kMax];
  for (size_t k = 0; k < m; ++k) {
    px[k] = p[k].x, py[k] = p[k].y, pz[k] = p[k].z;
    nx[k] = normal[k].x, ny[k] = normal[k].y, nz[k] = normal[k].z;
    none[k] = no_normal(normal[k]);
  }
  for (int s = 0; s < LightTreeNode::kWide; ++s) {
    float* __restrict out = scratch + size_t(s) * m;
    for (size_t k = 0; k < m; ++k)
      out[k] = slot_importance(root, s, px[k], py[k], pz[k], nx[k], ny[k], nz[k], none[k]);
  }
  for (size_t k = 0; k < m; ++k) slots[k] = walk_step(scratch + k, m, &u[k], &prob[k]);
  return walk_moves(nodes, m, at, index, u, prob, slots, pmf, light);
}

}  // namespace

int LightTree::choose(const vec3& p, const vec3& normal, float u, float* pmf) const {
  int light;
  choose_many(1, &p, &normal, &u, &light, pmf);
  return light;
}

void LightTree::choose_many(size_t n, const vec3* p, const vec3* normal, const float* u, int* light,
                            float* pmf) const {
  if (nodes_.empty()) {
    for (size_t k = 0; k < n; ++k) light[k] = -1, pmf[k] = 0.f;
    return;
  }
  // The walking points packed to the front: each one's node, index, u and probability.
  constexpr size_t kChunk = kWalkChunk;
  float walk_u[kChunk], walk_prob[kChunk];
  int32_t at[kChunk], index[kChunk];
  alignas(32) float scratch[kChunk * LightTreeNode::kWide];
  int32_t slots[kChunk];
  for (size_t base = 0; base < n; base += kChunk) {
    const size_t m = std::min(kChunk, n - base);
    for (size_t k = 0; k < m; ++k) {
      walk_u[k] = u[base + k];
      walk_prob[k] = 1.f;
      at[k] = 0;
      index[k] = int32_t(k);
    }
    size_t walking = light_tree_walk_root(nodes_.data(), m, at, index, p + base, normal + base, walk_u,
                                          walk_prob, pmf + base, light + base, scratch, slots);
    while (walking > 0)
      walking = light_tree_walk_level(nodes_.data(), walking, at, index, p + base, normal + base, walk_u,
                                      walk_prob, pmf + base, light + base, scratch, slots);
  }
}

float LightTree::pmf(const vec3& p, const vec3& normal, int id) const {
  if (id < 0 || size_t(id) >= slot_of_.size() || slot_of_[size_t(id)].first < 0) return 0.f;
  // The path from the root to the light's slot, then its probabilities in choose()'s order.
  std::pair<int32_t, int32_t> path[64];
  int depth = 0;
  for (std::pair<int32_t, int32_t> at = slot_of_[size_t(id)]; at.first >= 0 && depth < 64;) {
    path[depth++] = at;
    const LightTreeNode& n = nodes_[size_t(at.first)];
    at = {n.parent, n.parent_slot};
  }
  float prob = 1.f;
  for (int level = depth - 1; level >= 0; --level) {
    float imp[LightTreeNode::kWide];
    light_tree_importance(nodes_[size_t(path[level].first)], p, normal, imp);
    float total = 0.f;
    for (int k = 0; k < LightTreeNode::kWide; ++k) total += imp[k];  // choose()'s order
    if (!(total > 0.f)) return 0.f;
    prob *= imp[path[level].second] / total;
  }
  return prob;
}

}  // namespace penumbra
