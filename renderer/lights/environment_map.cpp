#include "renderer/lights/environment_map.h"

#include <algorithm>
#include <atomic>
#include <bit>

#include "renderer/core/arc_tangent.h"
#include "renderer/core/row_blocks.h"
#include "renderer/core/simd_clones.h"
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

float clean(float v) { return clean_texel(v); }
// Whether clean() leaves every value as it is, to the bit (texel_is_clean). Chunks of
// branch-free compares, which GCC vectorises (the scan of an 8192 x 4096 map took 100 ms with
// an early exit per value), in blocks on all cores.
bool all_clean(const std::vector<float>& values, size_t n) {
  constexpr size_t kChunk = 4096;
  std::atomic<bool> clean{true};
  for_row_blocks((n + kChunk - 1) / kChunk, rows_per_block(kChunk), [&](size_t first, size_t last) {
    for (size_t chunk = first; chunk < last && clean.load(std::memory_order_relaxed); ++chunk) {
      const size_t begin = chunk * kChunk, end = std::min(n, begin + kChunk);
      uint32_t bad = 0;
      for (size_t i = begin; i < end; ++i) bad |= uint32_t(!texel_is_clean(values[i]));
      if (bad) clean.store(false, std::memory_order_relaxed);
    }
  });
  return clean.load();
}

// Density on the unit square, proportional to the bilinear interpolant of the four corners.
inline float bilinear_pdf(float x, float y, float w00, float w10, float w01, float w11) {
  const float sum = w00 + w10 + w01 + w11;
  const float v = (1.f - x) * (1.f - y) * w00 + x * (1.f - y) * w10 + (1.f - x) * y * w01 + x * y * w11;
  return sum > 0.f ? 4.f * v / sum : 0.f;
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

EnvironmentMap::EnvironmentMap(const EnvironmentMapDesc& desc)
    : uniform_sampling_(desc.uniform_sampling) {
  const float scale = clean(desc.scale);
  const bool has_pixels = desc.width > 0 && desc.height > 0 && desc.rgb &&
                          desc.rgb->size() >= size_t(desc.width) * size_t(desc.height) * 3;
  width_ = has_pixels ? desc.width : 1;
  const int rows = has_pixels ? desc.height : 1;
  // One row is a map that does not vary with v: its row stands at both poles.
  height_ = std::max(rows, 2);
  const size_t count = size_t(width_) * size_t(height_);
  if (has_pixels && rows >= 2 && scale == 1.f && all_clean(*desc.rgb, count * 3)) {
    // The texels as they are (the api's maps: scaled and clean): shared, not copied.
    texel_store_ = desc.rgb;
  } else {
    auto texels = std::make_shared<std::vector<float>>(count * 3, 0.f);
    if (has_pixels)
      for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x) {
          const size_t src = (size_t(std::min(y, rows - 1)) * size_t(width_) + size_t(x)) * 3;
          const size_t dst = (size_t(y) * size_t(width_) + size_t(x)) * 3;
          // Scaled here, so luminances and weights stay within the range the loader checked
          // (brightest texel x scale <= 1e30) even for texels near the float maximum.
          for (size_t c = 0; c < 3; ++c) (*texels)[dst + c] = clean(clean((*desc.rgb)[src + c]) * scale);
        }
    texel_store_ = std::move(texels);
  }
  texels_ = texel_store_->data();
  to_world_ = desc.to_world;
  to_local_ = glm::transpose(desc.to_world);  // orthogonal: the inverse is the transpose
  half_texel_ = 0.5f / float(width_);

  const int nv = height_ - 1;
  row_sin_.resize(size_t(height_));
  const double pole_sin = std::sin(M_PI / (4.0 * nv));
  for (int y = 0; y < height_; ++y) row_sin_[size_t(y)] = float(std::max(std::sin(M_PI * y / nv), pole_sin));
  integrate_luminance();  // the sampling distribution waits for the first sample (distribution())
}

