// The OpenImageIO plug-in: the only code of penumbra that links OpenImageIO. Built as a shared
// module (libpenumbra_oiio.so) and loaded by renderer/io/oiio_module.cpp on first use.
#include <OpenImageIO/imageio.h>

#include <cstring>
#include <exception>
#include <memory>
#include <string>

#include "renderer/io/oiio_plugin/oiio_plugin_abi.h"

namespace {

void set_error(char* error, size_t size, const std::string& message) {
  if (!error || size == 0) return;
  const size_t n = std::min(size - 1, message.size());
  std::memcpy(error, message.data(), n);
  error[n] = '\0';
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int penumbra_oiio_abi_version(void) {
  return PENUMBRA_OIIO_ABI_VERSION;
}

__attribute__((visibility("default"))) void* penumbra_oiio_open(const char* path,
                                                                PenumbraImageSpec* spec,
                                                                char* error, size_t error_size) {
  try {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
      set_error(error, error_size, OIIO::geterror());
      return nullptr;
    }
    const OIIO::ImageSpec& s = in->spec();
    spec->width = s.width;
    spec->height = s.height;
    spec->depth = s.depth;
    spec->channels = s.nchannels;
    spec->is_float = s.format.is_floating_point() ? 1 : 0;
    spec->is_uint8 = s.format.basetype == OIIO::TypeDesc::UINT8 ? 1 : 0;
    return in.release();
  } catch (const std::exception& e) {
    set_error(error, error_size, e.what());
    return nullptr;
  }
}

__attribute__((visibility("default"))) int penumbra_oiio_read(void* handle, int channels, int type,
                                                              void* pixels, char* error,
                                                              size_t error_size) {
  auto* in = static_cast<OIIO::ImageInput*>(handle);
  const OIIO::TypeDesc format = type == PENUMBRA_OIIO_UINT8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
  try {
    if (!in->read_image(0, 0, 0, channels, format, pixels)) {
      set_error(error, error_size, in->geterror());
      return 0;
    }
    return 1;
  } catch (const std::exception& e) {
    set_error(error, error_size, e.what());
    return 0;
  }
}

__attribute__((visibility("default"))) void penumbra_oiio_close(void* handle) {
  std::unique_ptr<OIIO::ImageInput> in(static_cast<OIIO::ImageInput*>(handle));
  if (in) in->close();
}
}
