// The light tree chooses among many lights by where the shading point is: a distribution over
// the lights at every point (its pmf sums to one, choose() draws by it), which favours near and
// bright lights and never chooses a light that cannot reach the point.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "renderer/lights/light_sampler.h"
#include "renderer/lights/light_tree.h"

namespace penumbra::test {
namespace {

const vec3 kNoNormal(0.f);

// A one-sided square panel of side s at c facing n (one of the axes), or a point when s = 0.
LightBounds panel(const vec3& c, float s, const vec3& n, float phi) {
  LightBounds b;
  const vec3 half = 0.5f * s * (vec3(1.f) - glm::abs(n));
  b.bounds.extend(c - half);
  b.bounds.extend(c + half);
  b.normals.axis = n;
  b.normals.cos_theta = 1.f;
  b.phi = phi;
  return b;
}
LightBounds point(const vec3& c, float phi) {
  LightBounds b;
  b.bounds.extend(c);
  b.phi = phi;
  return b;
}

// 40 ceiling panels facing down and 10 points, of powers 0.5..5.
struct ManyLights {
  std::vector<LightBounds> lights;
  std::vector<int> ids;
  ManyLights() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (int i = 0; i < 40; ++i) {
      lights.push_back(panel(vec3(-4.f + 8.f * u(rng), 3.f, -10.f + 10.f * u(rng)), 0.3f, vec3(0, -1, 0),
                             0.5f + 4.5f * u(rng)));
      ids.push_back(3 * i + 1);  // ids need not be dense
    }
    for (int i = 0; i < 10; ++i) {
      lights.push_back(point(vec3(-4.f + 8.f * u(rng), 0.5f + 2.f * u(rng), -10.f + 10.f * u(rng)),
                             0.5f + 4.5f * u(rng)));
      ids.push_back(200 + i);
    }
  }
};

TEST(LightTree, PmfSumsToOneAndChooseDrawsByIt) {
  const ManyLights scene;
  const LightTree tree(scene.lights, scene.ids);
  ASSERT_EQ(tree.size(), scene.lights.size());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int trial = 0; trial < 20; ++trial) {
    const vec3 p(-4.f + 8.f * u(rng), 2.9f * u(rng), -10.f + 10.f * u(rng));
    // A receiving surface of random orientation, or none.
    const vec3 nrm = trial % 2 ? glm::normalize(vec3(u(rng) - 0.5f, u(rng) - 0.5f, u(rng) - 0.5f)) : kNoNormal;
    double sum = 0.0;
    for (int id : scene.ids) sum += tree.pmf(p, nrm, id);
    EXPECT_NEAR(sum, 1.0, 1e-5) << trial;
    // Stratified u: each light's share of draws within 0.5% of its pmf, and the pmf choose()
    // reports is pmf() to the bit.
    std::vector<int> count(256, 0);
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
      float pmf = 0.f;
      const int id = tree.choose(p, nrm, (float(k) + 0.5f) / float(n), &pmf);
      ASSERT_GE(id, 0);
      ASSERT_EQ(pmf, tree.pmf(p, nrm, id));
      ++count[size_t(id)];
    }
    for (int id : scene.ids) EXPECT_NEAR(double(count[size_t(id)]) / n, tree.pmf(p, nrm, id), 5e-3) << id;
  }
  EXPECT_EQ(tree.pmf(vec3(0.f), vec3(0.f), 0), 0.f);  // not in the tree
}

TEST(LightTree, ManyLevels) {
  std::vector<LightBounds> lights;
  std::vector<int> ids;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (int i = 0; i < 700; ++i) {
    lights.push_back(point(vec3(40.f * u(rng), 3.f * u(rng), 40.f * u(rng)), 0.1f + u(rng)));
    ids.push_back(i);
  }
  lights.push_back(point(vec3(1.f), 1.f));  // two lights at one place
  ids.push_back(700);
  lights.push_back(point(vec3(1.f), 1.f));
  ids.push_back(701);
  const LightTree tree(lights, ids);
  for (int trial = 0; trial < 5; ++trial) {
    const vec3 p(40.f * u(rng), 1.f, 40.f * u(rng));
    const vec3 nrm(0.f, 1.f, 0.f);
    double sum = 0.0;
    for (int id : ids) sum += tree.pmf(p, nrm, id);
    EXPECT_NEAR(sum, 1.0, 1e-4);
    for (int k = 0; k < 2000; ++k) {
      float pmf;
      const int id = tree.choose(p, nrm, u(rng), &pmf);
      ASSERT_GE(id, 0);
      ASSERT_EQ(pmf, tree.pmf(p, nrm, id));
    }
  }
}

