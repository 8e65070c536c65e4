#!/usr/bin/env bash
# Container smoke test (CI): builds docker/Dockerfile with podman, starts the image with a token
# on a loopback port, renders a small Cornell box over HTTP (POST /v1/jobs, poll, fetch PNG and
# EXR), checks auth, the HEALTHCHECK, the non-root user, a graceful stop and that the job survives
# a restart on the data volume; then checks docker/compose.yaml and, unless SMOKE_PROXY=0, the
# nginx proxy of the compose file in front of the service (limits, auth passthrough).
#
# Idempotent and non-interactive; needs root (or sudo) for apt-get and rootful podman. Installs
# podman, runc and debootstrap if missing, and makes the debian:bookworm base image locally with
# debootstrap when podman does not have it (no registry is needed; see docs/container.md).
# Images stay in podman's storage (so a second run reuses layers); containers, volumes, networks
# and temporary files are always removed.
#
# Environment: SMOKE_IMAGE (default localhost/penumbra:smoke), SMOKE_PORT (host port, default:
# any free one), SMOKE_PROXY=0 to skip the proxy part, SMOKE_KEEP=1 to keep containers on failure,
# SMOKE_PRUNE=1 to remove untagged images (old builds, the build stage) at the end: less disk,
# but the next build installs the build dependencies again.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "$(id -u)" -ne 0 ]; then exec sudo --preserve-env=SMOKE_IMAGE,SMOKE_PORT,SMOKE_PROXY,SMOKE_KEEP,SMOKE_PRUNE "$0" "$@"; fi

