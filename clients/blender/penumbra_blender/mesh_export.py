"""Blender meshes as binary PLY files (one per material slot in use), with uvs and, for smooth
shading, per-corner normals. Positions stay in object space; the object's world matrix goes into
the scene as the object's `transform`, so instances of one mesh share one file (and one upload).

Blender's uv (0, 0) is an image's bottom-left corner, penumbra's its top-left (glTF, Mitsuba 3):
v is written as 1 - v, which makes an image texture land where Blender puts it.
"""
from __future__ import annotations

import struct
import sys
from array import array
from typing import Dict, List, Tuple

from .export_context import ExportContext, safe_name


def _floats(n: int) -> array:
    return array("f", bytes(4 * n))


def _ints(n: int) -> array:
    return array("i", bytes(4 * n))


def mesh_parts(mesh) -> Dict[int, Tuple[array, array, array, array]]:
    """{material index: (positions, normals or empty, uvs or empty, indices)} of a Blender mesh.
    Each face corner becomes a vertex once (corners sharing position, normal and uv merge)."""
    mesh.calc_loop_triangles()
    n_tri = len(mesh.loop_triangles)
    n_loop = len(mesh.loops)
    if n_tri == 0:
        return {}
    tri_loops = _ints(3 * n_tri)
    mesh.loop_triangles.foreach_get("loops", tri_loops)
    tri_mat = _ints(n_tri)
    mesh.loop_triangles.foreach_get("material_index", tri_mat)
    loop_vert = _ints(n_loop)
    mesh.loops.foreach_get("vertex_index", loop_vert)
    co = _floats(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    smooth = array("b", bytes(len(mesh.polygons)))
    mesh.polygons.foreach_get("use_smooth", smooth)
    normals = None
    if any(smooth):
        # Split normals: smooth faces get interpolated ones, flat faces (and auto-smooth edges)
        # the face's own, which is what Cycles shades with.
        mesh.calc_normals_split()
        normals = _floats(3 * n_loop)
        mesh.loops.foreach_get("normal", normals)
    uvs = None
    if mesh.uv_layers.active is not None:
        uvs = _floats(2 * n_loop)
        mesh.uv_layers.active.data.foreach_get("uv", uvs)

    parts: Dict[int, list] = {}
    for t in range(n_tri):
        part = parts.get(tri_mat[t])
        if part is None:
            part = parts[tri_mat[t]] = [array("f"), array("f"), array("f"), array("i"), {}]
        pos, nrm, uv, idx, seen = part
        for k in range(3):
            loop = tri_loops[3 * t + k]
            v = loop_vert[loop]
            key = (v,
                   tuple(normals[3 * loop:3 * loop + 3]) if normals is not None else None,
                   tuple(uvs[2 * loop:2 * loop + 2]) if uvs is not None else None)
            i = seen.get(key)
            if i is None:
                i = seen[key] = len(pos) // 3
                pos.extend(co[3 * v:3 * v + 3])
                if normals is not None:
                    nrm.extend(key[1])
                if uvs is not None:
                    uv.extend((key[2][0], 1.0 - key[2][1]))
            idx.append(i)
    return {m: (p[0], p[1], p[2], p[3]) for m, p in parts.items()}


def write_ply(path: str, positions: array, normals: array, uvs: array, indices: array) -> None:
    """Binary little-endian PLY (the format penumbra's loader reads, docs/scene-format.md)."""
    n = len(positions) // 3
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {n}",
              "property float x", "property float y", "property float z"]
    if len(normals):
        header += ["property float nx", "property float ny", "property float nz"]
    if len(uvs):
        header += ["property float u", "property float v"]
    header += [f"element face {len(indices) // 3}", "property list uchar int vertex_indices",
               "end_header"]
    per_vertex = 3 + (3 if len(normals) else 0) + (2 if len(uvs) else 0)
    vertex_data = array("f", bytes(4 * per_vertex * n))
    for i in range(n):
        o = i * per_vertex
        vertex_data[o:o + 3] = positions[3 * i:3 * i + 3]
        o += 3
        if len(normals):
            vertex_data[o:o + 3] = normals[3 * i:3 * i + 3]
            o += 3
        if len(uvs):
            vertex_data[o:o + 2] = uvs[2 * i:2 * i + 2]
    face = struct.Struct("<B3i")
    faces = bytearray(face.size * (len(indices) // 3))
    for t in range(len(indices) // 3):
        face.pack_into(faces, t * face.size, 3, indices[3 * t], indices[3 * t + 1],
                       indices[3 * t + 2])
    if vertex_data.itemsize != 4:
        raise RuntimeError("this platform's C float is not 32 bits")
    if sys.byteorder != "little":
        vertex_data.byteswap()
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        f.write(vertex_data.tobytes())
        f.write(bytes(faces))


def export_mesh_data(ctx: ExportContext, obj, name: str) -> List[Tuple[int, str]]:
    """Writes the evaluated object's mesh; [(material index, scene file name)]."""
    try:
        mesh = obj.to_mesh()
    except RuntimeError:
        mesh = None
    if mesh is None:
        return []
    try:
        parts = mesh_parts(mesh)
        files = []
        for material_index in sorted(parts):
            positions, normals, uvs, indices = parts[material_index]
            suffix = f"_{material_index}" if len(parts) > 1 else ""
            scene_name, path = ctx.new_file("meshes/" + safe_name(name) + suffix + ".ply")
            write_ply(path, positions, normals, uvs, indices)
            files.append((material_index, scene_name))
        return files
    finally:
        obj.to_mesh_clear()