TEST(LightTree, FavoursNearLightsAndNeverChoosesOnesThatCannotReach) {
  // Two equal panels facing down at x = -5 and x = 5, one point light far off.
  const std::vector<LightBounds> lights = {panel(vec3(-5, 3, 0), 0.5f, vec3(0, -1, 0), 1.f),
                                           panel(vec3(5, 3, 0), 0.5f, vec3(0, -1, 0), 1.f),
                                           point(vec3(0, 1, -40), 1.f)};
  const LightTree tree(lights, {0, 1, 2});
  const vec3 below_first(-5, 0, 0);
  EXPECT_GT(tree.pmf(below_first, kNoNormal, 0), 0.8f);
  EXPECT_GT(tree.pmf(below_first, kNoNormal, 1), 0.f);  // far, but it still reaches: never zero
  // Above the panels (behind their emitting sides) only the point light can reach. (The panels'
  // node itself may still look reachable: inside its bounding sphere every direction counts,
  // so a choice that goes there ends without a light, -1, as pbrt-v4's does.)
  const vec3 above(0, 4, 0);
  EXPECT_EQ(tree.pmf(above, kNoNormal, 0), 0.f);
  EXPECT_EQ(tree.pmf(above, kNoNormal, 1), 0.f);
  EXPECT_GT(tree.pmf(above, kNoNormal, 2), 0.f);
  int chosen = 0;
  for (int k = 0; k < 100; ++k) {
    float pmf;
    const int light = tree.choose(above, kNoNormal, (float(k) + 0.5f) / 100.f, &pmf);
    EXPECT_TRUE(light == 2 || light == -1) << light;
    chosen += light == 2;
  }
  EXPECT_NEAR(chosen / 100.0, tree.pmf(above, kNoNormal, 2), 0.011);
}

TEST(LightTree, NoLightThatCanReachGivesNone) {
  const LightTree tree({panel(vec3(-1, 3, 0), 0.5f, vec3(0, -1, 0), 1.f), panel(vec3(1, 3, 0), 0.5f, vec3(0, -1, 0), 1.f)},
                       {0, 1});
  float pmf = 1.f;
  EXPECT_EQ(tree.choose(vec3(0, 5, 0), kNoNormal, 0.3f, &pmf), -1);
  EXPECT_EQ(pmf, 0.f);
}

TEST(LightTree, LightsNearTheEndOfTheFloatRangeAreLeftOut) {
  // Hostile coordinates: the tree is built without a NaN reaching its splits, the far lights are
  // never chosen, and choices among the rest stay finite.
  std::vector<LightBounds> lights = {point(vec3(3e38f, 0, 0), 1.f), point(vec3(-3e38f, 0, 0), 1.f),
                                     panel(vec3(0, 3e38f, 0), 2e38f, vec3(0, -1, 0), 1.f)};
  std::vector<int> ids = {0, 1, 2};
  for (int i = 0; i < 10; ++i) {
    lights.push_back(point(vec3(float(i), 1, 0), 1.f));
    ids.push_back(3 + i);
  }
  const LightTree tree(lights, ids);
  EXPECT_EQ(tree.size(), 10u);  // the three far lights left out
  for (int id = 0; id < 3; ++id) EXPECT_EQ(tree.pmf(vec3(0.5f, 0, 0), kNoNormal, id), 0.f);
  for (int k = 0; k < 100; ++k) {
    float pmf;
    const int id = tree.choose(vec3(0.5f, 0, 0), kNoNormal, (float(k) + 0.5f) / 100.f, &pmf);
    EXPECT_TRUE(std::isfinite(pmf));
    if (id >= 0) {
      EXPECT_EQ(pmf, tree.pmf(vec3(0.5f, 0, 0), kNoNormal, id));
    }
  }
}

