#!/usr/bin/env bash
# The Kubernetes manifests (docker/k8s/) brought up with `podman kube play` and rendered through:
# PostgreSQL, 2 API nodes and 3 workers on one shared volume; jobs submitted through both API
# nodes all finish exactly once, also when a worker is killed (kill -9) mid-render.
# Run after scripts/container-smoke.sh (it builds the penumbra image; PENUMBRA_IMAGE names
# another). Needs root (podman's bridge network, the pods reached by their IPs).
# Usage: scripts/kube-smoke.sh            (CI runs it from .ci/run)
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
IMAGE="${PENUMBRA_IMAGE:-localhost/penumbra:smoke}"
PG_IMAGE=localhost/penumbra-postgres:smoke
WORK=$(mktemp -d)
step() { echo "== $1 ($(date -u +%H:%M:%S))"; }
ok() { echo "   ok: $1"; }
fail() { echo "FAIL: $1" >&2; exit 1; }

# As scripts/container-smoke.sh: runc and explicit ulimits (the defaults fail on these machines).
cat >"$WORK/containers.conf" <<'CONF'
[containers]
default_ulimits = ["nofile=20000:20000", "nproc=4096:4096"]

[engine]
runtime = "runc"
CONF
export CONTAINERS_CONF="$WORK/containers.conf"

step "tools: podman, runc, catatonit (the pods' pause process), python3-yaml"
missing=()
for p in podman runc catatonit curl; do command -v "$p" >/dev/null 2>&1 || missing+=("$p"); done
[ -x /usr/libexec/podman/catatonit ] || command -v catatonit >/dev/null || missing+=(catatonit)
/usr/bin/python3 -c 'import yaml' >/dev/null 2>&1 || missing+=(python3-yaml)
if [ ${#missing[@]} -gt 0 ]; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
podman image exists "$IMAGE" || fail "no image $IMAGE: run scripts/container-smoke.sh first"

step "PostgreSQL image (docker/postgres.Dockerfile, the official image's contract)"
podman build --pull=never -q -f docker/postgres.Dockerfile -t "$PG_IMAGE" docker/ >/dev/null
ok "$PG_IMAGE"

manifest() {
  /usr/bin/python3 tests/kube/kube_manifest.py "docker/k8s/$1.yaml" \
    --image "docker.io/library/postgres:15=$PG_IMAGE" --image "localhost/penumbra:latest=$IMAGE" \
    >"$WORK/$1.yaml"
}
manifest postgres
manifest penumbra

TOKEN=$(head -c 16 /dev/urandom | od -An -tx1 | tr -d ' \n')
PGPASS=$(head -c 12 /dev/urandom | od -An -tx1 | tr -d ' \n')
b64() { printf %s "$1" | base64 -w0; }
# podman keeps a kube Secret as one JSON object of base64 values (what secretKeyRef reads).
secret() {
  podman secret rm penumbra-secrets >/dev/null 2>&1 || true
  printf '{"token":"%s","postgres-password":"%s","database-url":"%s"}' \
    "$(b64 "$TOKEN")" "$(b64 "$PGPASS")" "$(b64 "$1")" >"$WORK/secret.json"
  podman secret create penumbra-secrets "$WORK/secret.json" >/dev/null
}
cleanup() {
  set +e
  podman kube down "$WORK/penumbra.yaml" >/dev/null 2>&1
  podman kube down "$WORK/postgres.yaml" >/dev/null 2>&1
  podman volume rm -f penumbra-shared penumbra-postgres-data >/dev/null 2>&1
  podman secret rm penumbra-secrets >/dev/null 2>&1
  rm -rf "$WORK"
}
trap cleanup EXIT
cleanup_leftovers() {  # a previous run stopped half-way
  for pod in $(podman pod ps --format '{{.Name}}' | grep '^penumbra-\(api\|worker\|postgres\)-pod-' || true); do
    podman pod rm -f "$pod" >/dev/null
  done
  podman volume rm -f penumbra-shared penumbra-postgres-data >/dev/null 2>&1 || true
}
cleanup_leftovers
pod_ip() {
  local infra
  infra=$(podman pod inspect "$1" --format '{{.InfraContainerID}}')
  podman inspect "$infra" --format '{{range .NetworkSettings.Networks}}{{.IPAddress}}{{end}}'
}

step "podman kube play docker/k8s/postgres.yaml"
secret "postgres://unset"
podman kube play "$WORK/postgres.yaml" >"$WORK/play-postgres.log" 2>&1 || { cat "$WORK/play-postgres.log"; fail "play postgres"; }
for _ in $(seq 60); do
  podman exec penumbra-postgres-pod-0-postgres pg_isready -q -h 127.0.0.1 -U penumbra -d penumbra && break
  sleep 1
done
podman exec penumbra-postgres-pod-0-postgres pg_isready -q -h 127.0.0.1 -U penumbra -d penumbra || fail "PostgreSQL not ready"
PG_IP=$(pod_ip penumbra-postgres-pod-0)
ok "PostgreSQL at $PG_IP"

step "podman kube play docker/k8s/penumbra.yaml (2 API nodes, 3 workers)"
# No cluster DNS under podman: the Service name is replaced by the database pod's IP.
secret "postgres://penumbra:$PGPASS@$PG_IP:5432/penumbra"
podman kube play "$WORK/penumbra.yaml" >"$WORK/play-penumbra.log" 2>&1 || { cat "$WORK/play-penumbra.log"; fail "play penumbra"; }
API=()
for i in 0 1; do API+=("http://$(pod_ip "penumbra-api-pod-$i"):8080"); done
WORKERS=()
for i in 0 1 2; do WORKERS+=("http://$(pod_ip "penumbra-worker-pod-$i"):8080"); done
for url in "${API[@]}" "${WORKERS[@]}"; do
  for _ in $(seq 60); do
    [ "$(curl -s -o /dev/null -w '%{http_code}' "$url/readyz")" = 200 ] && break
    sleep 1
  done
  [ "$(curl -s -o /dev/null -w '%{http_code}' "$url/readyz")" = 200 ] ||
    { podman logs penumbra-api-pod-0-penumbra 2>&1 | tail -20; fail "$url/readyz"; }
done
ok "every pod ready (/readyz, no token)"

step "jobs through both API nodes; a worker killed mid-render"
/usr/bin/python3 tests/kube/farm_check.py --token "$TOKEN" --scene scenes/cornell_box.json \
  --api "${API[0]}" --api "${API[1]}" \
  --kill-worker "podman kill -s KILL penumbra-worker-pod-0-penumbra" ||
  { for p in api-pod-0 api-pod-1 worker-pod-0 worker-pod-1 worker-pod-2; do
      echo "--- $p"; podman logs "penumbra-$p-penumbra" 2>&1 | tail -15; done; fail "farm check"; }
step "done"
