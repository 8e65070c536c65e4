#!/usr/bin/env bash
# Fuzz the scene loader (api::load_scene, plus Scene::build and a 4x4 render of valid scenes)
# with libFuzzer under AddressSanitizer + UndefinedBehaviorSanitizer for a bounded time.
#   scripts/fuzz.sh [SECONDS]     (default 60)
# Builds with clang in build-fuzz/. Fails (non-zero) on any crash, sanitizer report, leak,
# timeout (an input taking more than 10 s) or out-of-memory (2 GB). Crash reproducers are left
# in build-fuzz/artifacts/; new corpus entries go to build-fuzz/corpus/ (fuzz/corpus/ is the seed).
set -euo pipefail
seconds="${1:-60}"
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build-fuzz"
jobs="${JOBS:-2}"

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPENUMBRA_FUZZ=ON -DPENUMBRA_SANITIZE=ON -DPENUMBRA_BUILD_TESTS=OFF -DPENUMBRA_BUILD_BENCH=OFF \
  -DPENUMBRA_BUILD_SERVER=OFF >/dev/null
ninja -C "$build" -j "$jobs" scene_loader_fuzzer

mkdir -p "$build/corpus" "$build/artifacts"
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
# -max_len covers the seed scenes; -timeout is per input; -rss_limit_mb bounds memory.
"$build/fuzz/scene_loader_fuzzer" "$build/corpus" "$root/fuzz/corpus" \
  -max_total_time="$seconds" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
  -artifact_prefix="$build/artifacts/" -print_final_stats=1
