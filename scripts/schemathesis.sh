#!/usr/bin/env bash
# Fuzzes the running service against /v1/openapi.json with every schemathesis check: a server
# without a token, one with a token (called with it, and without it: every route but /healthz
# must then answer the documented 401), and a render farm node on a throwaway PostgreSQL. Bounded: a fixed number of examples per
# operation and a fixed seed, a few minutes on 2 cores. Exit 0 only with 0 failures.
#
#   scripts/schemathesis.sh PENUMBRA_BINARY [VENV_DIR] [EXAMPLES]
#
# Without the venv (scripts/setup-schemathesis-venv.sh) it exits 77 (ctest: skipped) outside CI,
# and fails in CI (CI=true), where the venv is made before the tests.
set -euo pipefail
binary="$(realpath "$1")"
repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${2:-${PENUMBRA_SCHEMATHESIS_VENV:-$repo_root/.venv-schemathesis}}"
examples="${3:-100}"
st="$venv/bin/schemathesis"
if [ ! -x "$st" ]; then
  if [ "${CI:-}" = "true" ]; then
    echo "schemathesis.sh: no schemathesis in $venv (run scripts/setup-schemathesis-venv.sh)" >&2
    exit 1
  fi
  echo "schemathesis.sh: skipped: no venv at $venv (scripts/setup-schemathesis-venv.sh makes it)"
  exit 77
fi
work="$(mktemp -d)"
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  if declare -F stop_pg >/dev/null; then stop_pg; fi
  rm -rf "$work"
}
trap cleanup EXIT

# Starts penumbra serve on an ephemeral port; sets PORT (not in a subshell: the pid must stay in
# pids for the cleanup).
start_server() {
  local name="$1"; shift
  mkdir -p "$work/$name"
  "$binary" serve --port 0 --data-dir "$work/$name" --max-queue 1000 "$@" >"$work/$name.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 100); do
    if grep -q "listening on http://" "$work/$name.log"; then
      PORT="$(sed -n 's|.*listening on http://[^:]*:\([0-9]*\).*|\1|p' "$work/$name.log" | head -1)"
      return
    fi
    sleep 0.1
  done
  echo "schemathesis.sh: $name did not start: $(cat "$work/$name.log")" >&2
  exit 1
}

run() {
  local label="$1" schema="$2" base="$3"; shift 3
  echo "== schemathesis: $label"
  # --hypothesis-deadline: a render on a loaded 2-core machine may take seconds.
  ( cd "$work" && timeout 600 "$st" run "$schema" --base-url "$base" --checks all \
      --hypothesis-max-examples "$examples" --hypothesis-seed 15 --hypothesis-deadline 20000 \
      --hypothesis-suppress-health-check all --workers 2 "$@" ) \
    | grep -v -e "HypothesisDeprecationWarning" -e "next(self.gen)"
  return "${PIPESTATUS[0]}"
}

start_server open
open_port="$PORT"
token="st-$(head -c 12 /dev/urandom | od -An -tx1 | tr -d ' \n')"
start_server auth --token "$token"
auth_port="$PORT"
schema_file="$work/openapi.json"
curl -sf "http://127.0.0.1:$open_port/v1/openapi.json" -o "$schema_file"

status=0
# Without a token nothing is enforced, so the schema's declared bearer auth is not checked here.
run "no token configured" "$schema_file" "http://127.0.0.1:$open_port" \
  --exclude-checks ignored_auth || status=1
run "token configured, sent" "$schema_file" "http://127.0.0.1:$auth_port" \
  -H "Authorization: Bearer $token" || status=1
run "token configured, not sent" "$schema_file" "http://127.0.0.1:$auth_port" || status=1
names="open auth"
# A render farm node (--store postgres://..., docs/scale-out.md) answers the same document: once
# more against one on a throwaway PostgreSQL, when its server is installed (install-deps --farm).
if ls /usr/lib/postgresql/*/bin/initdb >/dev/null 2>&1; then
  pg_port="$(python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])')"
  chmod 755 "$work"
  pg_url="$("$repo_root/scripts/farm-postgres.sh" start "$work/pg" "$pg_port")"
  stop_pg() { "$repo_root/scripts/farm-postgres.sh" stop "$work/pg" immediate || true; }
  start_server farm --store "$pg_url" --role all --render-threads 1
  farm_port="$PORT"
  run "farm node (PostgreSQL store)" "$schema_file" "http://127.0.0.1:$farm_port" \
    --exclude-checks ignored_auth || status=1
  names="open auth farm"
elif [ "${CI:-}" = "true" ]; then
  echo "schemathesis.sh: no PostgreSQL server for the farm node (scripts/install-deps.sh --farm)" >&2
  status=1
fi
for name in $names; do
  if grep -q "internal error" "$work/$name.log"; then
    echo "schemathesis.sh: the $name server logged an internal error:" >&2
    grep "internal error" "$work/$name.log" >&2
    status=1
  fi
done
exit "$status"
