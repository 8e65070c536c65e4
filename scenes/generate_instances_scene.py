#!/usr/bin/env python3
"""Writes scenes/instances.json. Run from anywhere: python3 scenes/generate_instances_scene.py

A trefoil knot (scenes/meshes/trefoil.ply, made by generate_mesh_scene.py) stands in the middle
of a floor, and one "instances" object places 48 copies of it around it in rings, each turned,
tilted and scaled differently (some non-uniformly): 49 knots, one mesh in memory."""
import json
import math
import os
import random

HERE = os.path.dirname(os.path.abspath(__file__))


def copies():
    rng = random.Random(4)
    out = []
    for ring, (radius, count) in enumerate(((1.5, 12), (2.6, 16), (3.7, 20))):
        for k in range(count):
            angle = 2 * math.pi * (k + 0.5 * ring) / count
            s = rng.uniform(0.25, 0.42)
            stretch = rng.choice((1.0, 1.0, 1.6))  # some copies stretched along y
            out.append({
                "scale": [s, round(s * stretch, 4), s] if stretch != 1.0 else round(s, 4),
                "rotate": {"axis": [round(rng.uniform(-0.4, 0.4), 3), 1, round(rng.uniform(-0.4, 0.4), 3)],
                           "degrees": round(rng.uniform(0, 360), 1)},
                # Copies scale and turn the mesh where it stands (its lowest point just below
                # the floor, at y = -0.07), about the world origin on the floor: lift each by
                # what is left of that dip.
                "translate": [round(radius * math.sin(angle), 4), round(0.07 * s * stretch + 0.02, 4),
                              round(-radius * math.cos(angle), 4)],
            })
    for c in out:
        if isinstance(c["scale"], list):
            c["scale"] = [round(x, 4) for x in c["scale"]]
        else:
            c["scale"] = round(c["scale"], 4)
    return out


def scene():
    return {
        "version": 1,
        "render": {"width": 256, "height": 160, "spp": 64, "max_depth": 8, "integrator": "path"},
        "camera": {"position": [0, 3.4, 6.4], "look_at": [0, 0.3, 0], "fov": 40},
        "environment": {"radiance": [0.12, 0.13, 0.16]},
        "materials": {
            "floor": {"type": "diffuse", "color": [0.55, 0.55, 0.5]},
            "glaze": {"type": "plastic", "color": [0.65, 0.25, 0.08], "ior": 1.5, "roughness": 0.2},
            "light": {"type": "diffuse", "color": [0, 0, 0]},
        },
        "objects": [
            {"type": "quad", "origin": [-12, 0, 6], "u": [24, 0, 0], "v": [0, 0, -30], "material": "floor"},
            {"type": "quad", "origin": [-1.5, 4.5, -1.0], "u": [3, 0, 0], "v": [0, 0, 2],
             "material": "light", "emission": [6, 6, 6]},
            {"type": "mesh", "file": "meshes/trefoil.ply", "material": "glaze",
             "transform": {"scale": 0.5, "translate": [0, 0.6, 0]}},
            {"type": "instances", "mesh": 2, "transforms": copies()},
        ],
    }


def main():
    path = os.path.join(HERE, "instances.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scene(), f, indent=1)
        f.write("\n")
    print(path)


if __name__ == "__main__":
    main()
