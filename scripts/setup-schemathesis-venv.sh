#!/usr/bin/env bash
# Creates the Python venv with schemathesis, which fuzzes the HTTP API against its own OpenAPI
# document (scripts/schemathesis.sh, ctest label "schemathesis", .ci/run). Idempotent.
#
#   scripts/setup-schemathesis-venv.sh [VENV_DIR]     (default: .venv-schemathesis in the repo root)
#
# Versions are pinned: schemathesis 3.39 with hypothesis below 6.125 (later hypothesis releases
# break schemathesis 3.39's strategies: "'many' object has no attribute 'more'").
set -euo pipefail
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${1:-$repo_root/.venv-schemathesis}"
python="${PYTHON:-python3}"
if ! "$python" -m venv --help >/dev/null 2>&1 || ! "$python" -c 'import ensurepip' 2>/dev/null; then
  sudo_cmd=""
  if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends python3-venv
fi
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/pip" install -q --disable-pip-version-check "schemathesis==3.39.16" "hypothesis>=6.100,<6.125"
"$venv/bin/schemathesis" --version