// The luminance integral (for the light's power): each cell's mean luminance times its band's
// cos(theta0) - cos(theta1), the integral of sin(theta) dtheta; each cell spans 2 pi / width in
// azimuth. Each texel's luminance is computed once, into a pair of row buffers (a cell reads
// four). One core: the sum runs over the cells in row-major order, one addition at a time, as it
// always has (in another order its last bits could differ, and the compensated twin's floor and
// the light's power with them), and that chain of additions is most of the time. Computing the
// cells' terms in blocks on all cores ahead of it (a TBB pipeline, the sum its last stage) was
// measured: 46-66 ms instead of 61-86 for an 8192 x 4096 map, not worth the pipeline.
void EnvironmentMap::integrate_luminance() {
  const int nu = width_, nv = height_ - 1;
  std::vector<float> row(static_cast<size_t>(nu)), next(static_cast<size_t>(nu));
  float brightest = 0.f;
  const auto luminances = [&](int y, std::vector<float>& out) {
    for (int x = 0; x < nu; ++x) {
      out[size_t(x)] = luminance(texel(x, y));
      brightest = std::max(brightest, out[size_t(x)]);
    }
  };
  luminances(0, row);
  double sum = 0.0;
  for (int y = 0; y < nv; ++y) {
    luminances(y + 1, next);
    const double band = std::cos(M_PI * y / nv) - std::cos(M_PI * (y + 1) / nv);
    const auto cell = [&](size_t x0, size_t x1) {
      return 0.25 * (double(row[x0]) + row[x1] + next[x0] + next[x1]) * band;
    };
    // Cell x lies between texels x and x + 1, the last one across the seam (texel 0): apart, so
    // that there is no modulo, a division, per cell.
    for (size_t x = 0; x + 1 < size_t(nu); ++x) sum += cell(x, x + 1);
    sum += cell(size_t(nu) - 1, 0);
    row.swap(next);
  }
  integral_ = sum * (2.0 * M_PI / nu);
  max_luminance_ = brightest;
}

std::unique_ptr<EnvironmentMap> EnvironmentMap::compensated() const {
  if (uniform_sampling_ || is_black()) return nullptr;
  // The floor is the mean luminance over the sphere of directions (the integral is over 4 pi sr).
  return std::unique_ptr<EnvironmentMap>(new EnvironmentMap(*this, float(integral_ / (4.0 * M_PI))));
}

EnvironmentMap::EnvironmentMap(const EnvironmentMap& full, float floor)
    : width_(full.width_),
      height_(full.height_),
      texel_store_(full.texel_store_),
      texels_(full.texels_),
      floor_(floor),
      to_world_(full.to_world_),
      to_local_(full.to_local_),
      row_sin_(full.row_sin_),
      half_texel_(full.half_texel_),
      integral_(full.integral_),
      max_luminance_(full.max_luminance_),
      uniform_sampling_(full.uniform_sampling_) {
  // A corner weighs max(L - floor, 0) x sin(theta), and sin(theta) > 0 at every row: the density
  // is zero everywhere exactly when no texel is brighter than the floor.
  sampled_nowhere_ = !(max_luminance_ > floor_);
}

const Distribution2D& EnvironmentMap::distribution() const {
  std::call_once(distribution_built_, [this] { build_distribution(); });
  return distribution_;
}

