#!/usr/bin/env python3
"""Compare the distribution of single-render pixel values of penumbra and Mitsuba 3 on one scene.

A renderer whose mean is right can still have a heavier tail of outliers (fireflies) than
another: a path sampled with a smaller probability than it should be shows as rarer but larger
values. One render says little about a tail; this renders the scene with many seeds in both
renderers at a low sample count and compares, over all pixels of all renders, the ratio of a
pixel's mean luminance to the reference's (plus 0.01, relMSE's guard for dark pixels): its
mean, quantiles, the counts above fixed multiples, and its largest value.

    .venv-mitsuba/bin/python tools/compare_tails.py tests/accuracy/scenes/environment_map.json \
        --penumbra build/app/penumbra --renders 256 --spp 16

The reference is tests/accuracy/references/SCENE.exr unless --reference is given. docs/accuracy.md
has the environment_map table this produced (session 12).

A second table says where the renders' relMSE comes from: the mean relMSE, the share of it held
by the worst 0.01% / 0.1% / 1% of all pixels, the mean without each render's worst 0.1%
(bench_accuracy.py's relmse_trimmed) and the largest single pixel term with its seed and
position (docs/accuracy.md, session 24).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import penumbra_to_mitsuba as p2m  # noqa: E402
from bench_accuracy import trimmed_mean  # noqa: E402

THRESHOLDS = (10, 30, 100)
QUANTILES = (0.5, 0.99, 0.999, 0.9999)


def luminance_ratios(image: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Each pixel's mean over RGB relative to the reference's (+ 0.01)."""
    return image[..., :3].mean(axis=2) / (reference[..., :3].mean(axis=2) + 0.01)


def relative_errors(image: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """Each pixel's relMSE term, (x - ref)^2 / (ref^2 + 0.01) averaged over RGB."""
    return ((image[..., :3] - reference[..., :3]) ** 2 / (reference[..., :3] ** 2 + 0.01)).mean(axis=2)


def error_shares(errors: list[np.ndarray], first_seed: int) -> str:
    """One row of the second table: the mean relMSE of the renders and how its worst pixels make it."""
    pooled = np.stack(errors)
    flat = np.sort(pooled.ravel())[::-1]
    shares = [flat[:max(1, int(flat.size * q))].sum() / flat.sum() for q in (1e-4, 1e-3, 1e-2)]
    trimmed = float(np.mean([trimmed_mean(e) for e in errors]))
    k, y, x = np.unravel_index(np.argmax(pooled), pooled.shape)
    return (f"{pooled.mean():.4g} | " + " / ".join(f"{v:.3f}" for v in shares) + f" | {trimmed:.4g} | "
            f"{pooled[k, y, x]:.4g} (seed {first_seed + k}, pixel ({x}, {y})) |")


def summary(ratios: np.ndarray) -> dict:
    return {
        "mean": float(ratios.mean()),
        "quantiles": [float(q) for q in np.quantile(ratios, QUANTILES)],
        "above": [int((ratios > t).sum()) for t in THRESHOLDS],
        "max": float(ratios.max()),
    }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("scene")
    parser.add_argument("--penumbra", required=True, help="the penumbra binary")
    parser.add_argument("--reference", help="reference EXR (default: the accuracy suite's)")
    parser.add_argument("--renders", type=int, default=64, help="renders per renderer (seeds)")
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--first-seed", type=int, default=1000)
    parser.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant")
    parser.add_argument("--threads", type=int, default=2, help="penumbra's threads")
    args = parser.parse_args()
    if args.renders < 1 or args.spp < 1:
        parser.error("--renders and --spp must be positive")

    mi = p2m.import_mitsuba(args.variant)
    scene = p2m.load_json(args.scene)
    p2m.use_scene_folder(mi, args.scene)
    name = os.path.splitext(os.path.basename(args.scene))[0]
    ref_path = args.reference or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests",
                                              "accuracy", "references", name + ".exr")
    reference = np.array(mi.Bitmap(ref_path), dtype=np.float64)
    assets = os.path.dirname(os.path.abspath(args.scene))
    mscene = mi.load_dict(p2m.to_mitsuba(mi, scene, spp=args.spp, assets=assets))

    ratios: dict[str, list[np.ndarray]] = {"mitsuba " + args.variant: [], "penumbra": []}
    errors: dict[str, list[np.ndarray]] = {name: [] for name in ratios}
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "render.exr")
        for k in range(args.renders):
            seed = args.first_seed + k
            image = np.asarray(mi.render(mscene, spp=args.spp, seed=seed), dtype=np.float64)
            ratios["mitsuba " + args.variant].append(luminance_ratios(image, reference))
            errors["mitsuba " + args.variant].append(relative_errors(image, reference))
            subprocess.run([args.penumbra, "render", args.scene, "-o", out, "--spp", str(args.spp),
                            "--seed", str(seed), "--threads", str(args.threads)],
                           check=True, capture_output=True)
            image = np.array(mi.Bitmap(out), dtype=np.float64)
            ratios["penumbra"].append(luminance_ratios(image, reference))
            errors["penumbra"].append(relative_errors(image, reference))

    print(f"{name}: {args.renders} renders per renderer at {args.spp} spp, seeds "
          f"{args.first_seed}-{args.first_seed + args.renders - 1}; pixel / reference (mean luminance)")
    print("| renderer | mean | quantiles " + ", ".join(f"{q:g}" for q in QUANTILES) + " | above "
          + " / ".join(f"{t}x" for t in THRESHOLDS) + " | largest |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for renderer, values in ratios.items():
        s = summary(np.stack(values))
        print(f"| {renderer} | {s['mean']:.3f} | " + ", ".join(f"{q:.3g}" for q in s["quantiles"])
              + " | " + " / ".join(str(c) for c in s["above"]) + f" | {s['max']:.0f} |")
    print()
    print("| renderer | relMSE | share of the worst 0.01% / 0.1% / 1% of pixels | relMSE without each "
          "render's worst 0.1% | largest pixel term |")
    print("| --- | ---: | ---: | ---: | ---: |")
    for renderer, values in errors.items():
        print(f"| {renderer} | " + error_shares(values, args.first_seed))
    return 0


if __name__ == "__main__":
    sys.exit(main())
