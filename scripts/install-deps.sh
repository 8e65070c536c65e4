#!/usr/bin/env bash
# Installs every Debian 12 package penumbra needs to build, test and run.
# Idempotent; needs root (or sudo). Used by the README, .ci/run and docker/Dockerfile.
#   scripts/install-deps.sh           build, test and run
#   scripts/install-deps.sh --fuzz    also clang and its sanitizer/libFuzzer runtime (scripts/fuzz.sh)
#   scripts/install-deps.sh --schemathesis  also the Python venv with schemathesis, the HTTP API
#                                     fuzzer of the ctest label "schemathesis" (PyPI, pinned;
#                                     scripts/setup-schemathesis-venv.sh)
#   scripts/install-deps.sh --browser also Chromium, its WebDriver and a venv with Selenium for the
#                                     dashboard's browser test (ctest label "browser";
#                                     scripts/setup-browser-venv.sh)
#   scripts/install-deps.sh --blender also Debian's Blender 3.4 for the add-on's test (ctest label
#                                     "blender"; scripts/blender-test.sh)
#   scripts/install-deps.sh --farm    also PostgreSQL's server and client: the throwaway database
#                                     the ctest label "farm" starts (scripts/farm-postgres.sh)
# libpq-dev (always): the PostgreSQL store of the render farm (server/farm/, docs/scale-out.md).
# Flags combine: scripts/test.sh passes --schemathesis --browser --blender --farm.
set -euo pipefail
want() { local f; for f in "${ARGS[@]}"; do [ "$f" = "$1" ] && return 0; done; return 1; }
ARGS=("$@")
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
PKGS=(
  build-essential cmake ninja-build pkg-config git ca-certificates curl
  libembree-dev libopenimageio-dev openimageio-tools libglm-dev
  libcpp-httplib-dev nlohmann-json3-dev libsimdjson-dev libtbb-dev libsqlite3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libtinygltf-dev libpng-dev
  libopenexr-dev libjpeg62-turbo-dev libssl-dev
  libpq-dev
)
if want --farm; then PKGS+=(postgresql postgresql-client); fi
if want --fuzz; then PKGS+=(clang libclang-rt-14-dev); fi
# Debian's chromium and chromium-driver (the same version), fonts for readable screenshots.
if want --browser; then PKGS+=(chromium chromium-driver fonts-dejavu-core python3-venv); fi
# Debian's Blender (3.4.1, system Python 3.11): the add-on's headless test renders through it.
if want --blender; then PKGS+=(blender); fi
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
if want --schemathesis; then "$(dirname "$0")/setup-schemathesis-venv.sh"; fi
if want --browser; then "$(dirname "$0")/setup-browser-venv.sh"; fi
