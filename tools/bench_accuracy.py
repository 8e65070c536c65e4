#!/usr/bin/env python3
"""Run time against error: penumbra and Mitsuba 3 on the accuracy scenes.

    .venv-mitsuba/bin/python tools/bench_accuracy.py --penumbra build/app/penumbra \
        [--spp 4,16,64,256] [--seeds 3] [--heavy-seeds 8] \
        [--mitsuba llvm_ad_rgb,llvm_ad_rgb:ldsampler,llvm_ad_rgb:multijitter] [--only cornell] \
        [--adaptive 0.1,0.05,0.03] [--adaptive-cap 1024] [--path-reuse 4] \
        [--cycles /usr/bin/blender [--cycles-sphere-mesh 512] [--cycles-rough-glass] \
        [--cycles-reference-spp 4096]]

For each scene of tests/accuracy/scenes/, each renderer and each sample count of the ladder, over
several seeds, it records the render's seconds, spp, RMSE, relMSE and mean FLIP against the
Mitsuba reference (and "penumbra adaptive": one point per render.noise_threshold of
``--adaptive``, with ``--adaptive-cap`` as spp; and with ``--path-reuse N`` "penumbra reuse": the
ladder with ``render.path_reuse`` N) (tests/accuracy/references/<scene>.exr, see docs/accuracy.md), and writes

* ``<out>/bench.csv``   one row per render;
* ``<out>/bench.png``   relMSE against seconds, log-log, one panel per scene, one line per renderer;
* ``<out>/bench.md``    per scene the seconds each renderer needs to reach the same relMSE
  (penumbra's at its largest spp; interpolated on each curve) and the ratio penumbra / fastest
  Mitsuba; for the heavy-tailed scenes also the same for relMSE without each image's worst 0.1%
  of pixels (``relmse_trimmed``: one sun caustic of one seed must not decide the row); also
  printed.

A curve that has not reached penumbra's error by its last point is extended (spp doubled, or the
adaptive threshold divided by sqrt 2; at most ``--extend`` points), so times are interpolated
between measured points; a time that still had to be extrapolated is marked "~" in the table.

The renderers take turns: every seed of every point is rendered by each renderer in turn before
the next seed (the first in turn rotating with the seed), so that a drift of the machine's speed
over minutes reaches all of them alike; Cycles, a Blender process per render, runs its ladder
after the others.

The fastest Mitsuba is the fastest of its configurations: ``--mitsuba`` lists variants, each
optionally with a sampler (``llvm_ad_rgb:multijitter``). Mitsuba's default ``independent``
sampler is not its best: its stratified samplers (``multijitter``, ``ldsampler``) reach a given
error 1.5-10x sooner than it, as penumbra's Owen-scrambled Sobol sampler does, so a
comparison against ``independent`` alone credits penumbra with its sampler (docs/accuracy.md,
session 20).

Seconds are comparable work on both sides: for penumbra the scene build plus the render as its
summary line reports them (not process start or JSON parsing); for Mitsuba ``load_dict`` plus
``render`` (including Dr.Jit's kernel compilation, which its cache makes cheap after the first
render). Motion-blurred scenes have no native Mitsuba equivalent: Mitsuba renders them as the
average over shutter instants (at least one sample per instant), which inflates its time, so
their ratio is marked.

With ``--cycles BLENDER`` Blender Cycles joins the ladder for the scenes
tools/penumbra_to_cycles.py translates (the others are listed and skipped). Its seconds are
``bpy.ops.render.render`` (Cycles' sync, BVH build and sampling, the counterpart of penumbra's
build + render); the whole Blender process (start-up, conversion, EXR) is in the CSV as
``process_seconds``. Its error is against the Mitsuba reference when the translation is exact
and the material models agree; a scene whose spheres had to be tessellated
(``--cycles-sphere-mesh N``) is not the same scene, and Cycles' rough glass
(``--cycles-rough-glass``) is another model (:func:`cycles_differs`), so there Cycles is measured against its own
``--cycles-reference-spp`` render instead (the ``reference`` column and the table say which).

Error metrics (per render, against the reference):
  RMSE   = sqrt(mean over pixels and channels of (x - r)^2)
  relMSE = mean of (x - r)^2 / (r^2 + 0.01)
  FLIP   = mean LDR-FLIP of the clamped sRGB images (flip-evaluator)
"""
from __future__ import annotations

