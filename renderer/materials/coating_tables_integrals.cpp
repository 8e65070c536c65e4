#include "renderer/materials/coating_tables_integrals.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "renderer/core/quadrature.h"
#include "renderer/core/simd_clones.h"
#include "renderer/materials/fresnel.h"
#include "renderer/materials/lane_microfacet.h"
#include "renderer/sampling/sampling.h"

namespace penumbra {

namespace {

// The nodes' terms of one integral, lane by lane: the generic integral's fn(wi, m) at the
// visible normal m of every node (VisibleNormalQuadrature::integrate below has the scalar
// form). `view` = (t1, t2, vh, s) of stretched_view(alpha, wi); `reflect`: the reflectance's
// integrand, else the transmittance's.
struct NodeTermsArgs {
  const float *p1, *p1_slack, *p1_root, *py;
  float alpha, eta, wi[3], t1[3], t2[3], vh[3], s;
  bool reflect;
};

template <bool kReflect>
[[gnu::always_inline]] inline void node_terms(const NodeTermsArgs& args, size_t n, float* out) {
  const NodeTermsArgs A = args;  // a local copy: GCC reloads a struct's pointers otherwise
  for (size_t k = 0; k < n; ++k) {
    // GgxDistribution::sample_visible at the node: squeeze, lift onto the hemisphere, unstretch.
    const float p2 = (1.f - A.s) * A.p1_root[k] + A.s * A.py[k];
    const float lift = lane::safe_root(A.p1_slack[k] - p2 * p2);
    float nh[3];
    for (int c = 0; c < 3; ++c) nh[c] = (A.p1[k] * A.t1[c] + p2 * A.t2[c]) + lift * A.vh[c];
    float m[3] = {A.alpha * nh[0], A.alpha * nh[1], 0.f < nh[2] ? nh[2] : 0.f};
    lane::normalize(m);
    const float d = lane::dot3(A.wi, m);
    const lane::Fresnel fr = lane::fresnel_dielectric(d, A.eta);
    float wo[3];
    if constexpr (kReflect) {
      // reflect(wi, m) = 2 (wi.m) m - wi; F(wi.m) G1(wo, m) above the surface.
      for (int c = 0; c < 3; ++c) wo[c] = (2.f * d) * m[c] - A.wi[c];
      const float g = lane::Ggx::smith_g1(A.alpha, wo, m);
      out[k] = when(mask(wo[2] <= 0.f), 0.f, fr.reflectance * g);
    } else {
      // refract(wi, m, cos_t, eta_ti) = m (wi.m eta_ti + cos_t) - wi eta_ti; (1 - F) G1(wo, m)
      // below it, none under total internal reflection.
      for (int c = 0; c < 3; ++c) wo[c] = m[c] * (d * fr.eta_ti + fr.cos_t) - A.wi[c] * fr.eta_ti;
      const float g = lane::Ggx::smith_g1(A.alpha, wo, m);
      const Mask none = mask(fr.reflectance >= 1.f) | mask(wo[2] * A.wi[2] >= 0.f);
      out[k] = when(none, 0.f, (1.f - fr.reflectance) * g);
    }
  }
}

PENUMBRA_SIMD_CLONES
void node_terms_kernel(const NodeTermsArgs& args, size_t n, float* out) {
  if (args.reflect)
    node_terms<true>(args, n, out);
  else
    node_terms<false>(args, n, out);
}

}  // namespace

VisibleNormalQuadrature::VisibleNormalQuadrature(int res) : res_(res) {
  std::vector<double> x, w;
  gauss_legendre(res, x, w);
  const size_t nodes = size_t(res) * size_t(res);
  for (auto* a : {&p1_, &p1_slack_, &p1_root_, &py_}) a->reserve(nodes);
  weight_.reserve(nodes);
  for (int a = 0; a < res; ++a) {
    for (int b = 0; b < res; ++b) {
      // The same float input and map as GgxDistribution::sample_visible's.
      const vec2 u(float(0.5 * x[a] + 0.5), float(0.5 * x[b] + 0.5));
      const vec2 p = square_to_disk_concentric(u);
      const float slack = 1.f - p.x * p.x;
      p1_.push_back(p.x);
      p1_slack_.push_back(slack);
      p1_root_.push_back(safe_sqrt(slack));
      py_.push_back(p.y);
      weight_.push_back(0.25 * w[a] * w[b]);
    }
  }
}

// The generic integral (microfacet.cpp) with sample_visible (Heitz 2018, listing 1) split into
// its per-direction and per-node parts. Every float operation is the generic one's, in the same
// order, and the terms are summed in double in the generic order, so the sum is the same to the
// bit (a test checks): the tables, and so the images, do not change. Per node, as scalars:
//   p2 = (1 - s) sqrt(1 - p1^2) + s py;  nh = p1 t1 + p2 t2 + sqrt(1 - p1^2 - p2^2) vh
//   m = normalize(alpha nh.x, alpha nh.y, max(0, nh.z));  sum += weight fn(wi, m)
float VisibleNormalQuadrature::integrate(const GgxDistribution& distr, float cos_i, float eta,
                                         Integrand what) const {
  const float alpha = distr.alpha();
  const float c = std::clamp(cos_i, 1e-6f, 1.f);
  const vec3 wi(std::sqrt(std::max(0.f, 1.f - c * c)), 0.f, c);
  // Stretch to the alpha = 1 configuration and build the frame around the stretched view.
  const StretchedView f = stretched_view(alpha, wi);
  NodeTermsArgs args{p1_.data(), p1_slack_.data(), p1_root_.data(), py_.data(), alpha, eta,
                     {wi.x, wi.y, wi.z}, {f.t1.x, f.t1.y, f.t1.z}, {f.t2.x, f.t2.y, f.t2.z},
                     {f.vh.x, f.vh.y, f.vh.z}, f.s, what == Integrand::kReflectance};
  const size_t n = weight_.size();
  // (At most 64 x 64 floats: on the stack, no allocation per call.)
  alignas(64) float terms[64 * 64];
  double sum = 0.0;
  for (size_t first = 0; first < n; first += std::size(terms)) {
    const size_t count = std::min(std::size(terms), n - first);
    NodeTermsArgs part = args;
    part.p1 += first;
    part.p1_slack += first;
    part.p1_root += first;
    part.py += first;
    node_terms_kernel(part, count, terms);
    for (size_t k = 0; k < count; ++k) sum += weight_[first + k] * terms[k];
  }
  return float(sum);
}

float VisibleNormalQuadrature::reflectance(const GgxDistribution& distr, float cos_i,
                                           float eta) const {
  return integrate(distr, cos_i, eta, Integrand::kReflectance);
}

float VisibleNormalQuadrature::transmittance(const GgxDistribution& distr, float cos_i,
                                             float eta) const {
  return integrate(distr, cos_i, eta, Integrand::kTransmittance);
}

const VisibleNormalQuadrature& coating_quadrature(float eta) {
  // The resolutions of microfacet.cpp's rough_dielectric_* (magic statics: thread-safe).
  static const VisibleNormalQuadrature above(32), below(64);
  return eta > 1.f ? above : below;
}

}  // namespace penumbra
