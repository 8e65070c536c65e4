#!/usr/bin/env python3
"""Variance at equal samples of penumbra's two point patterns (render.sampler "cmj" and "sobol"),
scene by scene: each scene rendered with SEEDS seeds per pattern, the variance of a pattern being
the relMSE of its renders against their own mean (times n / (n - 1)), relative to the mean of
both patterns' means (plus 0.01, as tools/bench_accuracy.py's relMSE). Optionally Mitsuba 3's
multijitter sampler beside them (--mitsuba). Prints a Markdown table; docs/performance.md, levers,
session 38 has its numbers. From the repo root, with the Mitsuba venv
(scripts/setup-mitsuba-venv.sh):

  .venv-mitsuba/bin/python bench/sampler_variance.py [--spp 64] [--seeds 16] [--mitsuba]
      [--penumbra build/app/penumbra] [SCENE ...]   (default: every accuracy scene)
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bench_accuracy as ba  # noqa: E402
import penumbra_to_mitsuba as p2m  # noqa: E402

SCENES = os.path.join(ROOT, "tests", "accuracy", "scenes")


def variance(images, reference):
    v = np.array(images)
    mean = v.mean(axis=0)
    per = [np.mean((x - mean) ** 2 / (reference ** 2 + 0.01)) * len(v) / (len(v) - 1) for x in v]
    return float(np.mean(per)), float(np.std(per) / np.sqrt(len(per)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=16)
    ap.add_argument("--penumbra", default=os.path.join(ROOT, "build", "app", "penumbra"))
    ap.add_argument("--mitsuba", action="store_true", help="Mitsuba 3 llvm_ad_rgb with multijitter too")
    args = ap.parse_args()
    if args.seeds < 2:
        ap.error("--seeds must be at least 2")
    scenes = args.scenes or sorted(f[:-5] for f in os.listdir(SCENES) if f.endswith(".json"))
    mi = p2m.import_mitsuba("llvm_ad_rgb")
    out = os.path.join(tempfile.mkdtemp(), "image.exr")
    print(f"| scene ({args.spp} spp, {args.seeds} seeds) | sobol variance | cmj variance | cmj / sobol |"
          + (" multijitter / sobol |" if args.mitsuba else ""))
    print("| --- | ---: | ---: | ---: |" + (" ---: |" if args.mitsuba else ""))
    for name in scenes:
        path = os.path.join(SCENES, name + ".json")
        images = {"sobol": [], "cmj": [], "multijitter": []}
        for seed in range(args.seeds):
            for sampler in ("sobol", "cmj"):
                subprocess.run([args.penumbra, "render", path, "-o", out, "--spp", str(args.spp), "--seed",
                                str(seed), "--sampler", sampler, "-q"], check=True, capture_output=True)
                images[sampler].append(ba.read_exr(mi, out))
            if args.mitsuba:
                import json
                scene = json.load(open(path))
                img, _, _ = ba.run_mitsuba("llvm_ad_rgb", scene, args.spp, seed + 1000, 1, assets=SCENES,
                                           sampler="multijitter")
                images["multijitter"].append(img)
        used = {k: v for k, v in images.items() if v}
        reference = np.mean([np.mean(v, axis=0) for v in used.values()], axis=0)
        sobol, sobol_se = variance(images["sobol"], reference)
        cmj, cmj_se = variance(images["cmj"], reference)
        row = f"| {name} | {sobol:.4e} +- {sobol_se:.1e} | {cmj:.4e} +- {cmj_se:.1e} | {cmj / sobol:.3f} |"
        if args.mitsuba:
            mj, _ = variance(images["multijitter"], reference)
            row += f" {mj / sobol:.3f} |"
        print(row, flush=True)


if __name__ == "__main__":
    main()
