// The environment map: Mitsuba 3's lat-long orientation and bilinear lookup, importance sampling
// (chi-square against pdf(), pdf integrating to 1 over the sphere, sample/pdf agreement, a density
// proportional to radiance), its power, degenerate maps (black, one texel, one hot texel), and the
// MIS-compensated twin the path integrator samples (a density over max(L - mean L, 0)).
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>
#include <memory>
#include <vector>

#include "renderer/lights/environment_light.h"
#include "renderer/lights/environment_map.h"
#include "renderer/sampling/sampling.h"
#include "tests/renderer/sampling/chi2_util.h"

namespace penumbra::test {
namespace {

// A width x height map whose texel (x, y) holds f(x, y) in every channel.
template <typename F>
EnvironmentMapDesc make_map(int width, int height, F f) {
  EnvironmentMapDesc d;
  d.width = width;
  d.height = height;
  auto rgb = std::make_shared<std::vector<float>>(size_t(width) * height * 3);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) (*rgb)[(size_t(y) * width + x) * 3 + c] = f(x, y);
  d.rgb = std::move(rgb);
  return d;
}

// A smooth sky with a sun: enough structure for the sampling tests, with a seam-crossing sun.
EnvironmentMapDesc sky_with_sun(int width, int height) {
  return make_map(width, height, [&](int x, int y) {
    const float sun = (x == width - 1 || x == 0) && y == height / 3 ? 500.f : 0.f;
    return 0.2f + float(y) / height + 0.1f * float(x % 3) + sun;
  });
}

glm::mat3 rotation(float degrees, const vec3& axis) {
  return glm::mat3(glm::rotate(glm::mat4(1.f), glm::radians(degrees), axis));
}

float value(const EnvironmentMapDesc& d, int x, int y) { return (*d.rgb)[(size_t(y) * d.width + x) * 3]; }

TEST(EnvironmentMap, OrientationMatchesMitsubaEnvmap) {
  // Odd width: +z lands on a texel centre. Rows: 0 at +y, 2 at the horizon, 4 at -y.
  const auto desc = make_map(9, 5, [](int x, int y) {
    if (y == 0) return 100.f;
    if (y == 4) return 200.f;
    return float(1 + x + 10 * y);
  });
  const EnvironmentMap map(desc);
  EXPECT_FLOAT_EQ(map.radiance({0, 1, 0}).x, 100.f);   // +y: the top row
  EXPECT_FLOAT_EQ(map.radiance({0, -1, 0}).x, 200.f);  // -y: the bottom row
  EXPECT_FLOAT_EQ(map.radiance({0, 0, 1}).x, value(desc, 4, 2));  // +z: the centre column
  // -z: the left and right edges, which the lookup blends across the seam.
  EXPECT_FLOAT_EQ(map.radiance({0, 0, -1}).x, 0.5f * (value(desc, 0, 2) + value(desc, 8, 2)));
  // +x at u = 1/4 (x = 1.75 texels), -x at u = 3/4 (x = 6.25): right-handed, as Mitsuba.
  EXPECT_FLOAT_EQ(map.radiance({1, 0, 0}).x, 0.25f * value(desc, 1, 2) + 0.75f * value(desc, 2, 2));
  EXPECT_FLOAT_EQ(map.radiance({-1, 0, 0}).x, 0.75f * value(desc, 6, 2) + 0.25f * value(desc, 7, 2));
  // Between rows: theta = 67.5 degrees is halfway from row 1 (45) to row 2 (90).
  const float t = glm::radians(67.5f);
  EXPECT_NEAR(map.radiance({0, std::cos(t), std::sin(t)}).x,
              0.5f * (value(desc, 4, 1) + value(desc, 4, 2)), 1e-4f);
}

TEST(EnvironmentMap, ToWorldTurnsTheMap) {
  auto desc = make_map(9, 5, [](int x, int y) { return float(1 + x + 10 * y); });
  const EnvironmentMap plain(desc);
  desc.to_world = rotation(90.f, {0, 1, 0});  // right-handed about +y: +z -> +x
  const EnvironmentMap turned(desc);
  // The map's centre column (+z in map space) now faces +x.
  EXPECT_FLOAT_EQ(turned.radiance({1, 0, 0}).x, value(desc, 4, 2));
  Rng rng(3);
  for (int i = 0; i < 100; ++i) {
    const vec3 d = uniform_sphere(rng);
    EXPECT_NEAR(turned.radiance(desc.to_world * d).x, plain.radiance(d).x, 1e-3f);
    EXPECT_NEAR(turned.pdf(desc.to_world * d), plain.pdf(d), 1e-3f * plain.pdf(d) + 1e-6f);
  }
}

TEST(EnvironmentMap, UvAndDirectionAreInverse) {
  Rng rng(9);
  for (int i = 0; i < 1000; ++i) {
    const vec2 uv(rng.next(), 0.01f + 0.98f * rng.next());
    const vec2 back = EnvironmentMap::direction_to_uv(EnvironmentMap::uv_to_direction(uv));
    EXPECT_NEAR(back.x, uv.x, 1e-4f);
    EXPECT_NEAR(back.y, uv.y, 1e-4f);
  }
}

// Integral of pdf() over the sphere in world (theta, phi) coordinates about +y, by its own cubature
// rather than the map's lat-long parameterisation. A map's density per steradian grows as
// 1 / sin(theta) towards a pole, which the measure's sin(theta) cancels about the unrotated map's
// poles: a map lit at a pole integrates as accurately as any other (over cos(theta) about z its
// integral came out 1.6% low).
double pdf_integral(const EnvironmentLight& env) {
  AdaptiveCubature cubature([&](double theta, double phi) {
    const double s = std::sin(theta);
    return s * double(env.pdf(vec3(float(s * std::cos(phi)), float(std::cos(theta)), float(s * std::sin(phi)))));
  }, 12);
  double total = 0.0;
  constexpr int n = 32;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      total += cubature.integrate(M_PI * i / n, M_PI * (i + 1) / n, 2 * M_PI * j / n,
                                  2 * M_PI * (j + 1) / n, 1e-7);
  return total;
}

TEST(EnvironmentMap, PdfIntegratesToOneOverTheSphere) {
  auto desc = sky_with_sun(16, 9);
  desc.to_world = rotation(30.f, glm::normalize(vec3(1, 2, 0.5f)));
  EXPECT_NEAR(pdf_integral(EnvironmentMap(desc)), 1.0, 2e-3);
  desc.uniform_sampling = true;
  EXPECT_NEAR(pdf_integral(EnvironmentMap(desc)), 1.0, 1e-4);
}

// Whether sample()'s directions follow pdf(), by a chi-square test over bins in world
// (cos theta, phi).
void expect_sampling_follows_pdf(const EnvironmentMap& map) {
  // Bins in world (cos theta, phi); expected counts by cubature of pdf().
  constexpr int nt = 16, np = 32, samples = 300000;
  std::vector<double> observed(nt * np, 0.0), expected(nt * np, 0.0);
  Rng rng(21);
  for (int i = 0; i < samples; ++i) {
    LightSample ls;
    if (!map.sample(vec3(0.f), 0.f, rng.next2(), &ls)) continue;
    float phi = std::atan2(ls.wi.y, ls.wi.x);
    if (phi < 0.f) phi += 2.f * kPi;
    const int ti = std::clamp(int((ls.wi.z + 1.f) * 0.5f * nt), 0, nt - 1);
    const int pi = std::clamp(int(phi / (2.f * kPi) * np), 0, np - 1);
    observed[size_t(ti * np + pi)] += 1.0;
  }
  AdaptiveCubature cubature([&](double c, double phi) {
    const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
    return double(map.pdf(vec3(float(s * std::cos(phi)), float(s * std::sin(phi)), float(c))));
  }, 12);
  for (int ti = 0; ti < nt; ++ti)
    for (int pi = 0; pi < np; ++pi)
      expected[size_t(ti * np + pi)] =
          samples * cubature.integrate(-1.0 + 2.0 * ti / nt, -1.0 + 2.0 * (ti + 1) / nt,
                                       2 * M_PI * pi / np, 2 * M_PI * (pi + 1) / np, 1e-8);
  const auto fit = chi2_goodness_of_fit(observed, expected);
  EXPECT_TRUE(fit.pass) << fit.message;
}

TEST(EnvironmentMap, SamplingFollowsPdfChiSquare) {
  auto desc = sky_with_sun(12, 7);
  desc.to_world = rotation(-50.f, glm::normalize(vec3(0.3f, 1, -1)));
  expect_sampling_follows_pdf(EnvironmentMap(desc));
}

TEST(EnvironmentMap, SampleAgreesWithPdfAndRadiance) {
  auto desc = sky_with_sun(32, 17);
  desc.to_world = rotation(120.f, glm::normalize(vec3(-1, 0.2f, 0.4f)));
  desc.scale = 2.5f;
  const EnvironmentMap map(desc);
  Rng rng(4);
  int accepted = 0;
  for (int i = 0; i < 20000; ++i) {
    LightSample ls;
    if (!map.sample(vec3(1, 2, 3), 0.f, rng.next2(), &ls)) continue;
    ++accepted;
    ASSERT_NEAR(glm::length(ls.wi), 1.f, 1e-5f);
    EXPECT_FALSE(ls.is_delta);
    EXPECT_EQ(ls.distance, kInfinity);
    ASSERT_NEAR(ls.pdf, map.pdf(ls.wi), 2e-3f * ls.pdf);
    const Spectrum l = map.radiance(ls.wi);
    ASSERT_NEAR(ls.value.x, l.x, 2e-3f * l.x + 1e-5f);
  }
  EXPECT_GT(accepted, 19990);
}

// An escaped ray asks for both at once; they must be radiance() and pdf() to the bit (images
// depend on it), for sampled and uniform maps and a black one, and no pdf where none is asked.
TEST(EnvironmentMap, RadianceAndPdfAreRadianceAndPdfToTheBit) {
  auto sky = sky_with_sun(32, 17);
  sky.to_world = rotation(70.f, glm::normalize(vec3(0.3f, 1, -0.2f)));
  auto uniform = sky;
  uniform.uniform_sampling = true;
  EnvironmentMapDesc black = make_map(8, 4, [](int, int) { return 0.f; });
  Rng rng(9);
  for (const EnvironmentMapDesc* desc : {&sky, &uniform, &black}) {
    const EnvironmentMap map(*desc);
    const EnvironmentLight& light = map;
    for (int i = 0; i < 5000; ++i) {
      const vec3 dir = square_to_uniform_sphere(rng.next2());
      float pdf = -1.f;
      const Spectrum l = light.radiance_and_pdf(dir, &pdf);
      const Spectrum expected = map.radiance(dir);
      for (int c = 0; c < 3; ++c) ASSERT_EQ(l[c], expected[c]);
      ASSERT_EQ(pdf, map.pdf(dir));
      const Spectrum alone = light.radiance_and_pdf(dir, nullptr);
      for (int c = 0; c < 3; ++c) ASSERT_EQ(alone[c], expected[c]);
    }
    // Many at once (across chunk boundaries), the pdf asked for by some: the same values, and
    // no pdf written where none was asked for.
    constexpr size_t n = 333;
    std::vector<vec3> dirs(n);
    std::vector<uint8_t> want(n);
    for (size_t k = 0; k < n; ++k) {
      dirs[k] = square_to_uniform_sphere(rng.next2());
      want[k] = uint8_t(k % 3 != 1);
    }
    std::vector<Spectrum> radiance(n);
    std::vector<float> pdf(n, -7.f);
    light.radiance_and_pdf_many(n, dirs.data(), want.data(), radiance.data(), pdf.data());
    for (size_t k = 0; k < n; ++k) {
      const Spectrum expected = map.radiance(dirs[k]);
      for (int c = 0; c < 3; ++c) ASSERT_EQ(radiance[k][c], expected[c]) << k;
      ASSERT_EQ(pdf[k], want[k] ? map.pdf(dirs[k]) : -7.f) << k;
    }
  }
}

// sample_many runs sample()'s chain in stages over many requests: each result must be the one
// sample() gives for that request, to the bit, failures included (a map with black regions), for
// any count (chunk boundaries), with uniform sampling and for a black map.
TEST(EnvironmentMap, SampleManyIsSampleToTheBit) {
  auto sky = sky_with_sun(32, 17);
  sky.to_world = rotation(70.f, glm::normalize(vec3(0.3f, 1, -0.2f)));
  auto patchy = make_map(24, 9, [](int x, int y) { return (x / 4 + y) % 3 == 0 ? 0.f : 1.f + x; });
  auto uniform = sky;
  uniform.uniform_sampling = true;
  EnvironmentMapDesc black = make_map(8, 4, [](int, int) { return 0.f; });
  Rng rng(17);
  for (const EnvironmentMapDesc* desc : {&sky, &patchy, &uniform, &black})
    for (const bool compensated : {false, true}) {
    const EnvironmentMap full(*desc);
    const auto twin = full.compensated();
    if (compensated && !twin) continue;  // (uniform and black maps have none)
    const EnvironmentMap& map = compensated ? *twin : full;
    for (const size_t n : {size_t(1), size_t(63), size_t(64), size_t(65), size_t(300)}) {
      std::vector<vec3> refs(n, vec3(0.5f, -1.f, 2.f));
      std::vector<float> times(n, 0.25f);
      std::vector<vec2> u(n);
      for (vec2& x : u) x = rng.next2();
      u[0] = vec2(0.f);  // the distributions' ends
      if (n > 1) u[n - 1] = vec2(kOneMinusEpsilon);
      std::vector<LightSample> out(n);
      std::unique_ptr<bool[]> ok = std::make_unique<bool[]>(n);
      map.sample_many(n, refs.data(), times.data(), u.data(), out.data(), ok.get());
      int failures = 0;
      for (size_t k = 0; k < n; ++k) {
        LightSample one;
        const bool expected = map.sample(refs[k], times[k], u[k], &one);
        ASSERT_EQ(ok[k], expected) << k;
        if (!expected) {
          ++failures;
          continue;
        }
        ASSERT_EQ(out[k].pdf, one.pdf);
        ASSERT_EQ(out[k].distance, one.distance);
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(out[k].wi[c], one.wi[c]);
          ASSERT_EQ(out[k].value[c], one.value[c]);
        }
      }
      if (desc == &black) {
        EXPECT_EQ(failures, int(n));
      }
    }
  }
}