IMAGE=${SMOKE_IMAGE:-localhost/penumbra:smoke}
PROXY_IMAGE=${IMAGE%:*}-proxy:${IMAGE##*:}
RUN_ID="penumbra-smoke-$$"
NAME="$RUN_ID"
PROXY_NAME="$RUN_ID-proxy"
NETWORK="$RUN_ID-net"
VOLUME="$RUN_ID-data"
T0=$(date +%s)

step() { printf '\n== [%4ss] %s\n' "$(( $(date +%s) - T0 ))" "$*"; }
ok() { printf '   ok: %s\n' "$*"; }
fail() {
  printf '\nFAIL: %s\n' "$*" >&2
  exit 1
}

WORK=$(mktemp -d "${TMPDIR:-/tmp}/penumbra-smoke.XXXXXX")
# podman's own messages go to a log shown on failure: without systemd, every container with a
# HEALTHCHECK logs harmless "unable to get systemd connection" errors (no periodic timer; the
# check itself works, see `podman healthcheck run` below).
pm() { podman "$@" 2>>"$WORK/podman.log"; }
cleanup() {
  local rc=$?
  if [ "$rc" -ne 0 ]; then
    if [ -s "$WORK/podman.log" ]; then
      echo "--- podman messages (without the systemd timer noise)" >&2
      grep -v 'systemd connection' "$WORK/podman.log" | tail -20 >&2 || true
    fi
    for c in "$NAME" "$PROXY_NAME"; do
      if podman container exists "$c" 2>/dev/null; then
        echo "--- last log lines of $c" >&2
        podman logs --tail 40 "$c" >&2 2>&1 || true
      fi
    done
  fi
  if [ "$rc" -ne 0 ] && [ "${SMOKE_KEEP:-0}" = 1 ]; then
    echo "SMOKE_KEEP=1: left $NAME, $PROXY_NAME, $NETWORK, $VOLUME and $WORK" >&2
    exit "$rc"
  fi
  podman rm -f -v -t 5 "$PROXY_NAME" "$NAME" >/dev/null 2>&1 || true
  podman network rm -f "$NETWORK" >/dev/null 2>&1 || true
  podman volume rm -f "$VOLUME" >/dev/null 2>&1 || true
  # Each build leaves its build stage behind as an untagged image (it is also the layer cache).
  if [ "${SMOKE_PRUNE:-0}" = 1 ]; then podman image prune -f >/dev/null 2>&1 || true; fi
  rm -rf "$WORK"
  if [ "$rc" -eq 0 ]; then
    printf '\n== [%4ss] container smoke test passed\n' "$(( $(date +%s) - T0 ))"
  else
    printf '\n== container smoke test FAILED (exit %s)\n' "$rc" >&2
  fi
  exit "$rc"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

# ------------------------------------------------------------------------------------------------
step "tools: podman, runc, debootstrap, curl, python3"
missing=()
for p in podman runc debootstrap curl python3; do
  command -v "$p" >/dev/null 2>&1 || missing+=("$p")
done
# The compose check reads YAML with Debian's python3 (python3-yaml is small).
if ! /usr/bin/python3 -c 'import yaml' >/dev/null 2>&1; then missing+=(python3-yaml); fi
if [ ${#missing[@]} -gt 0 ]; then
  echo "   installing ${missing[*]}"
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
podman --version

# The default runtime (crun) and the default ulimits fail on these machines: runc, explicit limits.
cat >"$WORK/containers.conf" <<'EOF'
[containers]
default_ulimits = ["nofile=20000:20000", "nproc=4096:4096"]

[engine]
runtime = "runc"
EOF
export CONTAINERS_CONF="$WORK/containers.conf"

# ------------------------------------------------------------------------------------------------
step "base image debian:bookworm"
if podman image exists debian:bookworm; then
  ok "present in podman's storage"
else
  echo "   not in podman's storage: debootstrap --variant=minbase bookworm (about a minute)"
  t=$(date +%s)
  ROOTFS="$WORK/rootfs"
  debootstrap --variant=minbase bookworm "$ROOTFS" http://deb.debian.org/debian >"$WORK/debootstrap.log" 2>&1 ||
    { tail -20 "$WORK/debootstrap.log" >&2; fail "debootstrap"; }
  # The same apt sources as Docker Hub's debian:bookworm (with updates and security fixes).
  rm -f "$ROOTFS/etc/apt/sources.list"
  cat >"$ROOTFS/etc/apt/sources.list.d/debian.sources" <<'EOF'
Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg

Types: deb
URIs: http://deb.debian.org/debian-security
Suites: bookworm-security
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
EOF
  rm -rf "$ROOTFS"/var/cache/apt/archives/*.deb "$ROOTFS"/var/lib/apt/lists/* "$ROOTFS"/tmp/*
  tar -C "$ROOTFS" -c . | podman import \
    --change 'ENV=PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin' \
    --change 'CMD=["bash"]' - debian:bookworm >/dev/null 2>>"$WORK/podman.log"
  rm -rf "$ROOTFS"
  podman image exists debian:bookworm || fail "podman import did not create debian:bookworm"
  ok "debian:bookworm imported in $(( $(date +%s) - t )) s"
fi

# ------------------------------------------------------------------------------------------------
step "build $IMAGE from docker/Dockerfile (--pull=never)"
# Open Image Denoise staged on the host (the build's containers may not reach PyPI through this
# machine's proxy): the Dockerfile takes vendor/oidn/ when it is there.
./scripts/install-oidn.sh "$PWD/vendor/oidn" >/dev/null || fail "install-oidn.sh vendor/oidn"
t=$(date +%s)
nice -n 10 podman build --pull=never --format docker -f docker/Dockerfile -t "$IMAGE" . \
  >"$WORK/build.log" 2>&1 || { tail -40 "$WORK/build.log" >&2; fail "image build"; }
ok "built in $(( $(date +%s) - t )) s, $(podman image inspect --format '{{.Size}}' "$IMAGE" | awk '{printf "%.0f MB", $1/1e6}')"
pm run --rm "$IMAGE" --version
# An environment map is read through the OpenImageIO plug-in (lib/penumbra/libpenumbra_oiio.so),
# loaded only then: the image must ship it where the binary looks.
pm run --rm --entrypoint sh "$IMAGE" -c 'cd /tmp && penumbra render \
    /usr/share/penumbra/scenes/sun_and_sky.json -o sky.png --width 32 --height 24 --spp 2 -q' ||
  fail "rendering a scene with an environment map in the image (the OpenImageIO plug-in)"
ok "a scene with an environment map renders in the image (OpenImageIO plug-in loaded)"
pm run --rm --entrypoint sh "$IMAGE" -c 'cd /tmp && penumbra render \
    /usr/share/penumbra/scenes/cornell_box.json -o cb.png --width 32 --height 32 --spp 4 \
    --denoise -q 2>&1' >"$WORK/denoise.log" || { cat "$WORK/denoise.log" >&2; fail "--denoise in the image"; }
grep -q "denoised in" "$WORK/denoise.log" ||
  { cat "$WORK/denoise.log" >&2; fail "the image did not denoise (Open Image Denoise missing?)"; }
ok "--denoise works in the image (Open Image Denoise shipped with its licence)"
podman image inspect --format '{{json .Config.Healthcheck}}' "$IMAGE" | grep -q healthz ||
  fail "the image has no HEALTHCHECK on /healthz (was it built with --format docker?)"
ok "HEALTHCHECK on /healthz in the image config"

# ------------------------------------------------------------------------------------------------
step "start the container (token from the environment, loopback port)"
TOKEN=$(head -c 24 /dev/urandom | od -An -tx1 | tr -d ' \n')
# Without a token the image must refuse to listen on 0.0.0.0.
if podman run --rm "$IMAGE" >"$WORK/notoken.log" 2>&1; then fail "the service started on 0.0.0.0 without a token"; fi
grep -q "refusing to listen" "$WORK/notoken.log" || { cat "$WORK/notoken.log" >&2; fail "no token: unexpected output"; }
ok "without a token: refuses to listen on 0.0.0.0"
podman volume create "$VOLUME" >/dev/null
pm run -d --name "$NAME" -e PENUMBRA_TOKEN="$TOKEN" -v "$VOLUME:/var/lib/penumbra" \
  -p "127.0.0.1:${SMOKE_PORT:-}:8080" "$IMAGE" >/dev/null
PORT=$(podman port "$NAME" 8080 | head -1 | sed 's/.*://')
[ -n "$PORT" ] || fail "no published port"
BASE="http://127.0.0.1:$PORT"
ok "$NAME on $BASE"

wait_healthy() {
  local deadline=$(( $(date +%s) + 60 ))
  until curl -fsS -o /dev/null --max-time 2 "$BASE/healthz" 2>/dev/null; do
    [ "$(podman inspect --format '{{.State.Running}}' "$NAME")" = true ] || fail "the container exited"
    [ "$(date +%s)" -lt "$deadline" ] || fail "/healthz did not answer within 60 s"
    sleep 0.5
  done
}
wait_healthy
ok "/healthz answers 200 (no token needed)"
[ "$(podman exec "$NAME" id -u)" != 0 ] || fail "the service runs as root"
ok "runs as $(podman exec "$NAME" id -un) (uid $(podman exec "$NAME" id -u))"
podman healthcheck run "$NAME" >/dev/null 2>&1 || fail "podman healthcheck run: unhealthy"
ok "the image's HEALTHCHECK command passes"

# ------------------------------------------------------------------------------------------------
step "auth"
code() { curl -sS -o /dev/null -w '%{http_code}' --max-time 10 "$@"; }
c=$(code "$BASE/v1/jobs"); [ "$c" = 401 ] || fail "GET /v1/jobs without a token: $c, expected 401"
c=$(code -H "Authorization: Bearer wrong-$TOKEN" "$BASE/v1/jobs"); [ "$c" = 401 ] || fail "wrong token: $c, expected 401"
c=$(code -H 'Content-Type: application/json' --data-binary @scenes/cornell_box.json "$BASE/v1/jobs")
[ "$c" = 401 ] || fail "POST /v1/jobs without a token: $c, expected 401"
c=$(code -H "Authorization: Bearer $TOKEN" "$BASE/v1/jobs"); [ "$c" = 200 ] || fail "GET /v1/jobs with the token: $c"
ok "no token / wrong token -> 401, right token -> 200"

# ------------------------------------------------------------------------------------------------
step "render scenes/cornell_box.json (64x48, 8 spp) through POST /v1/jobs"
W=64 H=48
python3 - scenes/cornell_box.json "$W" "$H" >"$WORK/scene.json" <<'EOF' || fail "cannot make the scene"
import json, sys
scene = json.load(open(sys.argv[1]))
scene["render"].update(width=int(sys.argv[2]), height=int(sys.argv[3]), spp=8)
json.dump(scene, sys.stdout)
EOF
auth=(-H "Authorization: Bearer $TOKEN")
c=$(curl -sS -D "$WORK/post.headers" -o "$WORK/post.json" -w '%{http_code}' --max-time 30 "${auth[@]}" \
  -H 'Content-Type: application/json' --data-binary @"$WORK/scene.json" "$BASE/v1/jobs")
[ "$c" = 202 ] || { cat "$WORK/post.json" >&2; fail "POST /v1/jobs: $c, expected 202"; }
JOB=$(tr -d '\r' <"$WORK/post.headers" | sed -n 's/^[Ll]ocation: *//p' | head -1)
case "$JOB" in /v1/jobs/?*) ;; *) fail "202 without a Location: /v1/jobs/{id} header" ;; esac
ok "202 Accepted, Location: $JOB"

state=""
deadline=$(( $(date +%s) + 180 ))
while :; do
  curl -fsS --max-time 10 "${auth[@]}" "$BASE$JOB" >"$WORK/job.json" || fail "GET $JOB"
  state=$(python3 -c 'import json,sys; print(json.load(sys.stdin)["state"])' <"$WORK/job.json")
  case "$state" in
    succeeded) break ;;
    queued | running) ;;
    *) cat "$WORK/job.json" >&2; fail "job ended $state" ;;
  esac
  [ "$(date +%s)" -lt "$deadline" ] || fail "job still $state after 180 s"
  sleep 0.5
