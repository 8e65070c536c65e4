#pragma once
// Wavefront OBJ through Debian's tinyobjloader (libtinyobjloader-dev 2.0.0rc10), which is not
// written for hostile input. So it only ever sees bytes this reader has screened first (see
// obj_reader.cpp): statements other than v, vn, vt and f are turned into comments, every count
// and index is checked against the limits, and only then does tinyobjloader allocate.
//
// Positions, normals and uvs are read; `mtllib` and `usemtl` are ignored (the scene's material
// applies, and no other file is opened). As Mitsuba 3's obj plugin, v is flipped on load
// (OBJ's v runs upward, the scene format's uv (0, 0) is an image's top-left). Polygons are
// fan-triangulated from their first corner. Corners that share a position but not a normal or
// uv become distinct vertices.
#include <string>

#include "renderer/io/mesh_file.h"

namespace penumbra {

// Takes the bytes by value: screening rewrites them in place. Throws MeshFileError.
MeshFile parse_obj(std::string bytes, const std::string& name, const MeshFileLimits& limits = {});

}  // namespace penumbra
