# Session 39 measurement (docs/performance.md, levers, session 39). From the repository root:
#   .venv-mitsuba/bin/python docs/experiments/session39_cmj_blocks.py SCENE ...  (env: SEEDS, SPP)
import os, subprocess, sys, tempfile
import numpy as np
sys.path.insert(0, "tools")
import bench_accuracy as ba, penumbra_to_mitsuba as p2m
mi = p2m.import_mitsuba("llvm_ad_rgb")
out = os.path.join(tempfile.mkdtemp(), "i.exr")
S = int(os.environ.get("SEEDS", 16))
def render(name, spp, sampler, seed):
    subprocess.run(["build/app/penumbra", "render", f"tests/accuracy/scenes/{name}.json", "-o", out, "--spp", str(spp), "--seed", str(seed), "-q", "--sampler", sampler], check=True)
    return ba.read_exr(mi, out)
for name in sys.argv[1:]:
    ref = None
    V = {}
    imgs = {}
    for key in [("cmj",4),("cmj",16),("cmj",32),("cmj",64),("sobol",64),("sobol",100),("sobol",128)]:
        imgs[key] = np.array([render(name, key[1], key[0], 1000*key[1]+s) for s in range(S)])
    ref = imgs[("sobol",128)].mean(axis=0)
    for key, v in imgs.items():
        m = v.mean(axis=0)
        V[key] = float(np.mean((v - m)**2 / (ref**2 + 0.01)) * S/(S-1))
    prog64 = V[("cmj",16)]/8 + V[("cmj",32)]/4
    prog128 = V[("cmj",16)]*2*(16/128)**2 + V[("cmj",32)]*(32/128)**2 + V[("cmj",64)]*(64/128)**2
    n100 = (64/100)**2*V[("cmj",64)] + (32/100)**2*V[("cmj",32)] + (4/100)**2*V[("cmj",4)]
    print(f"{name}: 64: cmj {V[('cmj',64)]/V[('sobol',64)]:.3f} prog16+16+32 {prog64/V[('sobol',64)]:.3f} | 128 prog16+16+32+64 {prog128/V[('sobol',128)]:.3f} | 100 = 64+32+4 {n100/V[('sobol',100)]:.3f}  (of Sobol at equal spp)", flush=True)