done
ok "state succeeded"

check_png() {  # file width height
  python3 - "$@" <<'EOF'
import struct, sys
data = open(sys.argv[1], "rb").read()
if data[:8] != b"\x89PNG\r\n\x1a\n" or data[12:16] != b"IHDR":
    sys.exit(f"not a PNG ({len(data)} bytes)")
w, h = struct.unpack(">II", data[16:24])
if (w, h) != (int(sys.argv[2]), int(sys.argv[3])):
    sys.exit(f"PNG is {w}x{h}, expected {sys.argv[2]}x{sys.argv[3]}")
print(f"   ok: PNG {w}x{h}, {len(data)} bytes")
EOF
}
c=$(curl -sS -D "$WORK/png.headers" -o "$WORK/result.png" -w '%{http_code}' --max-time 30 "${auth[@]}" \
  "$BASE$JOB/result?format=png")
[ "$c" = 200 ] || fail "GET $JOB/result?format=png: $c"
grep -qi '^content-type: image/png' "$WORK/png.headers" || fail "result is not served as image/png"
check_png "$WORK/result.png" "$W" "$H" || fail "the PNG result"
c=$(curl -sS -o "$WORK/result.exr" -w '%{http_code}' --max-time 30 "${auth[@]}" "$BASE$JOB/result?format=exr")
[ "$c" = 200 ] || fail "GET $JOB/result?format=exr: $c"
[ "$(head -c 4 "$WORK/result.exr" | od -An -tx1 | tr -d ' ')" = 762f3101 ] || fail "the EXR result has no OpenEXR magic"
ok "EXR $(wc -c <"$WORK/result.exr") bytes"

