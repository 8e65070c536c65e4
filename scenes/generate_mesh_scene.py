#!/usr/bin/env python3
"""Writes the mesh example scenes. Run from anywhere: python3 scenes/generate_mesh_scene.py

scenes/mesh.json       a smooth-shaded torus (inline mesh with per-vertex normals) on a floor
                       under an area light;
scenes/mesh_file.json  a trefoil-knot tube read from scenes/meshes/trefoil.ply (binary PLY of
                       quads, with vertex normals and uvs), written here too."""
import json
import math
import os
import struct

MAJOR_SEGMENTS = 96   # around the ring
MINOR_SEGMENTS = 48   # around the tube -> 2 * 96 * 48 = 9216 triangles
MAJOR_RADIUS = 0.7
MINOR_RADIUS = 0.28


def torus():
    positions, normals, indices = [], [], []
    for i in range(MAJOR_SEGMENTS):
        phi = 2 * math.pi * i / MAJOR_SEGMENTS
        for j in range(MINOR_SEGMENTS):
            theta = 2 * math.pi * j / MINOR_SEGMENTS
            # Unit normal of the tube; the ring lies in the xz plane, y is up.
            n = (math.cos(theta) * math.cos(phi), math.sin(theta), math.cos(theta) * math.sin(phi))
            centre = (MAJOR_RADIUS * math.cos(phi), 0.0, MAJOR_RADIUS * math.sin(phi))
            positions += [round(centre[k] + MINOR_RADIUS * n[k], 6) for k in range(3)]
            normals += [round(c, 6) for c in n]
    for i in range(MAJOR_SEGMENTS):
        for j in range(MINOR_SEGMENTS):
            a = i * MINOR_SEGMENTS + j
            b = ((i + 1) % MAJOR_SEGMENTS) * MINOR_SEGMENTS + j
            c = ((i + 1) % MAJOR_SEGMENTS) * MINOR_SEGMENTS + (j + 1) % MINOR_SEGMENTS
            d = i * MINOR_SEGMENTS + (j + 1) % MINOR_SEGMENTS
            # Counter-clockwise seen from outside the tube (front = outward normal).
            indices += [a, d, c, a, c, b]
    return positions, normals, indices


def dump(value, indent=0):
    """JSON with objects indented and arrays of numbers kept on one line."""
    pad = "  " * indent
    if isinstance(value, dict):
        items = [f'{pad}  {json.dumps(k)}: {dump(v, indent + 1)}' for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, list) and any(isinstance(v, (dict, list)) for v in value):
        return "[\n" + ",\n".join(pad + "  " + dump(v, indent + 1) for v in value) + "\n" + pad + "]"
    return json.dumps(value, separators=(", ", ": "))


# ---- scenes/mesh_file.json: a mesh file -------------------------------------------------------

KNOT_SEGMENTS = 160   # along the knot
KNOT_SIDES = 16       # around the tube -> 2560 quads, 5120 triangles
KNOT_TUBE = 0.14


def trefoil(t):
    """A point of the (2, 3) trefoil knot, about 1.2 units across."""
    return (0.4 * (math.sin(t) + 2 * math.sin(2 * t)),
            0.4 * (math.cos(t) - 2 * math.cos(2 * t)),
            -0.4 * math.sin(3 * t))


def sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def unit(a):
    length = math.sqrt(sum(x * x for x in a))
    return tuple(x / length for x in a)


def trefoil_tube():
    """Vertices (position, normal, uv) and quads of a tube around the trefoil knot. The frame
    follows the curve's tangent and a fixed reference axis; u runs along the knot, v around the
    tube. The seam vertices are duplicated so that uvs stay continuous."""
    vertices, quads = [], []
    for i in range(KNOT_SEGMENTS + 1):
        t = 2 * math.pi * i / KNOT_SEGMENTS
        centre = trefoil(t)
        tangent = unit(sub(trefoil(t + 1e-4), trefoil(t - 1e-4)))
        side = unit(cross(tangent, (0.3, 0.2, 1.0)))
        up = cross(side, tangent)
        for j in range(KNOT_SIDES + 1):
            a = 2 * math.pi * j / KNOT_SIDES
            n = tuple(math.cos(a) * s_ + math.sin(a) * u_ for s_, u_ in zip(side, up))
            p = tuple(c + KNOT_TUBE * k for c, k in zip(centre, n))
            vertices.append((p, n, (i / KNOT_SEGMENTS, j / KNOT_SIDES)))
    row = KNOT_SIDES + 1
    for i in range(KNOT_SEGMENTS):
        for j in range(KNOT_SIDES):
            a, b = i * row + j, (i + 1) * row + j
            # Counter-clockwise seen from outside the tube (front = outward normal).
            quads.append((a, b, b + 1, a + 1))
    return vertices, quads


