#!/usr/bin/env bash
# The Python client's tests (clients/python/tests) against the real `penumbra serve` given as $1:
# makes a venv (.venv-client in the repo root, or $CLIENT_VENV), installs numpy and the client
# from the repo as a user would (`pip install ./clients/python`, not an editable install), and
# runs the tests from outside the source folder so that the installed package is what they
# import. ctest label "client"; exits 77 (skipped) when no venv can be made outside CI.
set -euo pipefail
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
binary="$1"
venv="${CLIENT_VENV:-$repo_root/.venv-client}"
python="${PYTHON:-python3}"
if [ ! -x "$venv/bin/python" ]; then
  if ! "$python" -m venv "$venv" >/dev/null 2>&1; then
    [ "${CI:-}" = true ] && { echo "cannot create a venv with $python" >&2; exit 1; }
    echo "no venv (python3-venv missing?): skipped" >&2
    exit 77
  fi
fi
"$venv/bin/pip" install -q --disable-pip-version-check "numpy>=1.24,<3"
"$venv/bin/pip" install -q --disable-pip-version-check --force-reinstall --no-deps "$repo_root/clients/python"
cd "$(mktemp -d)"
trap 'rm -rf "$PWD"' EXIT
PENUMBRA_BINARY="$binary" "$venv/bin/python" -m unittest discover -s "$repo_root/clients/python/tests" -v 2>&1
