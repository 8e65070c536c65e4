#include "renderer/lights/light_sampler.h"

#include <algorithm>

#include "renderer/sampling/sampling.h"
#include "renderer/scene/scene_impl.h"

namespace penumbra {
namespace {

float light_power(const Light& l, float scene_radius, const std::vector<ObjectRecord>& objects) {
  const float r2 = scene_radius * scene_radius;
  switch (l.type) {
    case Light::Type::kArea: return luminance(l.value) * objects[l.object].area * kPi;
    case Light::Type::kPoint: return 4.f * kPi * luminance(l.value);
    case Light::Type::kDirectional: return luminance(l.value) * kPi * r2;
    case Light::Type::kEnvironment: return luminance(l.value) * 4.f * kPi * kPi * r2;
  }
  return 0.f;
}

// Solid-angle density of picking point p (normal n) uniformly by area on a surface of `area`.
float area_to_solid_angle(const vec3& ref, const vec3& p, const vec3& n, float area) {
  const vec3 w = p - ref;
  const float dist2 = glm::dot(w, w);
  const float cos_l = std::abs(glm::dot(n, w)) / std::sqrt(dist2);
  return cos_l > 0.f && area > 0.f ? dist2 / (cos_l * area) : 0.f;
}

}  // namespace

void LightSampler::build(std::vector<Light> lights, float scene_radius,
                         const std::vector<ObjectRecord>& objects) {
  lights_ = std::move(lights);
  environment_ = -1;
  const size_t n = lights_.size();
  pmf_.assign(n, 0.f);
  cdf_.assign(n, 0.f);
  if (n == 0) return;
  std::vector<double> power(n);
  double total = 0.0;
  for (size_t i = 0; i < n; ++i) {
    if (lights_[i].type == Light::Type::kEnvironment) environment_ = int(i);
    power[i] = std::max(0.f, light_power(lights_[i], scene_radius, objects));
    if (!std::isfinite(power[i])) power[i] = 0.0;
    total += power[i];
  }
  double acc = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const double by_power = total > 0.0 ? power[i] / total : 1.0 / double(n);
    pmf_[i] = float(0.5 * by_power + 0.5 / double(n));
    acc += pmf_[i];
    cdf_[i] = float(acc);
  }
  cdf_.back() = 1.f;
}

float LightSampler::environment_pdf() const {
  return environment_ < 0 ? 0.f : pmf_[environment_] * uniform_sphere_pdf();
}

bool LightSampler::sample(const SceneImpl& scene, const vec3& ref, float time, float u_select,
                          const vec2& u, LightSample* out) const {
  if (lights_.empty()) return false;
  const int index = int(std::min<size_t>(
      std::upper_bound(cdf_.begin(), cdf_.end(), u_select) - cdf_.begin(), lights_.size() - 1));
  const Light& light = lights_[index];
  const float pmf = pmf_[index];
  switch (light.type) {
    case Light::Type::kPoint: {
      const vec3 d = light.position - ref;
      const float dist2 = glm::dot(d, d);
      if (!(dist2 > 0.f)) return false;
      out->distance = std::sqrt(dist2);
      out->wi = d / out->distance;
      out->value = light.value / dist2;
      out->pdf = pmf;
      out->is_delta = true;
      out->p = light.position;
      out->p_error = vec3(0.f);
      out->n = vec3(0.f);
      return true;
    }
    case Light::Type::kDirectional:
      out->wi = -light.direction;
      out->distance = kInfinity;
      out->value = light.value;
      out->pdf = pmf;
      out->is_delta = true;
      return true;
    case Light::Type::kEnvironment:
      out->wi = square_to_uniform_sphere(u);
      out->distance = kInfinity;
      out->value = light.value;
      out->pdf = pmf * uniform_sphere_pdf();
      out->is_delta = false;
      return true;
    case Light::Type::kArea: break;
  }

  const ObjectRecord& obj = scene.objects[light.object];
  const vec3 disp = obj.displacement_at(time, scene.shutter_open, scene.shutter_span);
  ShapeSample ss;
  if (obj.kind == ObjectRecord::Kind::kSphere) {
    ss = sample_sphere(obj.center + disp, obj.radius, ref, u);
  } else if (obj.is_quad) {
    const vec3 su = u.x * obj.quad.u, sv = u.y * obj.quad.v;
    const vec3 o = obj.quad.origin + disp;
    ss.p = o + su + sv;
    ss.p_error = gamma_bound(6) * (glm::abs(o) + glm::abs(su) + glm::abs(sv));
    ss.n = glm::normalize(glm::cross(obj.quad.u, obj.quad.v));
    ss.pdf = area_to_solid_angle(ref, ss.p, ss.n, obj.area);
  } else {
    const auto it = std::upper_bound(obj.triangle_cdf.begin(), obj.triangle_cdf.end(), u.x);
    const size_t t = std::min<size_t>(it - obj.triangle_cdf.begin(), obj.triangle_cdf.size() - 1);
    const float lo = t > 0 ? obj.triangle_cdf[t - 1] : 0.f;
    const float width = obj.triangle_cdf[t] - lo;
    const float ux = width > 0.f ? std::min((u.x - lo) / width, kOneMinusEpsilon) : 0.5f;
    const vec2 b = square_to_triangle(vec2(ux, u.y));
    const uint32_t* tri = &obj.indices[3 * t];
    const vec3 p0 = obj.positions[tri[0]] + disp, p1 = obj.positions[tri[1]] + disp,
               p2 = obj.positions[tri[2]] + disp;
    const vec3 t0 = (1.f - b.x - b.y) * p0, t1 = b.x * p1, t2 = b.y * p2;
    ss.p = t0 + t1 + t2;
    ss.p_error = gamma_bound(7) * (glm::abs(t0) + glm::abs(t1) + glm::abs(t2));
    const vec3 ng = glm::cross(p1 - p0, p2 - p0);
    const float len = glm::length(ng);
    if (!(len > 0.f)) return false;
    ss.n = ng / len;
    ss.pdf = area_to_solid_angle(ref, ss.p, ss.n, obj.area);
  }
  if (!(ss.pdf > 0.f) || !std::isfinite(ss.pdf)) return false;
  const vec3 d = ss.p - ref;
  const float dist = glm::length(d);
  if (!(dist > 0.f)) return false;
  out->wi = d / dist;
  out->distance = dist;
  // Emission leaves the front side only.
  if (glm::dot(ss.n, out->wi) >= 0.f) return false;
  out->value = light.value;
  out->pdf = pmf * ss.pdf;
  out->is_delta = false;
  out->p = ss.p;
  out->p_error = ss.p_error;
  out->n = ss.n;
  return true;
}

float LightSampler::area_pdf(const SceneImpl& scene, int light, const vec3& ref, const vec3& p,
                             const vec3& n, float time) const {
  const ObjectRecord& obj = scene.objects[lights_[light].object];
  float pdf;
  if (obj.kind == ObjectRecord::Kind::kSphere) {
    const vec3 disp = obj.displacement_at(time, scene.shutter_open, scene.shutter_span);
    pdf = sphere_pdf(obj.center + disp, obj.radius, ref, p, n);
  } else {
    pdf = area_to_solid_angle(ref, p, n, obj.area);
  }
  return pmf_[light] * pdf;
}

}  // namespace penumbra