# ------------------------------------------------------------------------------------------------
step "graceful stop (SIGTERM) and restart on the same data volume"
t=$(date +%s)
pm stop -t 30 "$NAME" >/dev/null
exit_code=$(podman inspect --format '{{.State.ExitCode}}' "$NAME")
[ "$exit_code" = 0 ] || fail "the service exited with $exit_code after SIGTERM"
ok "stopped in $(( $(date +%s) - t )) s, exit code 0"
pm start "$NAME" >/dev/null
PORT=$(podman port "$NAME" 8080 | head -1 | sed 's/.*://')
BASE="http://127.0.0.1:$PORT"
wait_healthy
state=$(curl -fsS --max-time 10 "${auth[@]}" "$BASE$JOB" | python3 -c 'import json,sys; print(json.load(sys.stdin)["state"])')
[ "$state" = succeeded ] || fail "after the restart the job is $state"
curl -fsS --max-time 30 "${auth[@]}" -o "$WORK/again.png" "$BASE$JOB/result?format=png" || fail "result after restart"
cmp -s "$WORK/result.png" "$WORK/again.png" || fail "the result changed across the restart"
ok "after the restart the job and its PNG are still served"

# ------------------------------------------------------------------------------------------------
step "docker/compose.yaml"
/usr/bin/python3 - docker/compose.yaml <<'EOF' || fail "docker/compose.yaml"
import sys, yaml
doc = yaml.safe_load(open(sys.argv[1]))
services = doc["services"]
assert set(services) == {"penumbra", "proxy"}, f"services: {sorted(services)}"
published = [name for name, s in services.items() if s.get("ports")]
assert published == ["proxy"], f"services publishing ports: {published} (only the proxy should)"
svc = services["penumbra"]
assert "PENUMBRA_TOKEN" in svc["environment"], "the service gets no PENUMBRA_TOKEN"
assert any(str(v).endswith(":/var/lib/penumbra") for v in svc["volumes"]), "no data volume"
for v in svc["volumes"]:
    name = str(v).split(":")[0]
    assert name in (doc.get("volumes") or {}), f"volume {name} is not a named volume"
