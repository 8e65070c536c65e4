// libFuzzer target: arbitrary bytes read as an image asset (renderer/io/image_reader.h) by the
// readers penumbra carries itself: PNG (libpng), EXR (OpenEXR), Radiance HDR and JPEG
// (libjpeg-turbo). Bytes no such reader takes are skipped (the OpenImageIO plug-in is not part of this program). Bad files must
// give ImageIoError, never a crash, an unbounded allocation or undefined behaviour; an image that
// reads has the size its header gave and finite values (PNG's in [0, 1]).
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <vector>

#include "renderer/io/asset_decoder.h"
#include "renderer/io/exr_reader.h"
#include "renderer/io/hdr_reader.h"
#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"
#include "renderer/io/jpeg_reader.h"
#include "renderer/io/png_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra;
  const ImageSource source("fuzz", std::make_shared<const std::vector<uint8_t>>(data, data + size), "png");
  const SourceHead head = read_source_head(source);
  const bool png = has_png_signature(head), exr = has_exr_signature(head),
             hdr = has_hdr_signature(head), jpeg = has_jpeg_signature(head);
  if (!png && !exr && !hdr && !jpeg) return 0;
  ImageReadLimits limits;
  limits.max_pixels = 256 * 256;  // small caps keep each input fast
  limits.max_dimension = 4096;
  try {
    // Forms these readers leave to the plug-in are skipped.
    if ((exr && !open_exr(source)) || (hdr && !open_hdr(source)) ||
        (jpeg && !open_jpeg(source)))
      return 0;
    const AssetImageInfo info = probe_asset_image(source, limits);
    const AssetImage image = read_asset_image(source, limits);
    if (image.width != info.width || image.height != info.height || image.channels != info.channels ||
        image.pixels.size() != size_t(info.width) * size_t(info.height) * size_t(info.channels))
      std::abort();
    for (float v : image.pixels)
      if (!std::isfinite(v) || ((png || jpeg) && (v < 0.f || v > 1.f))) std::abort();
    if (info.is_8bit && read_asset_image_8bit(source, limits).pixels.size() != image.pixels.size()) std::abort();
  } catch (const ImageIoError&) {
  }
  return 0;
}
