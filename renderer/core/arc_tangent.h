#pragma once
// atan2 as inline arithmetic instead of libm's call: selects and one division, so a loop over
// many directions (the environment map's lat-long coordinates of every escaped ray) vectorises,
// and a scalar caller gets the same bits as the loop.
//
// Reduction (Cody and Waite 1980, ch. 11): t = min(|x|, |y|) / max(|x|, |y|) in [0, 1]; above
// 1/2, atan(t) = pi/4 + atan((t - 1) / (t + 1)) brings the argument into [-1/3, 0], so it is
// within [-1/3, 1/2]. There the Taylor series r - r^3/3 + ... - r^23/23 leaves a truncation
// error below r^25/25 (2.4e-9 of r, far under float's half ulp), so what remains is the
// rounding of the operations: within 3 ulps of libm's atan2f
// (ArcTangent.WithinThreeUlpsOfLibm; 0.04% of random directions are 2 ulps off,
// one in a million 3). The quadrant follows from the signs of x and y as atan2's
// (C99 F.9.1.4: atan2(+-0, -0) = +-pi, atan2(+-0, +0) = +-0); NaN in gives NaN out.
#include <cmath>

#include "renderer/core/math.h"

namespace penumbra {

// atan(r) for |r| <= 1/2.
inline float atan_reduced(float r) {
  const float r2 = r * r;
  return r * (1.f + r2 * (-1.f / 3.f + r2 * (1.f / 5.f + r2 * (-1.f / 7.f + r2 * (1.f / 9.f +
             r2 * (-1.f / 11.f + r2 * (1.f / 13.f + r2 * (-1.f / 15.f + r2 * (1.f / 17.f +
             r2 * (-1.f / 19.f + r2 * (1.f / 21.f + r2 * (-1.f / 23.f))))))))))));
}

inline float atan2_inline(float y, float x) {
  const float ay = std::abs(y), ax = std::abs(x);
  const float big = ax > ay ? ax : ay, small = ax > ay ? ay : ax;
  // big == 0: both zero, the angle is 0 before the quadrant (and pi for x = -0).
  // Folded where small >= big / 2: there small - big is exact (Sterbenz), so the folded
  // argument (small - big) / (small + big) in [-1/3, 0] carries two roundings, not three.
  const bool fold = small >= 0.5f * big && big > 0.f;
  const float r = fold ? (small - big) / (small + big) : (big > 0.f ? small / big : small);
  // Each constant in two parts, its float and the remainder (Cody and Waite), the small part
  // added first: pi/4 + a cancels to about half of pi/4 where a is near -1/3, and a constant
  // rounded to float alone would cost an ulp there.
  constexpr float kPi4Hi = 0.785398185253143310546875f, kPi4Lo = -2.1855694143368964e-08f;
  constexpr float kPi2Hi = 1.57079637050628662109375f, kPi2Lo = -4.371138828673793e-08f;
  constexpr float kPiHi = 3.1415927410125732421875f, kPiLo = -8.742277657347586e-08f;
  float a = atan_reduced(r);
  a = fold ? kPi4Hi + (kPi4Lo + a) : a;
  a = ay > ax ? kPi2Hi + (kPi2Lo - a) : a;
  a = std::signbit(x) ? kPiHi + (kPiLo - a) : a;
  a = std::isnan(x) || std::isnan(y) ? x + y : a;
  return std::copysign(a, y);
}

}  // namespace penumbra
