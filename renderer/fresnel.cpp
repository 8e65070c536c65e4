#include "renderer/fresnel.h"

namespace penumbra {

FresnelDielectric fresnel_dielectric(float cos_i, float eta) {
  const bool outside = cos_i >= 0.f;
  const float eta_it = outside ? eta : 1.f / eta;
  const float eta_ti = outside ? 1.f / eta : eta;

  if (eta == 1.f) return {0.f, -cos_i, 1.f, 1.f};

  // Snell: sin_t = eta_ti * sin_i.
  const float cos_t_sqr = 1.f - eta_ti * eta_ti * std::max(0.f, 1.f - cos_i * cos_i);
  if (cos_t_sqr <= 0.f) return {1.f, 0.f, eta_it, eta_ti};  // total internal reflection

  const float ci = std::abs(cos_i);
  const float ct = std::sqrt(cos_t_sqr);
  if (ci == 0.f) return {1.f, outside ? -ct : ct, eta_it, eta_ti};

  // Amplitude coefficients for s- and p-polarised light, written with eta_it = n_t / n_i.
  const float r_s = (ci - eta_it * ct) / (ci + eta_it * ct);
  const float r_p = (ct - eta_it * ci) / (ct + eta_it * ci);
  const float f = std::min(1.f, 0.5f * (r_s * r_s + r_p * r_p));
  return {f, outside ? -ct : ct, eta_it, eta_ti};
}

float fresnel_diffuse_reflectance(float eta) {
  if (eta < 1.f) {
    // Egan & Hilgeman 1973.
    return -1.4399f * eta * eta + 0.7099f * eta + 0.6681f + 0.0636f / eta;
  }
  // d'Eon & Irving 2011.
  const float x = 1.f / eta;
  return 0.919317f + x * (-3.4793f + x * (6.75335f + x * (-7.80989f + x * (4.98554f - 1.36881f * x))));
}

}  // namespace penumbra
