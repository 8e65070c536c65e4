#pragma once
// JPEG image assets (the usual form of a glTF asset's base colour textures) decoded by libjpeg-turbo
// directly, so such a scene does not load the OpenImageIO plug-in (oiio_module.h). Grey and
// YCbCr/RGB JPEGs, decoded with libjpeg's defaults, as OpenImageIO's reader does (tests compare
// the two bit for bit); CMYK and YCCK files go to the plug-in, which converts them to RGB.
#include <memory>

#include "renderer/io/asset_decoder.h"

namespace penumbra {

// True when the source starts with a JPEG start-of-image marker (FF D8 FF).
bool has_jpeg_signature(const SourceHead& head);

// Reads the header (ImageIoError naming the source when it is broken); null for a valid file
// this reader leaves to the plug-in (CMYK, YCCK).
std::unique_ptr<AssetDecoder> open_jpeg(const ImageSource& source);

}  // namespace penumbra