// Cell (x, y) lies between rows y and y + 1, at polar angles theta0..theta1, and between the
// centres of texels x and x + 1. Sampling density: each corner (texel) carries its luminance x
// its row's sin(theta); within a cell the density is their bilinear interpolant, so a cell's
// weight is their mean. The sin(theta) factor keeps the poles, which the map stretches across
// a whole row, from drawing samples out of proportion to their solid angle (pbrt-v3 §14.2.4;
// Mitsuba's envmap weights its grid by sin(theta) too). A pole row's sin(theta) would be 0, and
// a map lit only there (or a one-row map, whose two rows are both poles) would then have no
// samples at all: the poles count as sin(theta) a quarter row in, which only shapes the density
// within their cells. So a cell is zero only if its four texels are, i.e. only where the
// radiance is zero (for the compensated twin, whose corners carry max(L - floor, 0): only where
// no corner is brighter than the mean).
// Built once, by the first sample or density asked of this map: a render samples either the
// full map (the distributed integrator) or its compensated twin (the path integrator), so the
// other's table, 8 bytes per texel (280 MB for an 8192 x 4096 map), is never made.
void EnvironmentMap::build_distribution() const {
  const int nu = width_, nv = height_ - 1;
  const auto corner_row = [&](int y, std::vector<float>& out) {
    for (int x = 0; x < nu; ++x) out[size_t(x)] = corner(x, y);
  };
  // The cells' weights go to the distribution row by row (no nu x nv array of them), in blocks
  // of rows on all cores. Within a block each texel's corner weight is computed once, in a pair
  // of row buffers (a block computes its first row's too, which the block before it computed as
  // its last): corner(x, y) is the value corners() computes for it, to the bit (the warp within a
  // cell reads corners()), so the weights do not depend on the blocks.
  distribution_ = Distribution2D(nu, nv, [&](int begin, int end, const Distribution2D::RowPut& put) {
    std::vector<float> row(static_cast<size_t>(nu)), next(static_cast<size_t>(nu)), weights(static_cast<size_t>(nu));
    corner_row(begin, row);
    for (int y = begin; y < end; ++y) {
      corner_row(y + 1, next);
      const auto cell = [&](size_t x0, size_t x1) {
        return float(0.25 * (double(row[x0]) + double(row[x1]) + double(next[x0]) + double(next[x1])));
      };
      // The last cell across the seam (texel 0), apart: no modulo, a division, per cell.
      for (size_t x = 0; x + 1 < size_t(nu); ++x) weights[x] = cell(x, x + 1);
      weights[size_t(nu) - 1] = cell(size_t(nu) - 1, 0);
      put(y, weights);
      row.swap(next);
    }
  });
  table_built_.store(true, std::memory_order_release);
}

EnvironmentMap::Corners EnvironmentMap::corners(int x, int y) const {
  const int x1 = x + 1 == width_ ? 0 : x + 1;
  return {corner(x, y), corner(x1, y), corner(x, y + 1), corner(x1, y + 1)};
}

float EnvironmentMap::corner(int x, int y) const {
  // (With floor_ 0 this is the luminance itself times sin(theta): texels are >= 0.)
  return std::max(luminance(texel(x, y)) - floor_, 0.f) * row_sin_[size_t(y)];
}

Spectrum EnvironmentMap::lookup(const TexelSpot& t) const {
  const Spectrum top = texel(t.x0, t.y0) * (1.f - t.tx) + texel(t.x1, t.y0) * t.tx;
  const Spectrum bottom = texel(t.x0, t.y0 + 1) * (1.f - t.tx) + texel(t.x1, t.y0 + 1) * t.tx;
  return top * (1.f - t.ty) + bottom * t.ty;
}

