#include "renderer/io/png_writer.h"

#include <png.h>

#include <string>

#include "renderer/io/image_io.h"

namespace penumbra {
namespace {

// libpng reports errors by longjmp to the setjmp point (its documented contract), and its C
// frames must never be unwound by a C++ exception: the output buffer is reserved up front for the
// largest PNG the pixels can make (deflate's stored blocks add 5 bytes per 64 KB, each row a
// filter byte, plus the chunks), so appending never allocates, and a write past that bound is
// reported through png_error, not thrown.
void append(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<uint8_t>*>(png_get_io_ptr(png));
  if (out->size() + length > out->capacity()) png_error(png, "output larger than its bound");
  out->insert(out->end(), data, data + length);
}
void flush(png_structp) {}

// Every libpng call that may fail, behind the setjmp point: this frame holds nothing with a
// destructor and changes no local after setjmp, so the longjmp of an error is well defined.
bool write_png(png_structp png, png_infop info, png_bytepp rows, png_textp texts, int text_count,
               int width, int height, bool srgb, std::vector<uint8_t>* out) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_write_fn(png, out, append, flush);
  png_set_IHDR(png, info, png_uint_32(width), png_uint_32(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  // The pixels are sRGB-encoded: say so (sRGB chunk plus the gAMA/cHRM fallbacks).
  if (srgb) png_set_sRGB_gAMA_and_cHRM(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
  if (text_count > 0) png_set_text(png, info, texts, text_count);
  png_set_rows(png, info, rows);
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  return true;
}


}  // namespace

std::vector<uint8_t> encode_png(const uint8_t* rgb8, int width, int height,
                                const ImageMetadata& metadata, bool srgb) {
  std::vector<uint8_t> out;
  size_t bound = (size_t(width) * 3 + 1) * size_t(height);
  bound += bound / 64 + 65536;  // IDAT chunks of 8 KB add 12 bytes each
  for (const auto& [key, value] : metadata) bound += key.size() + value.size() + 16;
  out.reserve(bound);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) throw ImageIoError("cannot encode image: libpng could not start");
  png_infop info = png_create_info_struct(png);
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw ImageIoError("cannot encode image: libpng could not start");
  }
  std::vector<png_text> texts(metadata.size());
  std::vector<png_bytep> rows(static_cast<size_t>(height));
  for (int y = 0; y < height; ++y)
    rows[size_t(y)] = const_cast<png_bytep>(rgb8 + size_t(y) * size_t(width) * 3);
  for (size_t i = 0; i < metadata.size(); ++i) {
    texts[i] = png_text{};
    texts[i].compression = PNG_TEXT_COMPRESSION_NONE;
    texts[i].key = const_cast<png_charp>(metadata[i].first.c_str());
    texts[i].text = const_cast<png_charp>(metadata[i].second.c_str());
    texts[i].text_length = metadata[i].second.size();
  }
  const bool ok = write_png(png, info, rows.data(), texts.data(), int(texts.size()), width, height, srgb, &out);
  png_destroy_write_struct(&png, &info);
  if (!ok) throw ImageIoError("cannot encode image: libpng failed");
  return out;
}

}  // namespace penumbra
