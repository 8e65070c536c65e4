#pragma once
// The rough coating's directional albedos, as microfacet.h's rough_dielectric_reflectance and
// rough_dielectric_transmittance define them (the same Gauss-Legendre rule over the unit square of
// visible-normal sampling, the same float operations, the same order of summation: the same
// result to the bit), computed several times faster for the many cosines a coating table needs.
//
// Why it is faster: of one evaluation of the generic integral, most of the work does not depend
// on the incident direction -- the rule's nodes (a Newton solve per call) and their image on the
// disk under the concentric map (a sincos per node) -- and what depends on it only through the
// stretched view vector (Heitz 2018's frame t1, t2, vh and the squeeze s) is one setup per
// cosine. Both are hoisted here: per node there remain the squeeze, the unstretch, the
// normalisation and the Fresnel and Smith factors, which one loop computes for all nodes in SIMD
// lanes (materials/lane_microfacet.h, the scalar functions' operations in their order, no FMA
// contraction) before the terms are summed in double in the generic order.
#include <vector>

#include "renderer/materials/microfacet.h"

namespace penumbra {

// Nodes and weights of the res x res tensor rule mapped onto the disk, computed once per res.
class VisibleNormalQuadrature {
 public:
  explicit VisibleNormalQuadrature(int res);

  // E_m[F(wi.m) G1(wo_r, m)] and E_m[(1 - F(wi.m)) G1(wo_t, m)] over the visible normals of the
  // direction of cosine cos_i, as rough_dielectric_reflectance / _transmittance at this res.
  float reflectance(const GgxDistribution& distr, float cos_i, float eta) const;
  float transmittance(const GgxDistribution& distr, float cos_i, float eta) const;

  int res() const { return res_; }

 private:
  enum class Integrand { kReflectance, kTransmittance };
  float integrate(const GgxDistribution& distr, float cos_i, float eta, Integrand what) const;

  int res_;
  // The nodes, row-major in (a, b) (the generic integral's order of summation), one array per
  // quantity so the per-node terms are computed in SIMD lanes:
  std::vector<float> p1_;        // disk point along t1
  std::vector<float> p1_slack_;  // 1 - p1^2, the disk's half-height at p1 squared
  std::vector<float> p1_root_;   // safe_sqrt(1 - p1^2)
  std::vector<float> py_;        // disk point along t2 before the squeeze
  std::vector<double> weight_;   // w_a w_b / 4: the product rule on [0, 1]^2
};

// The rule at the res microfacet.cpp uses for a coating of relative ior eta (32 above 1, 64 at
// and below), shared by the process (built on first use, thread-safe).
const VisibleNormalQuadrature& coating_quadrature(float eta);

// Bit-identical to rough_dielectric_reflectance / rough_dielectric_transmittance.
inline float coating_reflectance(const GgxDistribution& distr, float cos_i, float eta) {
  return coating_quadrature(eta).reflectance(distr, cos_i, eta);
}
inline float coating_transmittance(const GgxDistribution& distr, float cos_i, float eta) {
  return coating_quadrature(eta).transmittance(distr, cos_i, eta);
}

}  // namespace penumbra
