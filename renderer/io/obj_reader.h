#pragma once
// Wavefront OBJ, our own reader (obj_reader.cpp; why not tinyobjloader: docs/mesh-files.md):
// one pass reads v, vn, vt and f statements and skips every other line, with every count held to
// the limits as it grows and every malformed number or index an error naming its line.
//
// Positions, normals and uvs are read; `mtllib` and `usemtl` are ignored (the scene's material
// applies, and no other file is opened). As Mitsuba 3's obj plugin, v is flipped on load
// (OBJ's v runs upward, the scene format's uv (0, 0) is an image's top-left). Polygons are
// fan-triangulated from their first corner. Corners that share a position but not a normal or
// uv become distinct vertices.
#include <string>

#include "renderer/io/file_bytes.h"
#include "renderer/io/mesh_file.h"

namespace penumbra {

// Throws MeshFileError. A file of 8 MB or more is read in parts (of at least 4 MB) on threads.
// `bytes` is released once its statements are read (before the vertices are merged), to lower
// the peak memory; the caller may still ask it whether it stayed intact.
MeshFile parse_obj(FileBytes&& bytes, const std::string& name, const MeshFileLimits& limits = {});

namespace obj_reader_detail {
// parse_obj with the file read in `parts` pieces (for the tests and the fuzzer: any count gives
// parse_obj's mesh).
MeshFile parse_obj_in_parts(FileBytes&& bytes, const std::string& name, const MeshFileLimits& limits,
                            size_t parts);
}  // namespace obj_reader_detail

}  // namespace penumbra
