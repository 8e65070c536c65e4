// tinygltf's implementation, compiled once with tiny_gltf_config.h's settings (third-party code:
// built without warnings, see renderer/CMakeLists.txt).
// Its writer (never called here) uses std::ofstream even with TINYGLTF_NO_FS, without including
// <fstream> itself.
#include <fstream>

#define TINYGLTF_IMPLEMENTATION
#include "renderer/io/tiny_gltf_config.h"