// The map's arithmetic over a chunk of lanes, in structure-of-arrays form so that GCC vectorises
// it (target clones); the texel and distribution loads between the kernels (scattered over the
// map) stay scalar loops, after prefetch hints for all the chunk's lanes. Every scalar entry
// point runs the same kernels on one lane, so a path's bits do not depend on the driver.
namespace {

constexpr size_t kChunk = 64;

struct MapShape {
  glm::mat3 to_world, to_local;
  int width, height;
  float half_texel;
};

// The lanes of radiance_and_pdf_many, after `locate`.
struct LocatedLanes {
  float sin_theta[kChunk];
  int cx[kChunk], cy[kChunk];  // the density's cell and the place in it
  float fx[kChunk], fy[kChunk];
  int x0[kChunk], x1[kChunk], y0[kChunk];  // the lookup's texels and weights
  float tx[kChunk], ty[kChunk];
};

// Each direction's lat-long coordinates, the cell of the distribution holding it (the one
// distribution_.pdf would find: cell coordinates start half a texel right of u) and the texels
// of its bilinear lookup.
PENUMBRA_SIMD_CLONES
void locate_kernel(size_t m, const vec3* __restrict dirs, const MapShape& __restrict shape,
                   LocatedLanes* __restrict out) {
  for (size_t k = 0; k < m; ++k) {
    const vec3 d = shape.to_local * dirs[k];
    const vec2 uv = EnvironmentMap::direction_to_uv(d);
    float s = uv.x - shape.half_texel;
    s = s < 0.f ? s + 1.f : s;
    out->sin_theta[k] = std::sqrt(d.x * d.x + d.z * d.z);
    const EnvironmentMap::CellPoint q = EnvironmentMap::cell_point(s, uv.y, shape.width, shape.height);
    out->cx[k] = q.x;
    out->cy[k] = q.y;
    out->fx[k] = q.fx;
    out->fy[k] = q.fy;
    const EnvironmentMap::TexelSpot t = EnvironmentMap::texel_spot(uv.x, uv.y, shape.width, shape.height);
    out->x0[k] = t.x0;
    out->x1[k] = t.x1;
    out->y0[k] = t.y0;
    out->tx[k] = t.tx;
    out->ty[k] = t.ty;
  }
}

// The lanes of sample_many's last stage.
struct CellLanes {
  int cx[kChunk], cy[kChunk];
  float fx[kChunk], fy[kChunk];  // the uniform point in the cell
  float w00[kChunk], w10[kChunk], w01[kChunk], w11[kChunk];  // the cell's corners
  float pdf_cell[kChunk];
};
struct WarpedLanes {
  int32_t ok[kChunk];  // 0 or 1: as wide as the floats, so the loop's masks need no conversion
  float wx[kChunk], wy[kChunk], wz[kChunk], pdf[kChunk];
  int x0[kChunk], x1[kChunk], y0[kChunk];
  float tx[kChunk], ty[kChunk];
};

// A sample of [0, 1] with density proportional to (1 - x) a + x b, 0 <= a, b <= 2 (pbrt-v4
// SampleLinear): the root of the CDF's quadratic in the form that stays accurate for a << b;
// a = b = 0 has no shape to follow (its density is 0 anyway) and keeps u.
inline float sample_linear(float u, float a, float b) {
  const float x = std::min(u * (a + b) / (a + std::sqrt((1.f - u) * a * a + u * b * b)), kOneMinusEpsilon);
  return !(a + b > 0.f) ? u : (u == 0.f && a == 0.f ? 0.f : x);
}

// GCC's tree PRE merges the lane's validity tests into selects between booleans of different
// widths, which its vectoriser refuses (as the metallic-roughness kernel's, surface_stage.cpp):
// without it the loop vectorises.
#if defined(__GNUC__) && !defined(__clang__)
#define PENUMBRA_WARP_NO_TREE_PRE __attribute__((optimize("no-tree-pre")))
#else
#define PENUMBRA_WARP_NO_TREE_PRE
#endif

// The bilinear warp within each cell (its density follows the bilinear interpolant of the
// corners), the direction, its density and the texels of its radiance lookup.
PENUMBRA_SIMD_CLONES PENUMBRA_WARP_NO_TREE_PRE
void warp_kernel(size_t m, const CellLanes& __restrict in, const MapShape& __restrict shape,
                 WarpedLanes* __restrict out) {
  for (size_t k = 0; k < m; ++k) {
    const float pdf_cell = in.pdf_cell[k];
    // The warp depends only on the corners' ratios: scaled to at most 1, their squares cannot
    // overflow (texels up to 1e30 are allowed).
    const float top = std::max(std::max(in.w00[k], in.w10[k]), std::max(in.w01[k], in.w11[k]));
    const bool usable = pdf_cell > 0.f && top > 0.f;
    const float inv = usable ? 1.f / top : 0.f;
    const float c00 = in.w00[k] * inv, c10 = in.w10[k] * inv, c01 = in.w01[k] * inv, c11 = in.w11[k] * inv;
    const float fy = sample_linear(in.fy[k], c00 + c10, c01 + c11);
    const float fx = sample_linear(in.fx[k], (1.f - fy) * c00 + fy * c01, (1.f - fy) * c10 + fy * c11);
    const float pdf_uv = pdf_cell * bilinear_pdf(fx, fy, c00, c10, c01, c11);
    float u = (float(in.cx[k]) + fx) / float(shape.width) + shape.half_texel;
    u = u >= 1.f ? u - 1.f : u;
    const float v = std::min((float(in.cy[k]) + fy) / float(shape.height - 1), 1.f);
    float sin_theta, cos_theta;
    sincos_two_pi(0.5f * v, &sin_theta, &cos_theta);  // theta = pi v
    const vec3 wi = shape.to_world * EnvironmentMap::uv_to_direction(u, sin_theta, cos_theta);
    const float pdf = pdf_uv * kInv2PiSquared / sin_theta;
    out->ok[k] = usable && pdf_uv > 0.f && sin_theta > kMinSinTheta && pdf > 0.f && std::isfinite(pdf) ? 1 : 0;
    out->wx[k] = wi.x;
    out->wy[k] = wi.y;
    out->wz[k] = wi.z;
    out->pdf[k] = pdf;
    const EnvironmentMap::TexelSpot t = EnvironmentMap::texel_spot(u, v, shape.width, shape.height);
    out->x0[k] = t.x0;
    out->x1[k] = t.x1;
    out->y0[k] = t.y0;
    out->tx[k] = t.tx;
    out->ty[k] = t.ty;
  }
}

}  // namespace

