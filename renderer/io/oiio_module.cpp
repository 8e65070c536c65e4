#include "renderer/io/oiio_module.h"

#include <dlfcn.h>

#include <atomic>
#include <cstdlib>
#include <vector>

#include "renderer/io/executable_dir.h"
#include "renderer/io/image_io.h"
#include "renderer/io/image_reader.h"

namespace penumbra {
namespace {

constexpr const char* kModuleName = "libpenumbra_oiio.so";

struct Module {
  decltype(&penumbra_oiio_open) open = nullptr;
  decltype(&penumbra_oiio_open_memory) open_memory = nullptr;
  decltype(&penumbra_oiio_read) read = nullptr;
  decltype(&penumbra_oiio_close) close = nullptr;
  std::string error;  // why it could not be loaded ("" = loaded)
};

std::atomic<bool> g_loaded{false};

std::vector<std::string> candidates() {
  if (const char* env = std::getenv("PENUMBRA_OIIO_MODULE"); env && *env) return {env};
  const std::string dir = executable_dir();
  if (dir.empty()) return {kModuleName};
  return {dir + "/../lib/penumbra/" + kModuleName, dir + "/" + kModuleName};
}

Module load() {
  Module m;
  std::string tried;
  for (const std::string& path : candidates()) {
    void* lib = ::dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
      const char* why = ::dlerror();
      tried += (tried.empty() ? "" : "; ") + std::string(why ? why : path);
      continue;
    }
    // The library stays loaded for the life of the process: OpenImageIO keeps global state.
    auto version = reinterpret_cast<decltype(&penumbra_oiio_abi_version)>(
        ::dlsym(lib, "penumbra_oiio_abi_version"));
    m.open = reinterpret_cast<decltype(&penumbra_oiio_open)>(::dlsym(lib, "penumbra_oiio_open"));
    m.open_memory = reinterpret_cast<decltype(&penumbra_oiio_open_memory)>(
        ::dlsym(lib, "penumbra_oiio_open_memory"));
    m.read = reinterpret_cast<decltype(&penumbra_oiio_read)>(::dlsym(lib, "penumbra_oiio_read"));
    m.close = reinterpret_cast<decltype(&penumbra_oiio_close)>(::dlsym(lib, "penumbra_oiio_close"));
    if (!version || !m.open || !m.open_memory || !m.read || !m.close || version() != PENUMBRA_OIIO_ABI_VERSION) {
      tried += (tried.empty() ? "" : "; ") + path + ": not a penumbra OpenImageIO plug-in of this version";
      m = Module{};
      continue;
    }
    g_loaded = true;
    return m;
  }
  m.error = "reading images needs OpenImageIO through " + std::string(kModuleName) +
            ", which could not be loaded (" + tried + ")";
  return m;
}

const Module& module() {
  static const Module m = load();  // thread-safe initialisation (C++11 magic statics)
  return m;
}

}  // namespace

PluginImage::~PluginImage() { module().close(handle_); }

void PluginImage::read(int channels, float* pixels) { read(channels, PENUMBRA_OIIO_FLOAT, pixels); }
void PluginImage::read(int channels, uint8_t* pixels) { read(channels, PENUMBRA_OIIO_UINT8, pixels); }

void PluginImage::read(int channels, int type, void* pixels) {
  char error[512] = "";
  if (!module().read(handle_, channels, type, pixels, error, sizeof error))
    throw ImageIoError(path_ + ": cannot decode the image: " + error);
}

std::unique_ptr<PluginImage> open_plugin_image(const std::string& path) {
  const Module& m = module();
  if (!m.error.empty()) throw ImageIoError(path + ": " + m.error);
  PenumbraImageSpec spec{};
  char error[512] = "";
  void* handle = m.open(path.c_str(), &spec, error, sizeof error);
  if (!handle) throw ImageIoError(path + ": cannot read the image: " + error);
  return std::unique_ptr<PluginImage>(new PluginImage(handle, spec, path));
}

std::unique_ptr<PluginImage> open_plugin_image(const ImageSource& source) {
  if (!source.bytes) return open_plugin_image(source.path);
  const Module& m = module();
  if (!m.error.empty()) throw ImageIoError(source.path + ": " + m.error);
  PenumbraImageSpec spec{};
  char error[512] = "";
  void* handle = m.open_memory(source.bytes->data(), source.bytes->size(), source.format.c_str(),
                               &spec, error, sizeof error);
  if (!handle) throw ImageIoError(source.path + ": cannot read the image: " + error);
  auto image = std::unique_ptr<PluginImage>(new PluginImage(handle, spec, source.path));
  image->bytes_ = source.bytes;  // the plug-in reads them until the handle is closed
  return image;
}

bool oiio_module_loaded() { return g_loaded.load(); }

}  // namespace penumbra