// For a constant map the ideal density is uniform over the sphere, 1 / (4 pi). Without the
// sin(theta) weight the cells near the poles, stretched over whole rows, would take as many
// samples as the cells at the horizon (density 1 / (2 pi^2 sin(theta)) instead).
TEST(EnvironmentMap, DensityOfAConstantMapIsUniform) {
  constexpr int width = 64, height = 33;
  const EnvironmentMap map(make_map(width, height, [](int, int) { return 3.f; }));
  for (int row = 0; row < height - 1; ++row) {
    const float theta = kPi * (row + 0.5f) / (height - 1);  // the middle of a band of cells
    // The density within a cell is bilinear in its corners' sin(theta): within 2e-3 of sin(theta)
    // itself except in the two bands at the poles, whose pole corners count sin(theta) a quarter
    // row in (environment_map.cpp), 25% high in their middle.
    const bool pole = row == 0 || row == height - 2;
    for (float phi : {0.1f, 1.f, 2.5f, 4.f}) {
      const vec3 d(std::sin(phi) * std::sin(theta), std::cos(theta), -std::cos(phi) * std::sin(theta));
      EXPECT_NEAR(map.pdf(d) * 4.f * kPi, 1.f, pole ? 0.3f : 2e-3f) << "theta " << theta << " phi " << phi;
    }
  }
  EXPECT_NEAR(map.luminance_integral(), 4.0 * M_PI * 3.0, 1e-4);
}

