#!/usr/bin/env bash
# Render seconds (the summary line's render phase, scene build excluded) and CPU seconds (user +
# system of the whole process) of penumbra binaries side by side: every repeat renders each scene
# with each binary in turn, so a shared machine's load falls evenly on all of them; prints the
# medians per scene and binary and their ratios to the first binary. On a loaded machine the
# CPU seconds of one-thread renders (ARGS="--threads 1") are the steadier figure: wall time then
# mostly measures the scheduler. A binary may be given as ENV=VALUE:PATH to run it with one
# environment variable set. From the repository root:
#   bench/compare_renders.sh "SCENE..." BINARY [BINARY...]      (REPEAT=5, extra render flags in ARGS)
set -euo pipefail
source "$(dirname "$0")/binary_spec.sh"
scenes=$1; shift
repeat=${REPEAT:-5}
read -r -a extra <<<"${ARGS:-}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
printf '| scene | binary | render s (median of %s) | / first | CPU s | / first |\n| --- | --- | ---: | ---: | ---: | ---: |\n' "$repeat"
for scene in $scenes; do
  name=$(basename "$scene" .json)
  for ((r = 0; r < repeat; ++r)); do
    i=0
    for bin in "$@"; do
      split_binary "$bin"
      env "${binary_env[@]}" /usr/bin/time -o "$out/cpu" -f "%U %S" "$binary_path" render "$scene" -o "$out/img.exr" \
        "${extra[@]}" >"$out/log" 2>&1
      render_phase_seconds <"$out/log" >>"$out/$name.$i"
      awk '{print $1 + $2}' "$out/cpu" >>"$out/$name.cpu.$i"
      i=$((i + 1))
    done
  done
  first=$(median <"$out/$name.0")
  first_cpu=$(median <"$out/$name.cpu.0")
  i=0
  for bin in "$@"; do
    m=$(median <"$out/$name.$i")
    c=$(median <"$out/$name.cpu.$i")
    printf '| %s | %s | %.3f | %.3f | %.2f | %.3f |\n' "$name" "$bin" "$m" "$(awk -v a="$m" -v b="$first" 'BEGIN {print a / b}')" \
      "$c" "$(awk -v a="$c" -v b="$first_cpu" 'BEGIN {print a / b}')"
    i=$((i + 1))
  done
done