import argparse
import csv
import dataclasses
import json
import glob
import math
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import penumbra_to_cycles as p2c  # noqa: E402
import penumbra_to_mitsuba as p2m  # noqa: E402

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ACCURACY = os.path.join(REPO, "tests", "accuracy")
#: Scenes whose relMSE is decided by rare, very bright samples (caustics of the sun through glass,
#: in every renderer): one render of a few seeds can be 20x the median (docs/accuracy.md, session
#: 12's tail comparison), so they get --heavy-seeds seeds.
HEAVY_TAILED = {"environment_map", "kitchen_sink"}

#: penumbra_to_cycles.py's closing line
CYCLES_SUMMARY = re.compile(r"cycles: render ([0-9.]+) s, process ([0-9.]+) s")

#: penumbra's closing line: "...: 64x64, 64.0 spp (...), 0.900 s (+0.345 s build), ..."
SUMMARY = re.compile(r"([0-9.]+) spp .*?, ([0-9.]+) s \(\+([0-9.]+) s build\)")


def srgb(linear: np.ndarray) -> np.ndarray:
    """Clamp to [0, 1] and apply the sRGB transfer curve."""
    x = np.clip(linear, 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)


def errors(image: np.ndarray, reference: np.ndarray) -> dict:
    """RMSE, relMSE and mean FLIP of ``image`` against ``reference`` (both linear RGB)."""
    import flip_evaluator

    d2 = (image - reference) ** 2
    _, flip, _ = flip_evaluator.evaluate(srgb(reference).astype(np.float32), srgb(image).astype(np.float32),
                                         "LDR", inputsRGB=True, applyMagma=False)
    rel = d2 / (reference ** 2 + 0.01)
    return {"rmse": float(np.sqrt(d2.mean())), "relmse": float(rel.mean()),
            "relmse_trimmed": trimmed_mean(rel.mean(axis=2)), "flip": float(flip)}


#: The share of an image's pixels with the largest error that "relmse_trimmed" sets aside.
TRIM = 0.001


def trimmed_mean(per_pixel: np.ndarray) -> float:
    """Mean of a per-pixel error map without its worst TRIM of pixels (at least one): relMSE as a
    few single samples do not decide it. On scenes whose error is rare bright samples (sun
    caustics through rough glass, HEAVY_TAILED) the plain mean over a few seeds is decided by
    which seed drew one of them and on which pixel (docs/accuracy.md, session 24); the trimmed
    one compares the rest of the image."""
    flat = np.sort(per_pixel.ravel())
    keep = flat.size - max(1, int(math.ceil(flat.size * TRIM)))
    return float(flat[:keep].mean())


def read_exr(mi, path: str) -> np.ndarray:
    """Linear RGB float64 array of an EXR, read with Mitsuba's Bitmap (not flip's loader,
    which misreads some PIZ-compressed files)."""
    return np.array(mi.Bitmap(path), dtype=np.float64)[..., :3]


