#pragma once
// JPEG image assets (the usual form of a glTF asset's base colour textures) decoded by libjpeg-turbo
// directly, so such a scene does not load the OpenImageIO plug-in (oiio_module.h). Grey and
// YCbCr/RGB JPEGs, decoded with libjpeg's defaults, as OpenImageIO's reader does (tests compare
// the two bit for bit); CMYK and YCCK files go to the plug-in, which converts them to RGB.
#include <cstdint>
#include <memory>
#include <vector>

#include "renderer/io/asset_decoder.h"

namespace penumbra {

// True when the source starts with a JPEG start-of-image marker (FF D8 FF).
bool has_jpeg_signature(const SourceHead& head);

class JpegImage final : public AssetDecoder {
 public:
  // Reads the header (ImageIoError naming the source when it is broken); null for a valid file
  // this reader leaves to the plug-in (CMYK, YCCK).
  static std::unique_ptr<JpegImage> open(const ImageSource& source);
  ~JpegImage();
  JpegImage(const JpegImage&) = delete;
  JpegImage& operator=(const JpegImage&) = delete;

  const PenumbraImageSpec& spec() const override { return spec_; }
  // The first `channels` channels, channel-interleaved, top row first: as float (value / 255,
  // computed as OpenImageIO does) or as the decoded 8-bit values.
  void read(int channels, float* pixels) override;
  void read(int channels, uint8_t* pixels) override;

 struct State;  // libjpeg's state (jpeg_reader.cpp)

 private:
  explicit JpegImage(std::unique_ptr<State> state);
  std::vector<uint8_t> decode();
  std::unique_ptr<State> state_;
  PenumbraImageSpec spec_{};
};

}  // namespace penumbra