TEST(EnvironmentMap, PowerIsConstantEnvironmentsForAConstantMap) {
  const EnvironmentMap map(make_map(8, 4, [](int, int) { return 0.7f; }));
  const ConstantEnvironment constant(Spectrum(0.7f));
  EXPECT_NEAR(map.power(3.f), constant.power(3.f), 1e-5f * constant.power(3.f));
}

TEST(EnvironmentMap, BlackMapEmitsNothingAndDividesByNothing) {
  const EnvironmentMap black(make_map(16, 8, [](int, int) { return 0.f; }));
  EXPECT_TRUE(black.is_black());
  LightSample ls;
  EXPECT_FALSE(black.sample(vec3(0.f), 0.f, vec2(0.3f, 0.6f), &ls));
  EXPECT_EQ(black.pdf(vec3(0, 0, 1)), 0.f);
  EXPECT_EQ(black.power(10.f), 0.f);
  auto scaled = make_map(4, 4, [](int, int) { return 1.f; });
  scaled.scale = 0.f;
  EXPECT_TRUE(EnvironmentMap(scaled).is_black());
  // Negative and non-finite texels count as black.
  EXPECT_TRUE(EnvironmentMap(make_map(4, 2, [](int x, int) { return x == 0 ? -5.f : NAN; })).is_black());
  // Missing pixels (an inconsistent description) are a black 1x1 map, not a crash.
  EnvironmentMapDesc empty;
  empty.width = 5;
  empty.height = 5;
  EXPECT_TRUE(EnvironmentMap(empty).is_black());
}

