#include "api/environment_parser.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

#include "api/transform.h"
#include "renderer/core/row_blocks.h"
#include "renderer/io/image_reader.h"

namespace penumbra::api {

namespace {

constexpr const char* kPointer = "/environment";

// The nearest orthogonal matrix (the orthogonal factor of the polar decomposition), by Newton's
// iteration Q <- (Q + Q^-T) / 2 (Higham 1986): a rotation typed with 7 decimals comes out
// orthogonal to double precision, so the renderer may invert it by transposing. A mirror stays
// a mirror (the determinant's sign is kept).
glm::dmat3 nearest_orthogonal(glm::dmat3 q) {
  for (int i = 0; i < 8; ++i) q = 0.5 * (q + glm::transpose(glm::inverse(q)));
  return q;
}

// The map's orientation from "rotate" or "matrix" (the object transform's forms and error
// messages), which must leave directions' lengths alone: an environment is infinitely far away,
// so translating it means nothing and scaling or shearing it would distort it.
std::optional<glm::mat3> parse_orientation(ObjectReader& reader, Diagnostics& diag) {
  Json forms = Json::object();
  for (const char* key : {"rotate", "matrix"})
    if (const Json* v = reader.get(key)) forms[key] = *v;
  if (forms.empty()) return glm::mat3(1.f);
  const auto transform = parse_transform(forms, kPointer, diag);
  if (!transform) return std::nullopt;
  const auto scale = transform->similarity_scale();
  const bool translates = transform->translation != glm::dvec3(0.0);
  if (translates || !scale || std::abs(*scale - 1.0) > 1e-6) {
    reader.error("matrix",
                 "must be a rotation (an orthogonal upper-left 3x3 block and no translation): an "
                 "environment is infinitely far away, so it can only be turned");
    return std::nullopt;
  }
  return glm::mat3(nearest_orthogonal(transform->linear));
}

// Reads the image named by "map" into `rgb` (linear RGB per texel, as decoded) and its size into
// `map`; false after reporting an error.
bool read_map(const std::string& relative, const AssetFolder& assets, EnvironmentMapDesc& map,
              std::vector<float>& rgb, std::vector<AssetUse>* uses, Diagnostics& diag) {
  const std::string pointer = child_pointer(kPointer, "map");
  const auto path = resolve_asset_path(assets, relative, pointer, diag);
  if (!path) return false;
  AssetImage image;
  try {
    image = read_asset_image(path->string());
  } catch (const ImageIoError& e) {
    // The reader (and OpenImageIO inside it) names the resolved path; the user typed the
    // relative one, and where the service keeps its folders is nobody's business.
    std::string reason = e.what();
    const std::string full = path->string();
    const std::string prefix = full + ": ";
    if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
    for (size_t at = reason.find(full); at != std::string::npos;
         at = reason.find(full, at + relative.size()))
      reason.replace(at, full.size(), relative);
    diag.error(pointer, "'" + relative + "': " + reason);
    return false;
  }
  uses->push_back(AssetUse{pointer, relative,
                           describe_image(image.width, image.height, image.channels,
                                          image.is_float ? "float" : "integer")});
  // Integer formats (PNG, JPEG) store sRGB-encoded values, as Mitsuba's Bitmap assumes too.
  if (!image.is_float) srgb_to_linear_in_place(image);
  map.width = image.width;
  map.height = image.height;
  const size_t count = size_t(image.width) * size_t(image.height);
  const int c = image.channels;
  if (c == 3) {
    // The decoded image's own buffer (an 8192 x 4096 map is 400 MB: no copy of it).
    rgb = std::move(image.pixels);
  } else {
    rgb.resize(count * 3);
    for (size_t i = 0; i < count; ++i) {
      const float* p = &image.pixels[i * size_t(c)];
      // One or two channels: grey (and alpha, which an environment has no use for).
      for (size_t k = 0; k < 3; ++k) rgb[i * 3 + k] = c >= 3 ? p[k] : p[0];
    }
  }
  return true;
}

// Makes every value what the light would make of it, in place: clean (finite and >= 0), then,
// for a scale other than 1, clean(value x scale). Returns the largest clean value before the
// scale (for the check on the brightest texel; where it fails, the values are dropped). One pass
// over the texels in blocks on all cores: each value is its own, and the largest of the blocks'
// largest values is the largest, whatever the blocks (an 8192 x 4096 map is 100M values).
float clean_and_scale(std::vector<float>& rgb, float scale) {
  // clean_texel is branch-free, so the loops vectorise. Clean values order as their bits do, so
  // the largest is found among the bits (integer compares, which vectorise too).
  const size_t per_block = kRowBlockCells;
  std::vector<uint32_t> block_brightest((rgb.size() + per_block - 1) / per_block, 0u);
  for_row_blocks(rgb.size(), per_block, [&](size_t begin, size_t end) {
    uint32_t brightest = 0;
    float* v = rgb.data();
    if (scale == 1.f) {
      for (size_t i = begin; i < end; ++i) {
        v[i] = clean_texel(v[i]);
        brightest = std::max(brightest, std::bit_cast<uint32_t>(v[i]));
      }
    } else {
      for (size_t i = begin; i < end; ++i) {
        const float c = clean_texel(v[i]);
        brightest = std::max(brightest, std::bit_cast<uint32_t>(c));
        v[i] = clean_texel(c * scale);
      }
    }
    block_brightest[begin / per_block] = brightest;
  });
  uint32_t brightest = 0;
  for (const uint32_t b : block_brightest) brightest = std::max(brightest, b);
  return std::bit_cast<float>(brightest);
}

}  // namespace

bool parse_environment(const Json* value, const AssetFolder& assets, SceneInput& scene,
                       std::vector<AssetUse>* uses, Diagnostics& diag) {
  if (!value) return false;
  ObjectReader r(*value, kPointer, diag);
  if (!r.valid()) return false;
  const std::size_t errors_before = diag.error_count();

  if (!r.has("map")) {
    if (auto radiance = r.vec3("radiance", Range::at_least(0), Presence::kRequired))
      scene.environment = vec3(float(radiance->x), float(radiance->y), float(radiance->z));
    for (const char* key : {"scale", "rotate", "matrix"})
      if (r.has(key)) r.error(key, "applies only to an image environment (\"map\")");
    r.allow({"map", "scale", "rotate", "matrix"});
    r.report_unknown_keys();
    return !is_black(scene.environment);
  }

  if (r.has("radiance"))
    r.error("radiance",
            "cannot be combined with \"map\": an environment is either a constant radiance or an "
            "image (use \"scale\" to brighten the image)");
  r.allow({"radiance"});
  EnvironmentMapDesc map;
  const auto file = r.string("map", Presence::kRequired);
  const auto scale = r.number("scale", Range::at_least(0));
  const auto to_world = parse_orientation(r, diag);
  r.report_unknown_keys();
  if (scale) map.scale = float(*scale);
  if (to_world) map.to_world = *to_world;
  // The file is checked even when other fields are wrong: validation reports every problem.
  std::vector<float> rgb;
  if (!file || !read_map(*file, assets, map, rgb, uses, diag) || diag.error_count() != errors_before)
    return false;
  // The scale applied here, as the light would (clean(texel x scale), in range by the check
  // below), so the light shares these texels instead of making a scaled copy.
  const float brightest = clean_and_scale(rgb, map.scale);

  // Scaled radiance must stay finite through the renderer's single-precision arithmetic, as
  // every other radiance in a scene (kMaxMagnitude).
  if (double(brightest) * map.scale > kMaxMagnitude) {
    r.error("scale", "makes the map's brightest texel " +
                         format_number(double(brightest) * map.scale) + "; at most " +
                         format_number(kMaxMagnitude));
    return false;
  }
  const bool lit = brightest > 0.f && map.scale > 0.f;
  if (!lit)
    r.warning("map", "the environment map is black (every texel is 0, or scale is 0): it emits "
                     "nothing");
  map.scale = 1.f;
  map.rgb = std::make_shared<const std::vector<float>>(std::move(rgb));
  scene.environment_map = std::move(map);
  return lit;
}

}  // namespace penumbra::api
