#pragma once
// PNG image assets decoded by libpng directly, which the binary links already for writing PNG:
// a scene whose textures are PNG files (or PNG images embedded in a glTF asset) does not load the
// OpenImageIO plug-in (oiio_module.h: 0.35 s and 130 MB per process). Other formats still go
// through the plug-in (image_reader.cpp chooses by the file's signature).
//
// The values are the ones OpenImageIO's PNG reader gives, bit for bit (tests compare the two):
// palettes expanded to RGB, a tRNS chunk to an alpha channel, grey below 8 bits scaled to 8 bits,
// 16-bit values kept, no gamma applied (a gAMA chunk does not change the stored values). One
// difference, on purpose: colour is not multiplied by alpha. PNG stores unassociated alpha, glTF
// and Mitsuba 3 read it so; OpenImageIO premultiplies unless asked not to, which darkens the
// colour of partly transparent texels of a cut-out leaf or a glTF base colour.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "renderer/io/asset_decoder.h"

namespace penumbra {

// True when the source's first eight bytes are the PNG signature.
bool has_png_signature(const SourceHead& head);

// A PNG whose header has been read; its pixels are decoded by read(). Errors throw ImageIoError
// naming the source ("<path>: <reason>").
class PngImage final : public AssetDecoder {
 public:
  // Reads the header (and nothing more: the caller checks the size before read()).
  static std::unique_ptr<PngImage> open(const ImageSource& source);
  ~PngImage();
  PngImage(const PngImage&) = delete;
  PngImage& operator=(const PngImage&) = delete;

  const PenumbraImageSpec& spec() const override { return spec_; }
  // The first `channels` channels (at most spec().channels), channel-interleaved, top row first:
  // as float in [0, 1] (value / 255 or / 65535), or as the stored 8-bit values (8-bit images only).
  void read(int channels, float* pixels) override;
  void read(int channels, uint8_t* pixels) override;

 private:
  struct State;
  explicit PngImage(std::unique_ptr<State> state);
  std::vector<uint8_t> decode();  // every row at the stored depth, after the expansions above
  std::unique_ptr<State> state_;
  PenumbraImageSpec spec_{};
};

}  // namespace penumbra
