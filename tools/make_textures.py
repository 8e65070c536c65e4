#!/usr/bin/env python3
"""Write the generated texture images that example and accuracy scenes use.

    python3 tools/make_textures.py [FOLDER ...]

Default folders: ``scenes/textures`` and ``tests/accuracy/scenes/textures``. Only the Python
standard library is used (PNG written with zlib), and every pixel is a pure function of its
coordinates, so the files are byte-for-byte reproducible; they are small and committed.

=============  =================================================================================
checker.png    8 x 8 RGB checkerboard of two sRGB colours: big texels that show bilinear
               filtering, wrapping at the border and the top-left origin
wood.png       128 x 128 RGB wood grain (rings around an off-centre axis, sRGB browns)
rough.png      64 x 64 grey roughness map (linear values 0.12 ... 0.8 in blobs and stripes)
normal.png     64 x 64 RGB tangent-space normal map, (n + 1) / 2: a grid of round bumps
               (x right, y up, z out of the surface, as Mitsuba 3's ``normalmap``)
=============  =================================================================================
"""
from __future__ import annotations

import math
import os
import struct
import sys
import zlib

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_FOLDERS = [os.path.join(REPO, "scenes", "textures"),
                   os.path.join(REPO, "tests", "accuracy", "scenes", "textures")]


def write_png(path: str, width: int, height: int, channels: int, pixel) -> None:
    """Write an 8-bit PNG; ``pixel(x, y)`` returns ``channels`` values in [0, 1]; row 0 is the top."""
    color_type = {1: 0, 3: 2}[channels]
    rows = bytearray()
    for y in range(height):
        rows.append(0)  # filter type: none
        for x in range(width):
            value = pixel(x, y)
            values = value if isinstance(value, (tuple, list)) else (value,)
            assert len(values) == channels
            rows.extend(max(0, min(255, int(round(v * 255.0)))) for v in values)

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, color_type, 0, 0, 0)
    data = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(bytes(rows), 9)) + \
        chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(data)


def hash01(x: int, y: int, seed: int = 0) -> float:
    """A deterministic value in [0, 1) per integer lattice point (integer hash, no RNG state)."""
    h = (x * 374761393 + y * 668265263 + seed * 2147483647) & 0xFFFFFFFF
    h = ((h ^ (h >> 13)) * 1274126177) & 0xFFFFFFFF
    return ((h ^ (h >> 16)) & 0xFFFFFF) / float(1 << 24)


def value_noise(x: float, y: float, seed: int) -> float:
    """Smooth value noise in [0, 1): bilinear interpolation of lattice hashes with a smoothstep."""
    x0, y0 = math.floor(x), math.floor(y)
    fx, fy = x - x0, y - y0
    sx, sy = fx * fx * (3 - 2 * fx), fy * fy * (3 - 2 * fy)
    top = hash01(x0, y0, seed) * (1 - sx) + hash01(x0 + 1, y0, seed) * sx
    bottom = hash01(x0, y0 + 1, seed) * (1 - sx) + hash01(x0 + 1, y0 + 1, seed) * sx
    return top * (1 - sy) + bottom * sy


def checker(x: int, y: int):
    """Cream and slate squares, one texel each; texel (0, 0) (the top-left) is cream."""
    return (0.93, 0.87, 0.72) if (x + y) % 2 == 0 else (0.16, 0.22, 0.32)


def wood(x: int, y: int):
    """Rings around an axis off the image's centre, their radius disturbed by noise."""
    u, v = x / 128.0, y / 128.0
    r = math.hypot(u - 0.3, (v - 1.2) * 0.35) * 18.0 + 2.5 * value_noise(u * 6, v * 6, 7)
    ring = 0.5 + 0.5 * math.sin(2 * math.pi * r)
    grain = 0.85 + 0.15 * value_noise(u * 40, v * 4, 3)
    light, dark = (0.78, 0.55, 0.33), (0.45, 0.26, 0.13)
    t = ring ** 2.5
    return tuple((d + (l - d) * t) * grain for l, d in zip(light, dark))


def roughness(x: int, y: int) -> float:
    """Linear roughness: smooth blobs in a rough field, crossed by a smoother stripe."""
    n = value_noise(x / 9.0, y / 9.0, 11)
    stripe = 1.0 if 24 <= (x + y // 2) % 64 < 34 else 0.0
    r = 0.12 + 0.68 * n
    return 0.12 + (r - 0.12) * (1 - 0.8 * stripe)


def normal(x: int, y: int):
    """Round bumps on an 8-texel grid: a spherical cap of height h, its slope as the normal."""
    cx, cy = (x % 8) + 0.5 - 4.0, (y % 8) + 0.5 - 4.0
    r2 = cx * cx + cy * cy
    radius = 3.5
    if r2 >= radius * radius:
        n = (0.0, 0.0, 1.0)
    else:
        # Height sqrt(R^2 - r^2) scaled by 0.45: gradient (-s cx / h, -s cy / h); image y grows
        # downwards, the map's y upwards, hence the sign of the y slope.
        h = math.sqrt(radius * radius - r2)
        s = 0.45
        gx, gy = -s * cx / max(h, 0.5), s * cy / max(h, 0.5)
        n = (gx, gy, 1.0)
    length = math.sqrt(sum(c * c for c in n))
    return tuple(0.5 * (c / length + 1.0) for c in n)


def main(argv: list[str]) -> int:
    for folder in argv or DEFAULT_FOLDERS:
        os.makedirs(folder, exist_ok=True)
        write_png(os.path.join(folder, "checker.png"), 8, 8, 3, checker)
        write_png(os.path.join(folder, "wood.png"), 128, 128, 3, wood)
        write_png(os.path.join(folder, "rough.png"), 64, 64, 1, roughness)
        write_png(os.path.join(folder, "normal.png"), 64, 64, 3, normal)
        print(f"wrote checker.png, wood.png, rough.png, normal.png in {folder}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