// Scale applies to the radiance, the samples and the power, also for a texel near the float
// maximum under a small scale (what the loader allows: brightest texel x scale <= 1e30).
TEST(EnvironmentMap, ScaleAppliesToRadianceSamplesAndPower) {
  constexpr float kTexel = 3e38f, kScale = 1e-10f;
  auto desc = make_map(16, 8, [](int x, int y) { return x == 3 && y == 4 ? kTexel : 0.f; });
  desc.scale = kScale;
  const EnvironmentMap map(desc);
  ASSERT_FALSE(map.is_black());
  // The texel's centre: u = 3.5 / 16, v = 4 / 7.
  const vec3 centre = EnvironmentMap::uv_to_direction(vec2(3.5f / 16.f, 4.f / 7.f));
  EXPECT_NEAR(map.radiance(centre).x, kTexel * kScale, 1e-3f * kTexel * kScale);
  // Four cells (columns 2, 3; rows 3, 4) hold a quarter of the texel each, 2 pi / 16 wide.
  auto band = [](int y) { return std::cos(M_PI * y / 7) - std::cos(M_PI * (y + 1) / 7); };
  const double integral = 0.25 * double(kTexel) * kScale * 2 * (band(3) + band(4)) * 2 * M_PI / 16;
  EXPECT_NEAR(map.luminance_integral(), integral, 1e-5 * integral);
  LightSample ls;
  ASSERT_TRUE(map.sample(vec3(0.f), 0.f, vec2(0.5f, 0.5f), &ls));
  EXPECT_TRUE(is_finite(ls.value / ls.pdf));
  EXPECT_GT(ls.value.x, 0.f);
  EXPECT_LE(ls.value.x, kTexel * kScale * 1.0001f);
}

