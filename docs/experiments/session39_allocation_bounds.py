# Session 39 measurement (docs/performance.md, levers, session 39). From the repository root:
#   .venv-mitsuba/bin/python docs/experiments/session39_allocation_bounds.py SCENE ...  (env: SEEDS, SPP)
import os, subprocess, sys, tempfile
import numpy as np
sys.path.insert(0, "tools")
import bench_accuracy as ba, penumbra_to_mitsuba as p2m
mi = p2m.import_mitsuba("llvm_ad_rgb")
out = os.path.join(tempfile.mkdtemp(), "i.exr")
S = int(os.environ.get("SEEDS", 16)); spp = os.environ.get("SPP", "64")
def neigh(r):
    p = np.pad(r, 1, mode="edge"); s = np.zeros_like(r); c=0
    for dy in (-1,0,1):
        for dx in (-1,0,1):
            if dy==0 and dx==0: continue
            s += p[1+dy:1+dy+r.shape[0], 1+dx:1+dx+r.shape[1]]
    return s/8
for name in sys.argv[1:]:
    imgs = []
    for seed in range(S):
        subprocess.run(["build/app/penumbra", "render", f"tests/accuracy/scenes/{name}.json", "-o", out, "--spp", spp, "--seed", str(seed), "-q", "--sampler", os.environ.get("SAMPLER","auto")], check=True)
        imgs.append(ba.read_exr(mi, out))
    v = np.array(imgs); mean = v.mean(axis=0); var = v.var(axis=0, ddof=1)
    r2 = (var / (mean**2 + 0.01)).mean(axis=2); r = np.sqrt(r2)
    def gain(alloc):
        alloc = np.maximum(alloc, 1e-6*alloc.max())
        n = alloc/alloc.mean()
        return (r2/n).mean()/r2.mean()
    # half-split: estimate from half the seeds, apply to the other half's truth (noisy own estimate)
    h = S//2
    r_half = np.sqrt((v[:h].var(axis=0, ddof=1)/(mean**2+0.01)).mean(axis=2))
    print(f"{name}: own-true {gain(r):.3f}  neighbours {gain(neigh(r)):.3f}  max(own_half,neigh) {gain(np.maximum(r_half,neigh(r))):.3f} own-from-{h}-seeds {gain(r_half):.3f}")
