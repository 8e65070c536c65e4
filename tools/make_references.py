#!/usr/bin/env python3
"""Render the Mitsuba 3 reference images of the accuracy scenes.

    .venv-mitsuba/bin/python tools/make_references.py [--spp 8192] [--only cornell,dof]

For each ``tests/accuracy/scenes/<scene>.json`` this writes

* ``tests/accuracy/references/<scene>.exr``         the reference: linear RGB, float32;
* ``tests/accuracy/references/<scene>.stderr.exr``  per-pixel standard error of that mean,
  from the spread of ``--batches`` independent renders (different seeds) that it averages,
  so a test can tell the reference's own noise from penumbra's;

and records variant, spp, shutter instants, render time and the Mitsuba version in
``references/metadata.json``, from which ``references/README.md`` is regenerated. Scenes not
rendered in this run keep their earlier entries.

Motion blur: Mitsuba 3.9 has no moving shapes, so a scene with a shutter and moving objects is
rendered at ``--instants`` instants (midpoints of equal strata of the shutter), each with
spp / instants samples, and averaged; see tools/penumbra_to_mitsuba.py and docs/accuracy.md.
"""
from __future__ import annotations

import argparse
import datetime
import glob
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import penumbra_to_mitsuba as p2m  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = os.path.join(REPO, "tests", "accuracy", "scenes")
REFERENCES = os.path.join(REPO, "tests", "accuracy", "references")


def default_variant() -> str:
    """llvm_ad_rgb where Debian's libLLVM 19 is installed, else scalar_rgb."""
    return "llvm_ad_rgb" if os.path.exists(p2m.DEBIAN_LIBLLVM) else "scalar_rgb"


def render_reference(mi, scene: dict, spp: int, batches: int, instants: int, assets: str = "."):
    """Mean image and per-pixel standard error of the mean over ``batches`` independent renders
    of spp / batches samples each."""
    images = [p2m.render_average(mi, scene, spp // batches, instants, seed=1000 + b, assets=assets)
              for b in range(batches)]
    stack = np.stack(images)
    mean = stack.mean(axis=0)
    stderr = stack.std(axis=0, ddof=1) / np.sqrt(batches)
    return mean, stderr


def write_exr(mi, path: str, image: np.ndarray) -> None:
    """Write a linear RGB float32 EXR."""
    mi.Bitmap(np.ascontiguousarray(image, dtype=np.float32), mi.Bitmap.PixelFormat.RGB).write(path)


def load_metadata(path: str) -> dict:
    """The per-scene records of earlier runs (empty if none)."""
    if os.path.exists(path):
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    return {}


def write_readme(path: str, metadata: dict) -> None:
    """Regenerate references/README.md from the metadata records."""
    lines = [
        "# Mitsuba 3 reference images",
        "",
        "Made by `tools/make_references.py` from `tests/accuracy/scenes/*.json` (see `docs/accuracy.md`).",
        "`<scene>.exr` is the reference (linear RGB, float32); `<scene>.stderr.exr` is the per-pixel",
        "standard error of that mean, estimated from the independent batches it averages.",
        "Motion-blurred scenes are the average of renders at `instants` shutter instants.",
        "Render time is wall time on a shared 2-core machine (other jobs were running).",
        "",
        "| scene | size | variant | spp | batches | instants | render time (s) | Mitsuba | date |",
        "| --- | --- | --- | ---: | ---: | ---: | ---: | --- | --- |",
    ]
    for name in sorted(metadata):
        m = metadata[name]
        lines.append(f"| {name} | {m['width']}×{m['height']} | {m['variant']} | {m['spp']} | {m['batches']} | "
                     f"{m['instants']} | {m['seconds']:.0f} | {m['mitsuba']} | {m['date']} |")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--spp", type=int, default=8192, help="total samples per pixel per scene")
    ap.add_argument("--batches", type=int, default=4, help="independent renders averaged (for the stderr)")
    ap.add_argument("--instants", type=int, default=64, help="shutter instants for motion-blurred scenes")
    ap.add_argument("--variant", default=default_variant())
    ap.add_argument("--only", default="", help="comma-separated scene names (default: all)")
    ap.add_argument("--scenes", default=SCENES)
    ap.add_argument("--out", default=REFERENCES)
    args = ap.parse_args(argv)

    mi = p2m.import_mitsuba(args.variant)
    os.makedirs(args.out, exist_ok=True)
    meta_path = os.path.join(args.out, "metadata.json")
    metadata = load_metadata(meta_path)
    only = {s for s in args.only.split(",") if s}
    for path in sorted(glob.glob(os.path.join(args.scenes, "*.json"))):
        name = os.path.splitext(os.path.basename(path))[0]
        if only and name not in only:
            continue
        scene = p2m.load_json(path)
        p2m.use_scene_folder(mi, path)
        instants = len(p2m.shutter_instants(scene, args.instants))
        start = time.time()
        mean, stderr = render_reference(mi, scene, args.spp, args.batches, args.instants,
                                        assets=os.path.dirname(os.path.abspath(path)))
        seconds = time.time() - start
        write_exr(mi, os.path.join(args.out, f"{name}.exr"), mean)
        write_exr(mi, os.path.join(args.out, f"{name}.stderr.exr"), stderr)
        metadata[name] = {
            "width": int(mean.shape[1]), "height": int(mean.shape[0]), "variant": args.variant,
            "spp": args.spp // args.batches * args.batches, "batches": args.batches, "instants": instants,
            "seconds": round(seconds, 1), "mitsuba": mi.__version__,
            "date": datetime.date.today().isoformat(),
            "mean_rgb": [round(float(x), 6) for x in mean.mean(axis=(0, 1))],
        }
        print(f"{name}: {seconds:.1f} s, mean {np.round(mean.mean(axis=(0, 1)), 4)}, "
              f"median rel. stderr {np.median(stderr / np.maximum(mean, 1e-6)):.4f}", flush=True)
        with open(meta_path, "w", encoding="utf-8") as f:
            json.dump(metadata, f, indent=1, sort_keys=True)
            f.write("\n")
        write_readme(os.path.join(args.out, "README.md"), metadata)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