// The light reads the scene input's texels in place where they are final (scale 1, clean, two
// rows or more: the api's maps) and makes its own scaled, cleaned copy otherwise; either way a
// map and its pre-scaled twin give the same radiance and density to the bit.
TEST(EnvironmentMap, SharesTheInputsTexelsWhereTheyAreFinal) {
  const auto f = [](int x, int y) { return 0.25f + 0.5f * float(x) + float(y * y) + (x == 5) * 40.f; };
  EnvironmentMapDesc final_map = make_map(16, 8, f);
  {
    const EnvironmentMap map(final_map);
    EXPECT_EQ(final_map.rgb.use_count(), 2);  // shared
  }
  EnvironmentMapDesc scaled = make_map(16, 8, [&](int x, int y) { return f(x, y) / 4.f; });
  scaled.scale = 4.f;
  const auto copies = [](const EnvironmentMapDesc& d) {
    const EnvironmentMap map(d);
    return d.rgb.use_count() == 1;
  };
  EXPECT_TRUE(copies(scaled));
  EnvironmentMapDesc one_row = make_map(16, 1, f);
  EXPECT_TRUE(copies(one_row));
  for (const float bad : {-1.f, -0.f, std::numeric_limits<float>::quiet_NaN(),
                          std::numeric_limits<float>::infinity()}) {
    EnvironmentMapDesc unclean = make_map(16, 8, f);
    auto rgb = std::make_shared<std::vector<float>>(*unclean.rgb);
    (*rgb)[37 * 3 + 1] = bad;
    unclean.rgb = std::move(rgb);
    EXPECT_TRUE(copies(unclean)) << bad;
  }
  // Shared or copied, the same light: f / 4 x 4 is f exactly (powers of two).
  const EnvironmentMap shared(final_map), copied(scaled);
  for (int i = 0; i < 200; ++i) {
    const vec3 d = EnvironmentMap::uv_to_direction(vec2((float(i) + 0.3f) / 200.f, (float(i % 17) + 0.5f) / 17.f));
    float pdf_shared = 0.f, pdf_copied = 0.f;
    EXPECT_EQ(shared.radiance_and_pdf(d, &pdf_shared), copied.radiance_and_pdf(d, &pdf_copied));
    EXPECT_EQ(pdf_shared, pdf_copied);
  }
}

// An 8192 x 4096 map's loading runs in blocks of rows on all cores (renderer/core/row_blocks.h:
// 65536 cells a block): the texels' check (shared or copied) and the sampling table's rows.
// Against a reference computed here one row at a time, the way the light did before, to the bit:
// the luminance integral (summed in row-major order) and every number of both tables (full map
// and twin), for maps whose rows make several blocks with a shorter last one (1000 x 200: 65 rows
// a block, and 4 left; 3000 x 50: 21 and 7), one column (65536 rows a block: two blocks), rows
// wider than a block (one row a block), one row, and two rows.
void expect_table_is_one_row_at_a_time(const EnvironmentMap& map, const std::vector<float>& lum, int nu,
                                       int height, float floor, const std::string& where) {
  const int nv = height - 1;
  std::vector<float> row_sin(static_cast<size_t>(height));
  const double pole_sin = std::sin(M_PI / (4.0 * nv));
  for (int y = 0; y < height; ++y) row_sin[size_t(y)] = float(std::max(std::sin(M_PI * y / nv), pole_sin));
  const auto corner = [&](int x, int y) {
    return std::max(lum[size_t(y) * size_t(nu) + size_t(x)] - floor, 0.f) * row_sin[size_t(y)];
  };
  std::vector<float> weights(size_t(nu) * size_t(nv));
  for (int y = 0; y < nv; ++y)
    for (int x = 0; x < nu; ++x) {
      const int x1 = (x + 1) % nu;
      weights[size_t(y) * size_t(nu) + size_t(x)] =
          float(0.25 * (double(corner(x, y)) + double(corner(x1, y)) + double(corner(x, y + 1)) + double(corner(x1, y + 1))));
    }
  // One block of every row: built one row after the other (Distribution2D's own test checks that
  // against Distribution1D rows).
  const Distribution2D reference(nu, nv, [&](int begin, int end, const Distribution2D::RowPut& put) {
    for (int y = begin; y < end; ++y) put(y, std::span<const float>(weights).subspan(size_t(y) * size_t(nu), size_t(nu)));
  }, nv);
  const Distribution2D& table = map.sampling_table();
  const auto bits = [](float v) { return std::bit_cast<uint32_t>(v); };
  ASSERT_EQ(table.nu(), nu) << where;
  ASSERT_EQ(table.nv(), nv) << where;
  ASSERT_EQ(table.integral(), reference.integral()) << where;
  ASSERT_EQ(table.search_steps(), reference.search_steps()) << where;
  for (int y = 0; y <= nv; ++y) ASSERT_EQ(bits(table.marginal().cdf()[size_t(y)]), bits(reference.marginal().cdf()[size_t(y)])) << where;
  for (int y = 0; y < nv; ++y) {
    for (int x = 0; x <= nu; ++x)
      ASSERT_EQ(bits(table.row_cdf(y)[size_t(x)]), bits(reference.row_cdf(y)[size_t(x)])) << where << " row " << y;
    ASSERT_TRUE(std::ranges::equal(table.row_guide(y), reference.row_guide(y))) << where << " row " << y;
    for (int x = 0; x < nu; ++x) ASSERT_EQ(bits(table.cell_pdf(x, y)), bits(reference.cell_pdf(x, y))) << where << " cell " << x << ", " << y;
  }
}

