#!/usr/bin/env python3
"""Two penumbra binaries side by side at equal samples: seconds per render and relMSE against the
Mitsuba reference, scene by scene, renders alternating between the binaries (so that a busy
spell of this shared machine falls on both). Written for the light tree (a change of estimator:
its images differ, so bench/bit_identity.sh cannot judge it): the table gives the time ratio,
the error ratio and their product, which is the ratio of the time each needs to reach the same
error. ``--max-depth 2`` keeps direct light only (what a light choice changes first). From the
repo root, with the Mitsuba venv (scripts/setup-mitsuba-venv.sh):

  .venv-mitsuba/bin/python bench/light_choice.py BASE NEW [--spp 64] [--seeds 8]
      [--max-depth N] [SCENE ...]      (default: the accuracy scenes with two or more lights
                                        that have a place: those the light tree chooses for)

docs/performance.md (levers, session 42) has its numbers.
"""
import argparse
import json
import os
import sys
import tempfile

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))
import bench_accuracy as ba  # noqa: E402

SCENES = os.path.join(ROOT, "tests", "accuracy", "scenes")
DEFAULT = ["many_lights", "all_lights", "kitchen_sink", "motion_blur", "textured_diffuse"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("base")
    ap.add_argument("new")
    ap.add_argument("scenes", nargs="*")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seeds", type=int, default=8)
    ap.add_argument("--max-depth", type=int, default=0, help="override the scenes' max_depth (2: direct light)")
    args = ap.parse_intermixed_args()
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    print(f"| scene | spp | base s | new s | time new/base | base relMSE | new relMSE | error new/base | time x error new/base |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name in args.scenes or DEFAULT:
        path = os.path.join(SCENES, f"{name}.json")
        with tempfile.TemporaryDirectory() as tmp:
            if args.max_depth > 0:
                # The override and a reference of its own: base's render at 64x the samples.
                scene = json.load(open(path))
                scene["render"]["max_depth"] = args.max_depth
                path = os.path.join(SCENES, f".{name}_depth{args.max_depth}.json")  # assets resolve here
                with open(path, "w") as f:
                    json.dump(scene, f)
                reference, _ = ba.run_penumbra(args.base, path, 64 * args.spp, 999, mi)
            else:
                reference = ba.read_exr(mi, os.path.join(ba.ACCURACY, "references", f"{name}.exr"))
            try:
                seconds = {args.base: [], args.new: []}
                error = {args.base: [], args.new: []}
                for seed in range(args.seeds):
                    for binary in (args.base, args.new) if seed % 2 == 0 else (args.new, args.base):
                        image, s = ba.run_penumbra(binary, path, args.spp, seed, mi)
                        seconds[binary].append(s)
                        error[binary].append(float(np.mean((image - reference) ** 2 / (reference ** 2 + 0.01))))
            finally:
                if args.max_depth > 0:
                    os.remove(path)
        tb, tn = np.median(seconds[args.base]), np.median(seconds[args.new])
        eb, en = np.mean(error[args.base]), np.mean(error[args.new])
        print(f"| {name} | {args.spp} | {tb:.3f} | {tn:.3f} | {tn / tb:.2f} | {eb:.3e} | {en:.3e} | {en / eb:.2f} | "
              f"{tn * en / (tb * eb):.2f} |", flush=True)


if __name__ == "__main__":
    main()
