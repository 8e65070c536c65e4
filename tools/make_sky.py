#!/usr/bin/env python3
"""Write a procedural HDR sky with a small, bright sun as an equirectangular Radiance .hdr file.

    python3 tools/make_sky.py scenes/sky_sun.hdr [--width 512] [--height 256]
        [--sun-elevation 35] [--sun-azimuth 150] [--sun-radius 1.5] [--sun-irradiance 12]

Python standard library only. The output is deterministic (same arguments, same bytes), so the
committed assets can be checked against this script.

Layout: Mitsuba 3's ``envmap`` and penumbra's ``environment.map``: texel column i looks along
azimuth phi = 2 pi (i + 1/2) / width, row j along polar angle theta = pi j / (height - 1) from +y
(the first row is the zenith, the last the nadir), direction
(sin phi sin theta, cos theta, -cos phi sin theta). ``--sun-azimuth`` is phi in degrees: 0 faces
-z (the image's left and right edges), 180 faces +z (its centre column), 90 faces +x.

The sky is a simple analytic model, not a physical one: a blue gradient from zenith to a pale
horizon, a warm glow around the sun, a dark ground below the horizon, and the sun: a disc of
``--sun-radius`` degrees whose radiance gives ``--sun-irradiance`` on a surface facing it
(texels near the disc are supersampled, so its power hardly depends on the resolution). With the
defaults the sun is ~10^4 times brighter than the sky and delivers most of the light: the case
where sampling the environment by importance matters.
"""
from __future__ import annotations

import argparse
import math
import struct
import sys


def direction(phi: float, theta: float) -> tuple[float, float, float]:
    """Unit vector of azimuth phi and polar angle theta (from +y), Mitsuba's envmap convention."""
    s = math.sin(theta)
    return (math.sin(phi) * s, math.cos(theta), -math.cos(phi) * s)


def sky_radiance(d, sun, sun_cos_radius: float, sun_radiance: float) -> tuple[float, float, float]:
    """Linear RGB radiance arriving from direction ``d`` (unit vector)."""
    up = d[1]
    cos_sun = max(-1.0, min(1.0, d[0] * sun[0] + d[1] * sun[1] + d[2] * sun[2]))
    if cos_sun >= sun_cos_radius:
        return (sun_radiance * 1.0, sun_radiance * 0.92, sun_radiance * 0.80)
    gamma = math.acos(cos_sun)  # angle to the sun
    glow = 1.6 * math.exp(-gamma / 0.15) + 0.25 * math.exp(-gamma / 0.7)
    if up >= 0.0:
        t = (1.0 - up) ** 4  # 0 at the zenith, 1 at the horizon
        zenith, horizon = (0.10, 0.22, 0.55), (0.62, 0.72, 0.85)
        base = [z + (h - z) * t for z, h in zip(zenith, horizon)]
    else:
        # Ground: dark, fading into the horizon haze over a few degrees.
        t = math.exp(up / 0.05)
        ground, horizon = (0.06, 0.05, 0.04), (0.40, 0.45, 0.50)
        base = [g + (h - g) * t for g, h in zip(ground, horizon)]
        glow *= t
    warm = (1.0, 0.75, 0.45)
    return tuple(b + glow * w for b, w in zip(base, warm))


