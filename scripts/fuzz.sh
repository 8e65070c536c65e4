#!/usr/bin/env bash
# Fuzz every libFuzzer target under AddressSanitizer + UndefinedBehaviorSanitizer for a bounded
# total time, shared equally between the targets:
#   scene_loader  api::load_scene (plus Scene::build and a 4x4 render of valid scenes)
#   json_document the scene text's two JSON parsers (simdjson's fast path, nlohmann's) against
#                 each other: same value, or the fast path defers to nlohmann
#   ply_reader    renderer/io/ply_reader (our own PLY parser)
#   obj_reader    renderer/io/obj_reader (our own OBJ statement reader)
#   gltf_reader   renderer/io/gltf_file (GLB checks + tinygltf + accessors, hierarchy)
#   exr_window    renderer/io/exr_window_file (a frame's window as penumbra merge reads it)
#   image_asset   renderer/io/image_reader's own readers: PNG, EXR, Radiance HDR, JPEG
#   http_head     the HTTP service's head-line checks and Range decisions (server/http)
#   multipart     the one-shot job form parser and the job envelope's manifest (server/http, api)
#   scripts/fuzz.sh [SECONDS] [TARGET...]     (default 60 seconds, all targets)
# Builds with clang in build-fuzz/. Fails (non-zero) on any crash, sanitizer report, leak,
# timeout (an input taking more than 10 s) or out-of-memory (2 GB). Crash reproducers are left
# in build-fuzz/artifacts/<target>/; new corpus entries go to build-fuzz/corpus/<target>/
# (fuzz/corpus/<target>/ is the seed, fuzz/dict/<target>.dict the dictionary where there is one).
set -euo pipefail
seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then targets=(scene_loader json_document ply_reader obj_reader gltf_reader exr_window image_asset http_head multipart); fi
root="$(cd "$(dirname "$0")/.." && pwd)"
build="$root/build-fuzz"
jobs="${JOBS:-2}"

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPENUMBRA_FUZZ=ON -DPENUMBRA_SANITIZE=ON -DPENUMBRA_BUILD_TESTS=OFF -DPENUMBRA_BUILD_BENCH=OFF \
  -DPENUMBRA_BUILD_SERVER=OFF >/dev/null
ninja -C "$build" -j "$jobs" "${targets[@]/%/_fuzzer}"

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"
share=$(( seconds / ${#targets[@]} ))
if [ "$share" -lt 1 ]; then share=1; fi
for target in "${targets[@]}"; do
  echo "== fuzz $target for ${share} s" >&2
  mkdir -p "$build/corpus/$target" "$build/artifacts/$target"
  dict=()
  if [ -f "$root/fuzz/dict/$target.dict" ]; then dict=(-dict="$root/fuzz/dict/$target.dict"); fi
  # -max_len covers the seeds; -timeout is per input; -rss_limit_mb bounds memory.
  "$build/fuzz/${target}_fuzzer" "$build/corpus/$target" "$root/fuzz/corpus/$target" "${dict[@]}" \
    -max_total_time="$share" -max_len=8192 -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$build/artifacts/$target/" -print_final_stats=1
done