def run_penumbra(binary: str, scene_path: str, spp: int, seed: int, mi,
                 noise_threshold: float = 0.0, path_reuse: int = 1) -> tuple[np.ndarray, float]:
    """Render with the penumbra CLI (adaptive sampling when ``noise_threshold`` > 0, with ``spp``
    as the per-pixel cap); returns the image and build + render seconds."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.exr")
        cmd = [binary, "render", scene_path, "-o", out, "--spp", str(spp), "--seed", str(seed), "-q"]
        if noise_threshold > 0:
            cmd += ["--noise-threshold", str(noise_threshold)]
        if path_reuse > 1:
            cmd += ["--path-reuse", str(path_reuse)]
        proc = subprocess.run(cmd, capture_output=True, text=True, check=True)
        match = SUMMARY.search(proc.stdout + proc.stderr)
        if not match:
            raise RuntimeError(f"no summary line from penumbra: {proc.stdout}{proc.stderr}")
        return read_exr(mi, out), float(match.group(2)) + float(match.group(3))


def run_cycles(blender: str, scene_path: str, spp: int, seed: int, mi,
               sphere_mesh: int = 0, rough_glass: bool = False) -> tuple[np.ndarray, float, float]:
    """Render with Cycles through tools/penumbra_to_cycles.py in a headless Blender; returns the
    image, the render seconds measured inside Blender and the whole process's seconds."""
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "penumbra_to_cycles.py")
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "out.exr")
        cmd = [blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python", script, "--",
               scene_path, "-o", out, "--spp", str(spp), "--seed", str(seed), "--sphere-mesh", str(sphere_mesh)] \
            + (["--rough-glass"] if rough_glass else [])
        proc = subprocess.run(cmd, capture_output=True, text=True)
        match = CYCLES_SUMMARY.search(proc.stdout)
        if proc.returncode != 0 or not match:
            raise RuntimeError(f"Cycles failed ({proc.returncode}): {proc.stdout[-2000:]}{proc.stderr[-2000:]}")
        return read_exr(mi, out), float(match.group(1)), float(match.group(2))


def cycles_differs(scene: dict) -> str:
    """Why Cycles does not render exactly the Mitsuba reference's scene ('' when it does):
    tessellated spheres, or a rough dielectric (Cycles 3.x's rough Glass BSDF is another model,
    see tools/penumbra_to_cycles.py)."""
    reasons = []
    if any(o.get("type") == "sphere" for o in scene.get("objects", [])):
        reasons.append("spheres tessellated")
    if any(m.get("type") == "dielectric" and float(m.get("roughness", 0)) > 0
           for m in scene.get("materials", {}).values()):
        reasons.append("rough glass")
    return ", ".join(reasons)


