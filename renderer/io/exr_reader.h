#pragma once
// EXR image assets (environment maps, float textures) decoded by OpenEXR directly, which the
// binary links already for writing EXR: such a scene does not load the OpenImageIO plug-in
// (oiio_module.h). This reader takes the common form, a single-part scanline or tiled image
// (its full-resolution level) whose channels are exactly R, G, B (A) or Y (A), half or float,
// unsubsampled; any other EXR (layers, luminance-chroma, multi-part, deep, integer channels) goes
// to the plug-in, as before. Values are the stored ones converted to float, as OpenImageIO gives
// them (half to float is exact), the data window as the image (tests compare the two readers).
#include <memory>

#include "renderer/io/asset_decoder.h"

namespace penumbra {

// True when the source's first four bytes are OpenEXR's magic number.
bool has_exr_signature(const SourceHead& head);

// Reads and checks the header (exr_header_check.h; ImageIoError naming the source when it is
// broken); null for a valid EXR this reader leaves to the plug-in.
std::unique_ptr<AssetDecoder> open_exr(const ImageSource& source);

}  // namespace penumbra
