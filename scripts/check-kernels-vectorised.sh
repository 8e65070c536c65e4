#!/usr/bin/env bash
# Whether the SIMD kernels of a GCC x86-64 build of penumbra really run in vector registers.
# PENUMBRA_SIMD_CLONES (renderer/core/simd_clones.h) compiles each kernel also for x86-64-v3
# (AVX2); a loop GCC fails to vectorise still compiles, to scalar code in that clone, and the
# only symptom is a slower render (the metallic-roughness kernel did this until GCC's tree PRE
# was switched off for it, session 14). Here every surface stage kernel (*_step_kernel) and the
# other per-lane array kernels named below must have a v3 clone in which at least MIN_SHARE of
# the instructions touch a 256-bit register (vectorised kernels: 0.26-0.32; the same loop left
# scalar: 0.00, the metallic-roughness kernel with tree PRE on).
#   scripts/check-kernels-vectorised.sh PATH/TO/penumbra
set -euo pipefail
binary=$1
min_share=${MIN_SHARE:-0.15}
command -v objdump >/dev/null || { echo "objdump (binutils) is missing" >&2; exit 1; }
# Kernels beside the step kernels that must be vectorised (share in the last measured build).
others="scrambled_sobol_kernel scrambled_sobol_z_kernel quad_kernel quad_kernel_one sphere_kernel sphere_kernel_one packet_intersect16 packet_occluded16 lens_rays"  # 0.26, 0.37, 0.23, 0.26, 0.32, 0.32, 0.88, 0.90, 0.28
# (packet_*: the parallelogram's packets, shapes/parallelogram.cpp)
table=$(objdump -d --no-show-raw-insn "$binary" | awk '
  /^[0-9a-f]+ <.*>:$/ { name = substr($2, 2, length($2) - 3); on = (name ~ /\.arch_x86_64_v3$/); next }
  /^$/ { on = 0 }
  on { n[name]++; if (/ymm/) y[name]++ }
  END { for (k in n) printf "%s %d %d\n", k, y[k] + 0, n[k] }')
status=0
steps=0
check() {  # symbol ymm-count instruction-count
  local share
  share=$(awk -v y="$2" -v n="$3" 'BEGIN { printf "%.2f", y / n }')
  if awk -v s="$share" -v m="$min_share" 'BEGIN { exit !(s < m) }'; then
    echo "NOT VECTORISED: $1 ($2 of $3 instructions on ymm registers, share $share < $min_share)"
    status=1
  else
    echo "ok $share $1"
  fi
}
while read -r symbol ymm count; do
  case $symbol in *_step_kernel*) steps=$((steps + 1)); check "$symbol" "$ymm" "$count" ;; esac
done <<<"$table"
# The eight surface models of renderer/render/surface_stage.h's StageModel (kStageModels).
if [ "$steps" -lt 8 ]; then
  echo "expected the v3 clones of 8 surface stage kernels, found $steps" >&2
  status=1
fi
for kernel in $others; do
  # (The mangled name, length-prefixed and closed, so that quad_kernel does not also match
  # quad_kernel_one.)
  line=$(grep -F "${#kernel}${kernel}E" <<<"$table" || true)
  if [ -z "$line" ]; then
    echo "no x86-64-v3 clone of $kernel" >&2
    status=1
    continue
  fi
  check $line
done
# The light tree's root level (lights/light_tree.cpp): its importance loop runs across the points
# in vectors, and left scalar (a node field read under a condition did that, session 44) the
# function still has a quarter of its instructions on ymm registers from its other loops, so
# the share above cannot tell: the vectorised loop's square roots can (3 vsqrtps; 0 when scalar).
root_sqrt=$(objdump -d --no-show-raw-insn "$binary" | awk '
  /^[0-9a-f]+ <.*>:$/ { on = ($2 ~ /20light_tree_walk_root.*\.arch_x86_64_v3>:$/); next }
  /^$/ { on = 0 }
  on && /vsqrtps.*ymm/ { c++ }
  END { print c + 0 }')
if [ "$root_sqrt" -lt 3 ]; then
  echo "NOT VECTORISED: light_tree_walk_root ($root_sqrt vsqrtps on ymm registers in its v3 clone, want 3)"
  status=1
else
  echo "ok light_tree_walk_root ($root_sqrt vsqrtps on ymm registers)"
fi
exit $status