print("   ok: YAML parses; only the proxy publishes a port; token from the environment; named data volume")
EOF
# (Debian 12's podman-compose 1.0.3 has no `config` command, and its --dry-run still creates
# the volume and network, so the YAML check above is all that runs here.)

# ------------------------------------------------------------------------------------------------
if [ "${SMOKE_PROXY:-1}" != 0 ]; then
  step "nginx proxy (docker/proxy.Dockerfile, docker/nginx.conf) in front of the service"
  t=$(date +%s)
  nice -n 10 podman build --pull=never --format docker -f docker/proxy.Dockerfile -t "$PROXY_IMAGE" docker \
    >"$WORK/proxy-build.log" 2>&1 || { tail -30 "$WORK/proxy-build.log" >&2; fail "proxy image build"; }
  ok "proxy image built in $(( $(date +%s) - t )) s"
  # The compose topology by hand: one network, the service known as 'penumbra', only the proxy
  # publishes a port; the service keeps its data volume.
  pm rm -f -t 10 "$NAME" >/dev/null
  pm network create "$NETWORK" >/dev/null
  pm run -d --name "$NAME" --network "$NETWORK" -e PENUMBRA_TOKEN="$TOKEN" \
    -v "$VOLUME:/var/lib/penumbra" --read-only --tmpfs /tmp --cap-drop ALL \
    --security-opt no-new-privileges "$IMAGE" >/dev/null
  deadline=$(( $(date +%s) + 60 ))
  until podman healthcheck run "$NAME" >/dev/null 2>&1; do
    [ "$(date +%s)" -lt "$deadline" ] || fail "the service did not become healthy behind the proxy"
    sleep 0.5
  done
  # Compose networks resolve service names; podman's default CNI network here has no DNS plugin,
  # so the proxy is told the service's address directly.
  SERVICE_IP=$(podman inspect --format '{{range .NetworkSettings.Networks}}{{.IPAddress}}{{end}}' "$NAME")
  [ -n "$SERVICE_IP" ] || fail "no address for $NAME on $NETWORK"
  pm run -d --name "$PROXY_NAME" --network "$NETWORK" --add-host "penumbra:$SERVICE_IP" -p "127.0.0.1::8080" --read-only --tmpfs /tmp \
    --cap-drop ALL --security-opt no-new-privileges "$PROXY_IMAGE" >/dev/null
  PPORT=$(podman port "$PROXY_NAME" 8080 | head -1 | sed 's/.*://')
  PBASE="http://127.0.0.1:$PPORT"
  deadline=$(( $(date +%s) + 30 ))
  until curl -fsS -o /dev/null --max-time 2 "$PBASE/healthz" 2>/dev/null; do
    [ "$(podman inspect --format '{{.State.Running}}' "$PROXY_NAME")" = true ] || fail "the proxy exited"
    [ "$(date +%s)" -lt "$deadline" ] || fail "the proxy did not answer /healthz within 30 s"
    sleep 0.5
  done
  ok "proxy on $PBASE"
  c=$(code "$PBASE$JOB"); [ "$c" = 401 ] || fail "via proxy without a token: $c, expected 401"
  c=$(code "${auth[@]}" "$PBASE$JOB"); [ "$c" = 200 ] || fail "via proxy with the token: $c (Authorization not passed?)"
  ok "Authorization passes through: 401 without, 200 with the token; the job survived the new container"
  c=$(curl -sS -o "$WORK/proxy.png" -w '%{http_code}' --max-time 30 "${auth[@]}" "$PBASE$JOB/result?format=png")
  [ "$c" = 200 ] && cmp -s "$WORK/result.png" "$WORK/proxy.png" || fail "PNG via the proxy: $c"
  ok "PNG via the proxy is byte-identical"
  # A new render through the proxy, with the service's root file system read-only and no
  # capabilities (as in compose.yaml): it may write only to its data volume and /tmp.
  c=$(curl -sS -D "$WORK/post2.headers" -o /dev/null -w '%{http_code}' --max-time 30 "${auth[@]}" \
    -H 'Content-Type: application/json' --data-binary @"$WORK/scene.json" "$PBASE/v1/jobs")
  [ "$c" = 202 ] || fail "POST /v1/jobs via the proxy: $c"
  JOB2=$(tr -d '\r' <"$WORK/post2.headers" | sed -n 's/^[Ll]ocation: *//p' | head -1)
  deadline=$(( $(date +%s) + 180 ))
  until [ "$(curl -fsS --max-time 10 "${auth[@]}" "$PBASE$JOB2" |
             python3 -c 'import json,sys; print(json.load(sys.stdin)["state"])')" = succeeded ]; do
    [ "$(date +%s)" -lt "$deadline" ] || fail "job $JOB2 via the proxy did not succeed in 180 s"
    sleep 1
  done
  curl -fsS --max-time 30 "${auth[@]}" -o "$WORK/proxy2.png" "$PBASE$JOB2/result?format=png" ||
    fail "PNG of $JOB2 via the proxy"
  check_png "$WORK/proxy2.png" "$W" "$H" || fail "the PNG of $JOB2"
  ok "a new job rendered through the proxy on a read-only root file system"
  head -c $(( 16 * 1024 * 1024 + 1 )) /dev/zero >"$WORK/big.json"
  c=$(code "${auth[@]}" -H 'Content-Type: application/json' --data-binary @"$WORK/big.json" "$PBASE/v1/jobs")
  [ "$c" = 413 ] || fail "16 MiB + 1 body via the proxy: $c, expected 413"
  ok "body of 16 MiB + 1 byte -> 413 at the proxy"
  c=$(code "${auth[@]}" -H "X-Padding: $(head -c 9000 /dev/zero | tr '\0' a)" "$PBASE/healthz")
  [ "$c" = 431 ] || [ "$c" = 400 ] || fail "a 9000-byte header via the proxy: $c, expected 431"
  ok "a 9 KB header line -> $c at the proxy"
  # Slow client: a request whose header never ends is dropped after client_header_timeout (10 s).
  t=$(date +%s)
  python3 - "$PPORT" <<'EOF' || fail "slow header"
