"""Blender meshes as binary PLY files (one per material slot in use), with uvs and, for smooth
shading, per-corner normals. Positions stay in object space; the object's world matrix goes into
the scene as the object's `transform`, so instances of one mesh share one file (and one upload).

Blender's uv (0, 0) is an image's bottom-left corner, penumbra's its top-left (glTF, Mitsuba 3):
v is written as 1 - v, which makes an image texture land where Blender puts it.
"""
from __future__ import annotations

import sys
from array import array
from itertools import chain
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

    # One hashable key per face corner, built by zip (in C): the corner's vertex, normal, uv.
    triples = zip(*[iter(normals)] * 3) if normals is not None else iter(lambda: None, 0)
    pairs = zip(*[iter(uvs)] * 2) if uvs is not None else iter(lambda: None, 0)
    corner_key = list(zip(loop_vert, triples, pairs))
    xs, ys, zs = co[0::3], co[1::3], co[2::3]
    parts = {}
    for material_index in sorted(set(tri_mat)):
        if len(parts) == 0 and tri_mat.count(material_index) == n_tri:
            corners = tri_loops
        else:
            corners = [loop for t in range(n_tri) if tri_mat[t] == material_index
                       for loop in tri_loops[3 * t:3 * t + 3]]
        # Corners sharing vertex, normal and uv become one vertex, numbered as first seen
        # (setdefault's len() is taken before the insertion).
        index: Dict[tuple, int] = {}
        indices = array("i", [index.setdefault(corner_key[loop], len(index)) for loop in corners])
        keys = list(index)
        verts = [k[0] for k in keys]
        positions = array("f", chain.from_iterable(zip(map(xs.__getitem__, verts),
                                                       map(ys.__getitem__, verts),
                                                       map(zs.__getitem__, verts))))
        nrm = array("f", chain.from_iterable(k[1] for k in keys)) if normals is not None \
            else array("f")
        uv = array("f", chain.from_iterable((k[2][0], 1.0 - k[2][1]) for k in keys)) \
            if uvs is not None else array("f")
        parts[material_index] = (positions, nrm, uv, indices)
    return parts


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
    columns = [zip(*[iter(positions)] * 3)]
    if len(normals):
        columns.append(zip(*[iter(normals)] * 3))
    if len(uvs):
        columns.append(zip(*[iter(uvs)] * 2))
    vertex_data = array("f", chain.from_iterable(chain.from_iterable(zip(*columns))))
    if vertex_data.itemsize != 4 or indices.itemsize != 4:
        raise RuntimeError("this platform's C float or int is not 32 bits")
    index_data = array("i", indices)
    if sys.byteorder != "little":
        vertex_data.byteswap()
        index_data.byteswap()
    # Each face: a count byte (3), then three int32; interleaved by strided slices (in C).
    n_faces = len(indices) // 3
    raw = index_data.tobytes()
    faces = bytearray(13 * n_faces)
    faces[0::13] = b"\x03" * n_faces
    for k in range(12):
        faces[1 + k::13] = raw[k::12]
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
