#!/usr/bin/env python3
"""Where a scene's relMSE comes from, penumbra against Mitsuba: K seeds of each at SPP, the
per-pixel relative squared errors against the scene's reference pooled over the seeds, and for
each renderer the mean relMSE, the median image's, the share of the total held by the worst
0.01% / 0.1% / 1% of pixels, the mean without the worst 0.1%, and the worst single pixels
(seed, x, y, value, reference). For scenes whose error is decided by rare bright samples
(docs/accuracy.md, session 24: environment_map). From the repository root:

    .venv-mitsuba/bin/python tools/compare_tails.py SCENE SEEDS SPP [--penumbra BIN] [--variant V]
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_accuracy as ba  # noqa: E402
import penumbra_to_mitsuba as p2m  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene", help="an accuracy scene's name, e.g. environment_map")
    ap.add_argument("seeds", type=int)
    ap.add_argument("spp", type=int)
    ap.add_argument("--penumbra", default=os.path.join(ba.REPO, "build", "app", "penumbra"))
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--sampler", default="independent")
    args = ap.parse_args()
    scene_path = os.path.join(ba.ACCURACY, "scenes", f"{args.scene}.json")
    mi = p2m.import_mitsuba(args.variant)
    p2m.use_scene_folder(mi, scene_path)
    scene = p2m.load_json(scene_path)
    reference = ba.read_exr(mi, os.path.join(ba.ACCURACY, "references", f"{args.scene}.exr"))
    assets = os.path.dirname(scene_path)
    for name in ("penumbra", f"mitsuba {args.variant} {args.sampler}"):
        errors, worst = [], []
        for seed in range(args.seeds):
            if name == "penumbra":
                image, _ = ba.run_penumbra(args.penumbra, scene_path, args.spp, seed, mi)
            else:
                image, _, _ = ba.run_mitsuba(args.variant, scene, args.spp, seed, 1, assets, args.sampler)
            e = ((image - reference) ** 2 / (reference ** 2 + 0.01)).mean(axis=2)
            errors.append(e)
            y, x = np.unravel_index(np.argmax(e), e.shape)
            worst.append((float(e[y, x]), seed, int(x), int(y), image[y, x].round(2).tolist(),
                          reference[y, x].round(3).tolist()))
        pooled = np.stack(errors)
        flat = np.sort(pooled.ravel())[::-1]
        n = flat.size
        print(f"{name}: mean relMSE {pooled.mean():.4g}, median image's {np.median(pooled.mean(axis=(1, 2))):.4g}")
        for q in (1e-4, 1e-3, 1e-2):
            k = max(1, int(n * q))
            print(f"  worst {q:g} of pixels hold {flat[:k].sum() / flat.sum():.3f} of it")
        print(f"  mean relMSE without the worst 0.001 of pixels: {flat[int(n * 1e-3):].sum() / n:.4g}")
        for w in sorted(worst, reverse=True)[:6]:
            print(f"  term {w[0]:.4g}: seed {w[1]}, pixel ({w[2]}, {w[3]}), value {w[4]}, reference {w[5]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
