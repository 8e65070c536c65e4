#!/usr/bin/env bash
# The test command: installs the dependencies, builds, and runs the whole test suite (ctest).
set -euo pipefail
cd "$(dirname "$0")/.."
# --schemathesis: also the pinned Python venv (.venv-schemathesis) of the "schemathesis" label;
# --browser: Debian's chromium and chromium-driver and the Selenium venv of the "browser" label;
# --blender: Debian's Blender for the add-on's test (label "blender").
# --farm: PostgreSQL for the "farm" label.
./scripts/install-deps.sh --schemathesis --browser --blender --farm
./scripts/build.sh
BUILD_DIR=${BUILD_DIR:-build}
# Open Image Denoise beside the binary (the pinned PyPI wheel's libraries; denoising tests).
BUILD_DIR="$BUILD_DIR" ./scripts/install-oidn.sh
export PENUMBRA_REQUIRE_OIDN=1
ctest --test-dir "$BUILD_DIR" --output-on-failure -j"$(nproc)" --timeout 300 "$@"