def cycles_reference(blender: str, scene_path: str, spp: int, mi, sphere_mesh: int, rough_glass: bool,
                     out: str) -> np.ndarray:
    """Cycles' own high-spp render of a scene (seed 1000, apart from the ladder's), kept in
    ``out`` and reused by later runs with the same settings."""
    name = os.path.splitext(os.path.basename(scene_path))[0]
    path = os.path.join(out, f"cycles_reference_{name}_{spp}spp_sphere{sphere_mesh}.exr")
    if not os.path.exists(path):
        image, seconds, _ = run_cycles(blender, scene_path, spp, 1000, mi, sphere_mesh, rough_glass)
        mi.Bitmap(image.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(path)
        print(f"{name:13s} cycles reference {spp} spp: {seconds:.1f} s -> {path}", flush=True)
    return read_exr(mi, path)


def run_mitsuba(variant: str, scene: dict, spp: int, seed: int, instants: int,
                assets: str = ".", sampler: str = "independent") -> tuple[np.ndarray, float, int]:
    """Render with Mitsuba in this process (its ``sampler`` plugin); returns the image, load +
    render seconds and the samples per pixel it took (its stratified samplers round the count:
    ldsampler to a power of four, multijitter to a multiple of its grid)."""
    mi = p2m.import_mitsuba(variant)
    times = p2m.shutter_instants(scene, instants)
    per_instant = max(1, spp // len(times))
    total, seconds, taken = None, 0.0, 0
    for k, t in enumerate(times):
        start = time.perf_counter()
        mscene = mi.load_dict(p2m.to_mitsuba(mi, scene, time=t, spp=per_instant, assets=assets,
                                             sampler=sampler))
        img = np.asarray(mi.render(mscene, spp=per_instant, seed=seed * len(times) + k), dtype=np.float64)
        seconds += time.perf_counter() - start
        taken += int(mscene.sensors()[0].sampler().sample_count())
        total = img if total is None else total + img
    return total / len(times), seconds, taken


def mitsuba_config(renderer: str) -> tuple[str, str]:
    """(variant, sampler) of a renderer named 'mitsuba VARIANT [SAMPLER]'."""
    parts = renderer.split()
    return parts[1], parts[2] if len(parts) > 2 else "independent"


def curve(rows: list[dict], key: str = "relmse") -> list[tuple[float, float]]:
    """(seconds, error) seed means per point of a renderer's ladder (an spp, or for adaptive
    sampling a threshold), in order of cost; the error is the rows' ``key``."""
    by_point: dict[tuple, list] = {}
    for r in rows:
        by_point.setdefault((r["spp"], r["threshold"]), []).append(r)
    pts = [(float(np.mean([r["seconds"] for r in rs])), float(np.mean([r.get(key, math.nan) for r in rs])))
           for rs in by_point.values()]
    return sorted(pts)


def penumbra_target(rows: list[dict], scene: str, key: str = "relmse") -> float:
    """The error the table compares at: penumbra's (uniform) seed mean of ``key`` at its largest
    spp."""
    pen = [r for r in rows if r["scene"] == scene and r["renderer"] == "penumbra"]
    if not pen:
        return math.nan
    top = max(r["spp"] for r in pen)
    return float(np.mean([r.get(key, math.nan) for r in pen if r["spp"] == top]))


def time_to_reach(rows: list[dict], target: float, key: str = "relmse") -> tuple[float, bool]:
    """Seconds to reach relMSE ``target``, and whether they were interpolated: log-log
    interpolation between the two points of the ladder (seed means) that bracket it, or, outside
    the ladder, a least-squares line through log(relMSE) against log(seconds) evaluated at the
    target. (A line through the whole ladder is biased where fixed costs dominate its cheapest
    points, hence the curves are extended until they bracket the target.)"""
    pts = curve(rows, key)
    if len(pts) < 2:
        return math.nan, False
    for (s0, e0), (s1, e1) in zip(pts, pts[1:]):
        if e1 < e0 and e1 <= target <= e0:
            f = math.log(target / e0) / math.log(e1 / e0)
            return float(math.exp(math.log(s0) + f * math.log(s1 / s0))), True
    x = np.log([p[0] for p in pts])
    y = np.log([p[1] for p in pts])
    if x.max() - x.min() < math.log(1.5):
        # Points at nearly one time (adaptive renders that all stopped at the spp cap): no line
        # through them says where the curve goes, and a fitted one extrapolates to nonsense.
        return math.nan, False
    slope, intercept = np.polyfit(x, y, 1)
    if slope >= 0:
        return math.nan, False
    return float(math.exp((math.log(target) - intercept) / slope)), False


def fmt_ratio(ratio: float) -> str:
    """A table's ratio, or "–" where a curve has no time (it never reached the error)."""
    return "–" if math.isnan(ratio) else f"{ratio:.2f}"


def summarise(rows: list[dict], scenes: list[str], renderers: list[str], key: str = "relmse") -> list[str]:
    """Markdown table: per scene, seconds to the error (the rows' ``key``: relMSE, or relMSE
    without each image's worst pixels) penumbra reaches at its largest spp, for each renderer, and
    penumbra / fastest Mitsuba (and penumbra / Cycles when Cycles ran)."""
    cycles = "cycles" in renderers
    adaptive = "penumbra adaptive" in renderers
    reuse = "penumbra reuse" in renderers
    label = "relMSE" if key == "relmse" else "trimmed relMSE"
    lines = [f"| scene | target {label} | " + " | ".join(f"{r} (s)" for r in renderers) + " | penumbra / fastest Mitsuba |"
             + (" adaptive / fastest Mitsuba |" if adaptive else "") + (" reuse / fastest Mitsuba |" if reuse else "")
             + (" penumbra / cycles |" if cycles else ""),
             "| --- | ---: | " + " | ".join("---:" for _ in renderers) + " | ---: |" + (" ---: |" if adaptive else "")
             + (" ---: |" if reuse else "") + (" ---: |" if cycles else "")]
    for scene in scenes:
        target = penumbra_target(rows, scene, key)
        if math.isnan(target):
            continue
        reached = {name: time_to_reach([r for r in rows if r["scene"] == scene and r["renderer"] == name],
                                       target, key)
                   for name in renderers}
        secs = {name: t for name, (t, _) in reached.items()}
        # "~": the curve did not reach the target, its time is extrapolated (less certain)
        mark = {name: "" if interpolated else "~" for name, (_, interpolated) in reached.items()}
        mitsuba = [v for k, v in secs.items() if k.startswith("mitsuba") and not math.isnan(v)]
        ratio = secs["penumbra"] / min(mitsuba) if mitsuba else math.nan
        adaptive_ratio = secs["penumbra adaptive"] / min(mitsuba) if mitsuba and adaptive else math.nan
        reuse_ratio = secs["penumbra reuse"] / min(mitsuba) if mitsuba and reuse else math.nan
        moving = any(r["instants"] > 1 for r in rows if r["scene"] == scene)
        own = {r["reference"] for r in rows if r["scene"] == scene and r["renderer"] == "cycles"
               and r.get("reference", "mitsuba") != "mitsuba"}
        notes = (["motion: Mitsuba averages instants"] if moving else []) + \
                [f"Cycles against its own {ref.removeprefix('cycles ')}" for ref in sorted(own)]
        lines.append(f"| {scene}{' (' + '; '.join(notes) + ')' if notes else ''} | {target:.2e} | "
                     + " | ".join("–" if math.isnan(secs[n]) else f"{mark[n]}{secs[n]:.2f}" for n in renderers)
                     + f" | {fmt_ratio(ratio)} |"
                     + (f" {fmt_ratio(adaptive_ratio)} |" if adaptive else "")
                     + (f" {fmt_ratio(reuse_ratio)} |" if reuse else "")
                     + (f" {secs['penumbra'] / secs['cycles']:.2f} |" if cycles and not math.isnan(secs["cycles"])
                        else " – |" if cycles else ""))
    return lines


def plot(rows: list[dict], scenes: list[str], renderers: list[str], path: str) -> None:
    """relMSE against seconds, log-log, one panel per scene, one line per renderer."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    cols = 4
    nrows = math.ceil(len(scenes) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(4 * cols, 3.2 * nrows), squeeze=False)
    for ax, scene in zip(axes.ravel(), scenes):
        for name in renderers:
            pts = curve([r for r in rows if r["scene"] == scene and r["renderer"] == name])
            xs, ys = [p[0] for p in pts], [p[1] for p in pts]
            if xs:
                ax.loglog(xs, ys, "o-", label=name)
        ax.set_title(scene)
        ax.set_xlabel("seconds")
        ax.set_ylabel("relMSE")
        ax.grid(True, which="both", alpha=0.3)
    for ax in axes.ravel()[len(scenes):]:
        ax.axis("off")
    axes[0, 0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)


def write_report(rows: list[dict], scenes: list[str], renderers: list[str], out: str) -> None:
    """bench.png and bench.md in ``out``; the table is also printed."""
    plot(rows, scenes, renderers, os.path.join(out, "bench.png"))
    table = summarise(rows, scenes, renderers)
    # The same with each image's worst 0.1% of pixels set aside, for the scenes whose relMSE rare
    # bright samples decide (HEAVY_TAILED; rows of older CSVs have no such column).
    heavy = [s for s in scenes if s in HEAVY_TAILED]
    if heavy and any(not math.isnan(r.get("relmse_trimmed", math.nan)) for r in rows):
        table += ["", f"Without each image's worst {TRIM:.1%} of pixels (relmse_trimmed):", ""]
        table += summarise(rows, heavy, renderers, "relmse_trimmed")
    with open(os.path.join(out, "bench.md"), "w", encoding="utf-8") as f:
        f.write("\n".join(table) + "\n")
    print("\n".join(table))


@dataclasses.dataclass
class RunContext:
    """What every render of one scene needs."""
    penumbra: str
    scene_name: str
    scene_path: str
    scene: dict
    assets: str
    instants: int
    mi: object
    reference: np.ndarray
    path_reuse: int = 1


class Curve:
    """One renderer's points on one scene: its spp ladder, or for "penumbra adaptive" its noise
    thresholds under the spp cap; extended by :meth:`next_point`."""

    def __init__(self, renderer: str, ladder: list[int], thresholds: list[float], cap: int):
        self.renderer = renderer
        self.is_penumbra = renderer.startswith("penumbra")
        self.adaptive = renderer == "penumbra adaptive"
        self.reuse = renderer == "penumbra reuse"
        self.variant, self.sampler = ("", "") if self.is_penumbra else mitsuba_config(renderer)
        self.points = [(cap, t) for t in thresholds] if self.adaptive else [(s, 0.0) for s in ladder]
        self.errors: list[float] = []  # seed-mean relMSE per measured point
        self.base_points = len(self.points)
        self.stalled = False  # an extension that lowered no error (an adaptive cap reached)

    def render(self, ctx: RunContext, spp: int, threshold: float, seed: int) -> tuple[np.ndarray, float, int, int]:
        """Image, seconds, spp taken and shutter instants of one render."""
        if self.is_penumbra:
            image, seconds = run_penumbra(ctx.penumbra, ctx.scene_path, spp, seed, ctx.mi, threshold,
                                          ctx.path_reuse if self.reuse else 1)
            return image, seconds, spp, 1
        image, seconds, used = run_mitsuba(self.variant, ctx.scene, max(spp, ctx.instants), seed,
                                           ctx.instants, ctx.assets, self.sampler)
        return image, seconds, used, ctx.instants

    def warm_up(self, ctx: RunContext, spp: int) -> None:
        self.render(ctx, spp, 0.0, 0)

    def warm_up_count(self, ctx: RunContext, spp: int) -> None:
        """Mitsuba's other samplers compile the sample count into their kernels: a discarded
        render per count keeps that compilation (0.3 s and more, paid once per count thanks to
        Dr.Jit's kernel cache) out of the measured seeds."""
        if not self.is_penumbra and self.sampler != "independent":
            self.render(ctx, spp, 0.0, 0)

    def wants_more(self, target: float) -> bool:
        """Whether the curve has not reached penumbra's error yet and can be extended (plain
        penumbra's ladder defines the target and is never extended)."""
        return self.renderer != "penumbra" and not self.stalled and self.errors[-1] > target

    def next_point(self) -> tuple[int, float]:
        spp, threshold = self.points[-1]
        point = (spp, threshold / math.sqrt(2.0)) if self.adaptive else (spp * 2, threshold)
        self.points.append(point)
        return point

    def record(self, error: float) -> None:
        if len(self.errors) >= self.base_points and not error < self.errors[-1]:
            self.stalled = True
        self.errors.append(error)


def measure_round(ctx: RunContext, jobs: list[tuple[Curve, int, float]], seeds: int) -> list[dict]:
    """One point (spp, threshold) of each curve over all seeds, the curves taking turns within
    each seed (the first in turn rotating with the seed); records each curve's seed-mean
    relMSE and returns the rows."""
    for c, spp, _ in jobs:
        c.warm_up_count(ctx, spp)
    rows: list[dict] = []
    errs: dict[int, list[float]] = {id(c): [] for c, _, _ in jobs}
    for seed in range(seeds):
        turn = seed % len(jobs)
        for c, spp, threshold in jobs[turn:] + jobs[:turn]:
            start = time.perf_counter()
            image, seconds, used_spp, used_instants = c.render(ctx, spp, threshold, seed)
            process = time.perf_counter() - start
            row = {"scene": ctx.scene_name, "renderer": c.renderer, "spp": used_spp, "threshold": threshold,
                   "seed": seed, "seconds": seconds, "instants": used_instants, **errors(image, ctx.reference),
                   "process_seconds": process, "reference": "mitsuba"}
            rows.append(row)
            errs[id(c)].append(row["relmse"])
            print(f"{ctx.scene_name:13s} {c.renderer:20s} spp {spp:5d} t {threshold:g} seed {seed}: {seconds:7.3f} s  "
                  f"relMSE {row['relmse']:.3e}  FLIP {row['flip']:.4f}", flush=True)
    for c, _, _ in jobs:
        c.record(float(np.mean(errs[id(c)])))
    return rows


def measure_cycles(args, scene_name: str, scene_path: str, scene: dict, ladder: list[int], seeds: int,
                   mi, reference: np.ndarray) -> list[dict]:
    """Blender Cycles' ladder on one scene, against the Mitsuba reference, or against its own
    render where its translation or material models differ (:func:`cycles_differs`)."""
    approximate = cycles_differs(scene)
    if approximate:
        reference = cycles_reference(args.cycles, scene_path, args.cycles_reference_spp, mi,
                                     args.cycles_sphere_mesh, args.cycles_rough_glass, args.out)
        ref_name = f"cycles {args.cycles_reference_spp} spp render: {approximate}"
    run_cycles(args.cycles, scene_path, ladder[0], 0, mi, args.cycles_sphere_mesh, args.cycles_rough_glass)
    rows: list[dict] = []
    for spp in ladder:
        for seed in range(seeds):
            image, seconds, process = run_cycles(args.cycles, scene_path, spp, seed, mi,
                                                 args.cycles_sphere_mesh, args.cycles_rough_glass)
            row = {"scene": scene_name, "renderer": "cycles", "spp": spp, "threshold": 0.0,
                   "seed": seed, "seconds": seconds, "instants": 1, **errors(image, reference),
                   "process_seconds": process, "reference": ref_name if approximate else "mitsuba"}
            rows.append(row)
            print(f"{scene_name:13s} {'cycles':20s} spp {spp:5d} t 0 seed {seed}: {seconds:7.3f} s  "
                  f"(process {process:.2f} s)  relMSE {row['relmse']:.3e}  FLIP {row['flip']:.4f}"
                  f"{'  vs ' + ref_name if approximate else ''}", flush=True)
    return rows


def main(argv: list[str]) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--penumbra", help="the penumbra executable (required unless --summarise)")
    ap.add_argument("--spp", default="4,16,64,256", help="sample-count ladder")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--heavy-seeds", type=int, default=8,
                    help="seeds for the firefly-dominated scenes (HEAVY_TAILED), whose mean relMSE "
                         "over a few seeds is decided by one render's outliers")
    ap.add_argument("--mitsuba", default="llvm_ad_rgb,llvm_ad_rgb:ldsampler,llvm_ad_rgb:multijitter",
                    help="Mitsuba variants to measure, comma-separated ('' for none); VARIANT:SAMPLER "
                         "renders with that Mitsuba sampler instead of 'independent' (e.g. "
                         "llvm_ad_rgb:ldsampler, Mitsuba's low-discrepancy (0,2)-sequence), shown as "
                         "'mitsuba VARIANT SAMPLER'")
    ap.add_argument("--instants", type=int, default=16, help="shutter instants for Mitsuba motion blur")
    ap.add_argument("--only", default="", help="comma-separated scene names (default: all)")
    ap.add_argument("--adaptive", default="0.1,0.05,0.03",
                    help="render.noise_threshold values for the 'penumbra adaptive' curve ('' to skip)")
    ap.add_argument("--adaptive-cap", type=int, default=1024, help="spp cap of the adaptive renders")
    ap.add_argument("--path-reuse", type=int, default=1, metavar="N",
                    help="also a 'penumbra reuse' curve: the ladder with render.path_reuse N (1 = none)")
    ap.add_argument("--extend", type=int, default=4,
                    help="at most this many extra points (spp doubled, or threshold / sqrt 2) for a "
                         "curve that has not reached penumbra's error yet")
    ap.add_argument("--cycles", metavar="BLENDER", default="",
                    help="add Blender Cycles (this blender executable) for the scenes it translates")
    ap.add_argument("--cycles-sphere-mesh", type=int, default=0, metavar="N",
                    help="tessellate spheres for Cycles as UV spheres of N segments (0: skip such scenes)")
    ap.add_argument("--cycles-rough-glass", action="store_true",
                    help="let Cycles render rough glass with its own model (else skip such scenes)")
    ap.add_argument("--cycles-reference-spp", type=int, default=4096,
                    help="spp of Cycles' own reference for scenes it renders only approximately")
    ap.add_argument("--out", default=os.path.join(REPO, "bench", "out"))
    ap.add_argument("--summarise", metavar="CSV", help="only redo bench.md/bench.png from a bench.csv")
    args = ap.parse_args(argv)

    if args.summarise:
        with open(args.summarise, newline="", encoding="utf-8") as f:
            rows = [{k: (v if k in ("scene", "renderer", "reference") else float(v or "nan"))
                     for k, v in r.items()} for r in csv.DictReader(f)]
        scenes = list(dict.fromkeys(r["scene"] for r in rows))
        renderers = list(dict.fromkeys(r["renderer"] for r in rows))
        os.makedirs(args.out, exist_ok=True)
        write_report(rows, scenes, renderers, args.out)
        return 0

    if not args.penumbra:
        ap.error("--penumbra is required (unless --summarise)")
    ladder = [int(s) for s in args.spp.split(",")]
    variants = [v for v in args.mitsuba.split(",") if v]
    only = {s for s in args.only.split(",") if s}
    scenes = [os.path.splitext(os.path.basename(p))[0] for p in sorted(glob.glob(os.path.join(ACCURACY, "scenes", "*.json")))]
    scenes = [s for s in scenes if not only or s in only]
    os.makedirs(args.out, exist_ok=True)
    mi = p2m.import_mitsuba(variants[0].split(":")[0] if variants else "scalar_rgb")

    rows: list[dict] = []
    thresholds = [float(t) for t in args.adaptive.split(",") if t]
    renderers = ["penumbra"] + (["penumbra adaptive"] if thresholds else []) \
        + (["penumbra reuse"] if args.path_reuse > 1 else []) + [f"mitsuba {v.replace(':', ' ')}" for v in variants]
    if args.cycles:
        renderers.append("cycles")
    for scene_name in scenes:
        scene_path = os.path.join(ACCURACY, "scenes", f"{scene_name}.json")
        scene = p2m.load_json(scene_path)
        # Files the scene names (environment maps, textures) are relative to its folder, as for penumbra.
        p2m.use_scene_folder(mi, scene_path)
        assets = os.path.dirname(os.path.abspath(scene_path))
        reference = read_exr(mi, os.path.join(ACCURACY, "references", f"{scene_name}.exr"))
        instants = len(p2m.shutter_instants(scene, args.instants))
        seeds = max(args.seeds, args.heavy_seeds) if scene_name in HEAVY_TAILED else args.seeds
        with open(scene_path, encoding="utf-8") as f:
            refused = p2c.refusals(json.load(f), args.cycles_sphere_mesh, args.cycles_rough_glass)
        curves = [Curve(r, ladder, thresholds, args.adaptive_cap) for r in renderers if r != "cycles"]
        ctx = RunContext(args.penumbra, scene_name, scene_path, scene, assets, instants, mi, reference,
                         args.path_reuse)
        # One discarded warm-up render each: Dr.Jit compiles its kernels on first use, and the
        # first penumbra run pays for reading the scene file from a cold cache.
        for c in curves:
            c.warm_up(ctx, ladder[0])
        # The renderers take turns within every seed of every point (the first in turn rotating
        # with the seed), instead of each running its whole ladder in turn: this machine's speed
        # drifts by a quarter over minutes, and renderers measured minutes apart drifted apart
        # (docs/accuracy.md, session 31); taking turns gives them the same drift.
        for i in range(max(len(c.points) for c in curves)):
            rows += measure_round(ctx, [(c, *c.points[i]) for c in curves if i < len(c.points)], seeds)
        # Extend the curves until they bracket the target (penumbra's relMSE at its top spp,
        # measured first), so the time to reach it is interpolated, not extrapolated: a line
        # through a ladder whose cheap points are mostly fixed cost (start-up, kernel
        # compilation) overstates how fast a renderer's error falls with time. The extensions
        # take turns as well.
        target = penumbra_target(rows, scene_name)
        for _ in range(args.extend):
            due = [c for c in curves if c.wants_more(target)]
            if not due:
                break
            rows += measure_round(ctx, [(c, *c.next_point()) for c in due], seeds)
        # Cycles runs as a Blender process per render, its ladder on its own after the others.
        if "cycles" in renderers:
            if refused:
                print(f"{scene_name:13s} cycles: skipped, " + "; ".join(str(p) for p in refused), flush=True)
            else:
                rows += measure_cycles(args, scene_name, scene_path, scene, ladder, seeds, mi, reference)

    with open(os.path.join(args.out, "bench.csv"), "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]), restval="")
        writer.writeheader()
        writer.writerows(rows)
    write_report(rows, scenes, renderers, args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
