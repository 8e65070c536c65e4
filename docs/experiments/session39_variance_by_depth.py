# Session 39 measurement (docs/performance.md, levers, session 39). From the repository root:
#   .venv-mitsuba/bin/python docs/experiments/session39_variance_by_depth.py SCENE ...  (env: SEEDS, SPP)
import os, subprocess, sys, tempfile
import numpy as np
sys.path.insert(0, "tools")
import bench_accuracy as ba, penumbra_to_mitsuba as p2m
mi = p2m.import_mitsuba("llvm_ad_rgb")
out = os.path.join(tempfile.mkdtemp(), "i.exr")
S = int(os.environ.get("SEEDS", 16)); spp = os.environ.get("SPP", "64")
for name in sys.argv[1:]:
    res = {}
    for depth in ("2", "3", "4", "0"):
        imgs = []
        for seed in range(S):
            args = ["build/app/penumbra", "render", f"tests/accuracy/scenes/{name}.json", "-o", out, "--spp", spp, "--seed", str(seed), "-q"]
            if depth != "0": args += ["--max-depth", depth]
            subprocess.run(args, check=True)
            imgs.append(ba.read_exr(mi, out))
        res[depth] = np.array(imgs)
    ref = res["0"].mean(axis=0)
    V = {d: float(np.mean((v - v.mean(axis=0))**2/(ref**2+0.01))*S/(S-1)) for d, v in res.items()}
    print(f"{name}: depth2 {V['2']/V['0']:.3f} depth3 {V['3']/V['0']:.3f} depth4 {V['4']/V['0']:.3f}", flush=True)