def write_binary_ply(path, vertices, faces):
    """Binary little-endian PLY: float x y z nx ny nz u v, faces as uchar-counted int lists."""
    header = ("ply\nformat binary_little_endian 1.0\ncomment scenes/generate_mesh_scene.py\n"
              f"element vertex {len(vertices)}\n"
              + "".join(f"property float {n}\n" for n in ("x", "y", "z", "nx", "ny", "nz", "u", "v"))
              + f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        for p, n, uv in vertices:
            f.write(struct.pack("<8f", *p, *n, *uv))
        for face in faces:
            f.write(struct.pack(f"<B{len(face)}i", len(face), *face))


def write_mesh_file_scene(here):
    vertices, quads = trefoil_tube()
    os.makedirs(os.path.join(here, "meshes"), exist_ok=True)
    ply = os.path.join(here, "meshes", "trefoil.ply")
    write_binary_ply(ply, vertices, quads)
    scene = {
        "version": 1,
        "render": {"width": 256, "height": 256, "spp": 64, "max_depth": 8, "integrator": "path"},
        "camera": {"position": [0, 1.9, 4.0], "look_at": [0, 1.25, 0], "fov": 38},
        "environment": {"radiance": [0.1, 0.11, 0.14]},
        "materials": {
            "floor": {"type": "diffuse", "color": [0.55, 0.55, 0.5]},
            "glaze": {"type": "plastic", "color": [0.1, 0.3, 0.65], "ior": 1.5, "roughness": 0.15},
            "light": {"type": "diffuse", "color": [0, 0, 0]},
        },
        "objects": [
            {"type": "quad", "origin": [-4, 0, 4], "u": [8, 0, 0], "v": [0, 0, -8], "material": "floor"},
            {"type": "quad", "origin": [-1, 3.6, -0.5], "u": [2, 0, 0], "v": [0, 0, 1],
             "material": "light", "emission": [5, 5, 5]},
            {"type": "mesh", "file": "meshes/trefoil.ply", "material": "glaze",
             "transform": {"rotate": {"axis": [0, 1, 0], "degrees": 20}, "translate": [0, 1.45, 0]}},
        ],
    }
    path = os.path.join(here, "mesh_file.json")
    with open(path, "w") as f:
        f.write(dump(scene) + "\n")
    print(f"wrote {path} and {ply}: {len(quads)} quads, {len(vertices)} vertices "
          f"({os.path.getsize(ply)} bytes)")


def main():
    write_mesh_file_scene(os.path.dirname(os.path.abspath(__file__)))
    positions, normals, indices = torus()
    scene = {
        "version": 1,
        "render": {"width": 256, "height": 256, "spp": 64, "max_depth": 8, "integrator": "path"},
        "camera": {"position": [0, 1.6, 3.2], "look_at": [0, 0.25, 0], "fov": 40},
        "environment": {"radiance": [0.08, 0.09, 0.12]},
        "materials": {
            "floor": {"type": "diffuse", "color": [0.6, 0.6, 0.6]},
            "copper": {"type": "conductor", "color": [0.95, 0.64, 0.54], "roughness": 0.25},
            "light": {"type": "diffuse", "color": [0, 0, 0]},
        },
        "objects": [
            {"type": "quad", "origin": [-4, 0, 4], "u": [8, 0, 0], "v": [0, 0, -8], "material": "floor"},
            {"type": "quad", "origin": [-0.75, 3, -0.75], "u": [1.5, 0, 0], "v": [0, 0, 1.5],
             "material": "light", "emission": [6, 6, 6]},
            {"type": "mesh", "material": "copper", "positions": positions, "indices": indices,
             "normals": normals,
             "transform": {"rotate": {"axis": [1, 0, 0], "degrees": 25}, "translate": [0, 0.55, 0]}},
        ],
    }
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "mesh.json")
    with open(path, "w") as f:
        f.write(dump(scene) + "\n")
    print(f"wrote {path}: {len(indices) // 3} triangles")


if __name__ == "__main__":
    main()
