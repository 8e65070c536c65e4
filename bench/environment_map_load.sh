#!/usr/bin/env bash
# Whole-process time and peak memory of loading a large environment map: `penumbra render` of the
# accuracy scene tests/accuracy/scenes/environment_map.json with its sky replaced by an 8192 x 4096
# Radiance map, at 64 x 64 pixels and 1 spp, so that nearly all of the time is reading the map,
# building the light and its sampling table. Two binaries, runs alternating (this machine is
# shared and noisy: compare ranges and medians, not single runs). From the repository root:
#   bench/environment_map_load.sh BASE_BINARY NEW_BINARY      (REPEAT=7 runs each)
# The map is MAP (default /tmp/penumbra_big_sky.hdr), made if missing by bench/make_big_sky.py
# (the scene's sky at 8192 x 4096 with noise, 105 MB; PYTHON: a Python with Mitsuba, default
# .venv-mitsuba/bin/python).
# A binary may be given as ENV=VALUE:PATH (bench/binary_spec.sh).
set -euo pipefail
source "$(dirname "$0")/binary_spec.sh"
base=$1
new=$2
repeat=${REPEAT:-7}
map=${MAP:-/tmp/penumbra_big_sky.hdr}
if [[ ! -f $map ]]; then
  echo "making $map (bench/make_big_sky.py)" >&2
  "${PYTHON:-.venv-mitsuba/bin/python}" bench/make_big_sky.py "$map"
fi
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# The scene must name a file inside its own folder: a hard link (or a copy on another file system).
ln "$map" "$out/big_sky.hdr" 2>/dev/null || cp "$map" "$out/big_sky.hdr"
python3 - "$out/scene.json" <<'EOF'
import json, sys
scene = json.load(open("tests/accuracy/scenes/environment_map.json"))
scene["environment"]["map"] = "big_sky.hdr"
scene["render"]["spp"] = 1
json.dump(scene, open(sys.argv[1], "w"))
EOF
run() {  # binary-spec label
  split_binary "$1"
  env "${binary_env[@]}" /usr/bin/time -o "$out/time" -f "%e %M" "$binary_path" render "$out/scene.json" \
    --spp 1 -o "$out/image.exr" -q >/dev/null 2>&1
  read -r wall kb <"$out/time"
  echo "$wall $((kb / 1024))" >>"$out/$2"
}
for ((r = 0; r < repeat; ++r)); do
  run "$base" base
  run "$new" new
done
summary() {  # label name
  local walls mbs
  walls=$(cut -d' ' -f1 "$out/$1" | sort -g)
  mbs=$(cut -d' ' -f2 "$out/$1" | sort -g)
  printf '| %s | %s-%s | %s | %s-%s |\n' "$2" "$(head -1 <<<"$walls")" "$(tail -1 <<<"$walls")" \
    "$(median <<<"$walls")" "$(head -1 <<<"$mbs")" "$(tail -1 <<<"$mbs")"
}
echo "| binary ($repeat runs each, alternating) | wall (s), range | wall (s), median | peak memory (MB) |"
echo "| --- | ---: | ---: | ---: |"
summary base "$base"
summary new "$new"
