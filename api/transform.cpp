#include "api/transform.h"

#include <cmath>

namespace penumbra::api {

glm::dvec3 AffineTransform::normal(const glm::dvec3& n) const {
  return glm::transpose(glm::inverse(linear)) * n;
}

std::optional<double> AffineTransform::similarity_scale() const {
  // linear = s * Q with Q orthogonal  <=>  linear^T * linear = s^2 * I.
  const glm::dmat3 gram = glm::transpose(linear) * linear;
  const double s2 = (gram[0][0] + gram[1][1] + gram[2][2]) / 3.0;
  if (!(s2 > 0) || !std::isfinite(s2)) return std::nullopt;
  constexpr double kTolerance = 1e-6;  // relative; rotations typed as decimals are not exact
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) {
      const double target = r == c ? s2 : 0.0;
      if (std::abs(gram[c][r] - target) > kTolerance * s2) return std::nullopt;
    }
  return std::sqrt(s2);
}

namespace {
// Rodrigues' rotation formula for a unit axis.
glm::dmat3 rotation(const glm::dvec3& unit_axis, double degrees) {
  const double radians = degrees * (M_PI / 180.0);
  const double c = std::cos(radians), s = std::sin(radians), t = 1.0 - c;
  const double x = unit_axis.x, y = unit_axis.y, z = unit_axis.z;
  // glm matrices are column-major: m[column][row].
  glm::dmat3 m;
  m[0] = {t * x * x + c, t * x * y + s * z, t * x * z - s * y};
  m[1] = {t * x * y - s * z, t * y * y + c, t * y * z + s * x};
  m[2] = {t * x * z + s * y, t * y * z - s * x, t * z * z + c};
  return m;
}

std::optional<AffineTransform> parse_matrix(const Json& value, const std::string& pointer,
                                            Diagnostics& diag) {
  if (!value.is_array() || value.size() != 16) {
    diag.error(pointer, "must be an array of 16 numbers (a 4x4 matrix, row-major)");
    return std::nullopt;
  }
  double m[16];
  bool ok = true;
  for (std::size_t i = 0; i < 16; ++i) {
    const auto x = read_number(value[i], child_pointer(pointer, i), diag);
    if (x)
      m[i] = *x;
    else
      ok = false;
  }
  if (!ok) return std::nullopt;
  if (m[12] != 0 || m[13] != 0 || m[14] != 0 || m[15] != 1) {
    diag.error(pointer, "must be affine: the last row must be [0, 0, 0, 1]");
    return std::nullopt;
  }
  AffineTransform transform;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) transform.linear[c][r] = m[4 * r + c];
    transform.translation[r] = m[4 * r + 3];
  }
  // Invertible relative to the size of the columns, so a tiny uniform scale still passes but a
  // flattening matrix does not.
  const double det = glm::determinant(transform.linear);
  const double scale = glm::length(transform.linear[0]) * glm::length(transform.linear[1]) *
                       glm::length(transform.linear[2]);
  if (!(std::abs(det) > 1e-12 * scale) || !std::isfinite(det)) {
    diag.error(pointer, "must be invertible (its upper-left 3x3 block is singular)");
    return std::nullopt;
  }
  return transform;
}
}  // namespace

AffineTransform compose(const AffineTransform& outer, const AffineTransform& inner) {
  AffineTransform t;
  t.linear = outer.linear * inner.linear;
  t.translation = outer.linear * inner.translation + outer.translation;
  return t;
}

// x = A y + b  <=>  y = A^-1 x - A^-1 b.
AffineTransform inverse(const AffineTransform& t) {
  AffineTransform inv;
  inv.linear = glm::inverse(t.linear);
  inv.translation = -(inv.linear * t.translation);
  return inv;
}

std::optional<AffineTransform> parse_transform(const Json& value, const std::string& pointer,
                                               Diagnostics& diag) {
  ObjectReader reader(value, pointer, diag);
  if (!reader.valid()) return std::nullopt;
  const std::size_t errors_before = diag.error_count();

  if (reader.has("matrix")) {
    for (const char* other : {"scale", "rotate", "translate"})
      if (reader.has(other))
        reader.error(other, "cannot be combined with \"matrix\"; use one form or the other");
    reader.allow({"scale", "rotate", "translate"});
    const auto transform = parse_matrix(*reader.get("matrix"), reader.pointer_of("matrix"), diag);
    reader.report_unknown_keys();
    if (diag.error_count() != errors_before) return std::nullopt;
    return transform;
  }
  reader.allow({"matrix"});

  glm::dvec3 scale{1.0};
  if (const Json* s = reader.get("scale")) {
    const std::string p = reader.pointer_of("scale");
    if (s->is_number()) {
      if (const auto x = read_number(*s, p, diag)) {
        if (*x == 0)
          diag.error(p, "must be nonzero");
        else
          scale = glm::dvec3(*x);
      }
    } else if (const auto v = read_vec3(*s, p, diag)) {
      for (int i = 0; i < 3; ++i)
        if ((*v)[i] == 0) diag.error(child_pointer(p, std::size_t(i)), "must be nonzero");
      scale = *v;
    }
  }

  glm::dmat3 rotate{1.0};
  if (const Json* r = reader.get("rotate")) {
    ObjectReader rot(*r, reader.pointer_of("rotate"), diag);
    const auto axis = rot.vec3("axis", Range::any(), Presence::kRequired);
    const auto degrees = rot.number("degrees", Range::any(), Presence::kRequired);
    rot.report_unknown_keys();
    if (axis && glm::length(*axis) == 0)
      rot.error("axis", "must be a nonzero vector");
    else if (axis && degrees)
      rotate = rotation(glm::normalize(*axis), *degrees);
  }

  const glm::dvec3 translate = reader.vec3("translate").value_or(glm::dvec3(0.0));
  reader.report_unknown_keys();
  if (diag.error_count() != errors_before) return std::nullopt;

  AffineTransform transform;
  // Scale first, then rotate: columns of diag(scale) scaled, then rotated.
  glm::dmat3 scale_matrix(1.0);
  for (int i = 0; i < 3; ++i) scale_matrix[i][i] = scale[i];
  transform.linear = rotate * scale_matrix;
  transform.translation = translate;
  return transform;
}

}  // namespace penumbra::api
