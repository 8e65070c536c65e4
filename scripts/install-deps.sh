#!/usr/bin/env bash
# Installs every Debian 12 package penumbra needs to build, test and run.
# Idempotent; needs root (or sudo). Used by the README, .ci/run and docker/Dockerfile.
#   scripts/install-deps.sh           build, test and run
#   scripts/install-deps.sh --fuzz    also clang and its sanitizer/libFuzzer runtime (scripts/fuzz.sh)
#   scripts/install-deps.sh --schemathesis  also the Python venv with schemathesis, the HTTP API
#                                     fuzzer of the ctest label "schemathesis" (PyPI, pinned;
#                                     scripts/setup-schemathesis-venv.sh)
set -euo pipefail
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PKGS=(
  build-essential cmake ninja-build pkg-config git ca-certificates curl
  libembree-dev libopenimageio-dev openimageio-tools libglm-dev
  libcpp-httplib-dev nlohmann-json3-dev libtbb-dev libsqlite3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libtinyobjloader-dev libtinygltf-dev libpng-dev
  libopenexr-dev libssl-dev
)
if [ "${1:-}" = "--fuzz" ]; then PKGS+=(clang libclang-rt-14-dev); fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
if [ "${1:-}" = "--schemathesis" ]; then "$(dirname "$0")/setup-schemathesis-venv.sh"; fi
