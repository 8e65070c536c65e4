#!/usr/bin/env bash
# Creates the Python venv used to make and compare against the Mitsuba 3 reference images
# (tools/make_references.py, the accuracy benchmark). Idempotent: re-running only fills in
# what is missing.
#
#   scripts/setup-mitsuba-venv.sh [VENV_DIR]      (default: .venv-mitsuba in the repo root)
#
# Installs into the venv: mitsuba 3.9.x, numpy, flip-evaluator, matplotlib.
# Installs from Debian (needs root or sudo): libllvm19, which Mitsuba's llvm_ad_rgb variant
# needs. Dr.Jit picks Debian 12's default LLVM 15 otherwise, and renders then abort with
# "Cannot select ... fminimum"; LLVM 14 is refused. Without libLLVM only scalar_rgb works.
set -euo pipefail

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${1:-$repo_root/.venv-mitsuba}"
python="${PYTHON:-python3}"

sudo_cmd=""
if [ "$(id -u)" -ne 0 ]; then sudo_cmd="sudo"; fi

# --- Debian: python venv support and libLLVM 19 --------------------------------------------
apt_missing=()
for pkg in python3-venv libllvm19; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || apt_missing+=("$pkg")
done
if [ ${#apt_missing[@]} -gt 0 ]; then
  echo "setup-mitsuba-venv: installing ${apt_missing[*]} from Debian" >&2
  $sudo_cmd apt-get update -qq
  if ! DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq --no-install-recommends "${apt_missing[@]}"; then
    echo "setup-mitsuba-venv: warning: could not install ${apt_missing[*]};" \
         "llvm_ad_rgb will not work, tools fall back to scalar_rgb" >&2
  fi
fi

# --- the venv ---------------------------------------------------------------------------------
if [ ! -x "$venv/bin/python" ]; then
  echo "setup-mitsuba-venv: creating $venv" >&2
  "$python" -m venv "$venv"
fi
want=("mitsuba==3.9.*" "numpy" "flip-evaluator" "matplotlib")
if ! "$venv/bin/python" - <<'EOF' 2>/dev/null
import importlib.metadata as md, sys
v = md.version("mitsuba")
for name in ("numpy", "flip-evaluator", "matplotlib"):
    md.version(name)
sys.exit(0 if v.startswith("3.9.") else 1)
EOF
then
  echo "setup-mitsuba-venv: installing ${want[*]}" >&2
  "$venv/bin/pip" install -q --upgrade pip
  "$venv/bin/pip" install -q "${want[@]}"
fi

# --- report which variants render -------------------------------------------------------------
# libllvm19's soname is libLLVM.so.19.1; Dr.Jit is pointed at it through DRJIT_LIBLLVM_PATH so
# it does not pick another installed LLVM first.
llvm_lib="$(ls /usr/lib/llvm-19/lib/libLLVM.so* /usr/lib/x86_64-linux-gnu/libLLVM.so.19* 2>/dev/null | head -n1 || true)"
# Each variant is tried in its own process: a bad libLLVM aborts the process, not just a call.
for variant in llvm_ad_rgb scalar_rgb; do
  DRJIT_LIBLLVM_PATH="${DRJIT_LIBLLVM_PATH:-$llvm_lib}" "$venv/bin/python" - "$variant" <<'EOF' \
    || echo "setup-mitsuba-venv: $variant: unavailable (its test render failed)" >&2
import sys
import mitsuba as mi
mi.set_variant(sys.argv[1])
mi.render(mi.load_dict(mi.cornell_box()), spp=1)
print(f"setup-mitsuba-venv: mitsuba {mi.__version__} {sys.argv[1]}: ok")
EOF
done
echo "setup-mitsuba-venv: done; use $venv/bin/python" >&2
