#!/usr/bin/env bash
# The dashboard's browser test (tests/browser) against the real `penumbra serve` given as $1, in
# Debian's headless chromium through chromium-driver and Selenium (.venv-browser, made by
# scripts/setup-browser-venv.sh; install-deps.sh --browser installs all three). ctest label
# "browser"; exits 77 (skipped) when they are missing outside CI.
#   PENUMBRA_SCREENSHOT=docs/images/dashboard.png scripts/browser-test.sh build/app/penumbra
#   also saves a screenshot of the page.
set -euo pipefail
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${BROWSER_VENV:-$repo_root/.venv-browser}"
if [ ! -x "$venv/bin/python" ] || [ ! -x /usr/bin/chromium ] || [ ! -x /usr/bin/chromedriver ]; then
  [ "${CI:-}" = true ] && { echo "browser test: chromium, chromium-driver or $venv missing" >&2; exit 1; }
  echo "browser test: run scripts/install-deps.sh --browser first; skipped" >&2
  exit 77
fi
if [ -n "${PENUMBRA_SCREENSHOT:-}" ]; then
  PENUMBRA_SCREENSHOT="$(cd "$(dirname "$PENUMBRA_SCREENSHOT")" && pwd)/$(basename "$PENUMBRA_SCREENSHOT")"
  export PENUMBRA_SCREENSHOT
fi
PENUMBRA_BINARY="$1" "$venv/bin/python" -m unittest discover -s "$repo_root/tests/browser" \
  -p '*_test.py' -v 2>&1
