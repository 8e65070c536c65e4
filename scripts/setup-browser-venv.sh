#!/usr/bin/env bash
# Creates the Python venv with Selenium that drives Debian's chromium through chromium-driver in
# the dashboard's browser test (tests/browser, ctest label "browser"). Idempotent.
#
#   scripts/setup-browser-venv.sh [VENV_DIR]     (default: .venv-browser in the repo root)
set -euo pipefail
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${1:-$repo_root/.venv-browser}"
python="${PYTHON:-python3}"
[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
"$venv/bin/pip" install -q --disable-pip-version-check "selenium==4.27.1"
"$venv/bin/python" -c 'import selenium; print("selenium", selenium.__version__)'
