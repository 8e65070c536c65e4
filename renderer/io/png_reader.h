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
#include <memory>

#include "renderer/io/asset_decoder.h"

namespace penumbra {

// True when the source's first eight bytes are the PNG signature.
bool has_png_signature(const SourceHead& head);

// A PNG whose header has been read; its pixels are decoded by read(). Errors throw ImageIoError
// naming the source ("<path>: <reason>").
// Reads the header (and nothing more: the caller checks the size before read()).
std::unique_ptr<AssetDecoder> open_png(const ImageSource& source);

}  // namespace penumbra
