#!/usr/bin/env bash
# Builds with AddressSanitizer + UndefinedBehaviorSanitizer (-DPENUMBRA_SANITIZE=ON) in
# build-asan/ and runs the renderer, api and stress test binaries under them.
#   scripts/sanitize.sh [extra gtest args...]
# The server tests are left out: they start the real binary many times and wait on sockets and
# timeouts, which under ASan takes far longer than their budget; the server's request handling
# is exercised through api::load_scene by these tests and by scripts/fuzz.sh.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build-asan"
jobs="${JOBS:-2}"

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPENUMBRA_SANITIZE=ON \
  -DPENUMBRA_BUILD_SERVER=OFF -DPENUMBRA_BUILD_BENCH=OFF >/dev/null
ninja -C "$build" -j "$jobs" renderer_tests api_tests stress_tests

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:${ASAN_OPTIONS:-}"
# Leaks inside third-party libraries (scripts/lsan.supp says which and why) are not ours to fix.
export LSAN_OPTIONS="suppressions=$root/scripts/lsan.supp:${LSAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
status=0
for t in renderer_tests api_tests stress_tests; do
  echo "== $t (ASan + UBSan)"
  start=$(date +%s)
  (cd "$root" && "$build/tests/$t" --gtest_brief=1 "$@") || status=1
  echo "== $t: $(( $(date +%s) - start )) s"
done
exit $status
