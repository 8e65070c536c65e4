#pragma once
// Path reuse across neighbouring pixels (Bekaert, Sbert and Halton 2002, "Accelerating path
// tracing by re-using paths"): the paths of a small group of pixels, one sample each, share
// their second vertices. Pixel k's indirect light at its first vertex x1_k is the integral over
// the points x2 it sees of f(x1_k -> x2) G(x1_k, x2) L_r(x2), where L_r is the light x2 reflects
// (its own emission stays with the path that hit it, weighted by MIS against light sampling as
// before). Every path i of the group sampled its x2_i from its own x1_i by BSDF sampling, and
// its tail from x2_i on is an estimate of L_r(x2_i); each is a sampling technique for every
// pixel of the group, and the balance heuristic over them (Veach 1997, ch. 9) gives pixel k
//     sum_i f(x1_k -> x2_i) c(k, i) V(k, i)  L_r(x2_i) / sum_m pdf_m(x2_i) c(m, i) V(m, i)
// with f including the cosine at x1, pdf_m the solid-angle pdf of x1_m's BSDF towards x2_i and
// c(m, i) = |cos| at x2_i towards x1_m / d(m, i)^2 the change to area measure at x2_i. (That
// cosine is one per pair, not a common factor: dropping it biased the pixels by a concave
// corner by +-5%.) An unbiased estimate whose indirect variance falls with the group's size,
// at the price of a shadow ray and a BSDF evaluation per pair.
//
// What keeps it unbiased (each condition a property of the point x2 or of the technique, so the
// weights of the techniques that can produce a point sum to one):
//  * L_r(x2) must not depend on the direction it is seen from. x2 qualifies only on a plain
//    Lambertian model without a normal map, and only within the class of outgoing directions
//    that share both signs against its geometric and shading normals (two-sided surfaces light
//    their two sides differently); elsewhere only the path's own technique counts x2.
//  * x1 must have no Dirac lobe (its pdf is then a density for any direction); a pixel whose x1
//    has one keeps its own path and offers nothing.
//  * A technique estimates a colour channel of L_r only where its x1's BSDF passes it (the tail's
//    estimate is its radiance divided by the throughput at x2): the denominators are per channel.
//  * Russian roulette and the depth limit must not act on x1's bounce (rr_depth >= 2,
//    max_depth > 2) and the group's paths share one instant (no motion blur).
#include <cstdint>
#include <vector>

#include "renderer/core/math.h"
#include "renderer/core/ray.h"
#include "renderer/render/path_step.h"
#include "renderer/scene/scene.h"

namespace penumbra {

// What a path records for reuse: its first two hits, the throughput arriving at the second, and
// its radiance once the second hit's emission was added (what the tail adds after that is
// throughput x L_r(x2)).
struct ReuseRecord {
  SurfaceHit x1;
  SurfaceHit x2;
  vec3 wi1{0.f};  // towards the camera from x1
  float time = 0.f;
  Spectrum beta1{0.f};
  Spectrum radiance_at_x2{0.f};
  bool has_x1 = false;
  bool has_x2 = false;
};

// Whether a render may reuse paths at all: the conditions above that are the render's, and
// some surface of the scene a plain Lambertian one without a normal map.
bool path_reuse_applies(const Scene& scene, const IntegratorSettings& settings);

// Reuses the paths of each group: `group_starts` delimits runs of `paths` (indices into
// `records` and `states`) that are one group each. Replaces each member's radiance by its
// reuse estimate. Returns the shadow rays traced.
uint64_t reuse_paths(const Scene& scene, const ReuseRecord* records, PathState* states,
                     const uint32_t* paths, const std::vector<size_t>& group_starts);

}  // namespace penumbra
