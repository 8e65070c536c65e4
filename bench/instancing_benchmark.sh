#!/usr/bin/env bash
# Memory and time of instancing: one 100k-triangle mesh (a binary PLY, generated here) and an
# "instances" object placing COPIES copies of it (default 1000: 100 million triangles drawn),
# rendered by `penumbra render` under /usr/bin/time. Reports peak resident memory and wall time
# of the mesh alone, with COPIES copies and with 10 x COPIES copies; the cost of one more copy is
# the difference of the last two over 9 x COPIES (the first copy also brings the mesh's second
# BVH, its child scene). Exits 1 if the peak with COPIES copies exceeds LIMIT_MB (default 1024).
#
#   bench/instancing_benchmark.sh [PENUMBRA_BINARY] [COPIES] [SPP] [LIMIT_MB]
#   defaults: build/app/penumbra 1000 16 1024
# Written down in docs/instancing.md.
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build/app/penumbra}
copies=${2:-1000}
spp=${3:-16}
limit_mb=${4:-1024}

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# A torus knot tube: 250 x 200 quads = 100,000 triangles, with vertex normals.
python3 - "$work" "$copies" "$spp" <<'PY'
import json, math, struct, sys
work, copies, spp = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
seg, sides, p, q = 250, 200, 2, 3
def knot(t):
    r = 1 + 0.4 * math.cos(q * t)
    return (r * math.cos(p * t), 0.4 * math.sin(q * t), r * math.sin(p * t))
verts = []
for i in range(seg):
    t = 2 * math.pi * i / seg
    c, c2 = knot(t), knot(t + 1e-3)
    tan = [c2[k] - c[k] for k in range(3)]
    ln = math.sqrt(sum(x * x for x in tan)); tan = [x / ln for x in tan]
    up = (0.0, 1.0, 0.0)
    b = [tan[1] * up[2] - tan[2] * up[1], tan[2] * up[0] - tan[0] * up[2], tan[0] * up[1] - tan[1] * up[0]]
    lb = math.sqrt(sum(x * x for x in b)); b = [x / lb for x in b]
    n = [b[1] * tan[2] - b[2] * tan[1], b[2] * tan[0] - b[0] * tan[2], b[0] * tan[1] - b[1] * tan[0]]
    for j in range(sides):
        a = 2 * math.pi * j / sides
        d = [math.cos(a) * n[k] + math.sin(a) * b[k] for k in range(3)]
        verts.append([c[k] + 0.15 * d[k] for k in range(3)] + d)
faces = []
for i in range(seg):
    for j in range(sides):
        a, b_ = i * sides + j, i * sides + (j + 1) % sides
        c_, d_ = ((i + 1) % seg) * sides + (j + 1) % sides, ((i + 1) % seg) * sides + j
        faces.append((a, d_, c_, b_))
with open(f"{work}/knot.ply", "wb") as f:
    f.write((f"ply\nformat binary_little_endian 1.0\nelement vertex {len(verts)}\n"
             + "".join(f"property float {n}\n" for n in ("x", "y", "z", "nx", "ny", "nz"))
             + f"element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n").encode())
    f.write(b"".join(struct.pack("<6f", *v) for v in verts))
    f.write(b"".join(struct.pack("<B4i", 4, *fc) for fc in faces))
side = math.ceil(math.sqrt(copies))
transforms = [{"rotate": {"axis": [0, 1, 0], "degrees": (37 * k) % 360},
               "translate": [3.2 * (k % side - side / 2), 0, -3.2 * (k // side)]} for k in range(copies)]
def scene(n):
    return {"version": 1, "render": {"width": 320, "height": 240, "spp": spp, "max_depth": 4, "seed": 1},
            "camera": {"position": [0, 12, 14], "look_at": [0, 0, -0.4 * 3.2 * side], "fov": 50},
            "environment": {"radiance": [0.6, 0.65, 0.7]},
            "materials": {"m": {"type": "plastic", "color": [0.6, 0.3, 0.1], "roughness": 0.3}},
            "objects": [{"type": "mesh", "file": "knot.ply", "material": "m"}]
                       + ([{"type": "instances", "mesh": 0, "transforms": transforms[:n]}] if n else [])}
json.dump(scene(copies), open(f"{work}/instances.json", "w"))
json.dump(scene(0), open(f"{work}/mesh_alone.json", "w"))
transforms = [{"rotate": {"axis": [0, 1, 0], "degrees": (37 * k) % 360},
               "translate": [3.2 * (k % side - side / 2), 3.2 * (k // (side * side)), -3.2 * ((k // side) % side)]}
              for k in range(10 * copies)]
json.dump(scene(10 * copies), open(f"{work}/instances_x10.json", "w"))
PY

measure() {  # scene -> "peak_kb wall_s summary-line"
  /usr/bin/time -f "%M %e" -o "$work/time.txt" "$bin" render "$work/$1" -o "$work/$1.exr" 2>"$work/err.txt" >/dev/null
  echo "$(cat "$work/time.txt") $(grep -o '[0-9.]* Mrays/s' "$work/err.txt" | tail -1)"
}
"$bin" info "$work/instances.json" | sed 's/^/  /'
read -r alone_kb alone_s alone_rays _ < <(measure mesh_alone.json)
read -r inst_kb inst_s inst_rays _ < <(measure instances.json)
read -r ten_kb ten_s ten_rays _ < <(measure instances_x10.json)
mb() { echo "$1 / 1024" | bc -l; }
printf '%-34s peak RSS %7.1f MB, wall %6.2f s, %s Mrays/s\n' "mesh alone (100k triangles):" "$(mb "$alone_kb")" "$alone_s" "$alone_rays"
printf '%-34s peak RSS %7.1f MB, wall %6.2f s, %s Mrays/s\n' "mesh + $copies copies:" "$(mb "$inst_kb")" "$inst_s" "$inst_rays"
printf '%-34s peak RSS %7.1f MB, wall %6.2f s, %s Mrays/s\n' "mesh + $((10 * copies)) copies:" "$(mb "$ten_kb")" "$ten_s" "$ten_rays"
printf 'first copy and child BVH: %.1f MB; each further copy: %.0f bytes of peak RSS\n' \
  "$(echo "($inst_kb - $alone_kb) / 1024" | bc -l)" "$(echo "($ten_kb - $inst_kb) * 1024 / (9 * $copies)" | bc -l)"
if (( inst_kb > limit_mb * 1024 )); then
  echo "FAIL: peak RSS above ${limit_mb} MB with $copies copies"
  exit 1
fi
