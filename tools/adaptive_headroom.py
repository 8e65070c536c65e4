#!/usr/bin/env python3
"""How much could adaptive sampling give on a scene, at best? (docs/performance.md, session 26)

For each pixel: v, the true error variance of a uniform render at --spp samples (the variance
across --seeds renders), and s^2, the variance of one sample (across --single renders of one
sample each: a scrambled Sobol point alone is uniformly random), both over relMSE's denominator
(reference^2 + 0.01, averaged over the channels, as tools/bench_accuracy.py). Taking a pixel's
error at n samples as v * spp / n, an allocation n_i at equal total samples gains
mean(v) / (mean(v / n) * mean(n)) over uniform sampling. Printed for: the oracle n ~ sqrt(v);
the oracle judged by the neighbours (the 3x3 window without the pixel, which keeps the pixel's
mean unbiased, renderer/render/adaptive_sampling.h); penumbra's rule, n ~ the neighbours' mean
of s; and the square root of that. The oracle judged on the same renders it was computed from
profits from the noise of v over a finite number of seeds (it gives the noisiest pixels of those
very renders more samples), so the tool also prints it cross-validated: v from one half of the
seeds, the gain judged on the other half's v (and the rule judged on it too). On heavy-tailed
scenes the difference is large (conductors, session 31: 1.89 on the same renders, 0.81-0.85
cross-validated, below uniform, against the rule's 1.22). Every allocation keeps --floor of its
mean count, as the renderer keeps a pixel's first 16 samples (without it a cross-validated
oracle starves pixels that showed no noise in one half: 0.00 on the furnace).

  .venv-mitsuba/bin/python tools/adaptive_headroom.py tests/accuracy/scenes/dof.json \
      --penumbra build/app/penumbra
"""
import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np


def renders(binary: str, scene: str, spp: int, seeds: int, mi) -> np.ndarray:
    """The renders of seeds 0 .. seeds-1 at spp samples, as linear RGB arrays."""
    out = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(seeds):
            path = os.path.join(tmp, f"{seed}.exr")
            subprocess.run([binary, "render", scene, "-o", path, "--spp", str(spp), "--seed", str(seed), "-q"],
                           capture_output=True, check=True)
            out.append(np.array(mi.Bitmap(path), dtype=np.float64)[..., :3])
    return np.array(out)


def neighbour_mean(a: np.ndarray) -> np.ndarray:
    """Each pixel's mean of a over its 3x3 window without itself (adaptive_sampling.cpp)."""
    height, width = a.shape
    out = np.empty_like(a)
    for y in range(height):
        for x in range(width):
            block = a[max(0, y - 1):y + 2, max(0, x - 1):x + 2]
            out[y, x] = (block.sum() - a[y, x]) / (block.size - 1) if block.size > 1 else a[y, x]
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("scenes", nargs="+", help="accuracy scenes (their reference is tests/accuracy/references/NAME.exr)")
    parser.add_argument("--penumbra", default="build/app/penumbra")
    parser.add_argument("--spp", type=int, default=16, help="samples of the renders whose error variance is v")
    parser.add_argument("--seeds", type=int, default=48, help="renders at --spp")
    parser.add_argument("--single", type=int, default=128, help="renders of one sample (for s)")
    parser.add_argument("--references", default=os.path.join(os.path.dirname(os.path.abspath(__file__)),
                                                             "..", "tests", "accuracy", "references"))
    parser.add_argument("--floor", type=float, default=1 / 16,
                        help="every allocation's least count, as a share of its mean (adaptive sampling's "
                             "min_samples over its mean count; 0 for none, as before session 31)")
    args = parser.parse_args()
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    for scene in args.scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        reference = np.array(mi.Bitmap(os.path.join(args.references, f"{name}.exr")), dtype=np.float64)[..., :3]
        denominator = reference ** 2 + 0.01

        def variance(images: np.ndarray) -> np.ndarray:
            """Per pixel, the variance across renders over relMSE's denominator, channels averaged."""
            return (images.var(axis=0, ddof=1) / denominator).mean(axis=2)

        s = np.sqrt(variance(renders(args.penumbra, scene, 1, args.single, mi)))
        stack = renders(args.penumbra, scene, args.spp, args.seeds, mi)
        half = args.seeds // 2
        v, v_a, v_b = variance(stack), variance(stack[:half]), variance(stack[half:])

        def gain(n: np.ndarray, on: np.ndarray = v) -> float:
            # The renderer's floor: every pixel keeps its first samples (16 of a mean of ~256).
            n = np.maximum(n, args.floor * n.mean())
            n = np.maximum(n, 1e-12)
            return float(on.mean() / ((on / n).mean() * n.mean()))

        judged = neighbour_mean(s)
        print(f"{name}: oracle {gain(np.sqrt(v)):.2f}, oracle by neighbours {gain(neighbour_mean(np.sqrt(v))):.2f}, "
              f"penumbra's rule {gain(judged):.2f}, its square root {gain(np.sqrt(judged)):.2f}; "
              f"cross-validated: oracle {gain(np.sqrt(v_a), v_b):.2f} / {gain(np.sqrt(v_b), v_a):.2f}, "
              f"by neighbours {gain(neighbour_mean(np.sqrt(v_a)), v_b):.2f} / {gain(neighbour_mean(np.sqrt(v_b)), v_a):.2f}, "
              f"the rule on either half {gain(judged, v_b):.2f} / {gain(judged, v_a):.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