TEST(EnvironmentMap, BlocksOfRowsGiveTheOneRowAtATimeIntegralAndTablesToTheBit) {
  for (const auto& [width, height] : std::vector<std::pair<int, int>>{
           {1000, 200}, {3000, 50}, {1, 70000}, {70000, 3}, {16, 1}, {9, 2}}) {
    const std::string where = std::to_string(width) + " x " + std::to_string(height);
    uint32_t state = uint32_t(width * 31 + height);
    const auto next = [&] {
      state = state * 1664525u + 1013904223u;
      return float(state >> 8) * 0x1p-24f;
    };
    EnvironmentMapDesc desc = make_map(width, height, [&](int x, int y) {
      // A sky with texture, a sun and a black patch (corners at 0, and below the twin's floor).
      return (x * 7 + y * 3) % 50 == 0 ? 0.f : 0.1f + next() * float(1 + y % 5) + (x == width / 3 && y == height / 2) * 1e4f;
    });
    auto rgb = std::make_shared<std::vector<float>>(*desc.rgb);
    for (size_t i = 1; i < rgb->size(); i += 3) (*rgb)[i] *= 0.5f + next();  // green unlike red and blue
    desc.rgb = rgb;
    const EnvironmentMap map(desc);
    // Shared where final (held by desc, rgb and the light), copied for one row.
    EXPECT_EQ(desc.rgb.use_count(), height >= 2 ? 3 : 2) << where;
    // The reference: each texel's luminance (a one-row map stands at both poles), the integral
    // summed cell by cell in row-major order.
    const int rows = std::max(height, 2), nu = width, nv = rows - 1;
    std::vector<float> lum(size_t(nu) * size_t(rows));
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < nu; ++x) {
        const float* t = &(*rgb)[(size_t(std::min(y, height - 1)) * size_t(nu) + size_t(x)) * 3];
        lum[size_t(y) * size_t(nu) + size_t(x)] = luminance(Spectrum(t[0], t[1], t[2]));
      }
    double sum = 0.0;
    for (int y = 0; y < nv; ++y) {
      const double band = std::cos(M_PI * y / nv) - std::cos(M_PI * (y + 1) / nv);
      for (int x = 0; x < nu; ++x) {
        const size_t x0 = size_t(x), x1 = size_t((x + 1) % nu), r = size_t(y) * size_t(nu), n = r + size_t(nu);
        sum += 0.25 * (double(lum[r + x0]) + lum[r + x1] + lum[n + x0] + lum[n + x1]) * band;
      }
    }
    const double integral = sum * (2.0 * M_PI / nu);
    ASSERT_EQ(map.luminance_integral(), integral) << where;
    expect_table_is_one_row_at_a_time(map, lum, nu, rows, 0.f, where);
    const auto twin = map.compensated();
    ASSERT_TRUE(twin) << where;
    // The twin samples somewhere exactly when a texel is brighter than the mean: the brightest.
    EXPECT_FALSE(twin->left_to_bsdf_sampling()) << where;
    expect_table_is_one_row_at_a_time(*twin, lum, nu, rows, float(integral / (4.0 * M_PI)), where + " (twin)");
  }
}

// The texels' check in blocks (4096 values a chunk, 16 chunks a block): a value the light would
// clean anywhere, in the first chunk, a middle one or the last, shorter chunk of the last,
// shorter block, makes it copy the texels.
TEST(EnvironmentMap, AnUncleanTexelInAnyBlockIsCopied) {
  const auto f = [](int x, int y) { return 0.5f + float((x + y) % 7); };
  const size_t n = size_t(1000) * 200 * 3;  // 146 full chunks and one of 1984 values
  for (const size_t at : {size_t(0), size_t(65536), n / 2 + 1, n - 1984, n - 1}) {
    EnvironmentMapDesc unclean = make_map(1000, 200, f);
    auto rgb = std::make_shared<std::vector<float>>(*unclean.rgb);
    (*rgb)[at] = -0.f;
    unclean.rgb = std::move(rgb);
    {
      const EnvironmentMap map(unclean);
      EXPECT_EQ(unclean.rgb.use_count(), 1) << at;
    }
  }
  const EnvironmentMapDesc clean = make_map(1000, 200, f);
  const EnvironmentMap map(clean);
  EXPECT_EQ(clean.rgb.use_count(), 2);
}

