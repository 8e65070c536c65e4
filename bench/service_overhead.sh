#!/usr/bin/env bash
# Measures what rendering through the HTTP service costs over `penumbra render` on the same
# scene: `curl --data-binary @scene /v1/render` (submit, queue, render, PNG + EXR written and
# fsync'd, PNG answered) against `penumbra render scene -o out.png`, run alternately (the order
# flips every round) so drift in machine load hits both alike. Two figures per side:
#  - wall time (what a user waits), noisy on a shared machine;
#  - CPU time (user + system): of the `penumbra render` process, and of the server process
#    during the request (from /proc/PID/stat), which other load on the machine barely moves.
# Prints the medians and both overheads; exits 1 if the CPU-time overhead exceeds the bound.
#
#   bench/service_overhead.sh [PENUMBRA_BINARY] [SCENE] [ROUNDS] [MAX_OVERHEAD_PERCENT]
#   defaults: build/app/penumbra scenes/cornell_box.json 7 2
set -euo pipefail
cd "$(dirname "$0")/.."
bin=${1:-build/app/penumbra}
scene=${2:-scenes/cornell_box.json}
rounds=${3:-7}
bound=${4:-2}

work=$(mktemp -d)
server_pid=
cleanup() {
  if [[ -n "$server_pid" ]]; then kill -TERM "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true; fi
  rm -rf "$work"
}
trap cleanup EXIT

"$bin" serve --port 0 --data-dir "$work/data" --drain 0s >"$work/server.out" 2>&1 &
server_pid=$!
for _ in $(seq 100); do
  grep -q "listening on" "$work/server.out" 2>/dev/null && break
  sleep 0.1
done
url=$(sed -n 's/^listening on \(http:[^ ]*\).*/\1/p' "$work/server.out")
[[ -n "$url" ]] || { echo "server did not start"; cat "$work/server.out"; exit 1; }

now() { date +%s.%N; }
ticks=$(getconf CLK_TCK)
server_cpu() { awk -v t="$ticks" '{print ($14 + $15) / t}' "/proc/$server_pid/stat"; }
cli_times=(); svc_times=(); cli_cpu=(); svc_cpu=()
run_cli() {
  local out
  out=$( { TIMEFORMAT='%R %U %S'; time "$bin" render "$scene" -o "$work/cli.png" -q 2>/dev/null; } 2>&1 )
  read -r real user sys <<<"$out"
  cli_times+=("$real")
  cli_cpu+=("$(echo "$user + $sys" | bc -l)")
}
run_svc() {
  local t0 t1 c0 c1 code
  c0=$(server_cpu); t0=$(now)
  code=$(curl -s -o "$work/svc.png" -w '%{http_code}' --data-binary @"$scene" "$url/v1/render")
  t1=$(now); c1=$(server_cpu)
  [[ "$code" == 200 ]] || { echo "service answered $code"; exit 1; }
  svc_times+=("$(echo "$t1 - $t0" | bc -l)")
  svc_cpu+=("$(echo "$c1 - $c0" | bc -l)")
}

run_cli >/dev/null; run_svc >/dev/null  # warm-up (page cache, CPU clocks), not counted
cli_times=(); svc_times=(); cli_cpu=(); svc_cpu=()
for i in $(seq "$rounds"); do
  if (( i % 2 )); then run_cli; run_svc; else run_svc; run_cli; fi
  printf 'round %d: render %.3f s (cpu %.2f s), service %.3f s (cpu %.2f s)\n' "$i" \
    "${cli_times[-1]}" "${cli_cpu[-1]}" "${svc_times[-1]}" "${svc_cpu[-1]}"
done

median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
cli_median=$(median "${cli_times[@]}")
svc_median=$(median "${svc_times[@]}")
cli_cpu_median=$(median "${cli_cpu[@]}")
svc_cpu_median=$(median "${svc_cpu[@]}")
overhead=$(echo "($svc_median / $cli_median - 1) * 100" | bc -l)
cpu_overhead=$(echo "($svc_cpu_median / $cli_cpu_median - 1) * 100" | bc -l)
printf 'scene %s, %d rounds\n' "$scene" "$rounds"
printf '  wall: penumbra render median %.3f s, service median %.3f s, overhead %+.2f%%\n' \
  "$cli_median" "$svc_median" "$overhead"
printf '  cpu:  penumbra render median %.2f s, service median %.2f s, overhead %+.2f%% (bound %s%%)\n' \
  "$cli_cpu_median" "$svc_cpu_median" "$cpu_overhead" "$bound"
if (( $(echo "$cpu_overhead > $bound" | bc -l) )); then echo "FAIL: overhead above ${bound}%"; exit 1; fi
echo "PASS"
