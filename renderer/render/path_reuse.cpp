#include "renderer/render/path_reuse.h"

#include <array>
#include <optional>
#include <variant>

#include "renderer/materials/diffuse.h"

namespace penumbra {
namespace {

// The largest group reuse_paths takes at once (a 4 x 4 block of pixels); larger runs are split.
constexpr size_t kMaxGroup = 16;

// A member's first vertex as a sampling technique: its BSDF and frame as path_scatter built them.
struct Technique {
  std::optional<SurfaceBsdf> textured;
  const SurfaceBsdf* bsdf = nullptr;
  Frame frame;
  vec3 wi_local{0.f};
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

// One pair (technique m, sample i): the BSDF of x1_m towards x2_i (f cos) over d^2, its pdf
// over d^2, and whether x2_i is what x1_m sees in that direction.
struct Pair {
  Spectrum f_over_d2{0.f};
  float pdf_over_d2 = 0.f;
  bool visible = false;
};

}  // namespace

bool path_reuse_applies(const Scene& scene, const IntegratorSettings& settings) {
  return !scene.features().motion && settings.rr_depth >= 2 &&
         (settings.max_depth < 0 || settings.max_depth > 2);
}

uint64_t reuse_paths(const Scene& scene, const ReuseRecord* records, PathState* states,
                     const uint32_t* paths, const std::vector<size_t>& group_starts) {
  using path_step_detail::geometry_agrees;
  uint64_t rays = 0;
  std::array<Technique, kMaxGroup> tech;
  std::array<bool, kMaxGroup> in_s{}, offers{};
  std::array<Pair, kMaxGroup * kMaxGroup> pairs;  // [i * n + m]
  std::array<Ray, Scene::kPacketSize> shadow_rays;
  std::array<uint16_t, kMaxGroup * kMaxGroup> pending;
  std::array<bool, Scene::kPacketSize> blocked;

  for (size_t g = 0; g + 1 < group_starts.size(); ++g) {
    for (size_t start = group_starts[g]; start < group_starts[g + 1]; start += kMaxGroup) {
      const size_t n = std::min(kMaxGroup, group_starts[g + 1] - start);
      const uint32_t* member = paths + start;
      if (n < 2) continue;
      // The techniques: members whose x1 has no Dirac lobe.
      size_t techniques = 0;
      for (size_t m = 0; m < n; ++m) {
        const ReuseRecord& r = records[member[m]];
        in_s[m] = false;
        offers[m] = false;
        if (!r.has_x1) continue;
        SurfaceHit hit = r.x1;
        const Material& material = scene.material(scene.object(hit.object).material);
        Technique& t = tech[m];
        t.textured.reset();
        t.bsdf = &material.bsdf();
        if (material.varies())
          t.bsdf = &t.textured.emplace(material.bsdf_at(TextureQuery{hit.p, hit.uv, r.time}));
        if (t.bsdf->lobes() & kLobeDelta) continue;
        t.frame = material.normal_mapped() ? path_step_detail::tangent_frame(scene, r.time, &hit)
                                           : Frame(hit.ns);
        t.wi_local = t.frame.to_local(r.wi1);
        in_s[m] = true;
        ++techniques;
        offers[m] = r.has_x2 && lambertian_without_normal_map(scene, r.x2);
      }
      if (techniques < 2) continue;

      // Every pair's BSDF terms; the visibility of each pair that has any, traced in packets.
      size_t queued = 0;
      auto flush_shadows = [&] {
        for (size_t k = 0; k < queued; k += Scene::kPacketSize) {
          const int count = int(std::min<size_t>(Scene::kPacketSize, queued - k));
          for (int q = 0; q < count; ++q) {
            const uint16_t idx = pending[k + size_t(q)];
            const ReuseRecord& from = records[member[idx % n]];
            const ReuseRecord& to = records[member[idx / n]];
            const vec3 w = glm::normalize(to.x2.p - from.x1.p);
            const vec3 origin = offset_ray_origin(from.x1.p, from.x1.p_error, from.x1.ng, w);
            const vec3 target = offset_ray_origin(to.x2.p, to.x2.p_error, to.x2.ng, -w);
            const vec3 d = target - origin;
            const float dist = glm::length(d);
            shadow_rays[size_t(q)] =
                Ray{origin, dist > 0.f ? d / dist : w, from.time, dist * (1.f - kShadowEpsilon)};
          }
          scene.occluded_packet(shadow_rays.data(), count, blocked.data());
          for (int q = 0; q < count; ++q) pairs[pending[k + size_t(q)]].visible = !blocked[size_t(q)];
        }
        rays += queued;
        queued = 0;
      };
      for (size_t i = 0; i < n; ++i) {
        if (!offers[i]) continue;
        const ReuseRecord& ri = records[member[i]];
        const int own_class = direction_class(ri.x2, glm::normalize(ri.x1.p - ri.x2.p));
        for (size_t m = 0; m < n; ++m) {
          Pair& pr = pairs[i * n + m];
          pr = Pair{};
          if (!in_s[m]) continue;
          const ReuseRecord& rm = records[member[m]];
          const vec3 d = ri.x2.p - rm.x1.p;
          const float d2 = glm::dot(d, d);
          if (!(d2 > 0.f)) continue;
          const vec3 w = d / std::sqrt(d2);
          if (m != i && direction_class(ri.x2, -w) != own_class) continue;
          const Technique& t = tech[m];
          const vec3 wo = t.frame.to_local(w);
          if (!geometry_agrees(rm.wi1, w, rm.x1.ng, t.wi_local, wo)) continue;
          const BsdfEvalPdf e = t.bsdf->eval_pdf(BsdfContext{}, t.wi_local, wo);
          if (!(e.pdf > 0.f)) continue;
          // Area measure at x2: the cosine there is the angle towards this x1, one per pair.
          const float cos2 = std::abs(glm::dot(ri.x2.ng, w)) / d2;
          pr.f_over_d2 = e.f * cos2;
          pr.pdf_over_d2 = e.pdf * cos2;
          if (m == i) {
            pr.visible = true;
          } else {
            pending[queued++] = uint16_t(i * n + m);
          }
        }
      }
      flush_shadows();

      // Each offered sample's L_r estimate spread over the members by the balance heuristic.
      std::array<Spectrum, kMaxGroup> added;
      added.fill(Spectrum(0.f));
      for (size_t i = 0; i < n; ++i) {
        if (!offers[i]) continue;
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
        for (size_t k = 0; k < n; ++k) {
          const Pair& pr = pairs[i * n + k];
          if (!pr.visible) continue;
          for (int c = 0; c < 3; ++c)
            if (denom[c] > 0.f) added[k][c] += pr.f_over_d2[c] * lr[c] / denom[c];
        }
      }
      for (size_t k = 0; k < n; ++k) {
        if (!in_s[k]) continue;
        const ReuseRecord& rk = records[member[k]];
        Spectrum& L = states[member[k]].radiance;
        const Spectrum own_tail = offers[k] ? L - rk.radiance_at_x2 : Spectrum(0.f);
        const Spectrum reused = L - own_tail + added[k];
        if (is_finite(reused)) L = reused;
      }
    }
  }
  return rays;
}

}  // namespace penumbra
