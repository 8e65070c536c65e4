#pragma once
// The C interface between penumbra and its OpenImageIO plug-in (libpenumbra_oiio.so), which is
// loaded only when a scene reads an image asset (renderer/io/oiio_module.h says why). Plain C
// types only: the two sides need not agree on a C++ ABI beyond this.
#include <cstddef>

extern "C" {

// Bumped whenever a declaration below changes; the loader refuses another version.
#define PENUMBRA_OIIO_ABI_VERSION 2

struct PenumbraImageSpec {
  int width;
  int height;
  int depth;        // > 1 for volume images
  int channels;
  int is_float;     // stored as floating point (EXR, HDR, float TIFF)
  int is_uint8;     // stored as 8-bit integers (PNG, JPEG, most TIFF): sRGB-encoded by convention
};

int penumbra_oiio_abi_version(void);
// Opens `path` and fills `spec` from its header without decoding pixels. Returns a handle, or
// null with a message in `error` (at most error_size bytes, NUL-terminated).
void* penumbra_oiio_open(const char* path, PenumbraImageSpec* spec, char* error, size_t error_size);
// Pixel types penumbra_oiio_read converts to.
#define PENUMBRA_OIIO_FLOAT 0
#define PENUMBRA_OIIO_UINT8 1
// Decodes the first `channels` channels of the first sub-image, converted to `type`,
// channel-interleaved, top row first, into `pixels` (width * height * channels values).
// Returns 0 on failure.
int penumbra_oiio_read(void* handle, int channels, int type, void* pixels, char* error,
                       size_t error_size);
void penumbra_oiio_close(void* handle);
}