TEST(LightImportance, ZeroOnlyWhereNoEmissionDirectionReaches) {
  // A panel facing +z: points just in front of its plane, even far to the side, get light.
  const LightBounds b = panel(vec3(0.f), 1.f, vec3(0, 0, 1), 1.f);
  EXPECT_GT(light_importance(b, vec3(0, 0, 1)), 0.f);
  EXPECT_GT(light_importance(b, vec3(30, 0, 1e-3f)), 0.f);
  EXPECT_EQ(light_importance(b, vec3(0, 0, -1)), 0.f);
  EXPECT_EQ(light_importance(b, vec3(30, 0, -1)), 0.f);
  // Nearer is more important, and importance is finite at the light itself.
  EXPECT_GT(light_importance(b, vec3(0, 0, 1)), light_importance(b, vec3(0, 0, 4)));
  EXPECT_TRUE(std::isfinite(light_importance(b, vec3(0.f))));
  // The receiver's normal: a light straight above counts fully, one at its horizon only by the
  // angle its bounding sphere subtends, from either side.
  const LightBounds lamp = point(vec3(0, 2, 0), 1.f);
  EXPECT_FLOAT_EQ(light_importance(lamp, vec3(0.f), vec3(0, 1, 0)), light_importance(lamp, vec3(0.f)));
  EXPECT_FLOAT_EQ(light_importance(lamp, vec3(0.f), vec3(0, -1, 0)), light_importance(lamp, vec3(0.f)));
  EXPECT_LT(light_importance(lamp, vec3(0.f), vec3(1, 0, 0)), 1e-6f * light_importance(lamp, vec3(0.f)));
  EXPECT_GT(light_importance(panel(vec3(0, 2, 0), 1.f, vec3(0, -1, 0), 1.f), vec3(0.f), vec3(1, 0, 0)), 0.f);
  // A point light at the point itself: no finite estimate, importance 0 (not a NaN).
  EXPECT_EQ(light_importance(point(vec3(1, 2, 3), 1.f), vec3(1, 2, 3)), 0.f);
  EXPECT_GT(light_importance(point(vec3(1, 2, 3), 1.f), vec3(1, 2, 4)), 0.f);
}

// The importance as pbrt-v4 writes it, with angles, in double precision: phi cos(theta') x
// cos(theta_i') / max(d^2, half the diagonal), theta' = max(0, theta_w - theta_o - theta_b),
// theta_i' = max(0, theta_i - theta_b), 0 where theta' reaches theta_e.
double reference_importance(const LightBounds& b, const vec3& p, const vec3& n) {
  const glm::dvec3 lo(b.bounds.lo), hi(b.bounds.hi), centre = 0.5 * (lo + hi), v = glm::dvec3(p) - centre;
  const double dist2 = glm::dot(v, v), d = std::sqrt(dist2), radius = 0.5 * glm::length(hi - lo);
  const double d2 = std::max(dist2, 0.5 * glm::length(hi - lo));
  const bool inside = dist2 <= radius * radius;
  const double theta_b = inside ? 0.5 * kPi : std::asin(std::min(1.0, radius / d));
  const glm::dvec3 axis(b.normals.axis);
  double cos_w = glm::dot(axis, v) / d;
  if (b.two_sided) cos_w = std::fabs(cos_w);
  const double theta_o = std::acos(std::clamp(double(b.normals.cos_theta), -1.0, 1.0));
  const double theta_p = std::max(0.0, std::acos(std::clamp(cos_w, -1.0, 1.0)) - theta_o - theta_b);
  const double cos_p = inside || b.normals.cos_theta <= -1.f ? 1.0 : std::cos(theta_p);
  if (!(cos_p > b.cos_theta_e)) return 0.0;
  double cos_ip = 1.0;
  if (glm::length(n) > 0.f && !inside) {
    const double cos_i = std::fabs(glm::dot(glm::dvec3(n), v)) / d;
    cos_ip = std::cos(std::max(0.0, std::acos(std::min(1.0, cos_i)) - theta_b));
  }
  return std::max(0.0, double(b.phi) * cos_p * cos_ip / d2);
}

