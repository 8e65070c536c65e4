#!/usr/bin/env bash
# Makes the installable Blender add-on zip: clients/blender/penumbra_blender with the Python
# client (clients/python/penumbra) copied in as its subpackage penumbra_blender.penumbra, so
# the installed add-on needs nothing else (docs/blender.md).
#   scripts/package-blender-addon.sh [OUT.zip]     default: build/penumbra_blender.zip
set -euo pipefail
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$repo_root/build/penumbra_blender.zip}"
out="$(mkdir -p "$(dirname "$out")" && cd "$(dirname "$out")" && pwd)/$(basename "$out")"
stage="$(mktemp -d)"
trap 'rm -rf "$stage"' EXIT
cp -r "$repo_root/clients/blender/penumbra_blender" "$stage/"
rm -rf "$stage/penumbra_blender/penumbra"
cp -r "$repo_root/clients/python/penumbra" "$stage/penumbra_blender/penumbra"
find "$stage" -name __pycache__ -type d -prune -exec rm -rf {} +
rm -f "$out"
(cd "$stage" && python3 -c '
import os, sys, zipfile
with zipfile.ZipFile(sys.argv[1], "w", zipfile.ZIP_DEFLATED) as z:
    for root, dirs, files in os.walk("penumbra_blender"):
        dirs.sort()
        for f in sorted(files):
            z.write(os.path.join(root, f))
' "$out")
echo "$out"
