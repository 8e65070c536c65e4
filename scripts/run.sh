#!/usr/bin/env bash
# The main job: installs the dependencies, builds, and renders the example Cornell box to
# out/cornell_box.png.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
mkdir -p out
./build/app/penumbra render scenes/cornell_box.json -o out/cornell_box.png "$@"
echo "wrote out/cornell_box.png"