TEST(LightImportance, IsPbrtsFormula) {
  // Boxes of every shape and cones of every width, one- and two-sided, narrow and Lambertian
  // emission, points near and far with and without a normal: within rounding of the formula
  // written with angles (where neither lies near a clamp, whose side rounding may decide).
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::normal_distribution<float> g;
  int compared = 0, zero = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    LightBounds b;
    const vec3 c(4.f * g(rng), 4.f * g(rng), 4.f * g(rng));
    const vec3 half = u(rng) < 0.2f ? vec3(0.f) : vec3(u(rng), u(rng), u(rng)) * (u(rng) < 0.5f ? 0.1f : 2.f);
    b.bounds.extend(c - half);
    b.bounds.extend(c + half);
    b.normals.axis = glm::normalize(vec3(g(rng), g(rng), g(rng)));
    const float width = u(rng);
    b.normals.cos_theta = width < 0.3f ? 1.f : (width < 0.4f ? -1.f : std::cos(3.14f * u(rng)));
    b.cos_theta_e = u(rng) < 0.7f ? 0.f : std::cos(1.5f * u(rng));
    b.two_sided = u(rng) < 0.3f;
    b.phi = 0.1f + 10.f * u(rng);
    const vec3 p = c + vec3(g(rng), g(rng), g(rng)) * (u(rng) < 0.5f ? 1.f : 10.f);
    const vec3 n = u(rng) < 0.2f ? vec3(0.f) : glm::normalize(vec3(g(rng), g(rng), g(rng)));
    const double want = reference_importance(b, p, n);
    const double got = light_importance(b, p, n);
    // Off the formula's jumps (the emission cone's edge theta' = theta_e, and the one-way
    // plane test's slack, LightTreeNode::behind_at), within 1e-4 of the importance the light
    // would have at that distance with every angle 0.
    const glm::dvec3 v = glm::dvec3(p) - 0.5 * glm::dvec3(b.bounds.lo + b.bounds.hi);
    const double scale = double(b.phi) / std::max(glm::dot(v, v), 0.5 * glm::length(glm::dvec3(b.bounds.hi - b.bounds.lo)));
    LightBounds open = b;
    open.cos_theta_e = -1.f;
    const double cos_p = reference_importance(open, p, vec3(0.f)) / scale;
    if (std::fabs(cos_p - b.cos_theta_e) < 1e-3) continue;
    if (b.normals.cos_theta >= 1.f && !b.two_sided && glm::dot(glm::dvec3(b.normals.axis), v) < 1e-3) continue;
    ++compared;
    zero += want == 0.0;
    EXPECT_NEAR(got, want, 1e-4 * scale) << "trial " << trial << " cos_o " << b.normals.cos_theta << " cos_e "
                                         << b.cos_theta_e << " two " << b.two_sided << " half " << half.x << " n "
                                         << glm::length(n) << " cos_p " << cos_p << " d " << glm::length(v);
  }
  EXPECT_GT(compared, 10000);
  EXPECT_GT(zero, 0);
}

TEST(DirectionCone, MergeHoldsBoth) {
  std::mt19937 rng(11);
  std::normal_distribution<float> g;
  for (int trial = 0; trial < 200; ++trial) {
    DirectionCone a, b;
    a.axis = glm::normalize(vec3(g(rng), g(rng), g(rng)));
    b.axis = glm::normalize(vec3(g(rng), g(rng), g(rng)));
    a.cos_theta = std::cos(0.5f * std::fabs(g(rng)));
    b.cos_theta = std::cos(0.5f * std::fabs(g(rng)));
    const DirectionCone m = DirectionCone::merge(a, b);
    // Each input's axis and edge lie within the merged cone.
    for (const DirectionCone& c : {a, b}) {
      EXPECT_GE(glm::dot(m.axis, c.axis), m.cos_theta - 1e-5f);
      const vec3 side = glm::normalize(glm::cross(c.axis, std::fabs(c.axis.x) < 0.9f ? vec3(1, 0, 0) : vec3(0, 1, 0)));
      const float s = std::sqrt(std::max(0.f, 1.f - c.cos_theta * c.cos_theta));
      for (int k = 0; k < 8; ++k) {
        const float phi = float(k) * 0.785398f;
        const vec3 other = glm::cross(c.axis, side);
        const vec3 edge = c.cos_theta * c.axis + s * (std::cos(phi) * side + std::sin(phi) * other);
        EXPECT_GE(glm::dot(m.axis, edge), m.cos_theta - 1e-4f) << trial;
      }
    }
  }
}

