#!/usr/bin/env bash
# The main job: installs the dependencies, builds, and starts the HTTP render service on
# http://127.0.0.1:8080 (data in ./penumbra-data). Extra arguments go to `penumbra serve`
# (e.g. --port 9000, --workers 2, --token SECRET); Ctrl-C or SIGTERM stops it gracefully.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/install-deps.sh
./scripts/build.sh
exec ./build/app/penumbra serve "$@"