def make_sky(width: int, height: int, sun_elevation: float, sun_azimuth: float, sun_radius: float,
             sun_irradiance: float) -> list[list[tuple[float, float, float]]]:
    """Rows (top first) of RGB texels."""
    sun = direction(math.radians(sun_azimuth), math.radians(90.0 - sun_elevation))
    cos_radius = math.cos(math.radians(sun_radius))
    # Radiance of a uniform disc of solid angle 2 pi (1 - cos r) giving irradiance E head-on.
    sun_radiance = sun_irradiance / (2.0 * math.pi * (1.0 - cos_radius))
    d_phi, d_theta = 2.0 * math.pi / width, math.pi / (height - 1)
    # Texels whose footprint may touch the disc are averaged over 8 x 8 points.
    near = math.cos(math.radians(sun_radius) + 1.5 * max(d_phi, d_theta))
    rows = []
    for j in range(height):
        theta = j * d_theta
        row = []
        for i in range(width):
            phi = (i + 0.5) * d_phi
            d = direction(phi, theta)
            if sum(a * b for a, b in zip(d, sun)) < near:
                row.append(sky_radiance(d, sun, cos_radius, sun_radiance))
                continue
            n, acc, weight = 8, [0.0, 0.0, 0.0], 0.0
            for a in range(n):
                for b in range(n):
                    th = min(math.pi, max(0.0, theta + ((a + 0.5) / n - 0.5) * d_theta))
                    ph = phi + ((b + 0.5) / n - 0.5) * d_phi
                    w = math.sin(th)  # solid-angle weight
                    rgb = sky_radiance(direction(ph, th), sun, cos_radius, sun_radiance)
                    acc = [x + w * y for x, y in zip(acc, rgb)]
                    weight += w
            row.append(tuple(x / weight for x in acc) if weight > 0 else sky_radiance(d, sun, cos_radius, sun_radiance))
        rows.append(row)
    return rows


def rgbe(rgb) -> bytes:
    """Ward's shared-exponent encoding of one texel (Graphics Gems II, "Real Pixels")."""
    v = max(rgb)
    if v < 1e-32:
        return b"\0\0\0\0"
    mantissa, exponent = math.frexp(v)
    scale = mantissa * 256.0 / v
    return bytes([min(255, int(c * scale)) for c in rgb] + [exponent + 128])


def rle(channel: bytes) -> bytes:
    """Run-length encoding of one channel of a scanline (Radiance's 'new' RLE): a run is
    (128 + count, value) for 3..127 equal bytes; a dump is (count, bytes...) for up to 128."""
    out = bytearray()
    i, n = 0, len(channel)
    while i < n:
        run = 1
        while i + run < n and run < 127 and channel[i + run] == channel[i]:
            run += 1
        if run >= 3:
            out += bytes([128 + run, channel[i]])
            i += run
            continue
        start = i
        while i < n and i - start < 128:
            if i + 2 < n and channel[i] == channel[i + 1] == channel[i + 2]:
                break
            i += 1
        out += bytes([i - start]) + channel[start:i]
    return bytes(out)


def write_hdr(path: str, rows) -> None:
    """A Radiance RGBE file, run-length encoded scanlines, top row first (-Y H +X W)."""
    height, width = len(rows), len(rows[0])
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(f"-Y {height} +X {width}\n".encode("ascii"))
        for row in rows:
            texels = [rgbe(t) for t in row]
            if not 8 <= width <= 0x7FFF:  # outside the RLE format's range: flat scanlines
                f.write(b"".join(texels))
                continue
            f.write(struct.pack(">BBH", 2, 2, width))
            for c in range(4):
                f.write(rle(bytes(t[c] for t in texels)))


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("output", help="output .hdr file")
    ap.add_argument("--width", type=int, default=512)
    ap.add_argument("--height", type=int, default=256)
    ap.add_argument("--sun-elevation", type=float, default=35.0, help="degrees above the horizon")
    ap.add_argument("--sun-azimuth", type=float, default=150.0, help="degrees; 180 = +z (centre column)")
    ap.add_argument("--sun-radius", type=float, default=1.5, help="angular radius in degrees")
    ap.add_argument("--sun-irradiance", type=float, default=12.0, help="on a surface facing the sun")
    args = ap.parse_args(argv)
    if args.width < 1 or args.height < 2:
        ap.error("the map needs width >= 1 and height >= 2")
    rows = make_sky(args.width, args.height, args.sun_elevation, args.sun_azimuth, args.sun_radius,
                    args.sun_irradiance)
    write_hdr(args.output, rows)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