TEST(EnvironmentMap, OneTexelMapIsConstant) {
  const EnvironmentMap map(make_map(1, 1, [](int, int) { return 2.f; }));
  EXPECT_FALSE(map.is_black());
  for (const vec3& d : {vec3(0, 1, 0), vec3(0, -1, 0), vec3(0, 0, -1), glm::normalize(vec3(1, 1, 1))})
    EXPECT_FLOAT_EQ(map.radiance(d).y, 2.f);
  EXPECT_NEAR(pdf_integral(map), 1.0, 2e-3);
  Rng rng(8);
  for (int i = 0; i < 2000; ++i) {
    LightSample ls;
    if (!map.sample(vec3(0.f), 0.f, rng.next2(), &ls)) continue;
    ASSERT_TRUE(std::isfinite(ls.pdf) && ls.pdf > 0.f);
    ASSERT_TRUE(is_finite(ls.value / ls.pdf));
  }
}

// Within a cell the density follows the bilinear radiance (as Mitsuba's warp does), not a constant:
// beside a one-texel sun the light falls off across the cell, and so must the density, or the
// samples that land where the light is faint carry large weights. pdf x sin(theta) / luminance is
// then the same all over the cell, up to sin(theta)'s own change across it (0.5% at the equator).
TEST(EnvironmentMap, DensityWithinACellFollowsTheBilinearRadiance) {
  constexpr int width = 64, height = 33, hx = 20, hy = 16;  // row 16: the equator
  const EnvironmentMap map(make_map(width, height, [&](int x, int y) { return x == hx && y == hy ? 50.f : 0.01f; }));
  double lo = 1e30, hi = 0.0;
  for (float fx = 0.05f; fx < 1.f; fx += 0.15f)
    for (float fy = 0.05f; fy < 1.f; fy += 0.15f) {
      const vec2 uv((float(hx) + 0.5f + fx) / width, (float(hy) + fy) / (height - 1));
      const vec3 d = EnvironmentMap::uv_to_direction(uv);
      const double ratio = double(map.pdf(d)) * std::sin(uv.y * kPi) / luminance(map.radiance(d));
      lo = std::min(lo, ratio);
      hi = std::max(hi, ratio);
    }
  EXPECT_LT(hi / lo, 1.01) << lo << " .. " << hi;
}

// One hot texel (a sun of one pixel) on a black map, on the seam and on a pole row: every sample
// lands next to it with a finite weight, and the density still integrates to 1.
TEST(EnvironmentMap, OneHotTexelIsSampledWithFiniteWeights) {
  for (const auto& [hx, hy] : {std::pair{10, 7}, std::pair{63, 12}, std::pair{5, 0}}) {
    const auto desc = make_map(64, 32, [&](int x, int y) { return x == hx && y == hy ? 1e6f : 0.f; });
    const EnvironmentMap map(desc);
    Rng rng(17);
    int accepted = 0;
    for (int i = 0; i < 5000; ++i) {
      LightSample ls;
      if (!map.sample(vec3(0.f), 0.f, rng.next2(), &ls)) continue;
      ++accepted;
      ASSERT_TRUE(std::isfinite(ls.pdf) && ls.pdf > 0.f);
      const Spectrum w = ls.value / ls.pdf;
      ASSERT_TRUE(is_finite(w));
      // Bounded: the warp follows the bilinear radiance times its corners' sin(theta), which within
      // a cell differs from sin(theta) itself by a bounded factor (largest in the pole cells).
      ASSERT_LE(w.x, 8.f * float(map.luminance_integral()));
      // Within one texel of the hot one (the bilinear tent's support).
      const vec2 uv = EnvironmentMap::direction_to_uv(ls.wi);
      const float dx = std::abs(uv.x * 64.f - 0.5f - float(hx));
      EXPECT_LE(std::min(dx, 64.f - dx), 1.001f);
      EXPECT_LE(std::abs(uv.y * 31.f - float(hy)), 1.001f);
    }
    EXPECT_GT(accepted, 4900) << hx << "," << hy;
    EXPECT_NEAR(pdf_integral(map), 1.0, 1e-2) << hx << "," << hy;
  }
}

