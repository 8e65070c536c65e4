#!/usr/bin/env bash
# Installs Intel Open Image Denoise 2.5.1 for denoising (renderer/denoise/oidn_denoiser.h). OIDN
# is not packaged in Debian 12; the PyPI wheel pyoidn 2.5.1.0 ships Intel's build of its shared
# libraries. This takes three of them (the API, the core with its trained weights, the CPU
# device) and OIDN's Apache-2.0 licence, and nothing else of the wheel: not its TBB (Debian's
# libtbb12 serves, and a second TBB would replace the one under Embree), not its GPU devices.
# The wheel is pinned by SHA-256. Idempotent.
#
#   scripts/install-oidn.sh [DEST]   (default: build/lib/penumbra/oidn, where build/app/penumbra
#                                     looks: <dir of the executable>/../lib/penumbra/oidn)
set -euo pipefail
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dest="${1:-$repo_root/${BUILD_DIR:-build}/lib/penumbra/oidn}"
wheel_name="pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl"
wheel_sha256="32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e"
libs=(libOpenImageDenoise.so.2 libOpenImageDenoise_core.so.2.5.1 libOpenImageDenoise_device_cpu.so.2.5.1)

have=1
for l in "${libs[@]}"; do [ -f "$dest/$l" ] || have=0; done
if [ "$have" = 1 ] && [ -f "$dest/LICENSE-Apache-2.0.txt" ]; then
  echo "install-oidn: present in $dest"
  exit 0
fi
if [ "$(uname -m)" != x86_64 ]; then
  echo "install-oidn: the pinned wheel is for x86_64; denoising stays off on $(uname -m)" >&2
  exit 0
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cache="${PENUMBRA_CACHE:-$HOME/.cache/penumbra}"
mkdir -p "$cache"
if ! echo "$wheel_sha256  $cache/$wheel_name" | sha256sum -c --status 2>/dev/null; then
  python="${PYTHON:-python3}"
  "$python" -m venv "$work/venv"
  "$work/venv/bin/pip" download -q --disable-pip-version-check --no-deps --only-binary=:all: \
    "pyoidn==2.5.1.0" -d "$work"
  mv "$work/$wheel_name" "$cache/$wheel_name"
fi
echo "$wheel_sha256  $cache/$wheel_name" | sha256sum -c --status ||
  { echo "install-oidn: $wheel_name does not have the pinned SHA-256" >&2; exit 1; }
mkdir -p "$work/x" "$dest"
( cd "$work/x" && python3 -m zipfile -e "$cache/$wheel_name" . )
for l in "${libs[@]}"; do install -m 0644 "$work/x/pyoidn/oidn/lib/$l" "$dest/$l"; done
# OIDN is Apache-2.0 (the wheel carries only its Python binding's MIT licence): Debian's copy of
# the Apache-2.0 text, the attribution, and the binding's licence for the packaging.
install -m 0644 /usr/share/common-licenses/Apache-2.0 "$dest/LICENSE-Apache-2.0.txt"
install -m 0644 "$work/x/pyoidn-2.5.1.0.dist-info/licenses/LICENSE" "$dest/LICENSE-pyoidn-MIT.txt"
cat >"$dest/NOTICE.txt" <<'NOTICE'
Intel(R) Open Image Denoise 2.5.1 (https://www.openimagedenoise.org), Copyright Intel Corporation,
licensed under the Apache License 2.0 (LICENSE-Apache-2.0.txt). These three libraries are
unmodified copies from the PyPI wheel pyoidn 2.5.1.0 (whose packaging is MIT-licensed,
LICENSE-pyoidn-MIT.txt), installed by penumbra's scripts/install-oidn.sh.
NOTICE
echo "install-oidn: Open Image Denoise 2.5.1 in $dest"