Spectrum EnvironmentMap::radiance(const vec3& dir) const {
  const uint8_t want = 0;
  Spectrum r;
  float unused = 0.f;
  radiance_and_pdf_many(1, &dir, &want, &r, &unused);
  return r;
}

bool EnvironmentMap::sample(const vec3& ref, float time, const vec2& u, LightSample* out) const {
  if (is_black()) return false;
  if (uniform_sampling_) {
    out->wi = square_to_uniform_sphere(u);
    out->pdf = uniform_sphere_pdf();
    out->value = radiance(out->wi);
    return finish_sample(out);
  }
  bool ok = false;
  sample_many(1, &ref, &time, &u, out, &ok);
  return ok;
}

void EnvironmentMap::sample_many(size_t n, const vec3* refs, const float* times, const vec2* u,
                                 LightSample* out, bool* ok) const {
  if (is_black() || uniform_sampling_) return Light::sample_many(n, refs, times, u, out, ok);
  // The chain of one sample (marginal search, the row's search, the cell's texels) is a series
  // of dependent loads; each stage's loads are independent across samples, so the processor
  // overlaps them. Chunks keep the stages' state on the stack.
  const MapShape shape{to_world_, to_local_, width_, height_, half_texel_};
  const Distribution2D& table = distribution();
  for (size_t k0 = 0; k0 < n; k0 += kChunk) {
    const size_t m = std::min(kChunk, n - k0);
    int row[kChunk], column[kChunk];
    float v[kChunk], x[kChunk];
    CellLanes cells;
    WarpedLanes warped;
    float ux[kChunk], uy[kChunk];
    for (size_t k = 0; k < m; ++k) ux[k] = u[k0 + k].x, uy[k] = u[k0 + k].y;
    table.sample_rows(m, uy, row, v);
    for (size_t k = 0; k < m; ++k) table.prefetch_column(row[k], ux[k]);
    table.sample_columns(m, row, ux, column, x);
    for (size_t k = 0; k < m; ++k) {
      table.prefetch_cell(column[k], row[k]);
      __builtin_prefetch(texel_address(column[k], row[k]));
      __builtin_prefetch(texel_address(column[k], row[k] + 1));
    }
    for (size_t k = 0; k < m; ++k) {
      cells.pdf_cell[k] = table.cell_pdf(column[k], row[k]);
      // A uniform point of the cell (its row and column were drawn independently), which the
      // bilinear warp then reshapes.
      const CellPoint q = cell_point(x[k], v[k], width_, height_);
      const Corners c = corners(q.x, q.y);
      cells.cx[k] = q.x, cells.cy[k] = q.y, cells.fx[k] = q.fx, cells.fy[k] = q.fy;
      cells.w00[k] = c.w00, cells.w10[k] = c.w10, cells.w01[k] = c.w01, cells.w11[k] = c.w11;
    }
    warp_kernel(m, cells, shape, &warped);
    for (size_t k = 0; k < m; ++k) {
      LightSample& s = out[k0 + k];
      ok[k0 + k] = warped.ok[k] != 0;
      if (!warped.ok[k]) continue;
      s.wi = vec3(warped.wx[k], warped.wy[k], warped.wz[k]);
      s.pdf = warped.pdf[k];
      s.value = lookup(TexelSpot{warped.x0[k], warped.x1[k], warped.y0[k], warped.tx[k], warped.ty[k]});
      finish_sample(&s);
    }
  }
}

