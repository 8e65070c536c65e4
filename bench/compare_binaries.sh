#!/usr/bin/env bash
# Side-by-side speed of two penumbra binaries (e.g. before and after a change): runs
# `penumbra bench` with each, alternating, ROUNDS times, and prints each run's renderer/Embree
# ratio and the median per binary. The ratio is measured inside one process (renderer and
# Embree-only tracing alternate), so it is robust to a machine's load; alternating the binaries
# spreads the rest of the noise evenly.
#   bench/compare_binaries.sh OLD_BINARY NEW_BINARY [ROUNDS] [bench options...]
set -euo pipefail
old=$1 new=$2 rounds=${3:-5}
shift $(( $# >= 3 ? 3 : $# ))
opts=("$@")
[ ${#opts[@]} -eq 0 ] && opts=(scenes/cornell_box.json --spp 16 --repeat 5)
declare -a r_old r_new
for ((i = 0; i < rounds; ++i)); do
  for which in old new; do
    bin=$old; [ $which = new ] && bin=$new
    ratio=$("$bin" bench "${opts[@]}" 2>&1 | sed -n 's/.*median:.*ratio \([0-9.]*\).*/\1/p')
    echo "round $i $which ratio $ratio"
    if [ $which = old ]; then r_old+=("$ratio"); else r_new+=("$ratio"); fi
  done
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
echo "median ratio: old $(median "${r_old[@]}")  new $(median "${r_new[@]}")  (${rounds} rounds, ${opts[*]})"
