#include "renderer/lights/environment_map.h"

#include "renderer/sampling/sampling.h"

namespace penumbra {
namespace {

// The lat-long map's Jacobian: dw = 2 pi^2 sin(theta) du dv, so a density p(u, v) is
// p / (2 pi^2 sin(theta)) per steradian (pbrt-v3 §14.2.4).
constexpr float kInv2PiSquared = 1.f / (2.f * kPi * kPi);
// Closer to a pole than this, sample() draws nothing and pdf() is 0, consistently: the density
// per steradian grows as 1 / sin(theta), and its square in the power heuristic must stay finite.
// BSDF sampling alone covers that cone (its MIS weight is then 1), so nothing is lost.
constexpr float kMinSinTheta = 1e-9f;

float clean(float v) { return std::isfinite(v) && v > 0.f ? v : 0.f; }

}  // namespace

vec2 EnvironmentMap::direction_to_uv(const vec3& d) {
  float u = std::atan2(d.x, -d.z) * kInv2Pi;
  if (u < 0.f) u += 1.f;
  return vec2(u, std::acos(std::clamp(d.y, -1.f, 1.f)) * kInvPi);
}

vec3 EnvironmentMap::uv_to_direction(const vec2& uv) {
  const float theta = uv.y * kPi, phi = uv.x * (2.f * kPi);
  const float sin_theta = std::sin(theta);
  return vec3(std::sin(phi) * sin_theta, std::cos(theta), -std::cos(phi) * sin_theta);
}

EnvironmentMap::EnvironmentMap(const EnvironmentMapDesc& desc)
    : uniform_sampling_(desc.uniform_sampling) {
  const float scale = clean(desc.scale);
  const bool has_pixels = desc.width > 0 && desc.height > 0 &&
                          desc.rgb.size() >= size_t(desc.width) * size_t(desc.height) * 3;
  width_ = has_pixels ? desc.width : 1;
  const int rows = has_pixels ? desc.height : 1;
  // One row is a map that does not vary with v: its row stands at both poles.
  height_ = std::max(rows, 2);
  texels_.resize(size_t(width_) * size_t(height_), Spectrum(0.f));
  if (has_pixels)
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x) {
        const size_t src = (size_t(std::min(y, rows - 1)) * size_t(width_) + size_t(x)) * 3;
        // Scaled here, so luminances and weights stay within the range the loader checked
        // (brightest texel x scale <= 1e30) even for texels near the float maximum.
        Spectrum& t = texels_[size_t(y) * size_t(width_) + size_t(x)];
        for (int c = 0; c < 3; ++c) t[c] = clean(clean(desc.rgb[src + size_t(c)]) * scale);
      }
  to_world_ = desc.to_world;
  to_local_ = glm::transpose(desc.to_world);  // orthogonal: the inverse is the transpose
  half_texel_ = 0.5f / float(width_);

  // Cell (x, y) lies between rows y and y + 1, at polar angles theta0..theta1, and between the
  // centres of texels x and x + 1. Its weight approximates the integral of luminance over its
  // solid angle: the mean of its four texels (the integral of the bilinear interpolant over the
  // cell) times the band's cos(theta0) - cos(theta1), the integral of sin(theta) dtheta. The
  // sin(theta) factor keeps the poles, which the map stretches across a whole row, from drawing
  // samples out of proportion to their solid angle (pbrt-v3 §14.2.4; Mitsuba's envmap weights its
  // grid by sin(theta) too). A cell is zero only if all four texels are, i.e. only where the
  // radiance is zero.
  const int nu = width_, nv = height_ - 1;
  std::vector<float> weights(size_t(nu) * size_t(nv));
  double sum = 0.0;
  for (int y = 0; y < nv; ++y) {
    const double band = std::cos(M_PI * y / nv) - std::cos(M_PI * (y + 1) / nv);
    for (int x = 0; x < nu; ++x) {
      const int x1 = (x + 1) % nu;
      const double mean = 0.25 * (double(luminance(texel(x, y))) + luminance(texel(x1, y)) +
                                  luminance(texel(x, y + 1)) + luminance(texel(x1, y + 1)));
      weights[size_t(y) * size_t(nu) + size_t(x)] = float(mean * band);
      sum += mean * band;
    }
  }
  distribution_ = Distribution2D(weights, nu, nv);
  // Each cell spans 2 pi / width in azimuth.
  integral_ = sum * (2.0 * M_PI / nu);
}

