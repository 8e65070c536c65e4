#!/usr/bin/env python3
"""Write a small glTF 2.0 binary asset (.glb) that uses what penumbra reads from glTF.

    python3 tools/make_gltf.py scenes/gltf_showcase.glb

Standard library only. The asset (about 100 kB) holds:

* a UV sphere mesh placed by two nodes (the same mesh twice: a shared mesh) under a parent node
  that is rotated and translated (a node hierarchy), one node with a mirroring scale;
* materials of the metallic-roughness model: a textured one (base colour checker, a
  metallic-roughness texture with metal stripes and varying roughness, a normal map of bumps),
  a plain rough gold (factors only), a floor with a sampler set to nearest filtering, and an
  emissive panel (emissive texture x factor x KHR_materials_emissive_strength);
* a perspective camera, and KHR_lights_punctual lights: a directional sun and a point light.

Images are PNGs embedded in the binary chunk; texture coordinate (0, 0) is their top-left
corner (glTF's convention).
"""
from __future__ import annotations

import json
import math
import struct
import sys
import zlib


def png(width: int, height: int, channels: int, pixel) -> bytes:
    """An 8-bit PNG (colour type 2 for RGB, 6 for RGBA) of pixel(x, y) -> tuple of ints."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)  # filter: none
        for x in range(width):
            rows.extend(pixel(x, y))

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    header = struct.pack(">IIBBBBB", width, height, 8, 2 if channels == 3 else 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(bytes(rows), 9))
            + chunk(b"IEND", b""))


def checker(x: int, y: int):
    c = ((x // 16) + (y // 16)) % 2
    return (235, 210, 160) if c else (60, 90, 150)


def metallic_roughness(x: int, y: int):
    # Green: roughness rising left to right; blue: metallic in vertical stripes.
    metal = 255 if (x // 32) % 2 == 0 else 0
    rough = int(40 + 200 * x / 127)
    return (0, rough, metal)


def bumps(x: int, y: int):
    # A tangent-space normal map of round bumps: n = (-dh/dx, -dh/dy, 1) normalised, stored as
    # (n + 1) / 2, +y up in the image (glTF).
    fx, fy = (x % 32) / 32.0 - 0.5, (y % 32) / 32.0 - 0.5
    r2 = fx * fx + fy * fy
    dx, dy = (-fx * 2.5, fy * 2.5) if r2 < 0.16 else (0.0, 0.0)
    length = math.sqrt(dx * dx + dy * dy + 1.0)
    return tuple(int(round((v / length * 0.5 + 0.5) * 255)) for v in (dx, dy, 1.0))


def glow(x: int, y: int):
    v = int(255 * (0.5 + 0.5 * math.cos(x / 63.0 * 6 * math.pi)))
    return (255, v, 40)


def uv_sphere(rings: int = 24, segments: int = 48):
    positions, normals, uvs, indices = [], [], [], []
    for r in range(rings + 1):
        v = r / rings
        theta = v * math.pi
        for s in range(segments + 1):
            u = s / segments
            phi = u * 2 * math.pi
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            positions += n
            normals += n
            uvs += (u * 2.0, v)  # the checker repeats twice around
    for r in range(rings):
        for s in range(segments):
            a = r * (segments + 1) + s
            b = a + segments + 1
            # The first and last rings meet at the poles: one triangle per cell there, not a
            # zero-area one.
            if r > 0:
                indices += (a, b, a + 1)
            if r < rings - 1:
                indices += (a + 1, b, b + 1)
    return positions, normals, uvs, indices


def quad(size: float, y: float, uv_repeat: float):
    h = size / 2
    positions = [-h, y, h, h, y, h, h, y, -h, -h, y, -h]
    normals = [0, 1, 0] * 4
    uvs = [0, uv_repeat, uv_repeat, uv_repeat, uv_repeat, 0, 0, 0]
    return positions, normals, uvs, [0, 1, 2, 0, 2, 3]


class Glb:
    def __init__(self):
        self.bin = bytearray()
        self.doc = {"asset": {"version": "2.0", "generator": "penumbra tools/make_gltf.py"},
                    "bufferViews": [], "accessors": [], "meshes": [], "materials": [], "textures": [],
                    "images": [], "samplers": [], "nodes": [], "cameras": []}

    def view(self, data: bytes) -> int:
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, values, kind: str, width: int) -> int:
        if kind == "indices":
            view = self.view(struct.pack(f"<{len(values)}I", *values))
            self.doc["accessors"].append({"bufferView": view, "componentType": 5125, "count": len(values),
                                          "type": "SCALAR"})
        else:
            view = self.view(struct.pack(f"<{len(values)}f", *values))
            count = len(values) // width
            acc = {"bufferView": view, "componentType": 5126, "count": count,
                   "type": {2: "VEC2", 3: "VEC3"}[width]}
            if kind == "position":
                acc["min"] = [min(values[i::3]) for i in range(3)]
                acc["max"] = [max(values[i::3]) for i in range(3)]
            self.doc["accessors"].append(acc)
        return len(self.doc["accessors"]) - 1

    def mesh(self, geometry, material: int) -> int:
        positions, normals, uvs, indices = geometry
        prim = {"attributes": {"POSITION": self.accessor(positions, "position", 3),
                               "NORMAL": self.accessor(normals, "normal", 3),
                               "TEXCOORD_0": self.accessor(uvs, "uv", 2)},
                "indices": self.accessor(indices, "indices", 1), "material": material}
        self.doc["meshes"].append({"primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def texture(self, image: bytes, sampler: int | None = None) -> int:
        self.doc["images"].append({"bufferView": self.view(image), "mimeType": "image/png"})
        tex = {"source": len(self.doc["images"]) - 1}
        if sampler is not None:
            tex["sampler"] = sampler
        self.doc["textures"].append(tex)
        return len(self.doc["textures"]) - 1

    def node(self, **fields) -> int:
        self.doc["nodes"].append(fields)
        return len(self.doc["nodes"]) - 1

    def write(self, path: str) -> None:
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["buffers"] = [{"byteLength": len(self.bin)}]
        text = json.dumps(self.doc, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        body = (struct.pack("<II", len(text), 0x4E4F534A) + text
                + struct.pack("<II", len(self.bin), 0x004E4942) + bytes(self.bin))
        with open(path, "wb") as f:
            f.write(struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body)


def build() -> Glb:
    g = Glb()
    g.doc["samplers"] = [{"magFilter": 9728, "minFilter": 9728}]  # nearest
    base = g.texture(png(128, 128, 3, checker))
    mr = g.texture(png(128, 128, 3, metallic_roughness))
    normal = g.texture(png(128, 128, 3, bumps))
    floor_tex = g.texture(png(64, 64, 3, lambda x, y: (200, 200, 200) if (x // 8 + y // 8) % 2 else (120, 120, 120)), 0)
    glow_tex = g.texture(png(64, 8, 3, glow))
    g.doc["materials"] = [
        {"name": "textured", "pbrMetallicRoughness": {"baseColorTexture": {"index": base},
                                                      "metallicRoughnessTexture": {"index": mr},
                                                      "metallicFactor": 1.0, "roughnessFactor": 1.0},
         "normalTexture": {"index": normal, "scale": 1.0}},
        {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.78, 0.34, 1.0],
                                                  "metallicFactor": 1.0, "roughnessFactor": 0.3}},
        {"name": "floor", "pbrMetallicRoughness": {"baseColorTexture": {"index": floor_tex},
                                                   "metallicFactor": 0.0, "roughnessFactor": 0.6}},
        {"name": "panel", "pbrMetallicRoughness": {"baseColorFactor": [0.05, 0.05, 0.05, 1.0],
                                                   "metallicFactor": 0.0, "roughnessFactor": 0.5},
         "emissiveTexture": {"index": glow_tex}, "emissiveFactor": [1.0, 1.0, 1.0],
         "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4.0}}},
    ]
    sphere = g.mesh(uv_sphere(), 0)
    gold_sphere = g.mesh(uv_sphere(16, 32), 1)
    floor = g.mesh(quad(8.0, 0.0, 4.0), 2)
    panel_geometry = quad(1.0, 0.0, 1.0)
    panel = g.mesh(panel_geometry, 3)
    # The textured sphere placed twice (a shared mesh), the second mirrored; a gold sphere; all
    # under a parent node turned 20 degrees about +y.
    a = g.node(name="textured sphere", mesh=sphere, translation=[-1.1, 1.0, 0.0], rotation=[0.0, 0.3826834, 0.0, 0.9238795])
    b = g.node(name="mirrored copy", mesh=sphere, translation=[1.1, 0.6, -0.6], scale=[-0.6, 0.6, 0.6])
    c = g.node(name="gold sphere", mesh=gold_sphere, translation=[0.6, 0.35, 1.0], scale=[0.35, 0.35, 0.35])
    # The panel stands up behind the spheres, facing +z (rotated 90 degrees about +x).
    d = g.node(name="glowing panel", mesh=panel, translation=[0.0, 1.2, -2.0], rotation=[0.7071068, 0.0, 0.0, 0.7071068],
               scale=[3.0, 1.0, 0.4])
    group = g.node(name="group", children=[a, b, c, d], rotation=[0.0, 0.1736482, 0.0, 0.9848078])
    ground = g.node(name="floor", mesh=floor)
    g.doc["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.6, "aspectRatio": 1.5, "znear": 0.1}}]
    # Camera at (0, 2.2, 6.5) looking down 15 degrees.
    camera = g.node(name="camera", camera=0, translation=[0.0, 2.2, 6.5], rotation=[-0.1305262, 0.0, 0.0, 0.9914449])
    g.doc["extensionsUsed"] = ["KHR_lights_punctual", "KHR_materials_emissive_strength"]
    g.doc["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "sun", "type": "directional", "color": [1.0, 0.95, 0.85], "intensity": 3.0},
        {"name": "lamp", "type": "point", "color": [0.8, 0.9, 1.0], "intensity": 6.0}]}}
    # The sun comes from the upper left front: -z of the node turned down and to the right.
    sun = g.node(name="sun", rotation=[-0.3535534, -0.3535534, -0.1464466, 0.8535534],
                 extensions={"KHR_lights_punctual": {"light": 0}})
    lamp = g.node(name="lamp", translation=[2.0, 2.5, 2.0], extensions={"KHR_lights_punctual": {"light": 1}})
    g.doc["scenes"] = [{"nodes": [group, ground, camera, sun, lamp]}]
    g.doc["scene"] = 0
    return g


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print(__doc__, file=sys.stderr)
        return 2
    build().write(argv[0])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
