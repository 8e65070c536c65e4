#pragma once
// PLY polygon files (Greg Turk's format, as described in Paul Bourke's "PLY - Polygon File
// Format" and written by Turk's ply.c): ASCII, binary little- and big-endian. Debian has no PLY
// library except assimp (which must not read untrusted files), so this is our own, small and
// fuzzed (fuzz/ply_reader_fuzzer.cpp).
//
// Read: element "vertex" with x, y, z; optional nx, ny, nz; optional uvs named u, v or s, t or
// texture_u, texture_v or texture_s, texture_t (exporters differ: Blender writes s, t); and
// element "face" with a list "vertex_indices" (or "vertex_index") of 3 or more corners,
// fan-triangulated from the first. Other elements and properties are skipped.
#include <string>
#include <string_view>

#include "renderer/io/mesh_file.h"

namespace penumbra {

// Throws MeshFileError("<name>: <reason>") for malformed, truncated or over-limit input.
MeshFile parse_ply(std::string_view bytes, const std::string& name,
                   const MeshFileLimits& limits = {});

}  // namespace penumbra
