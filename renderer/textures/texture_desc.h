#pragma once
// Image textures as plain input: which file, how its stored values decode to linear, and how it
// is looked up. api/ fills these from `{"texture": PATH, ...}`; the scene build turns each into
// an ImageSpectrumTexture or ImageFloatTexture over an image it decodes once per build.
#include <cstdint>
#include <string>

namespace penumbra {

// How stored values become linear ones. api/ resolves the user's default: sRGB for colours read
// from integer (8/16-bit) images, linear for float images and for everything not a colour.
enum class TextureColorspace : uint8_t { kSrgb, kLinear };
// Outside [0, 1): repeat the image, or extend its border texels (Mitsuba 3 `wrap_mode`).
enum class TextureWrap : uint8_t { kRepeat, kClamp };
// Mitsuba 3 `filter_type`: bilinear between the four nearest texel centres, or the texel itself.
enum class TextureFilter : uint8_t { kBilinear, kNearest };

struct ImageTextureDesc {
  std::string path;  // a file OpenImageIO reads; api/ resolved it inside the scene's asset folder
  TextureColorspace colorspace = TextureColorspace::kSrgb;
  int channel = 0;  // single-value textures (roughness): the channel read
  TextureWrap wrap = TextureWrap::kRepeat;
  TextureFilter filter = TextureFilter::kBilinear;
};

// Caps on decoded textures, applied by api/ to the files' headers and again by the scene build
// as it decodes (a file replaced in between cannot exceed them). Texels of 8-bit images are
// stored as bytes, others as 4-byte floats; at most 4 channels.
struct TextureLimits {
  int64_t max_pixels = int64_t(8192) * 8192;  // width x height of any one image
  int64_t max_bytes = int64_t(1) << 30;       // all distinct decoded images of one scene
};

// Bytes an image of this size takes once decoded (what TextureLimits::max_bytes counts).
inline int64_t decoded_texture_bytes(int64_t width, int64_t height, int channels, bool is_8bit) {
  return width * height * int64_t(channels < 4 ? channels : 4) *
         (is_8bit ? 1 : int64_t(sizeof(float)));
}

}  // namespace penumbra
