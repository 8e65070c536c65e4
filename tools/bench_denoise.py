#!/usr/bin/env python3
"""Denoising against the Mitsuba 3 references: relMSE of penumbra's image with and without
``--denoise`` (Open Image Denoise, albedo and normal guided) at a ladder of sample counts, and
the time each needs to reach the relMSE that 1024 undenoised spp give.

    .venv-mitsuba/bin/python tools/bench_denoise.py --penumbra build/app/penumbra \
        [--scenes cornell,textured_diffuse,glass_rough,environment_map,dof] [--seeds 3] \
        [--out bench/out/denoise]

Scenes and references are the accuracy suite's (tests/accuracy/scenes, tests/accuracy/references,
docs/accuracy.md). Seconds are the CLI's own: build + render (+ the denoiser, which the render's
seconds include). Writes ``<out>/denoise.csv``, ``<out>/denoise.md`` (the tables of
docs/denoising.md) and ``<out>/<scene>_4spp.png`` (noisy | denoised | reference, sRGB).
"""
from __future__ import annotations

import argparse
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_accuracy as ba  # noqa: E402

LADDER = [4, 16, 64]            # the table's columns
PLAIN_LADDER = [4, 16, 64, 256, 1024]
DENOISED_LADDER = [4, 16, 64, 256, 1024]


def render(binary, scene_path, spp, seed, denoise, mi, keep_png=None):
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.exr")
        cmd = [binary, "render", scene_path, "-o", out, "--spp", str(spp), "--seed", str(seed), "-q"]
        if denoise:
            cmd.append("--denoise")
        proc = subprocess.run(cmd, capture_output=True, text=True, check=True)
        text = proc.stdout + proc.stderr
        if denoise and "denoised in" not in text:
            raise RuntimeError(f"not denoised: {text}")
        match = ba.SUMMARY.search(text)
        return ba.read_exr(mi, out), float(match.group(2)) + float(match.group(3))


def relmse(image, reference):
    return float(((image - reference) ** 2 / (reference ** 2 + 0.01)).mean())


def main(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--penumbra", required=True)
    ap.add_argument("--scenes", default="cornell,textured_diffuse,glass_rough,environment_map,dof")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--out", default=os.path.join(ba.REPO, "bench", "out", "denoise"))
    args = ap.parse_args(argv)
    mi = ba.p2m.import_mitsuba("scalar_rgb")
    os.makedirs(args.out, exist_ok=True)
    rows = []
    for scene in args.scenes.split(","):
        path = os.path.join(ba.ACCURACY, "scenes", scene + ".json")
        reference = ba.read_exr(mi, os.path.join(ba.ACCURACY, "references", scene + ".exr"))
        for denoise, ladder in ((False, PLAIN_LADDER), (True, DENOISED_LADDER)):
            for spp in ladder:
                for seed in range(1, args.seeds + 1):
                    image, seconds = render(args.penumbra, path, spp, seed, denoise, mi)
                    rows.append({"scene": scene, "denoise": int(denoise), "spp": spp, "seed": seed,
                                 "seconds": seconds, "relmse": relmse(image, reference),
                                 "threshold": 0})
                    if seed == 1 and spp == 4:
                        png = os.path.join(args.out, f"{scene}_4spp_{'denoised' if denoise else 'noisy'}.png")
                        mi.Bitmap(ba.srgb(image).astype(np.float32)).convert(
                            mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True).write(png)
        ref_png = os.path.join(args.out, f"{scene}_reference.png")
        mi.Bitmap(ba.srgb(reference).astype(np.float32)).convert(
            mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, True).write(ref_png)
        print(f"{scene}: done", file=sys.stderr)

    with open(os.path.join(args.out, "denoise.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)

    def mean(scene, denoise, spp, key):
        vals = [r[key] for r in rows if r["scene"] == scene and r["denoise"] == denoise and r["spp"] == spp]
        return float(np.mean(vals))

    lines = ["| scene | relMSE 4 spp (noisy → denoised) | 16 spp | 64 spp | relMSE at 1024 spp, no denoiser | "
             "seconds to reach it: no denoiser / denoised | time saved |", "|---|---|---|---|---|---|---|"]
    for scene in args.scenes.split(","):
        cells = [f"{mean(scene, 0, s, 'relmse'):.2e} → {mean(scene, 1, s, 'relmse'):.2e}" for s in LADDER]
        target = mean(scene, 0, 1024, "relmse")
        plain_t = mean(scene, 0, 1024, "seconds")
        # The cheapest denoised point at or below the target, interpolated (log-log) from the
        # point before it; the denoiser's bias can keep it above the target at every count.
        pts = [(mean(scene, 1, s, "seconds"), mean(scene, 1, s, "relmse")) for s in DENOISED_LADDER]
        den_cell, speed = "not reached by 1024 spp", "–"
        for k, (t, e) in enumerate(pts):
            if e <= target:
                if k == 0:
                    den_t = t
                    den_cell = f"≤ {t:.3f} ({DENOISED_LADDER[0]} spp)"
                else:
                    (t0, e0) = pts[k - 1]
                    f = np.log(target / e0) / np.log(e / e0) if e < e0 else 1.0
                    den_t = float(np.exp(np.log(t0) + f * np.log(t / t0)))
                    den_cell = f"{den_t:.3f}"
                speed = f"{plain_t / den_t:.1f}×"
                break
        lines.append(f"| {scene} | {cells[0]} | {cells[1]} | {cells[2]} | {target:.2e} | "
                     f"{plain_t:.3f} / {den_cell} | {speed} |")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(args.out, "denoise.md"), "w") as f:
        f.write(text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
