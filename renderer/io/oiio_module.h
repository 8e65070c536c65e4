#pragma once
// OpenImageIO, loaded on first use. Linking it costs every run of the binary its ~250 shared
// libraries (OpenCV, GDAL, DCMTK, ffmpeg, ...): 0.3 s and 130 MB before main() on this machine.
// PNG and EXR output go through libpng and OpenEXR directly, and so does reading PNG assets
// (png_reader.h); reading image assets of any other format OpenImageIO knows goes through a
// plug-in, libpenumbra_oiio.so, loaded by this module the first time a scene reads one. Where it
// is looked for, in order:
//   $PENUMBRA_OIIO_MODULE (a path: only that file is tried)
//   <dir of the executable>/../lib/penumbra/libpenumbra_oiio.so   (build tree; installed prefix)
//   <dir of the executable>/libpenumbra_oiio.so
#include <cstdint>
#include <memory>
#include <string>

#include <vector>

#include "renderer/io/asset_decoder.h"
#include "renderer/io/oiio_plugin/oiio_plugin_abi.h"

namespace penumbra {

// An image opened by the plug-in; its header is known, its pixels not yet decoded.
class PluginImage final : public AssetDecoder {
 public:
  ~PluginImage() override;
  PluginImage(const PluginImage&) = delete;
  PluginImage& operator=(const PluginImage&) = delete;

  const PenumbraImageSpec& spec() const override { return spec_; }
  // Decodes the first `channels` channels as float (or as 8-bit values) into `pixels`; throws
  // ImageIoError.
  void read(int channels, float* pixels) override;
  void read(int channels, uint8_t* pixels) override;

 private:
  friend std::unique_ptr<PluginImage> open_plugin_image(const std::string& path);
  friend std::unique_ptr<PluginImage> open_plugin_image(const struct ImageSource& source);
  PluginImage(void* handle, const PenumbraImageSpec& spec, std::string path)
      : handle_(handle), spec_(spec), path_(std::move(path)) {}
  void read(int channels, int type, void* pixels);
  void* handle_;
  PenumbraImageSpec spec_;
  std::string path_;
  std::shared_ptr<const std::vector<uint8_t>> bytes_;  // an image in memory: kept alive
};

// Opens `path` through the plug-in (loading it on the first call, thread-safely). Throws
// ImageIoError("<path>: ...") if the plug-in cannot be loaded or the file cannot be opened.
std::unique_ptr<PluginImage> open_plugin_image(const std::string& path);

// The same for an image held in memory (ImageSource::bytes set; else its path is opened).
std::unique_ptr<PluginImage> open_plugin_image(const struct ImageSource& source);

// True once the plug-in has been loaded into this process (tests use it).
bool oiio_module_loaded();

}  // namespace penumbra
