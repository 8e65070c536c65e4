#!/usr/bin/env bash
# Two penumbra binaries timed at the same moment: each repeat renders the scene with binary A on
# one core and binary B on the other (one render thread each, pinned with taskset), the cores
# swapped every repeat, and takes the ratio of the pair's render seconds. This VM's speed drifts
# by a quarter over seconds to minutes, and runs taken one after the other (compare_renders.sh)
# saw it: the same binary against itself read 0.91 in a 21-repeat alternation. Run side by side,
# both renders see the same drift, and the median of the per-pair ratios resolves about 1%: the
# same binary against itself reads 0.997-1.002 over 30 pairs, session 31's early accept against
# its parent 0.984 and, in the other order, 1.014 (docs/performance.md, session 32). The two
# renders share the caches and memory bandwidth the machine has, symmetrically. A binary may be
# given as ENV=VALUE:PATH to run it with one environment variable set. From the repo root:
#   bench/pair_renders.sh "SCENE..." A B      (REPEAT=30 pairs, SPP=64; needs both cores idle)
set -euo pipefail
source "$(dirname "$0")/binary_spec.sh"
scenes=$1
spec_a=$2
spec_b=$3
repeat=${REPEAT:-30}
spp=${SPP:-64}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
render_seconds() {  # core spec scene file
  split_binary "$2"
  env "${binary_env[@]}" taskset -c "$1" "$binary_path" render "$3" -o "$out/img$1.exr" --spp "$spp" \
    --threads 1 -q 2>&1 | render_phase_seconds >"$4"
}
printf '| scene (%s spp, 1 thread each) | A render s | B render s | B / A (median of %s pairs) | lowest, highest pair |\n' "$spp" "$repeat"
printf '| --- | ---: | ---: | ---: | ---: |\n'
for scene in $scenes; do
  : >"$out/pairs"
  for ((r = 0; r < repeat; ++r)); do
    core_a=$((r % 2)) core_b=$((1 - r % 2))
    render_seconds "$core_a" "$spec_a" "$scene" "$out/a" &
    render_seconds "$core_b" "$spec_b" "$scene" "$out/b" &
    wait
    if [[ ! -s $out/a || ! -s $out/b ]]; then
      echo "pair_renders.sh: a render of $scene failed (no summary line)" >&2
      exit 1
    fi
    echo "$(cat "$out/a") $(cat "$out/b")" >>"$out/pairs"
  done
  a=$(awk '{print $1}' "$out/pairs" | median)
  b=$(awk '{print $2}' "$out/pairs" | median)
  ratio=$(awk '{print $2 / $1}' "$out/pairs" | median)
  range=$(awk '{print $2 / $1}' "$out/pairs" | sort -g | sed -n '1p;$p' | tr '\n' ' ')
  printf '| %s | %.3f | %.3f | %.3f | %s |\n' "$(basename "$scene" .json)" "$a" "$b" "$ratio" "$(echo "$range" | awk '{printf "%.3f, %.3f", $1, $2}')"
done
