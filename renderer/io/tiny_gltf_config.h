#pragma once
// tinygltf (Debian's libtinygltf-dev 2.7, header only: its implementation is compiled here in
// tiny_gltf_impl.cpp, not taken from the packaged shared library, which is built with stb_image
// and the default file system) with the configuration every translation unit must share:
//  * no stb_image / stb_image_write: images are kept encoded by our loader callback and decoded
//    by OpenImageIO, whose header check enforces the texture limits before decoding;
//  * no default file system: the only way to read a file a glTF names is the callbacks
//    gltf_file.cpp installs, which confine reads to the asset folder (the default ones would
//    also shell-expand `~` and `$VAR` in URIs).
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_FS
#include <tiny_gltf.h>