TEST(LightSampler, TreeGroupKeepsItsShareAndSumsToOne) {
  // An environment (no place) and kTreeFrom placed lights: the group has the share its lights
  // have by power and count, split by the tree at the point.
  const size_t placed = LightSampler::kTreeFrom;
  std::vector<float> powers;
  std::vector<std::optional<LightBounds>> places;
  for (size_t i = 0; i < placed; ++i) {
    powers.push_back(1.f + float(i));
    places.push_back(point(vec3(i == 1 ? 5.f : -5.f - float(i), 1.f, 0.f), 0.f));
  }
  powers.push_back(4.f);
  places.push_back(std::nullopt);
  const size_t count = powers.size(), env = placed;
  const std::vector<bool> sampled(count, true);
  const LightSampler flat(powers, sampled);
  const LightSampler spatial(powers, sampled, places);
  ASSERT_TRUE(spatial.spatial());
  ASSERT_FALSE(flat.spatial());
  const vec3 p(4, 0, 0), up(0, 1, 0);
  EXPECT_FLOAT_EQ(spatial.pmf(int(env), p, up), flat.pmf(int(env)));
  double group = 0.0, flat_group = 0.0;
  for (size_t l = 0; l < placed; ++l) group += spatial.pmf(int(l), p, up), flat_group += flat.pmf(int(l));
  EXPECT_NEAR(group, flat_group, 1e-6);
  EXPECT_GT(spatial.pmf(1, p, up), spatial.pmf(2, p, up));  // the near one
  std::vector<int> chosen(count, 0);
  const int n = 40000;
  for (int k = 0; k < n; ++k) {
    float pmf;
    const int light = spatial.choose((float(k) + 0.5f) / float(n), p, up, &pmf);
    ASSERT_GE(light, 0);
    EXPECT_EQ(pmf, spatial.pmf(light, p, up));
    ++chosen[size_t(light)];
  }
  for (size_t l = 0; l < count; ++l) EXPECT_NEAR(double(chosen[l]) / n, spatial.pmf(int(l), p, up), 2e-3) << l;
  // Placed lights that all have no power: still the group, which gives no light, at any point.
  const LightSampler dark(std::vector<float>(placed, 0.f), std::vector<bool>(placed, true),
                          std::vector<std::optional<LightBounds>>(places.begin(), places.begin() + std::ptrdiff_t(placed)));
  ASSERT_TRUE(dark.spatial());
  for (int k = 0; k < 10; ++k) {
    float pmf = 1.f;
    EXPECT_EQ(dark.choose((float(k) + 0.5f) / 10.f, p, up, &pmf), -1);
    EXPECT_EQ(pmf, 0.f);
  }
  // Fewer placed lights: no tree, the same choice as without places.
  std::vector<std::optional<LightBounds>> few(count, std::nullopt);
  for (size_t l = 0; l + 1 < LightSampler::kTreeFrom; ++l) few[l] = places[l];
  const LightSampler one(powers, sampled, few);
  EXPECT_FALSE(one.spatial());
  for (size_t l = 0; l < count; ++l) EXPECT_EQ(one.pmf(int(l)), flat.pmf(int(l)));
  EXPECT_EQ(one.cdf(), flat.cdf());
}

// LightSampler::choose_many, the stages' choice for many points, is choose() point by point to
// the bit: with every light in the tree (the points walk it as they are) and with a light outside
// it (the group's points gathered first).
TEST(LightSampler, ChooseManyIsChooseToTheBit) {
  const ManyLights many;
  std::vector<float> powers;
  std::vector<std::optional<LightBounds>> places;
  for (const LightBounds& b : many.lights) {
    powers.push_back(b.phi);
    places.push_back(b);
  }
  for (const bool with_environment : {false, true}) {
    SCOPED_TRACE(with_environment ? "a light outside the tree" : "every light in the tree");
    std::vector<float> all_powers = powers;
    std::vector<std::optional<LightBounds>> all_places = places;
    if (with_environment) {
      all_powers.push_back(20.f);
      all_places.push_back(std::nullopt);
    }
    const LightSampler sampler(all_powers, std::vector<bool>(all_powers.size(), true), all_places);
    ASSERT_TRUE(sampler.spatial());
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u01(0.f, 1.f);
    const size_t n = 700;  // (more than one of the tree's chunks of 256)
    std::vector<vec3> p(n), normal(n);
    std::vector<float> u(n), pmf(n);
    std::vector<int> light(n);
    for (size_t k = 0; k < n; ++k) {
      p[k] = vec3(-5.f + 10.f * u01(rng), 3.f * u01(rng), -11.f + 12.f * u01(rng));
      normal[k] = k % 5 == 0 ? kNoNormal : glm::normalize(vec3(u01(rng) - 0.5f, u01(rng), u01(rng) - 0.5f));
      u[k] = k == 0 ? 0.99999994f : u01(rng);
    }
    sampler.choose_many(n, p.data(), normal.data(), u.data(), light.data(), pmf.data());
    int outside = 0;
    for (size_t k = 0; k < n; ++k) {
      float one_pmf = -1.f;
      const int one = sampler.choose(u[k], p[k], normal[k], &one_pmf);
      EXPECT_EQ(light[k], one) << k;
      EXPECT_EQ(pmf[k], one_pmf) << k;
      if (one >= 0) {
        EXPECT_EQ(pmf[k], sampler.pmf(one, p[k], normal[k])) << k;
      }
      outside += one == int(powers.size());
    }
    EXPECT_EQ(outside > 0, with_environment);
  }
}

}  // namespace
}  // namespace penumbra::test