Spectrum EnvironmentMap::lookup(const vec2& uv) const {
  // Texel centres at u = (x + 0.5) / width; the seam wraps.
  const float fx = uv.x * float(width_) - 0.5f;
  const float x_floor = std::floor(fx);
  const float tx = fx - x_floor;
  // u in [0, 1] puts x0 in [-1, width - 1]: one wrap at most, without the two integer divisions
  // of a modulo (measured 1/5 of the lookup's time). Anything else (not from a direction) still
  // wraps by the modulo.
  int x0 = int(x_floor);
  if (x0 < 0) x0 += width_;
  if (x0 < 0 || x0 >= width_) {
    x0 = int(x_floor) % width_;
    if (x0 < 0) x0 += width_;
  }
  const int x1 = x0 + 1 == width_ ? 0 : x0 + 1;
  // Rows at v = y / (height - 1).
  const float fy = std::clamp(uv.y, 0.f, 1.f) * float(height_ - 1);
  const int y0 = std::min(int(fy), height_ - 2);
  const float ty = fy - float(y0);
  const Spectrum top = texel(x0, y0) * (1.f - tx) + texel(x1, y0) * tx;
  const Spectrum bottom = texel(x0, y0 + 1) * (1.f - tx) + texel(x1, y0 + 1) * tx;
  return top * (1.f - ty) + bottom * ty;
}

Spectrum EnvironmentMap::radiance(const vec3& dir) const {
  return lookup(direction_to_uv(to_local_ * dir));
}

bool EnvironmentMap::sample(const vec3&, float, const vec2& u, LightSample* out) const {
  if (is_black()) return false;
  if (uniform_sampling_) {
    out->wi = square_to_uniform_sphere(u);
    out->pdf = uniform_sphere_pdf();
    out->value = radiance(out->wi);
  } else {
    float pdf_cell = 0.f;
    const vec2 st = distribution_.sample(u, &pdf_cell);
    vec2 uv(st.x + half_texel_, st.y);
    if (uv.x >= 1.f) uv.x -= 1.f;
    const float sin_theta = std::sin(uv.y * kPi);
    if (!(pdf_cell > 0.f) || !(sin_theta > kMinSinTheta)) return false;
    out->wi = to_world_ * uv_to_direction(uv);
    out->pdf = pdf_cell * kInv2PiSquared / sin_theta;
    out->value = lookup(uv);
  }
  if (!(out->pdf > 0.f) || !std::isfinite(out->pdf)) return false;
  out->distance = kInfinity;
  out->is_delta = false;
  out->p = out->p_error = out->n = vec3(0.f);
  return true;
}

float EnvironmentMap::pdf(const vec3& dir) const {
  if (is_black()) return 0.f;
  if (uniform_sampling_) return uniform_sphere_pdf();
  const vec3 d = to_local_ * dir;
  return pdf_local(d, direction_to_uv(d));
}

Spectrum EnvironmentMap::radiance_and_pdf(const vec3& dir, float* pdf) const {
  const vec3 d = to_local_ * dir;
  const vec2 uv = direction_to_uv(d);
  if (pdf) *pdf = is_black() ? 0.f : uniform_sampling_ ? uniform_sphere_pdf() : pdf_local(d, uv);
  return lookup(uv);
}

float EnvironmentMap::pdf_local(const vec3& d, const vec2& uv) const {
  float s = uv.x - half_texel_;
  if (s < 0.f) s += 1.f;
  const float sin_theta = std::sqrt(d.x * d.x + d.z * d.z);
  if (!(sin_theta > kMinSinTheta)) return 0.f;
  const float p = distribution_.pdf(vec2(s, uv.y)) * kInv2PiSquared / sin_theta;
  return std::isfinite(p) ? p : 0.f;
}

float EnvironmentMap::power(float scene_radius) const {
  return float(integral_ * M_PI * double(scene_radius) * double(scene_radius));
}

}  // namespace penumbra
