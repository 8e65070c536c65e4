# Session 39 measurement (docs/performance.md, levers, session 39). From the repository root:
#   .venv-mitsuba/bin/python docs/experiments/session39_guiding_variance.py SCENE ...  (env: SEEDS, SPP)
#   Needs a build with docs/experiments/session39_path_guiding_grid.diff applied (git apply), which
#   reads PENUMBRA_GUIDE_TRAIN / PENUMBRA_GUIDE_USE (and PENUMBRA_GUIDE_G, _ALPHA, _ALL).
import os, subprocess, sys, tempfile
import numpy as np
sys.path.insert(0, "tools")
import bench_accuracy as ba, penumbra_to_mitsuba as p2m
mi = p2m.import_mitsuba("llvm_ad_rgb")
tmp = tempfile.mkdtemp(); out = os.path.join(tmp, "i.exr")
S = int(os.environ.get("SEEDS", 12)); spp = os.environ.get("SPP", "64"); train = os.environ.get("TRAIN", "256")
B = "build/app/penumbra"
def render(name, seed, env, spp):
    e = dict(os.environ); e.update(env)
    r = subprocess.run([B, "render", f"tests/accuracy/scenes/{name}.json", "-o", out, "--spp", str(spp), "--seed", str(seed), "--scalar"], check=True, env=e, capture_output=True, text=True)
    t = float(r.stderr.split(" s (+")[0].split(", ")[-1]) if " s (+" in r.stderr else float("nan")
    return ba.read_exr(mi, out), t
for name in sys.argv[1:]:
    g = os.path.join(tmp, name + ".bin")
    render(name, 999, {"PENUMBRA_GUIDE_TRAIN": g}, train)
    res = {}
    for mode, env in (("plain", {}), ("guided", {"PENUMBRA_GUIDE_USE": g})):
        imgs, ts = [], []
        for s in range(S):
            im, t = render(name, s, env, spp); imgs.append(im); ts.append(t)
        res[mode] = (np.array(imgs), np.median(ts))
    ref = (res["plain"][0].mean(axis=0) + res["guided"][0].mean(axis=0)) / 2
    V = {m: float(np.mean((v - v.mean(axis=0))**2/(ref**2+0.01))*S/(S-1)) for m, (v, t) in res.items()}
    mp, mg = res["plain"][0].mean(), res["guided"][0].mean()
    # block z-test of the means (8x8 blocks)
    def blocks(v):
        h, w = v.shape[1]//8*8, v.shape[2]//8*8
        b = v[:, :h, :w].reshape(v.shape[0], h//8, 8, w//8, 8, 3).mean(axis=(2,4,5))
        return b.mean(axis=0), b.var(axis=0, ddof=1)/v.shape[0]
    (a, va), (c, vc) = blocks(res["plain"][0]), blocks(res["guided"][0])
    z = (a - c)/np.sqrt(va + vc + 1e-30)
    print(f"{name}: guided/plain variance {V['guided']/V['plain']:.3f}  time {res['guided'][1]/res['plain'][1]:.2f}x  image means {mp:.4f} {mg:.4f} block mean z^2 {np.mean(z**2):.2f} max|z| {np.abs(z).max():.1f}", flush=True)
