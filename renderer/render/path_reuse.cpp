#include "renderer/render/path_reuse.h"

#include <array>
#include <optional>
#include <variant>

#include "renderer/materials/diffuse.h"

namespace penumbra {
namespace {

// The largest group reuse_paths takes at once (a 4 x 4 block of pixels); larger runs are split.
constexpr size_t kMaxGroup = 16;

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
  std::optional<SurfaceBsdf> textured;
  const SurfaceBsdf* bsdf = nullptr;
  Frame frame;
  vec3 wi_local{0.f};

  // From the path's record; whether it is a technique.
  bool set(const Scene& scene, const ReuseRecord& r);
};

// Which side of x2 a direction leaving it lies on, against its geometric and its shading
// normal: L_r(x2) is the same for every direction of one class of a Lambertian surface.
int direction_class(const SurfaceHit& x2, const vec3& w) {
  return (glm::dot(w, x2.ng) > 0.f ? 1 : 0) | (glm::dot(w, x2.ns) > 0.f ? 2 : 0);
}

bool lambertian_without_normal_map(const Scene& scene, const SurfaceHit& hit) {
  const Material& material = scene.material(scene.object(hit.object).material);
  return !material.normal_mapped() &&
         std::holds_alternative<DiffuseBsdf>(material.bsdf().model());
}

bool Member::set(const Scene& scene, const ReuseRecord& r) {
  in_s = offers = lambertian = false;
  if (!r.has_x1) return false;
  SurfaceHit hit = r.x1;
  const Material& material = scene.material(scene.object(hit.object).material);
  textured.reset();
  bsdf = &material.bsdf();
  if (material.varies()) bsdf = &textured.emplace(material.bsdf_at(TextureQuery{hit.p, hit.uv, r.time}));
  if (bsdf->lobes() & kLobeDelta) return false;
  frame = material.normal_mapped() ? path_step_detail::tangent_frame(scene, r.time, &hit) : Frame(hit.ns);
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

}  // namespace

bool path_reuse_applies(const Scene& scene, const IntegratorSettings& settings) {
  if (scene.features().motion || settings.rr_depth < 2 ||
      (settings.max_depth >= 0 && settings.max_depth <= 2))
    return false;
  // Some surface must be able to share its points (a scene of glossy, glass and normal-mapped
  // surfaces would pay for the records and the grouping and share nothing).
  for (uint32_t o = 0; o < scene.object_count(); ++o) {
    const Material& material = scene.material(scene.object(o).material);
    if (!material.normal_mapped() && std::holds_alternative<DiffuseBsdf>(material.bsdf().model()))
      return true;
  }
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
      size_t queued = 0;
      for (size_t i = 0; i < n; ++i) {
        if (!mem[i].offers) continue;
        const SurfaceHit& x2 = records[member[i]].x2;
        const vec3 back = records[member[i]].x1.p - x2.p;
        const int own_class = direction_class(x2, back);
        target[i] = offset_ray_origin(x2.p, x2.p_error, x2.ng, back);
        for (size_t m = 0; m < n; ++m) {
          Pair& pr = pairs[i * n + m];
          pr = Pair{};
          const Member& t = mem[m];
          if (!t.in_s) continue;
          const ReuseRecord& rm = records[member[m]];
          const vec3 d = x2.p - rm.x1.p;
          const float d2 = glm::dot(d, d);
          if (!(d2 > 0.f)) continue;
          const vec3 w = d / std::sqrt(d2);
          if (m != i && direction_class(x2, -w) != own_class) continue;
          // Area measure at x2: the cosine there is the angle towards this x1, one per pair.
          const float to_area = std::abs(glm::dot(x2.ng, w)) / d2;
          if (t.lambertian) {
            // DiffuseBsdf through SurfaceBsdf's two-sided mirror and path_scatter's geometry
            // test, inline: f cos = colour cos / pi and pdf = cos / pi with cos against the
            // shading normal turned to the camera's side.
            const float cos_o = glm::dot(w, t.facing);
            if (!(cos_o > 0.f) || !(t.ng_side * glm::dot(w, rm.x1.ng) > 0.f)) continue;
            pr.pdf_over_d2 = cos_o * kInvPi * to_area;
            pr.f_over_d2 = t.color * pr.pdf_over_d2;
          } else {
            const vec3 wo = t.frame.to_local(w);
            if (!geometry_agrees(rm.wi1, w, rm.x1.ng, t.wi_local, wo)) continue;
            const BsdfEvalPdf e = t.bsdf->eval_pdf(BsdfContext{}, t.wi_local, wo);
            if (!(e.pdf > 0.f)) continue;
            pr.f_over_d2 = e.f * to_area;
            pr.pdf_over_d2 = e.pdf * to_area;
          }
          if (m == i) pr.visible = true;
          else pending[queued++] = uint16_t(i * n + m);
        }
      }
      for (size_t k = 0; k < queued; k += Scene::kPacketSize) {
        const int count = int(std::min<size_t>(Scene::kPacketSize, queued - k));
        for (int q = 0; q < count; ++q) {
          const uint16_t idx = pending[k + size_t(q)];
          const size_t m = idx % n, i = idx / n;
          const SurfaceHit& x1 = records[member[m]].x1;
          const vec3 to = target[i];
          const vec3 origin = offset_ray_origin(x1.p, x1.p_error, x1.ng, to - x1.p);
          const vec3 d = to - origin;
          const float dist = glm::length(d);
          shadow_rays[size_t(q)] = Ray{origin, dist > 0.f ? d / dist : glm::normalize(to - x1.p),
                                       records[member[m]].time, dist * (1.f - kShadowEpsilon)};
        }
        scene.occluded_packet(shadow_rays.data(), count, blocked.data());
        for (int q = 0; q < count; ++q) pairs[pending[k + size_t(q)]].visible = !blocked[size_t(q)];
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
        const ReuseRecord& rk = records[member[k]];
        Spectrum& L = states[member[k]].radiance;
        const Spectrum own_tail = mem[k].offers ? L - rk.radiance_at_x2 : Spectrum(0.f);
        const Spectrum reused = L - own_tail + added[k];
        if (is_finite(reused)) L = reused;
      }
    }
  }
  return rays;
}

}  // namespace penumbra
