#!/usr/bin/env bash
# Measures what rendering through the HTTP service costs over `penumbra render` on the same
# scene: wall time of `curl --data-binary @scene /v1/render` (submit, queue, render, PNG + EXR
# written and fsync'd, PNG answered) against `penumbra render scene -o out.png`, run alternately
# (the order flips every round) so drift in machine load hits both alike. Prints the medians
# and the overhead; exits 1 if it exceeds the bound.
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
cli_times=()
svc_times=()
run_cli() {
  local t0 t1
  t0=$(now)
  "$bin" render "$scene" -o "$work/cli.png" -q 2>/dev/null
  t1=$(now)
  cli_times+=("$(echo "$t1 - $t0" | bc -l)")
}
run_svc() {
  local t0 t1 code
  t0=$(now)
  code=$(curl -s -o "$work/svc.png" -w '%{http_code}' --data-binary @"$scene" "$url/v1/render")
  t1=$(now)
  [[ "$code" == 200 ]] || { echo "service answered $code"; exit 1; }
  svc_times+=("$(echo "$t1 - $t0" | bc -l)")
}

run_cli >/dev/null; run_svc >/dev/null  # warm-up (page cache, CPU clocks), not counted
cli_times=(); svc_times=()
for i in $(seq "$rounds"); do
  if (( i % 2 )); then run_cli; run_svc; else run_svc; run_cli; fi
  printf 'round %d: render %.3f s, service %.3f s\n' "$i" "${cli_times[-1]}" "${svc_times[-1]}"
done

median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2 ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2)}'; }
cli_median=$(median "${cli_times[@]}")
svc_median=$(median "${svc_times[@]}")
overhead=$(echo "($svc_median / $cli_median - 1) * 100" | bc -l)
cmp -s "$work/cli.png" "$work/svc.png" && same="identical" || same="different"
printf 'scene %s, %d rounds: penumbra render median %.3f s, service median %.3f s, overhead %+.2f%% (bound %s%%); images %s\n' \
  "$scene" "$rounds" "$cli_median" "$svc_median" "$overhead" "$bound" "$same"
if (( $(echo "$overhead > $bound" | bc -l) )); then echo "FAIL: overhead above ${bound}%"; exit 1; fi
echo "PASS"
