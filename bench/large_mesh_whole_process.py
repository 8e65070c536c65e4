#!/usr/bin/env python3
"""Whole-process time and peak memory of rendering a 1M-triangle mesh file, penumbra's CLI beside
Mitsuba 3 (llvm_ad_rgb, from Python: import, the mesh file, the scene build, the render), runs
alternating. The files are bench/mesh_load_benchmark's (a wavy 708 x 708 grid of quads as
1,002,528 triangles with normals and uvs: OBJ, binary PLY and ASCII PLY), made by running it once;
the scene is its scene.json (camera, a diffuse material, a constant environment) at 256 x 256 and
1 spp, so the render itself is a few hundredths of a second and the rest is reading and building.
Prints a Markdown table of medians (min-max). docs/mesh-files.md has its numbers. From the repo
root, with the Mitsuba venv (scripts/setup-mitsuba-venv.sh):

  build/bench/mesh_load_benchmark --benchmark_filter=BM_ReadPlyBinary   # makes the files once
  .venv-mitsuba/bin/python bench/large_mesh_whole_process.py [--repeat 5] [--penumbra BIN ...]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FILES = os.path.join(tempfile.gettempdir(), "penumbra_mesh_load_benchmark")
MITSUBA = r"""
import sys, mitsuba as mi
mi.set_variant("llvm_ad_rgb")
kind = sys.argv[1].rsplit(".", 1)[1]
s = mi.load_dict({"type": "scene", "integrator": {"type": "path"},
  "sensor": {"type": "perspective", "fov": 39.6, "fov_axis": "smaller",
             "to_world": mi.ScalarTransform4f().look_at(origin=[0, 2, 3], target=[0, 0, 0], up=[0, 1, 0]),
             "film": {"type": "hdrfilm", "width": 256, "height": 256},
             "sampler": {"type": "independent", "sample_count": 1}},
  "env": {"type": "constant"},
  "mesh": {"type": kind, "filename": sys.argv[1],
           "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], 30)}})
mi.util.write_bitmap(sys.argv[2], mi.render(s))
"""


def timed(cmd):
    """(wall seconds, peak resident MB) of one run of cmd, by /usr/bin/time."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as t:
        subprocess.run(["/usr/bin/time", "-o", t.name, "-f", "%e %M"] + cmd, check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall, kb = t.read().split()[-2:]
    return float(wall), float(kb) / 1024


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--penumbra", nargs="+", default=[os.path.join(ROOT, "build", "app", "penumbra")])
    ap.add_argument("--no-mitsuba", action="store_true")
    args = ap.parse_args()
    base = os.path.join(FILES, "scene.json")
    if not os.path.exists(base):
        sys.exit(f"{base} missing: run build/bench/mesh_load_benchmark once to make the files")
    scene = json.load(open(base))
    out = tempfile.mkdtemp()
    script = os.path.join(out, "mitsuba_render.py")
    with open(script, "w") as f:
        f.write(MITSUBA)
    print("| mesh file | renderer | wall (s), median (min-max) | peak memory (MB) |")
    print("| --- | --- | ---: | ---: |")
    for name in ("grid.obj", "grid_binary.ply", "grid_ascii.ply"):
        path = os.path.join(FILES, name)
        scene["objects"][0]["file"] = name
        scene_path = os.path.join(FILES, f"scene_{name.replace('.', '_')}.json")
        with open(scene_path, "w") as f:
            json.dump(scene, f)
        runs = {}
        commands = {f"penumbra {os.path.relpath(b, ROOT) if b.startswith(ROOT) else b}":
                    [b, "render", scene_path, "-o", os.path.join(out, "p.png"), "--width", "256",
                     "--height", "256", "--spp", "1", "-q"] for b in args.penumbra}
        if not args.no_mitsuba:
            commands["Mitsuba 3 llvm_ad_rgb (Python)"] = [sys.executable, script, path,
                                                          os.path.join(out, "m.exr")]
        for _ in range(args.repeat):
            for label, cmd in commands.items():
                runs.setdefault(label, []).append(timed(cmd))
        for label, r in runs.items():
            walls = [w for w, _ in r]
            print(f"| {name} | {label} | {statistics.median(walls):.2f} ({min(walls):.2f}-{max(walls):.2f}) "
                  f"| {statistics.median([m for _, m in r]):.0f} |")


if __name__ == "__main__":
    main()
