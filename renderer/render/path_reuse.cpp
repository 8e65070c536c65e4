#include "renderer/render/path_reuse.h"

#include <array>
#include <cmath>
#include <optional>
#include <variant>

#include "renderer/core/simd_clones.h"
#include "renderer/materials/diffuse.h"
#include "renderer/scene/scene_input.h"

namespace penumbra {
namespace {

// The largest group reuse_paths takes at once (the largest block of pixels); larger runs are
// split.
constexpr size_t kMaxGroup = size_t(RenderSettings::kMaxPathReuse * RenderSettings::kMaxPathReuse);

// A member's first vertex as a sampling technique: its BSDF and frame as path_scatter built
// them, and whether it offers its second vertex. A plain Lambertian first vertex (the common
// case) is evaluated inline from its colour and normals instead of through SurfaceBsdf.
struct Member {
  bool in_s = false;
  bool offers = false;
  bool lambertian = false;
  Spectrum color{0.f};
  vec3 facing{0.f};     // the shading normal on the camera's side (lambertian)
  float ng_side = 0.f;  // the sign of the camera's side against the geometric normal (lambertian)
  vec3 origin{0.f};     // where its shadow rays start, off x1 on the camera's side (lambertian)
  std::optional<SurfaceBsdf> textured;
  const SurfaceBsdf* bsdf = nullptr;
  Frame frame;
  vec3 wi_local{0.f};

