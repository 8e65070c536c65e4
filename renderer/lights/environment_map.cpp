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

// A sample of [0, 1] with density proportional to (1 - x) a + x b, 0 <= a, b <= 2 (pbrt-v4
// SampleLinear): the root of the CDF's quadratic in the form that stays accurate for a << b.
float sample_linear(float u, float a, float b) {
  if (!(a + b > 0.f)) return u;  // both zero: no shape to follow (its density is 0 anyway)
  if (u == 0.f && a == 0.f) return 0.f;
  const float x = u * (a + b) / (a + std::sqrt((1.f - u) * a * a + u * b * b));
  return std::min(x, kOneMinusEpsilon);
}

// Density on the unit square, proportional to the bilinear interpolant of the four corners.
float bilinear_pdf(float x, float y, float w00, float w10, float w01, float w11) {
  const float sum = w00 + w10 + w01 + w11;
  if (!(sum > 0.f)) return 0.f;
  const float v = (1.f - x) * (1.f - y) * w00 + x * (1.f - y) * w10 + (1.f - x) * y * w01 + x * y * w11;
  return 4.f * v / sum;
}

// The end of every sample: a usable density, and the fields of a direction from infinity.
bool finish_sample(LightSample* out) {
  if (!(out->pdf > 0.f) || !std::isfinite(out->pdf)) return false;
  out->distance = kInfinity;
  out->is_delta = false;
  out->p = out->p_error = out->n = vec3(0.f);
  return true;
}

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
  // centres of texels x and x + 1. Sampling density: each corner (texel) carries its luminance x
  // its row's sin(theta); within a cell the density is their bilinear interpolant, so a cell's
  // weight is their mean. The sin(theta) factor keeps the poles, which the map stretches across
  // a whole row, from drawing samples out of proportion to their solid angle (pbrt-v3 §14.2.4;
  // Mitsuba's envmap weights its grid by sin(theta) too). A pole row's sin(theta) would be 0, and
  // a map lit only there (or a one-row map, whose two rows are both poles) would then have no
  // samples at all: the poles count as sin(theta) a quarter row in, which only shapes the density
  // within their cells. So a cell is zero only if its four texels are, i.e. only where the
  // radiance is zero. `sum` is the luminance integral itself (for the light's power): each cell's
  // mean luminance times its band's cos(theta0) - cos(theta1), the integral of sin(theta) dtheta.
  const int nu = width_, nv = height_ - 1;
  row_sin_.resize(size_t(height_));
  const double pole_sin = std::sin(M_PI / (4.0 * nv));
  for (int y = 0; y < height_; ++y) row_sin_[size_t(y)] = float(std::max(std::sin(M_PI * y / nv), pole_sin));
  std::vector<float> weights(size_t(nu) * size_t(nv));
  double sum = 0.0;
  for (int y = 0; y < nv; ++y) {
    const double band = std::cos(M_PI * y / nv) - std::cos(M_PI * (y + 1) / nv);
    for (int x = 0; x < nu; ++x) {
      const int x1 = (x + 1) % nu;
      const double mean = 0.25 * (double(luminance(texel(x, y))) + luminance(texel(x1, y)) +
                                  luminance(texel(x, y + 1)) + luminance(texel(x1, y + 1)));
      const Corners c = corners(x, y);
      weights[size_t(y) * size_t(nu) + size_t(x)] =
          float(0.25 * (double(c.w00) + double(c.w10) + double(c.w01) + double(c.w11)));
      sum += mean * band;
    }
  }
  distribution_ = Distribution2D(weights, nu, nv);
  // Each cell spans 2 pi / width in azimuth.
  integral_ = sum * (2.0 * M_PI / nu);
}

EnvironmentMap::Corners EnvironmentMap::corners(int x, int y) const {
  const int x1 = x + 1 == width_ ? 0 : x + 1;
  const float s0 = row_sin_[size_t(y)], s1 = row_sin_[size_t(y) + 1];
  return {luminance(texel(x, y)) * s0, luminance(texel(x1, y)) * s0, luminance(texel(x, y + 1)) * s1,
          luminance(texel(x1, y + 1)) * s1};
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
    return finish_sample(out);
  }
  float pdf_cell = 0.f;
  const vec2 st = distribution_.sample(u, &pdf_cell);
  return sample_in_cell(st, pdf_cell, out);
}

void EnvironmentMap::sample_many(size_t n, const vec3* refs, const float* times, const vec2* u,
                                 LightSample* out, bool* ok) const {
  if (is_black() || uniform_sampling_) return Light::sample_many(n, refs, times, u, out, ok);
  // The chain of one sample (marginal search, the row's search, the cell's texels) is a series
  // of dependent loads; each stage's loads are independent across samples, so the processor
  // overlaps them. Chunks keep the stages' state on the stack.
  constexpr size_t kChunk = 64;
  for (size_t k0 = 0; k0 < n; k0 += kChunk) {
    const size_t m = std::min(kChunk, n - k0);
    int row[kChunk], column[kChunk];
    float v[kChunk], x[kChunk];
    CellPoint q[kChunk];
    Corners c[kChunk];
    float pdf_cell[kChunk];
    for (size_t k = 0; k < m; ++k) v[k] = distribution_.sample_row(u[k0 + k].y, &row[k]);
    for (size_t k = 0; k < m; ++k) x[k] = distribution_.sample_column(row[k], u[k0 + k].x, &column[k]);
    for (size_t k = 0; k < m; ++k) {
      pdf_cell[k] = distribution_.cell_pdf(column[k], row[k]);
      q[k] = cell_point(vec2(x[k], v[k]));
      c[k] = corners(q[k].x, q[k].y);
    }
    for (size_t k = 0; k < m; ++k) ok[k0 + k] = sample_in_cell(q[k], c[k], pdf_cell[k], &out[k0 + k]);
  }
}

