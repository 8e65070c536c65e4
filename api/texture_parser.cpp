#include "api/texture_parser.h"

#include <limits>

#include "api/diagnostics.h"
#include "renderer/io/image_io.h"

namespace penumbra::api {
namespace {

Spectrum to_spectrum(const glm::dvec3& v) { return Spectrum(float(v.x), float(v.y), float(v.z)); }

std::string bytes_text(int64_t bytes) { return std::to_string(bytes) + " bytes"; }

// An enumerated string member; nullopt when absent or unknown (then with an error).
template <typename E>
std::optional<E> read_choice(ObjectReader& r, std::string_view key,
                             std::initializer_list<std::pair<const char*, E>> choices) {
  const auto text = r.string(key);
  if (!text) return std::nullopt;
  std::vector<std::string> names;
  for (const auto& [name, value] : choices) {
    if (*text == name) return value;
    names.push_back(name);
  }
  std::string expected;
  for (size_t i = 0; i < names.size(); ++i)
    expected += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + ("\"" + names[i] + "\"");
  r.error(key, "unknown value " + quote_user_string(*text) + did_you_mean(*text, names) +
                   "; expected " + expected);
  return std::nullopt;
}

// Resolves and probes the image `path` (written at `pointer`), picks its colorspace (the user's,
// else the role's default) and reserves its decoded size: fills desc.path and desc.colorspace.
bool resolve_image(const std::string& path, const std::string& pointer, TextureRole role,
                   std::optional<TextureColorspace> colorspace, TextureSet& textures,
                   Diagnostics& diag, ImageTextureDesc& desc) {
  const auto probed = textures.probe(path, pointer, diag);
  if (!probed) return false;
  const auto& [file, info] = *probed;
  desc.path = file;
  // Integer images hold sRGB-encoded colours by convention; float images (EXR, HDR) and
  // non-colours (roughness, normals) are linear.
  const bool is_color = role == TextureRole::kReflectance || role == TextureRole::kEmission;
  desc.colorspace = colorspace                     ? *colorspace
                    : (is_color && !info.is_float) ? TextureColorspace::kSrgb
                                                   : TextureColorspace::kLinear;
  return textures.reserve(file, desc.colorspace, info, pointer, diag);
}

struct ParsedTexture {
  ImageTextureDesc desc;
  Spectrum scale{1.f};
};

// One texture object at reader's pointer, for `role`; `scale_range` bounds its scale.
std::optional<ParsedTexture> parse_texture(ObjectReader& r, TextureRole role,
                                           const Range& scale_range, TextureSet& textures) {
  Diagnostics& diag = r.diagnostics();
  const std::size_t errors_before = diag.error_count();
  ParsedTexture out;
  const auto path = r.string("texture", Presence::kRequired);
  std::optional<TextureColorspace> colorspace;
  if (role == TextureRole::kNormalMap) {
    for (const char* key : {"colorspace", "channel", "scale"})
      if (r.has(key)) {
        r.allow({key});
        r.error(key, std::string("does not apply to a normal map (read linearly, as stored, "
                                 "n = 2 rgb - 1)"));
      }
  } else {
    colorspace = read_choice<TextureColorspace>(
        r, "colorspace",
        {{"srgb", TextureColorspace::kSrgb}, {"linear", TextureColorspace::kLinear}});
    if (role == TextureRole::kValue) {
      if (auto c = r.integer("channel", Range::closed(0, 3))) out.desc.channel = int(*c);
      if (auto s = r.number("scale", scale_range)) out.scale = Spectrum(float(*s));
    } else {
      if (r.has("channel")) {
        r.allow({"channel"});
        r.error("channel",
                "applies only to single-value textures (roughness); a colour reads the "
                "image's red, green and blue channels (grey images: the first)");
      }
      if (const Json* s = r.get("scale")) {
        if (s->is_array()) {
          if (auto v = read_vec3(*s, r.pointer_of("scale"), diag, scale_range))
            out.scale = to_spectrum(*v);
        } else if (auto v = read_number(*s, r.pointer_of("scale"), diag, scale_range)) {
          out.scale = Spectrum(float(*v));
        }
      }
    }
  }
  if (auto w = read_choice<TextureWrap>(
          r, "wrap", {{"repeat", TextureWrap::kRepeat}, {"clamp", TextureWrap::kClamp}}))
    out.desc.wrap = *w;
  if (auto f = read_choice<TextureFilter>(
          r, "filter",
          {{"bilinear", TextureFilter::kBilinear}, {"nearest", TextureFilter::kNearest}}))
    out.desc.filter = *f;
  r.report_unknown_keys();
  if (!path || diag.error_count() != errors_before) return std::nullopt;

  if (!resolve_image(*path, r.pointer_of("texture"), role, colorspace, textures, diag, out.desc))
    return std::nullopt;
  if (role == TextureRole::kValue && out.desc.channel >= textures.channels(out.desc.path)) {
    r.error("channel", "the image has " + std::to_string(textures.channels(out.desc.path)) +
                           " channel(s): channel " + std::to_string(out.desc.channel) +
                           " does not exist");
    return std::nullopt;
  }
  return out;
}

}  // namespace

std::optional<std::pair<std::string, AssetImageInfo>> TextureSet::probe(const std::string& path,
                                                                        const std::string& pointer,
                                                                        Diagnostics& diag) {
  // A path is probed once; a bad one is reported on each field that names it.
  if (auto it = probed_.find(path); it != probed_.end() && it->second) return it->second;
  std::optional<std::pair<std::string, AssetImageInfo>> result;
  if (const auto file = resolve_asset_path(assets_, path, pointer, diag)) {
    // The header's size is judged here, against the limit by name; the reader only refuses
    // what no limit could allow.
    ImageReadLimits header_only;
    header_only.max_pixels = std::numeric_limits<int64_t>::max();
    header_only.max_dimension = std::numeric_limits<int>::max();
    try {
      const AssetImageInfo info = probe_asset_image(file->string(), header_only);
      const int64_t pixels = int64_t(info.width) * info.height;
      if (pixels > limits_.max_texture_pixels)
        diag.error(pointer, "'" + path + "' is " + std::to_string(info.width) + " x " +
                                std::to_string(info.height) + " = " + std::to_string(pixels) +
                                " pixels, more than the limit of " +
                                std::to_string(limits_.max_texture_pixels) +
                                " (max_texture_pixels)");
      else
        result.emplace(file->string(), info);
      if (result) {
        channels_[file->string()] = info.channels;
        uses_.push_back(AssetUse{pointer, path,
                                 describe_image(info.width, info.height, info.channels,
                                                info.is_float  ? "float"
                                                : info.is_8bit ? "8-bit"
                                                               : "integer")});
      }
    } catch (const ImageIoError& e) {
      // The message names the resolved file; the user wrote `path`.
      std::string reason = e.what();
      const std::string prefix = file->string() + ": ";
      if (reason.rfind(prefix, 0) == 0) reason = reason.substr(prefix.size());
      diag.error(pointer, "'" + path + "': " + reason);
    }
  }
  probed_[path] = result;
  return result;
}

std::optional<AssetImageInfo> TextureSet::probe_memory(const std::string& key,
                                                      const ImageSource& source,
                                                      const std::string& pointer,
                                                      Diagnostics& diag) {
  if (auto it = memory_probed_.find(key); it != memory_probed_.end()) return it->second;
  std::optional<AssetImageInfo> result;
  ImageReadLimits header_only;
  header_only.max_pixels = std::numeric_limits<int64_t>::max();
  header_only.max_dimension = std::numeric_limits<int>::max();
  try {
    const AssetImageInfo info = probe_asset_image(source, header_only);
    const int64_t pixels = int64_t(info.width) * info.height;
    if (pixels > limits_.max_texture_pixels)
      diag.error(pointer, source.path + " is " + std::to_string(info.width) + " x " +
                              std::to_string(info.height) + " = " + std::to_string(pixels) +
                              " pixels, more than the limit of " +
                              std::to_string(limits_.max_texture_pixels) + " (max_texture_pixels)");
    else
      result = info;
  } catch (const ImageIoError& e) {
    diag.error(pointer, e.what());
  }
  if (result) channels_[key] = result->channels;
  memory_probed_[key] = result;
  return result;
}

bool TextureSet::reserve(const std::string& file, TextureColorspace colorspace,
                         const AssetImageInfo& info, const std::string& pointer,
                         Diagnostics& diag) {
  const auto key = std::make_pair(file, colorspace);
  if (reserved_.count(key)) return true;
  const int64_t bytes = decoded_texture_bytes(info.width, info.height, info.channels, info.is_8bit);
  if (bytes_ + bytes > limits_.max_texture_bytes) {
    diag.error(pointer, "this image takes " + bytes_text(bytes) +
                            " decoded, which brings the scene's "
                            "textures to " +
                            bytes_text(bytes_ + bytes) + ", more than the limit of " +
                            bytes_text(limits_.max_texture_bytes) + " (max_texture_bytes)");
    return false;
  }
  reserved_[key] = bytes;
  bytes_ += bytes;
  return true;
}

std::optional<SpectrumField> read_spectrum_field(ObjectReader& reader, std::string_view key,
                                                 const Range& range, TextureRole role,
                                                 TextureSet& textures) {
  const Json* value = reader.get(key);
  if (!value) return std::nullopt;
  const std::string pointer = reader.pointer_of(key);
  if (value->is_object()) {
    ObjectReader r(*value, pointer, reader.diagnostics());
    const auto t = parse_texture(r, role, range, textures);
    if (!t) return std::nullopt;
    return SpectrumField{t->scale, t->desc};
  }
  const auto v = read_vec3(*value, pointer, reader.diagnostics(), range);
  if (!v) return std::nullopt;
  return SpectrumField{to_spectrum(*v), std::nullopt};
}

std::optional<FloatField> read_float_field(ObjectReader& reader, std::string_view key,
                                           const Range& range, TextureSet& textures) {
  const Json* value = reader.get(key);
  if (!value) return std::nullopt;
  const std::string pointer = reader.pointer_of(key);
  if (value->is_object()) {
    ObjectReader r(*value, pointer, reader.diagnostics());
    const auto t = parse_texture(r, TextureRole::kValue, range, textures);
    if (!t) return std::nullopt;
    return FloatField{t->scale.x, t->desc};
  }
  const auto v = read_number(*value, pointer, reader.diagnostics(), range);
  if (!v) return std::nullopt;
  return FloatField{float(*v), std::nullopt};
}

std::optional<ImageTextureDesc> read_normal_map(ObjectReader& reader, std::string_view key,
                                                TextureSet& textures) {
  const Json* value = reader.get(key);
  if (!value) return std::nullopt;
  const std::string pointer = reader.pointer_of(key);
  if (value->is_string()) {
    ImageTextureDesc desc;
    if (!resolve_image(value->get<std::string>(), pointer, TextureRole::kNormalMap, std::nullopt,
                       textures, reader.diagnostics(), desc))
      return std::nullopt;
    return desc;
  }
  if (!value->is_object()) {
    reader.diagnostics().error(pointer,
                               "must be a file name or a texture {\"texture\": \"file.png\", ...}");
    return std::nullopt;
  }
  ObjectReader r(*value, pointer, reader.diagnostics());
  const auto t = parse_texture(r, TextureRole::kNormalMap, Range::any(), textures);
  return t ? std::optional(t->desc) : std::nullopt;
}

}  // namespace penumbra::api
