#!/usr/bin/env bash
# Instructions executed by `penumbra render` (whole process, one render thread), per scene and
# binary, counted by valgrind's callgrind: a count that does not depend on the machine's load,
# so binaries compare on a shared machine where wall time cannot. (perf stat's hardware counters
# would do the same faster, but this VM exposes none: "instructions <not supported>".) One
# thread, because a second one's spin-waiting in TBB adds a load-dependent count. A binary may
# be given as ENV=VALUE:PATH to run it with one environment variable set. From the repo root:
#   bench/perf_counts.sh "SCENE..." BINARY [BINARY...]      (SPP=16 by default)
set -euo pipefail
source "$(dirname "$0")/binary_spec.sh"
scenes=$1; shift
spp=${SPP:-16}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| scene (%s spp, 1 thread) | binary | instructions (1e9) |\n| --- | --- | ---: |\n' "$spp"
for scene in $scenes; do
  for bin in "$@"; do
    split_binary "$bin"
    env "${binary_env[@]}" valgrind --tool=callgrind --callgrind-out-file="$out/cg" \
      "$binary_path" render "$scene" -o "$out/img.exr" --spp "$spp" --threads 1 -q >"$out/log" 2>&1
    ir=$(sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$out/log")
    printf '| %s | %s | %.4f |\n' "$(basename "$scene" .json)" "$bin" "$(echo "$ir" | awk '{print $1 / 1e9}')"
  done
done