  // From the path's record; whether it is a technique.
  bool set(const Scene& scene, const ReuseRecord& r);
};

// Which side of x2 a direction leaving it lies on, against its geometric and its shading
// normal: L_r(x2) is the same for every direction of one class of a Lambertian surface. (The
// geometric side is also what the shadow ray decides, its end being offset to the sample's side:
// a first vertex on the other side of a thin surface sees it blocked. The shading side is what
// only the class tells, where interpolated normals lean.)
int direction_class(const SurfaceHit& x2, const vec3& w) {
  return (glm::dot(w, x2.ng) > 0.f ? 1 : 0) | (glm::dot(w, x2.ns) > 0.f ? 2 : 0);
}

// Whether a surface's points can be shared: a plain Lambertian model without a normal map.
bool shares_points(const Material& material) {
  return !material.normal_mapped() &&
         std::holds_alternative<DiffuseBsdf>(material.bsdf().model());
}

bool lambertian_without_normal_map(const Scene& scene, const SurfaceHit& hit) {
  return shares_points(scene.material(scene.object(hit.object).material));
}

bool Member::set(const Scene& scene, const ReuseRecord& r) {
  in_s = offers = lambertian = false;
  if (!r.has_x1) return false;
  SurfaceHit hit = r.x1;
  const Material& material = scene.material(scene.object(hit.object).material);
  textured.reset();
  bsdf = &material.bsdf();
  if (material.varies())
    bsdf = &textured.emplace(material.bsdf_at(TextureQuery{hit.p, hit.uv, r.time}));
  if (bsdf->lobes() & kLobeDelta) return false;
  frame = material.normal_mapped() ? path_step_detail::tangent_frame(scene, r.time, &hit)
                                   : Frame(hit.ns);
  wi_local = frame.to_local(r.wi1);
  in_s = true;
  offers = r.has_x2 && lambertian_without_normal_map(scene, r.x2);
  if (const auto* diffuse = std::get_if<DiffuseBsdf>(&bsdf->model());
      diffuse && !bsdf->normal_mapped() && bsdf->two_sided()) {
    // The camera's side against each normal, as SurfaceBsdf mirrors wi (wi.z < 0) and as
    // geometry_agrees compares the two; where wi lies in either plane no direction has a value
    // (nor had the path's own sample).
    const float cos_i = glm::dot(r.wi1, hit.ns), geo_i = glm::dot(r.wi1, hit.ng);
    lambertian = true;
    color = diffuse->albedo();
    facing = cos_i > 0.f ? hit.ns : cos_i < 0.f ? -hit.ns : vec3(0.f);
    ng_side = geo_i > 0.f ? 1.f : geo_i < 0.f ? -1.f : 0.f;
    origin = offset_ray_origin(hit.p, hit.p_error, hit.ng, r.wi1);
  }
  return true;
}

// One pair (technique m, sample i): the BSDF of x1_m towards x2_i (f cos) over d^2, its pdf
// over d^2, and whether x2_i is what x1_m sees in that direction.
struct Pair {
  Spectrum f_over_d2{0.f};
  float pdf_over_d2 = 0.f;
  bool visible = false;
};


// The Lambertian members of a group in lanes (structure of arrays), for one shared vertex at a
// time; and the pending shadow rays' directions. Lanes past a group's size hold zeros.
struct LambertLanes {
  alignas(64) float px[kMaxGroup], py[kMaxGroup], pz[kMaxGroup];  // x1
  alignas(64) float fx[kMaxGroup], fy[kMaxGroup], fz[kMaxGroup];  // facing shading normal
  alignas(64) float gx[kMaxGroup], gy[kMaxGroup], gz[kMaxGroup];  // geometric normal x side
};

// Per member m: pdf of x1_m's Lambertian lobe towards x2 in area measure at x2 (0 where the
// pair has no value: the geometry test, the cosine, or another class of directions at x2 than
// `own`'s). The arithmetic of the scalar terms it replaces, per lane.
PENUMBRA_SIMD_CLONES
void lambert_pair_kernel(const LambertLanes& l, float x, float y, float z, float ngx, float ngy,
                         float ngz, float nsx, float nsy, float nsz, int own_class, size_t own,
                         float* __restrict pdf_area) {
  for (size_t m = 0; m < kMaxGroup; ++m) {
    const float dx = x - l.px[m], dy = y - l.py[m], dz = z - l.pz[m];
    const float d2 = (dx * dx + dy * dy) + dz * dz;
    const float inv = 1.f / std::sqrt(d2);
    const float wx = dx * inv, wy = dy * inv, wz = dz * inv;
    const float back_g = -((wx * ngx + wy * ngy) + wz * ngz);
    const float back_s = -((wx * nsx + wy * nsy) + wz * nsz);
    const int cls = (back_g > 0.f ? 1 : 0) | (back_s > 0.f ? 2 : 0);
    const float cos_o = (wx * l.fx[m] + wy * l.fy[m]) + wz * l.fz[m];
    const float geo = (wx * l.gx[m] + wy * l.gy[m]) + wz * l.gz[m];
    const bool ok = d2 > 0.f && cos_o > 0.f && geo > 0.f && (m == own || cls == own_class);
    pdf_area[m] = ok ? cos_o * kInvPi * (std::abs(back_g) / d2) : 0.f;
  }
}

// Unit directions from the origins to the targets, and the shadow rays' lengths.
PENUMBRA_SIMD_CLONES
void shadow_dirs_kernel(size_t n, const float* __restrict ox, const float* __restrict oy,
                        const float* __restrict oz, const float* __restrict tx,
                        const float* __restrict ty, const float* __restrict tz,
                        float* __restrict dx, float* __restrict dy, float* __restrict dz,
                        float* __restrict t_max) {
  for (size_t q = 0; q < n; ++q) {
    const float x = tx[q] - ox[q], y = ty[q] - oy[q], z = tz[q] - oz[q];
    const float dist = std::sqrt((x * x + y * y) + z * z);
    const float inv = dist > 0.f ? 1.f / dist : 0.f;
    dx[q] = x * inv;
    dy[q] = y * inv;
    dz[q] = z * inv;
    t_max[q] = dist * (1.f - kShadowEpsilon);
  }
}

}  // namespace

bool path_reuse_applies(const Scene& scene, const IntegratorSettings& settings) {
  if (scene.features().motion || settings.rr_depth < 2 ||
      (settings.max_depth >= 0 && settings.max_depth <= 2))
    return false;
  // Some surface must be able to share its points (a scene of glossy, glass and normal-mapped
  // surfaces would pay for the records and the grouping and share nothing).
  for (uint32_t o = 0; o < scene.object_count(); ++o)
    if (shares_points(scene.material(scene.object(o).material))) return true;
  return false;
}

uint64_t reuse_paths(const Scene& scene, const ReuseRecord* records, PathState* states,
                     const uint32_t* paths, const std::vector<size_t>& group_starts) {
  using path_step_detail::geometry_agrees;
  uint64_t rays = 0;
  std::array<Member, kMaxGroup> mem;
  std::array<Pair, kMaxGroup * kMaxGroup> pairs;  // [i * n + m]
  std::array<Ray, Scene::kPacketSize> shadow_rays;
  std::array<uint16_t, kMaxGroup * kMaxGroup> pending;
  std::array<bool, Scene::kPacketSize> blocked;
  // Per offered sample: the end of its shadow rays, off x2 on the side its class looks from.
  std::array<vec3, kMaxGroup> target;
  alignas(64) float ray_lanes[10][Scene::kPacketSize];

  for (size_t g = 0; g + 1 < group_starts.size(); ++g) {
    for (size_t start = group_starts[g]; start < group_starts[g + 1]; start += kMaxGroup) {
      const size_t n = std::min(kMaxGroup, group_starts[g + 1] - start);
      const uint32_t* member = paths + start;
      if (n < 2) continue;
      // Nothing to do unless some member's second vertex can be shared.
      bool any_offer = false;
      for (size_t m = 0; m < n && !any_offer; ++m) {
        const ReuseRecord& r = records[member[m]];
        any_offer = r.has_x1 && r.has_x2 && lambertian_without_normal_map(scene, r.x2);
      }
      if (!any_offer) continue;
      size_t techniques = 0;
      for (size_t m = 0; m < n; ++m) techniques += mem[m].set(scene, records[member[m]]);
      if (techniques < 2) continue;

      // Every pair's BSDF terms; the visibility of each pair that has any, traced in packets.
      LambertLanes lanes{};
      bool any_lambert = false;
      for (size_t m = 0; m < n; ++m) {
        const Member& t = mem[m];
        if (!t.in_s || !t.lambertian) continue;
        any_lambert = true;
        const SurfaceHit& x1 = records[member[m]].x1;
        lanes.px[m] = x1.p.x;
        lanes.py[m] = x1.p.y;
        lanes.pz[m] = x1.p.z;
        lanes.fx[m] = t.facing.x;
        lanes.fy[m] = t.facing.y;
        lanes.fz[m] = t.facing.z;
        lanes.gx[m] = t.ng_side * x1.ng.x;
        lanes.gy[m] = t.ng_side * x1.ng.y;
        lanes.gz[m] = t.ng_side * x1.ng.z;
      }
      alignas(64) float lambert_pdf[kMaxGroup];
      size_t queued = 0;
      for (size_t i = 0; i < n; ++i) {
        if (!mem[i].offers) continue;
        const SurfaceHit& x2 = records[member[i]].x2;
        const vec3 back = records[member[i]].x1.p - x2.p;
        const int own_class = direction_class(x2, back);
        target[i] = offset_ray_origin(x2.p, x2.p_error, x2.ng, back);
        if (any_lambert)
          lambert_pair_kernel(lanes, x2.p.x, x2.p.y, x2.p.z, x2.ng.x, x2.ng.y, x2.ng.z, x2.ns.x,
                              x2.ns.y, x2.ns.z, own_class, i, lambert_pdf);
        for (size_t m = 0; m < n; ++m) {
          Pair& pr = pairs[i * n + m];
          pr = Pair{};
          const Member& t = mem[m];
          if (!t.in_s) continue;
          if (t.lambertian) {
            // DiffuseBsdf through SurfaceBsdf's two-sided mirror and path_scatter's geometry
            // test: f cos = colour cos / pi and pdf = cos / pi, with cos against the shading
            // normal turned to the camera's side (lambert_pair_kernel).
            if (!(lambert_pdf[m] > 0.f)) continue;
            pr.pdf_over_d2 = lambert_pdf[m];
            pr.f_over_d2 = t.color * lambert_pdf[m];
          } else {
            const ReuseRecord& rm = records[member[m]];
            const vec3 d = x2.p - rm.x1.p;
            const float d2 = glm::dot(d, d);
            if (!(d2 > 0.f)) continue;
            const vec3 w = d / std::sqrt(d2);
            if (m != i && direction_class(x2, -w) != own_class) continue;
            const vec3 wo = t.frame.to_local(w);
            if (!geometry_agrees(rm.wi1, w, rm.x1.ng, t.wi_local, wo)) continue;
            const BsdfEvalPdf e = t.bsdf->eval_pdf(BsdfContext{}, t.wi_local, wo);
            if (!(e.pdf > 0.f)) continue;
            // Area measure at x2: the cosine there is the angle towards this x1, one per pair.
            const float to_area = std::abs(glm::dot(x2.ng, w)) / d2;
            pr.f_over_d2 = e.f * to_area;
            pr.pdf_over_d2 = e.pdf * to_area;
          }
          if (m == i) pr.visible = true;
          else pending[queued++] = uint16_t(i * n + m);
        }
      }
      for (size_t k = 0; k < queued; k += Scene::kPacketSize) {
        const size_t count = std::min<size_t>(Scene::kPacketSize, queued - k);
        for (size_t q = 0; q < count; ++q) {
          const uint16_t idx = pending[k + q];
          const size_t m = idx % n, i = idx / n;
          const vec3 to = target[i];
          const SurfaceHit& x1 = records[member[m]].x1;
          const vec3 origin = mem[m].lambertian
                                  ? mem[m].origin
                                  : offset_ray_origin(x1.p, x1.p_error, x1.ng, to - x1.p);
          ray_lanes[0][q] = origin.x;
          ray_lanes[1][q] = origin.y;
          ray_lanes[2][q] = origin.z;
          ray_lanes[3][q] = to.x;
          ray_lanes[4][q] = to.y;
          ray_lanes[5][q] = to.z;
        }
        shadow_dirs_kernel(count, ray_lanes[0], ray_lanes[1], ray_lanes[2], ray_lanes[3],
                           ray_lanes[4], ray_lanes[5], ray_lanes[6], ray_lanes[7], ray_lanes[8],
                           ray_lanes[9]);
        for (size_t q = 0; q < count; ++q) {
          const size_t m = pending[k + q] % n;
          shadow_rays[q] = Ray{vec3(ray_lanes[0][q], ray_lanes[1][q], ray_lanes[2][q]),
                               vec3(ray_lanes[6][q], ray_lanes[7][q], ray_lanes[8][q]),
                               records[member[m]].time, ray_lanes[9][q]};
        }
        scene.occluded_packet(shadow_rays.data(), int(count), blocked.data());
        // (A target on its origin, t_max 0, counts as unseen.)
        for (size_t q = 0; q < count; ++q)
          pairs[pending[k + q]].visible = !blocked[q] && ray_lanes[9][q] > 0.f;
      }
      rays += queued;

      // Each offered sample's L_r estimate spread over the members by the balance heuristic.
      std::array<Spectrum, kMaxGroup> added;
      added.fill(Spectrum(0.f));
      for (size_t i = 0; i < n; ++i) {
        if (!mem[i].offers) continue;
        const ReuseRecord& ri = records[member[i]];
        const Spectrum tail = states[member[i]].radiance - ri.radiance_at_x2;
        Spectrum lr(0.f), denom(0.f);
        for (int c = 0; c < 3; ++c) lr[c] = ri.beta1[c] > 0.f ? tail[c] / ri.beta1[c] : 0.f;
        for (size_t m = 0; m < n; ++m) {
          const Pair& pr = pairs[i * n + m];
          if (!pr.visible) continue;
          for (int c = 0; c < 3; ++c)
            if (pr.f_over_d2[c] > 0.f) denom[c] += pr.pdf_over_d2;
        }
        for (int c = 0; c < 3; ++c) lr[c] = denom[c] > 0.f ? lr[c] / denom[c] : 0.f;
        for (size_t k = 0; k < n; ++k) {
          const Pair& pr = pairs[i * n + k];
          if (pr.visible) added[k] += pr.f_over_d2 * lr;
        }
      }
      for (size_t k = 0; k < n; ++k) {
        if (!mem[k].in_s) continue;
        // A member that offered its second vertex drops its own tail (its share is in added).
        Spectrum& L = states[member[k]].radiance;
        const Spectrum reused =
            (mem[k].offers ? records[member[k]].radiance_at_x2 : L) + added[k];
        if (is_finite(reused)) L = reused;
      }
    }
  }
  return rays;
}

}  // namespace penumbra
