#!/usr/bin/env bash
# The Blender add-on's test (tests/blender) in Debian's Blender, headless, against the real
# `penumbra serve` given as $1 (ctest label "blender"; install-deps.sh --blender installs
# Blender). Exits 77 (skipped) when Blender or oiiotool is missing outside CI.
#   PENUMBRA_KEEP_TEST_DIR=1 scripts/blender-test.sh build/app/penumbra   keeps the renders
set -euo pipefail
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
blender="${BLENDER:-$(command -v blender || true)}"
if [ -z "$blender" ] || ! command -v oiiotool >/dev/null || ! command -v idiff >/dev/null; then
  [ "${CI:-}" = true ] && { echo "blender test: blender or openimageio-tools missing" >&2; exit 1; }
  echo "blender test: run scripts/install-deps.sh --blender first; skipped" >&2
  exit 77
fi
binary="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
# Blender prints a status line per render step; keep the test's own lines and any error.
set +e
PENUMBRA_BINARY="$binary" "$blender" -b --factory-startup --python-exit-code 1 \
  --python "$repo_root/tests/blender/blender_test.py" -- "${@:2}" 2>&1 | grep -v '^Fra:'
rc=${PIPESTATUS[0]}
[ "$rc" -ne 0 ] || [ $# -gt 1 ] && exit "$rc"  # a chosen test case: only that

# The packaged zip, installed as a user installs it, renders with the client inside it.
work="$(mktemp -d)"
trap 'kill "$server" 2>/dev/null; wait "$server" 2>/dev/null; rm -rf "$work"' EXIT
"$repo_root/scripts/package-blender-addon.sh" "$work/penumbra_blender.zip" >/dev/null
mkfifo "$work/out"
"$binary" serve --port 0 --data-dir "$work/data" >"$work/out" 2>"$work/server.log" &
server=$!
exec 3<"$work/out"
read -r line <&3
url="$(sed -n 's/.*listening on \(http:[^ ]*\).*/\1/p' <<<"$line")"
[ -n "$url" ] || { echo "penumbra serve did not start: $line" >&2; exit 1; }
cat <&3 >/dev/null &
mkdir -p "$work/scripts"
BLENDER_USER_SCRIPTS="$work/scripts" BLENDER_USER_CONFIG="$work/config" PENUMBRA_URL="$url" \
  "$blender" -b --factory-startup --python-exit-code 1 \
  --python "$repo_root/tests/blender/zip_install_test.py" -- "$work/penumbra_blender.zip" 2>&1 |
  grep -E 'zip install|Error|Traceback|assert|^  '
rc=${PIPESTATUS[0]}
exit "$rc"
