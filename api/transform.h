#pragma once
// Object transforms of scene format v1. The renderer has no transforms: api/ applies them here,
// in double precision, and hands world-space shapes to the renderer.
#include <optional>
#include <string>

#include <glm/glm.hpp>

#include "api/json_reader.h"

namespace penumbra::api {

// x' = linear * x + translation.
struct AffineTransform {
  glm::dmat3 linear{1.0};
  glm::dvec3 translation{0.0};

  glm::dvec3 point(const glm::dvec3& p) const { return linear * p + translation; }
  glm::dvec3 vector(const glm::dvec3& v) const { return linear * v; }
  // Normals transform by the inverse transpose so they stay perpendicular to transformed
  // tangents; the result is not normalised.
  glm::dvec3 normal(const glm::dvec3& n) const;
  // The uniform scale factor s when linear = s * (rotation or reflection), i.e. the transform
  // maps spheres to spheres; nullopt for non-uniform scale or shear.
  std::optional<double> similarity_scale() const;
};

// outer after inner: x' = outer(inner(x)).
AffineTransform compose(const AffineTransform& outer, const AffineTransform& inner);
// The inverse of an invertible transform (the caller checks the determinant).
AffineTransform inverse(const AffineTransform& t);

// Parses {"scale", "rotate": {"axis", "degrees"}, "translate"} (applied in that order: scale,
// then rotate, then translate) or {"matrix": 16 numbers, row-major, affine, invertible}.
// Rotation is right-handed: positive degrees turn counter-clockwise when looking from the tip
// of the axis towards the origin (as glm::rotate, Mitsuba and pbrt).
std::optional<AffineTransform> parse_transform(const Json& value, const std::string& pointer,
                                               Diagnostics& diag);

}  // namespace penumbra::api
