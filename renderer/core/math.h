#pragma once
// Basic math vocabulary of the renderer: GLM vectors, RGB spectra and a few constants.
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace penumbra {

using glm::vec2;
using glm::vec3;
using glm::mat4;
using glm::dvec3;

// Linear RGB radiometric quantity (radiance, reflectance, throughput, ...).
using Spectrum = glm::vec3;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;
inline constexpr float kInv2Pi = 0.15915494309189533577f;
inline constexpr float kInv4Pi = 0.07957747154594766788f;
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;
inline constexpr float kInfinity = INFINITY;

inline float luminance(const Spectrum& s) { return 0.2126f * s.x + 0.7152f * s.y + 0.0722f * s.z; }
inline float max_component(const Spectrum& s) { return std::max(s.x, std::max(s.y, s.z)); }
inline bool is_black(const Spectrum& s) { return s.x == 0.f && s.y == 0.f && s.z == 0.f; }
inline bool is_finite(const Spectrum& s) {
  return std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.z);
}
// |v| per component with std::fabs, which compiles to one mask (andps). glm::abs is
// `x >= 0 ? x : -x`, which GCC keeps as a compare and branch per component (it differs from
// fabs on -0 and NaN), nine branches in a hit point's error bound (docs/performance.md).
inline vec3 abs_components(const vec3& v) { return vec3(std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)); }
inline float safe_sqrt(float x) { return std::sqrt(std::max(0.f, x)); }
inline float safe_acos(float x) { return std::acos(std::clamp(x, -1.f, 1.f)); }
inline float sqr(float x) { return x * x; }

}  // namespace penumbra
