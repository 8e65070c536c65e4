#pragma once
// Radiance RGBE (.hdr) image assets, the usual form of environment maps, decoded here so such a
// scene does not load the OpenImageIO plug-in (oiio_module.h). The format (Ward, "Real Pixels",
// Graphics Gems II, 1991; the RLE scanlines of Radiance 2.0): a text header ending in an empty
// line, a resolution line, then per scanline either run-length encoded components or flat
// 4-byte pixels. A value is mantissa * 2^(exponent - 136), 0 where the exponent is 0: exact in
// float, so the same floats as OpenImageIO's reader (tests compare the two). Taken: the standard
// orientation "-Y h +X w" and 32-bit_rle_rgbe; other orientations and XYZE go to the plug-in.
#include <memory>

#include "renderer/io/asset_decoder.h"

namespace penumbra {

// True when the source starts with "#?" (Radiance's header magic).
bool has_hdr_signature(const SourceHead& head);

// Reads the header (ImageIoError naming the source when it is broken); null for a valid file
// this reader leaves to the plug-in.
std::unique_ptr<AssetDecoder> open_hdr(const ImageSource& source);

}  // namespace penumbra
