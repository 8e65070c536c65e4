#!/usr/bin/env bash
# Start-up cost of penumbra binaries: best-of-7 wall time and peak resident memory of short
# commands (issue 11's "--version and validate under 30 ms and 30 MB, a 64x64 render under
# 100 ms"), the last two with image assets (PNG textures; a Radiance HDR environment map).
# Run from the repository root:   bench/startup.sh BINARY [BINARY...]
set -euo pipefail
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
for bin in "$@"; do
  echo "== $bin"
  for cmd in "--version" "validate scenes/cornell_box.json" \
             "render scenes/cornell_box.json -o $out/s.png --width 64 --height 64 --spp 4 -q" \
             "render tests/accuracy/scenes/textured_diffuse.json -o $out/s.png --width 64 --height 64 --spp 4 -q" \
             "render tests/accuracy/scenes/environment_map.json -o $out/s.png --width 64 --height 64 --spp 4 -q"; do
    for _ in 1 2 3 4 5 6 7; do
      /usr/bin/time -o "$out/t" -f "%e %M" "$bin" $cmd >/dev/null 2>&1
      cat "$out/t"
    done | sort -n | head -1 |
      awk -v c="${cmd/$out\//}" '{printf "  %-90s %6.3f s %7.1f MB\n", c, $1, $2 / 1024}'
  done
done