import socket, sys, time
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])))
s.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
s.settimeout(30)
start = time.time()
try:
    s.recv(4096)  # nginx resets the connection once client_header_timeout passes
except ConnectionResetError:
    pass
took = time.time() - start
if took > 20:
    sys.exit(f"slow header held the connection {took:.0f} s")
print(f"   ok: an unfinished header is dropped after {took:.0f} s")
EOF
  # Rate limit: 100 status polls on one keep-alive connection (well under a second) exceed
  # 20/s with a burst of 40.
  args=(); for _ in $(seq 100); do args+=(-o /dev/null "$PBASE$JOB"); done
  curl -sS "${auth[@]}" -w '%{http_code} %header{retry-after} %{content_type}\n' "${args[@]}" >"$WORK/polls.txt"
  codes=$(cut -d' ' -f1 "$WORK/polls.txt" | sort | uniq -c | tr -s ' \n' ' ')
  grep -q '^429 ' "$WORK/polls.txt" || fail "100 rapid polls were never limited: $codes"
  grep '^429 ' "$WORK/polls.txt" | grep -qv '^429 1 application/problem+json' &&
    fail "a rate-limited answer without Retry-After: 1 or problem+json: $(grep '^429 ' "$WORK/polls.txt" | sort -u)"
  ok "100 rapid polls: $codes(429 = rate limited, with Retry-After and problem+json)"
  # The slow-client attack of tests/hostile/slow_clients_test.cpp through the proxy: 264
  # connections from this host trickle heads and bodies or read nothing, while another client
  # (the service's container, another address on the network) probes /healthz and a job's status
  # through the proxy: each must answer 200 within 100 ms. The attacker's own address is held to
  # limit_conn (32 connections) and its unfinished heads are cut by client_header_timeout (10 s).
  PROXY_IP=$(podman inspect --format '{{range .NetworkSettings.Networks}}{{.IPAddress}}{{end}}' "$PROXY_NAME")
  rm -f "$WORK/attack.ready"
  python3 tests/hostile/proxy_slow_clients.py "$PPORT" "$TOKEN" "$JOB" "$WORK/attack.ready" 13 \
    >"$WORK/attack.out" 2>&1 &
  attacker=$!
  deadline=$(( $(date +%s) + 30 ))
  until [ -s "$WORK/attack.ready" ]; do
    kill -0 "$attacker" 2>/dev/null || { cat "$WORK/attack.out" >&2; fail "the attack script exited"; }
    [ "$(date +%s)" -lt "$deadline" ] || fail "the attack script did not open its connections"
    sleep 0.2
  done
  sleep 1
  pm exec "$NAME" sh -c "for i in \$(seq 15); do
      curl -s -o /dev/null -w 'healthz %{http_code} %{time_total}\n' --max-time 5 http://$PROXY_IP:8080/healthz
      curl -s -o /dev/null -w 'status %{http_code} %{time_total}\n' --max-time 5 \
        -H 'Authorization: Bearer $TOKEN' http://$PROXY_IP:8080$JOB
      sleep 0.2
    done" >"$WORK/probes.txt" || fail "probing through the proxy from the service's container"
  wait "$attacker" || { cat "$WORK/attack.out" >&2; fail "the attack script failed"; }
  python3 - "$WORK/probes.txt" "$WORK/attack.out" <<'EOF' || fail "slow clients through the proxy"
