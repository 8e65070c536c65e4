// The OpenImageIO plug-in: the only code of penumbra that links OpenImageIO. Built as a shared
// module (libpenumbra_oiio.so) and loaded by renderer/io/oiio_module.cpp on first use.
#include <OpenImageIO/filesystem.h>
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

// Runs `body`, and turns any exception into the error buffer and `failed`: no C++ exception may
// cross the C ABI into the renderer.
template <typename T, typename Body>
T guarded(char* error, size_t error_size, T failed, Body&& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    set_error(error, error_size, e.what());
  } catch (...) {
    set_error(error, error_size, "OpenImageIO threw an unknown exception");
  }
  return failed;
}

// What a handle points to: the reader and, for an image in memory, the proxy it reads through.
struct Handle {
  std::unique_ptr<OIIO::Filesystem::IOMemReader> proxy;
  std::unique_ptr<OIIO::ImageInput> in;
};

void fill(const OIIO::ImageSpec& s, PenumbraImageSpec* spec) {
  spec->width = s.width;
  spec->height = s.height;
  spec->depth = s.depth;
  spec->channels = s.nchannels;
  spec->is_float = s.format.is_floating_point() ? 1 : 0;
  spec->is_uint8 = s.format.basetype == OIIO::TypeDesc::UINT8 ? 1 : 0;
}

}  // namespace

extern "C" {

__attribute__((visibility("default"))) int penumbra_oiio_abi_version(void) {
  return PENUMBRA_OIIO_ABI_VERSION;
}

__attribute__((visibility("default"))) void* penumbra_oiio_open(const char* path,
                                                                PenumbraImageSpec* spec,
                                                                char* error, size_t error_size) {
  return guarded<void*>(error, error_size, nullptr, [&]() -> void* {
    auto h = std::make_unique<Handle>();
    h->in = OIIO::ImageInput::open(path);
    if (!h->in) {
      set_error(error, error_size, OIIO::geterror());
      return nullptr;
    }
    fill(h->in->spec(), spec);
    return h.release();
  });
}

__attribute__((visibility("default"))) void* penumbra_oiio_open_memory(
    const void* bytes, size_t size, const char* format, PenumbraImageSpec* spec, char* error,
    size_t error_size) {
  return guarded<void*>(error, error_size, nullptr, [&]() -> void* {
    auto h = std::make_unique<Handle>();
    h->proxy = std::make_unique<OIIO::Filesystem::IOMemReader>(bytes, size);
    h->in = OIIO::ImageInput::create(format, false, nullptr, h->proxy.get());
    if (!h->in) {
      set_error(error, error_size, std::string("no reader for the format '") + format + "'");
      return nullptr;
    }
    if (!h->in->set_ioproxy(h->proxy.get())) {
      set_error(error, error_size, std::string("the '") + format + "' reader cannot read from memory");
      return nullptr;
    }
    OIIO::ImageSpec opened;
    if (!h->in->open(std::string("memory.") + format, opened)) {
      set_error(error, error_size, h->in->geterror());
      return nullptr;
    }
    fill(h->in->spec(), spec);
    return h.release();
  });
}

__attribute__((visibility("default"))) int penumbra_oiio_read(void* handle, int channels, int type,
                                                              void* pixels, char* error,
                                                              size_t error_size) {
  OIIO::ImageInput* in = static_cast<Handle*>(handle)->in.get();
  const OIIO::TypeDesc format = type == PENUMBRA_OIIO_UINT8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT;
  return guarded<int>(error, error_size, 0, [&] {
    if (!in->read_image(0, 0, 0, channels, format, pixels)) {
      set_error(error, error_size, in->geterror());
      return 0;
    }
    return 1;
  });
}

__attribute__((visibility("default"))) void penumbra_oiio_close(void* handle) {
  std::unique_ptr<Handle> h(static_cast<Handle*>(handle));
  if (h && h->in) h->in->close();
}
}
