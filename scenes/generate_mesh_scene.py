#!/usr/bin/env python3
"""Writes scenes/mesh.json: a smooth-shaded torus (procedural mesh with per-vertex normals)
on a floor under an area light. Run from anywhere: python3 scenes/generate_mesh_scene.py"""
import json
import math
import os

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


def main():
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