import json, sys
probes = [line.split() for line in open(sys.argv[1]) if line.strip()]
outcome = json.loads(open(sys.argv[2]).read().strip().splitlines()[-1])
bad = [p for p in probes if p[1] != "200" or float(p[2]) >= 0.100]
times = sorted(float(p[2]) * 1000 for p in probes)
print(f"   probes: {len(probes)}, median {times[len(times) // 2]:.1f} ms, max {times[-1]:.1f} ms; "
      f"attacker's connections at the end: {outcome}")
if len(probes) != 30 or bad:
    sys.exit(f"probes not answered 200 within 100 ms: {bad or len(probes)}")
if outcome["heads"].get("closed", 0) != 100:
    sys.exit("unfinished heads were not all cut after client_header_timeout")
if outcome["bodies"].get("open", 0) > 32:
    sys.exit("more than limit_conn (32) trickling bodies held open for one address")
EOF
  ok "264 slow connections from one address: probes from another answer 200 within 100 ms"
  pm stop -t 30 "$NAME" >/dev/null
  c=$(curl -sS -D "$WORK/down.headers" -o /dev/null -w '%{http_code}' --max-time 10 "$PBASE/healthz")
  [ "$c" = 503 ] && grep -qi '^retry-after: 5' "$WORK/down.headers" ||
    fail "with the service stopped the proxy answered $c, expected 503 with Retry-After"
  ok "service stopped -> 503 with Retry-After from the proxy"
fi