float EnvironmentMap::pdf(const vec3& dir) const {
  float p = 0.f;
  radiance_and_pdf(dir, &p);
  return p;
}

Spectrum EnvironmentMap::radiance_and_pdf(const vec3& dir, float* pdf) const {
  const uint8_t want = pdf ? 1 : 0;
  Spectrum r;
  float p = 0.f;
  radiance_and_pdf_many(1, &dir, &want, &r, &p);
  if (pdf) *pdf = p;
  return r;
}

void EnvironmentMap::radiance_and_pdf_many(size_t n, const vec3* dirs, const uint8_t* want_pdf,
                                           Spectrum* radiance, float* pdf) const {
  const MapShape shape{to_world_, to_local_, width_, height_, half_texel_};
  // The density: 0 for a black map, the sphere's for uniform sampling, else the bilinear density
  // of the direction's cell (pbrt-v3 §14.2.4's Jacobian 1 / (2 pi^2 sin theta) per steradian; 0
  // within kMinSinTheta of a pole, as sample() draws nothing there).
  const int density = is_black() ? 0 : uniform_sampling_ ? 1 : 2;
  // The table only where a density is asked for: a radiance lookup alone (an escape after a
  // delta bounce, the first-hit record) leaves it unbuilt.
  const Distribution2D* table =
      density == 2 && std::any_of(want_pdf, want_pdf + n, [](uint8_t w) { return w != 0; }) ? &distribution()
                                                                                          : nullptr;
  for (size_t k0 = 0; k0 < n; k0 += kChunk) {
    const size_t m = std::min(kChunk, n - k0);
    LocatedLanes lanes;
    locate_kernel(m, dirs + k0, shape, &lanes);
    for (size_t k = 0; k < m; ++k) {
      if (table && want_pdf[k0 + k]) table->prefetch_cell(lanes.cx[k], lanes.cy[k]);
      __builtin_prefetch(texel_address(lanes.x0[k], lanes.y0[k]));
      __builtin_prefetch(texel_address(lanes.x0[k], lanes.y0[k] + 1));
    }
    for (size_t k = 0; k < m; ++k) {
      if (want_pdf[k0 + k]) {
        float p = density == 1 ? uniform_sphere_pdf() : 0.f;
        const float pdf_cell = table ? table->cell_pdf(lanes.cx[k], lanes.cy[k]) : 0.f;
        if (pdf_cell > 0.f && lanes.sin_theta[k] > kMinSinTheta) {
          const Corners c = corners(lanes.cx[k], lanes.cy[k]);
          p = pdf_cell * bilinear_pdf(lanes.fx[k], lanes.fy[k], c.w00, c.w10, c.w01, c.w11) *
              kInv2PiSquared / lanes.sin_theta[k];
          p = std::isfinite(p) ? p : 0.f;
        }
        pdf[k0 + k] = p;
      }
      radiance[k0 + k] = lookup(TexelSpot{lanes.x0[k], lanes.x1[k], lanes.y0[k], lanes.tx[k], lanes.ty[k]});
    }
  }
}

float EnvironmentMap::power(float scene_radius) const {
  return float(integral_ * M_PI * double(scene_radius) * double(scene_radius));
}

}  // namespace penumbra
