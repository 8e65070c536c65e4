#!/usr/bin/env python3
"""A split frame of a large mesh on the farm: what reading and building the scene costs per tile,
binaries side by side (docs/scale-out.md, "One scene per worker").

    build/bench/mesh_load_benchmark --benchmark_filter=BM_ReadPlyBinary   # makes the mesh once
    bench/farm_scene_reuse.py BINARY [BINARY ...] [--rounds 3] [--size 1024] [--spp 1]

The scene is bench/mesh_load_benchmark's 1M-triangle binary PLY (29 MB, uploaded as an asset)
under a constant environment, SIZE x SIZE at SPP samples, so the 16 tiles of the default
--tile-pixels are short and reading and building the scene is most of a tile's time, as it is for
a large scene rendered for a preview or a low sample count. Two farm layouts, each a fresh
PostgreSQL cluster, API node and workers (one render thread per slot): one worker process with
two slots, and two worker processes with one slot each. Per run: wall time from submission to
the job's end, the job's scene_builds and summed build_seconds (its stats), the worker
processes' CPU seconds (/proc) and their largest peak resident memory (VmHWM). The binaries take
turns within every round. A binary whose stats have no scene_builds built the scene per tile.
"""
import argparse
import hashlib
import json
import os
import statistics
import sys
import tempfile
import time
import urllib.request

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "tests", "farm"))
sys.path.insert(0, os.path.join(REPO, "bench"))
import farm_test  # noqa: E402  (the farm tests' process and PostgreSQL helpers)
from farm_throughput import cpu_seconds  # noqa: E402

MESH = os.path.join(tempfile.gettempdir(), "penumbra_mesh_load_benchmark", "grid_binary.ply")
LAYOUTS = [("1 worker x 2 slots", 1, 2), ("2 workers x 1 slot", 2, 1)]


def peak_rss_mb(pid):
    with open("/proc/%d/status" % pid) as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return 0.0


def one_run(binary, processes, slots, size, spp, mesh):
    farm = farm_test.Farm(binary, lease=30, heartbeat=5)
    try:
        api = farm.start("api", ("--max-asset-size", "200M"))
        workers = [farm.start("worker", ("--workers", str(slots), "--max-asset-size", "200M"))
                   for _ in range(processes)]
        digest = hashlib.sha256(mesh).hexdigest()
        req = urllib.request.Request(api["base"] + "/v1/assets/" + digest, data=mesh, method="PUT")
        req.add_header("Content-Type", "application/octet-stream")
        with urllib.request.urlopen(req, timeout=120) as r:
            assert r.status in (200, 201), r.status
        scene = {"version": 1,
                 "camera": {"position": [0, 2, 3], "look_at": [0, 0, 0]},
                 "materials": {"m": {"type": "diffuse"}},
                 "environment": {"radiance": [1, 1, 1]},
                 "objects": [{"type": "mesh", "file": "grid.ply", "material": "m",
                              "transform": {"rotate": {"axis": [0, 1, 0], "degrees": 30}}}],
                 "render": {"width": size, "height": size, "spp": spp}}
        pids = [w["proc"].pid for w in workers]
        cpu0 = cpu_seconds(pids)
        t0 = time.time()
        job = farm_test.submit(api["base"], {"scene": scene,
                                             "assets": {"grid.ply": "sha256:" + digest}})
        states = farm_test.wait_states(api["base"], [job], 1800)
        wall = time.time() - t0
        assert states[job] == "succeeded", states
        _, j = farm_test.get_json(api["base"], "/v1/jobs/" + job)
        stats = j["stats"]
        return {"wall_s": wall, "worker_cpu_s": cpu_seconds(pids) - cpu0,
                "peak_rss_mb": max(peak_rss_mb(p) for p in pids),
                "tasks": stats.get("tasks"), "scene_builds": stats.get("scene_builds", stats.get("tasks")),
                "build_s": stats.get("build_seconds"), "render_s": stats.get("seconds")}
    finally:
        farm.close()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("binaries", nargs="+")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--spp", type=int, default=1)
    ap.add_argument("--csv", default=None)
    args = ap.parse_args()
    if not os.path.exists(MESH):
        sys.exit(MESH + " missing: run build/bench/mesh_load_benchmark once to make it")
    with open(MESH, "rb") as f:
        mesh = f.read()
    samples = []
    for r in range(args.rounds):
        for label, processes, slots in LAYOUTS:
            order = args.binaries if r % 2 == 0 else list(reversed(args.binaries))
            for binary in order:
                row = {"round": r, "binary": binary, "layout": label}
                row.update(one_run(os.path.abspath(binary), processes, slots, args.size,
                                   args.spp, mesh))
                samples.append(row)
                print(json.dumps(row), file=sys.stderr, flush=True)
    if args.csv:
        import csv
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(samples[0].keys()))
            w.writeheader()
            w.writerows(samples)

    def cell(rows, key, fmt):
        values = [s[key] for s in rows]
        return (fmt + " (" + fmt + "-" + fmt + ")") % (statistics.median(values), min(values),
                                                       max(values))

    print("| binary | layout | tasks | scene builds | build s (summed) | wall s | worker CPU s "
          "| peak MB (one worker) |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for label, _, _ in LAYOUTS:
        for binary in args.binaries:
            rows = [s for s in samples if s["binary"] == binary and s["layout"] == label]
            print("| %s | %s | %d | %s | %s | %s | %s | %s |" % (
                binary, label, rows[0]["tasks"], cell(rows, "scene_builds", "%d"),
                cell(rows, "build_s", "%.2f"), cell(rows, "wall_s", "%.2f"),
                cell(rows, "worker_cpu_s", "%.2f"), cell(rows, "peak_rss_mb", "%.0f")))


if __name__ == "__main__":
    main()