bool EnvironmentMap::sample_in_cell(const vec2& st, float pdf_cell, LightSample* out) const {
  // The cell, and where in it the sample fell: a uniform point of the cell (its row and column
  // were drawn independently), which the bilinear warp then reshapes.
  if (!(pdf_cell > 0.f)) return false;
  const CellPoint q = cell_point(st);
  return sample_in_cell(q, corners(q.x, q.y), pdf_cell, out);
}

bool EnvironmentMap::sample_in_cell(const CellPoint& q, Corners c, float pdf_cell,
                                    LightSample* out) const {
  if (!(pdf_cell > 0.f)) return false;
  // The warp depends only on the corners' ratios: scaled to at most 1, their squares cannot
  // overflow (texels up to 1e30 are allowed).
  const float top = std::max(std::max(c.w00, c.w10), std::max(c.w01, c.w11));
  if (!(top > 0.f)) return false;
  const float inv = 1.f / top;
  c = {c.w00 * inv, c.w10 * inv, c.w01 * inv, c.w11 * inv};
  const float fy = sample_linear(q.fy, c.w00 + c.w10, c.w01 + c.w11);
  const float fx = sample_linear(q.fx, (1.f - fy) * c.w00 + fy * c.w01, (1.f - fy) * c.w10 + fy * c.w11);
  const float pdf_uv = pdf_cell * bilinear_pdf(fx, fy, c.w00, c.w10, c.w01, c.w11);
  vec2 uv((float(q.x) + fx) / float(width_) + half_texel_,
          std::min((float(q.y) + fy) / float(height_ - 1), 1.f));
  if (uv.x >= 1.f) uv.x -= 1.f;
  const float sin_theta = std::sin(uv.y * kPi);
  if (!(pdf_uv > 0.f) || !(sin_theta > kMinSinTheta)) return false;
  out->wi = to_world_ * uv_to_direction(uv);
  out->pdf = pdf_uv * kInv2PiSquared / sin_theta;
  out->value = lookup(uv);
  return finish_sample(out);
}

EnvironmentMap::CellPoint EnvironmentMap::cell_point(const vec2& st) const {
  const int nu = width_, nv = height_ - 1;
  const float sx = st.x * float(nu), sy = st.y * float(nv);
  const int cx = std::clamp(int(sx), 0, nu - 1), cy = std::clamp(int(sy), 0, nv - 1);
  return {cx, cy, std::clamp(sx - float(cx), 0.f, 1.f), std::clamp(sy - float(cy), 0.f, 1.f)};
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
  if (pdf) *pdf = pdf_local(d, uv);
  return lookup(uv);
}

void EnvironmentMap::radiance_and_pdf_many(size_t n, const vec3* dirs, const uint8_t* want_pdf,
                                           Spectrum* radiance, float* pdf) const {
  constexpr size_t kChunk = 64;
  for (size_t k0 = 0; k0 < n; k0 += kChunk) {
    const size_t m = std::min(kChunk, n - k0);
    vec3 d[kChunk];
    vec2 uv[kChunk];
    for (size_t k = 0; k < m; ++k) {
      d[k] = to_local_ * dirs[k0 + k];
      uv[k] = direction_to_uv(d[k]);
    }
    for (size_t k = 0; k < m; ++k) {
      if (want_pdf[k0 + k]) pdf[k0 + k] = pdf_local(d[k], uv[k]);
      radiance[k0 + k] = lookup(uv[k]);
    }
  }
}

float EnvironmentMap::pdf_local(const vec3& d, const vec2& uv) const {
  if (is_black()) return 0.f;
  if (uniform_sampling_) return uniform_sphere_pdf();
  float s = uv.x - half_texel_;
  if (s < 0.f) s += 1.f;
  const float sin_theta = std::sqrt(d.x * d.x + d.z * d.z);
  if (!(sin_theta > kMinSinTheta)) return 0.f;
  // The point's cell (the one distribution_.pdf would find) and its place in it.
  const CellPoint q = cell_point(vec2(s, uv.y));
  const float pdf_cell = distribution_.cell_pdf(q.x, q.y);
  if (!(pdf_cell > 0.f)) return 0.f;
  const Corners c = corners(q.x, q.y);
  const float p = pdf_cell * bilinear_pdf(q.fx, q.fy, c.w00, c.w10, c.w01, c.w11) * kInv2PiSquared / sin_theta;
  return std::isfinite(p) ? p : 0.f;
}

float EnvironmentMap::power(float scene_radius) const {
  return float(integral_ * M_PI * double(scene_radius) * double(scene_radius));
}

}  // namespace penumbra
