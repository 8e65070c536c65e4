#!/usr/bin/env bash
# Whether a change to the renderer left its images identical to the bit: renders every example
# scene (scenes/*.json) and every accuracy scene (tests/accuracy/scenes/*.json) with both
# integrators, short renders (SPP, default 16; both threads: a pixel's samples do not depend on
# the thread that renders them), with two binaries, and compares the EXR images' pixels exactly
# (OpenImageIO's idiff with zero tolerance: the files' metadata holds the render time).
# Speed work that claims "no image changed" is checked with this; a change that is meant to
# change images is checked by the accuracy tests instead. From the repository root:
#   bench/bit_identity.sh BASE_BINARY NEW_BINARY        (exit 1 if any image differs)
# A binary may be given as ENV=VALUE:PATH to run it with one environment variable set.
set -euo pipefail
source "$(dirname "$0")/binary_spec.sh"
base=$1
new=$2
spp=${SPP:-16}
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
run() {  # binary-spec scene integrator output
  split_binary "$1"
  env "${binary_env[@]}" "$binary_path" render "$2" --spp "$spp" --integrator "$3" -o "$4" >"$4.log" 2>&1 ||
    { echo "render failed: $binary_path $2 $3" >&2; cat "$4.log" >&2; return 1; }
}
images=0
differ=0
for scene in scenes/*.json tests/accuracy/scenes/*.json; do
  name=$(basename "$(dirname "$scene")")_$(basename "$scene" .json)
  for integrator in path distributed; do
    run "$base" "$scene" "$integrator" "$out/$name.$integrator.base.exr"
    run "$new" "$scene" "$integrator" "$out/$name.$integrator.new.exr"
    images=$((images + 1))
    if ! idiff -q -fail 0 -warn 0 "$out/$name.$integrator.base.exr" "$out/$name.$integrator.new.exr" \
      >/dev/null 2>&1; then
      echo "differs: $scene ($integrator)"
      differ=$((differ + 1))
    fi
  done
done
echo "$images images, $differ differ"
[ "$differ" -eq 0 ]