// The compensated twin (Karlik et al. 2019): the same radiance, a density that integrates to one
// and that sample() follows, zero wherever the map is dimmer than its mean all round a cell and
// positive where it is brighter.
TEST(EnvironmentMap, CompensatedTwinSamplesOnlyWhereTheMapIsAboveItsMean) {
  auto desc = sky_with_sun(16, 9);
  desc.to_world = rotation(30.f, glm::normalize(vec3(1, 2, 0.5f)));
  const EnvironmentMap full(desc);
  const auto twin = full.compensated();
  ASSERT_NE(twin, nullptr);
  EXPECT_FALSE(twin->left_to_bsdf_sampling());
  EXPECT_EQ(twin->luminance_integral(), full.luminance_integral());
  EXPECT_EQ(twin->power(2.f), full.power(2.f));
  EXPECT_NEAR(pdf_integral(*twin), 1.0, 2e-3);
  // (The chi-square test on a sky without the sun: the sun's twin density lives in slivers of
  // the test's bins too thin for the bins' cubature. Without it about half the sky is above the
  // mean, with cells where one to four corners are.)
  auto gradient = make_map(12, 7, [](int x, int y) { return 0.2f + float(y) / 7.f + 0.1f * float(x % 3); });
  gradient.to_world = desc.to_world;
  const auto gradient_twin = EnvironmentMap(gradient).compensated();
  EXPECT_NEAR(pdf_integral(*gradient_twin), 1.0, 2e-3);
  expect_sampling_follows_pdf(*gradient_twin);

  // The sun (texels 0 and 15 of row 3, 500 against a sky of 0.2-1.3) makes the mean about 4.6, so
  // only cells touching a sun texel keep a density.
  const float mean = float(full.luminance_integral() / (4.0 * M_PI));
  ASSERT_GT(mean, 1.5f);
  ASSERT_LT(mean, 20.f);
  const glm::mat3 to_local = glm::transpose(desc.to_world);
  int zero = 0, positive = 0;
  Rng rng(5);
  for (int i = 0; i < 4000; ++i) {
    const vec3 d = square_to_uniform_sphere(rng.next2());
    const vec2 uv = EnvironmentMap::direction_to_uv(to_local * d);
    // The cell's four texels: columns either side of u's texel centres, rows either side of v.
    const float s = uv.x * 16.f - 0.5f, t = uv.y * 8.f;
    const int x0 = int(std::floor(s)), y0 = std::min(int(t), 7);
    bool bright = false;
    for (const int x : {x0, x0 + 1})
      for (const int y : {y0, y0 + 1}) bright |= value(desc, (x % 16 + 16) % 16, y) > mean;
    // The radiance the integrator sees is the full map's, to the bit.
    const Spectrum a = twin->radiance(d), b = full.radiance(d);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(a[c], b[c]);
    const float pdf = twin->pdf(d);
    if (bright) {
      EXPECT_GT(pdf, 0.f) << d.x << " " << d.y << " " << d.z;
      ++positive;
    } else {
      EXPECT_EQ(pdf, 0.f) << d.x << " " << d.y << " " << d.z;
      EXPECT_GT(full.pdf(d), 0.f);
      ++zero;
    }
  }
  EXPECT_GT(zero, 3000);
  EXPECT_GT(positive, 5);
  for (int i = 0; i < 2000; ++i) {
    LightSample ls;
    if (!twin->sample(vec3(0.f), 0.f, rng.next2(), &ls)) continue;  // (a warp's rare rounding)
    ASSERT_GT(ls.pdf, 0.f);
    ASSERT_NEAR(ls.pdf, twin->pdf(ls.wi), 2e-3f * ls.pdf);
  }
}

// Where nothing is brighter than the mean (a constant map) the twin has no density at all and is
// left to BSDF sampling, as a constant environment is; a map sampled uniformly, or a black one,
// has no twin.
TEST(EnvironmentMap, CompensatedTwinOfAConstantMapIsLeftToBsdfSampling) {
  const EnvironmentMap constant(make_map(8, 5, [](int, int) { return 2.f; }));
  const auto twin = constant.compensated();
  ASSERT_NE(twin, nullptr);
  EXPECT_FALSE(constant.left_to_bsdf_sampling());
  EXPECT_TRUE(twin->left_to_bsdf_sampling());
  EXPECT_EQ(twin->pdf(vec3(0, 1, 0)), 0.f);
  LightSample ls;
  EXPECT_FALSE(twin->sample(vec3(0.f), 0.f, vec2(0.3f, 0.7f), &ls));

  auto uniform = sky_with_sun(8, 5);
  uniform.uniform_sampling = true;
  EXPECT_EQ(EnvironmentMap(uniform).compensated(), nullptr);
  EXPECT_EQ(EnvironmentMap(make_map(8, 5, [](int, int) { return 0.f; })).compensated(), nullptr);
}

}  // namespace
}  // namespace penumbra::test
