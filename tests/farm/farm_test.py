#!/usr/bin/env python3
"""The render farm against a real PostgreSQL (docs/scale-out.md): API nodes and worker processes
of `penumbra serve --store postgres://...` on one shared data folder.

    tests/farm/farm_test.py PENUMBRA_BINARY [TEST ...]

Tests: exactly_once (2 API nodes, 3 workers, 100 jobs), worker_kill (kill -9 mid-task: the task
runs again after its lease expires; the recovery time is printed), api_kill (kill -9 of an API
node mid-request: retried with the same Idempotency-Key on the other, one job per key),
postgres_restart (PostgreSQL restarted under load: nothing accepted is lost), cancel_running
(a cancel reaches the worker at its heartbeat), max_attempts (a task that keeps failing fails
its job with the reason), and jobs of several tasks: split_frame (a 1024x1024 frame in 16 tiles
over 3 workers equals `penumbra render` bit for bit), split_frame_worker_kill (the same with a
worker killed mid-tile), split_progress_and_preview, split_cancel, split_denoise,
split_retention, animation_frames (24 frames over 3 workers equal `penumbra render --frame i`). Exit 77 (ctest: skipped) without a PostgreSQL server, except with
CI=true, where that is a failure.
"""
import http.client
import json
import os
import random
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.error
import urllib.request

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PG_SCRIPT = os.path.join(REPO, "scripts", "farm-postgres.sh")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def scene(width=16, height=16, spp=2, seed=None):
    with open(os.path.join(REPO, "scenes", "cornell_box.json")) as f:
        s = json.load(f)
    s["render"]["width"] = width
    s["render"]["height"] = height
    s["render"]["spp"] = spp
    if seed is not None:
        s["render"]["seed"] = seed
    return s


def request(base, method, path, body=None, headers=None, timeout=30):
    data = json.dumps(body).encode() if body is not None else None
    req = urllib.request.Request(base + path, data=data, method=method)
    req.add_header("Content-Type", "application/json")
    for k, v in (headers or {}).items():
        req.add_header(k, v)
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            raw = r.read()
            return r.status, raw, dict(r.headers)
    except urllib.error.HTTPError as e:
        return e.code, e.read(), dict(e.headers)


def get_json(base, path):
    status, raw, _ = request(base, "GET", path)
    return status, (json.loads(raw) if raw and raw[:1] in (b"{", b"[") else None)


class Farm:
    def __init__(self, binary, lease=3.0, heartbeat=0.5, max_attempts=3):
        self.binary = binary
        self.work = tempfile.mkdtemp(prefix="penumbra-farm-")
        os.chmod(self.work, 0o755)
        self.pg_dir = os.path.join(self.work, "pg")
        self.data = os.path.join(self.work, "data")
        os.makedirs(self.data)
        self.url = subprocess.check_output(
            [PG_SCRIPT, "start", self.pg_dir, str(free_port())], text=True).strip()
        self.lease, self.heartbeat, self.max_attempts = lease, heartbeat, max_attempts
        self.procs = []

    def psql(self, sql):
        out = subprocess.check_output(["psql", self.url, "-At", "-F", "|", "-c", sql], text=True)
        return [line.split("|") for line in out.splitlines() if line]

    def start(self, role, extra=()):
        log = open(os.path.join(self.work, "node-%d-%s.log" % (len(self.procs), role)), "w+")
        p = subprocess.Popen(
            [self.binary, "serve", "--store", self.url, "--role", role, "--port", "0",
             "--data-dir", self.data, "--render-threads", "1", "--workers", "1",
             "--lease-seconds", str(self.lease), "--heartbeat", str(self.heartbeat),
             "--max-attempts", str(self.max_attempts), "--max-queue", "1000", "--drain", "0",
             *extra],
            stdout=subprocess.PIPE, stderr=log, text=True)
        deadline = time.time() + 30
        base = None
        while time.time() < deadline:
            line = p.stdout.readline()
            if not line:
                break
            m = re.match(r"listening on (http://\S+)", line)
            if m:
                base = m.group(1)
                break
        if base is None:
            raise RuntimeError("node did not start; log: " + log.name)
        threading.Thread(target=lambda: p.stdout.read(), daemon=True).start()
        node = {"proc": p, "base": base, "role": role, "log": log.name}
        self.procs.append(node)
        return node

    def close(self):
        for n in self.procs:
            if n["proc"].poll() is None:
                n["proc"].send_signal(signal.SIGTERM)
        for n in self.procs:
            try:
                n["proc"].wait(timeout=30)
            except subprocess.TimeoutExpired:
                n["proc"].kill()
        subprocess.call([PG_SCRIPT, "stop", self.pg_dir, "immediate"])
        if os.environ.get("PENUMBRA_KEEP_FARM"):
            print("kept", self.work)
        else:
            shutil.rmtree(self.work, ignore_errors=True)


def submit(base, body, key=None, retries=0):
    headers = {"Idempotency-Key": key} if key else {}
    for attempt in range(retries + 1):
        try:
            status, raw, _ = request(base, "POST", "/v1/jobs", body, headers)
        except (urllib.error.URLError, ConnectionError, socket.timeout,
                http.client.HTTPException):
            # No answer, or one cut short (IncompleteRead: the node died while it answered).
            status, raw = 0, b""
        if status == 202:
            return json.loads(raw)["id"]
        if attempt < retries:
            time.sleep(0.5)
    raise AssertionError("submit failed: %s %s" % (status, raw[:300]))


def wait_states(base, ids, timeout):
    deadline = time.time() + timeout
    states = {}
    pending = set(ids)
    while pending and time.time() < deadline:
        for i in list(pending):
            try:
                status, j = get_json(base, "/v1/jobs/" + i)
            except (urllib.error.URLError, ConnectionError, socket.timeout):
                continue
            if status == 200 and j["state"] in ("succeeded", "failed", "cancelled"):
                states[i] = j["state"]
                pending.discard(i)
        time.sleep(0.2)
    for i in pending:
        states[i] = "timeout"
    return states


def check(cond, what):
    if not cond:
        raise AssertionError(what)


def renders_per_job(farm, outcome="succeeded"):
    """Attempts per job from the attempt log (every attempt is a render), of one outcome or all."""
    where = "WHERE outcome = '%s'" % outcome if outcome else ""
    return {job: int(n) for job, n in farm.psql(
        "SELECT job_id, count(*) FROM task_attempts %s GROUP BY job_id" % where)}


def result_files(farm):
    return sorted(os.listdir(os.path.join(farm.data, "results")))


def test_exactly_once(farm):
    apis = [farm.start("api"), farm.start("api")]
    for _ in range(3):
        farm.start("worker")
    ids = []
    lock = threading.Lock()

    def client(k):
        for n in range(25):
            i = submit(apis[(k + n) % 2]["base"], scene(seed=k * 100 + n))
            with lock:
                ids.append(i)

    threads = [threading.Thread(target=client, args=(k,)) for k in range(4)]
    t0 = time.time()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    check(len(ids) == 100 and len(set(ids)) == 100, "100 distinct jobs accepted")
    states = wait_states(apis[1]["base"], ids, 240)
    elapsed = time.time() - t0
    bad = {i: s for i, s in states.items() if s != "succeeded"}
    check(not bad, "every job succeeded: %s" % list(bad.items())[:5])
    # Nothing failed here, so every attempt of every job must be its one successful render.
    renders = renders_per_job(farm, outcome=None)
    check(all(renders.get(i) == 1 for i in ids),
          "each job rendered exactly once: %s" % [(i, renders.get(i)) for i in ids
                                                  if renders.get(i) != 1][:5])
    # One committed result per job, nothing else: no duplicate or orphaned result files.
    files = result_files(farm)
    per_job = {}
    for f in files:
        per_job.setdefault(f.split(".")[0], set()).add(f.split(".")[1])
    check(set(per_job) == set(ids) and all(len(t) == 1 for t in per_job.values()),
          "one result set per job (%d files)" % len(files))
    # Any API node serves any job's result.
    for i in ids[:10]:
        for api in apis:
            status, raw, headers = request(api["base"], "GET", "/v1/jobs/%s/result" % i)
            check(status == 200 and raw[:4] == b"\x89PNG", "result of %s from %s" % (i, api["base"]))
    # Listing pages through every job on either node, newest first.
    listed, token = [], None
    while True:
        path = "/v1/jobs?limit=30" + ("&page_token=" + token if token else "")
        status, page = get_json(apis[len(listed) // 30 % 2]["base"], path)
        check(status == 200, "list answered %d" % status)
        listed += [j["id"] for j in page["jobs"]]
        token = page.get("next_page_token")
        if not token:
            break
    check(sorted(listed) == sorted(ids) and len(listed) == 100, "listed %d jobs" % len(listed))
    status, page = get_json(apis[0]["base"], "/v1/jobs?state=succeeded&limit=5")
    check(status == 200 and len(page["jobs"]) == 5, "filtered by state")
    status, page = get_json(apis[0]["base"], "/v1/jobs?state=queued")
    check(status == 200 and page["jobs"] == [], "nothing queued")
    workers = [w for w in get_json(apis[0]["base"], "/v1/workers")[1]["workers"]]
    done = sorted(w["tasks_succeeded"] for w in workers)
    check(len(workers) == 3 and sum(done) == 100, "3 workers did the 100 tasks: %s" % done)
    status, raw, _ = request(apis[0]["base"], "GET", "/metrics")
    check(b"penumbra_farm_worker_tasks_total" in raw and b"penumbra_farm_retries_total 0" in raw,
          "farm metrics")
    print("exactly_once: 100 jobs, 2 API nodes, 3 workers: %.1f s; tasks per worker %s"
          % (elapsed, done))


def running_owner(farm, job):
    rows = farm.psql("SELECT lease_owner FROM tasks WHERE job_id = '%s' AND state = 'running'" % job)
    return rows[0][0] if rows else None


def test_worker_kill(farm):
    api = farm.start("api")
    workers = [farm.start("worker"), farm.start("worker")]
    job = submit(api["base"], scene(64, 64, 1024))
    deadline = time.time() + 30
    owner = None
    while time.time() < deadline and not owner:
        owner = running_owner(farm, job)
        time.sleep(0.05)
    check(owner, "the job started")
    time.sleep(0.5)
    pid = int(owner.split("-")[-2])
    victim = [w for w in workers if w["proc"].pid == pid]
    check(victim, "the owner is one of our workers")
    victim[0]["proc"].send_signal(signal.SIGKILL)
    killed_at = time.time()
    rerun_at = None
    while time.time() < killed_at + 60:
        o = running_owner(farm, job)
        if o and o != owner:
            rerun_at = time.time()
            break
        time.sleep(0.05)
    check(rerun_at, "the task ran again on another worker")
    print("worker_kill: re-claimed %.2f s after kill -9" % (rerun_at - killed_at))
    states = wait_states(api["base"], [job], 240)
    check(states[job] == "succeeded", "the job finished: %s" % states[job])
    outcomes = sorted(r[0] for r in farm.psql(
        "SELECT outcome FROM task_attempts WHERE job_id = '%s'" % job))
    check(outcomes == ["lease_expired", "succeeded"], "attempts: %s" % outcomes)
    recovery = rerun_at - killed_at
    # The lease runs out at most one lease after the last heartbeat; an idle worker reaps it
    # within its fallback poll (2 s).
    check(recovery <= farm.lease + 2.0 + 1.5, "recovery %.2f s" % recovery)
    print("worker_kill: lease %.1f s, heartbeat %.1f s: the task ran again %.2f s after kill -9"
          % (farm.lease, farm.heartbeat, recovery))


def test_api_kill(farm):
    a, b = farm.start("api"), farm.start("api")
    farm.start("worker")
    keys = ["key-%d" % n for n in range(120)]
    ids = {}
    lock = threading.Lock()
    retried = []
    # A request surely under way at the kill: its head and half its body sent, the rest never.
    half = socket.create_connection(("127.0.0.1", int(a["base"].rsplit(":", 1)[1])))
    body = json.dumps(scene(seed=999)).encode()
    half.sendall(b"POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n"
                 b"Idempotency-Key: key-half\r\nContent-Length: %d\r\n\r\n" % len(body)
                 + body[:len(body) // 2])

    def client(k):
        for n in range(k, len(keys), 4):
            key = keys[n]
            try:
                i = submit(a["base"], scene(seed=n), key)
            except (AssertionError, urllib.error.URLError, ConnectionError, socket.timeout):
                # The node died mid-request: the client retries elsewhere with the same key.
                i = submit(b["base"], scene(seed=n), key, retries=5)
                with lock:
                    retried.append(key)
            with lock:
                ids[key] = i

    threads = [threading.Thread(target=client, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    # Killed once the clients are under way (some requests surely in flight besides the half one).
    while True:
        with lock:
            if len(ids) >= 10:
                break
        time.sleep(0.005)
    a["proc"].send_signal(signal.SIGKILL)
    for t in threads:
        t.join()
    half.close()
    check(a["proc"].wait(5) == -signal.SIGKILL, "the first API node was killed")
    check(len(ids) == len(keys) and len(set(ids.values())) == len(keys), "one job per key")
    # The half-sent request was never accepted: no job has its key.
    check(farm.psql("SELECT count(*) FROM jobs WHERE idempotency_key = 'key-half'") == [["0"]],
          "the unfinished request made no job")
    # A client that cannot tell which requests got through sends them all again, to the node
    # still up: every one is a replay of the job its key made.
    for n, key in enumerate(keys):
        status, raw, headers = request(b["base"], "POST", "/v1/jobs", scene(seed=n),
                                       {"Idempotency-Key": key})
        check(status == 202 and json.loads(raw)["id"] == ids[key]
              and headers.get("Idempotent-Replayed") == "true", "replay of %s" % key)
    count = int(farm.psql("SELECT count(*) FROM jobs")[0][0])
    check(count == len(keys), "no duplicate job in the store: %d" % count)
    states = wait_states(b["base"], list(ids.values()), 120)
    check(all(s == "succeeded" for s in states.values()), "all finished: %s" % states)
    check(retried, "some submissions were cut by the kill and retried")
    print("api_kill: %d jobs from 4 clients, %d retried on the other node after the kill, "
          "one job per key, all finished" % (len(keys), len(retried)))


def test_postgres_restart(farm):
    api = farm.start("api")
    farm.start("worker")
    farm.start("worker")
    ids = []
    for n in range(30):
        ids.append(submit(api["base"], scene(24, 24, 64, seed=n), "pg-%d" % n, retries=40))
        if n == 10:
            subprocess.check_call([PG_SCRIPT, "restart", farm.pg_dir])
    states = wait_states(api["base"], ids, 240)
    check(all(s == "succeeded" for s in states.values()),
          "all accepted jobs finished: %s" % [(i, s) for i, s in states.items() if s != "succeeded"])
    renders = renders_per_job(farm)
    check(all(renders.get(i) == 1 for i in ids), "each rendered once: %s" % renders)
    status, _, _ = request(api["base"], "GET", "/readyz")
    check(status == 200, "ready again")
    subprocess.check_call([PG_SCRIPT, "stop", farm.pg_dir])
    status, _, _ = request(api["base"], "GET", "/readyz")
    check(status == 503, "/readyz is 503 while the database is down: %d" % status)
    subprocess.check_call([PG_SCRIPT, "restart", farm.pg_dir] if False else
                          [PG_SCRIPT, "start", farm.pg_dir, open(os.path.join(farm.pg_dir, "port")).read().strip()],
                          stdout=subprocess.DEVNULL)
    print("postgres_restart: 30 jobs, PostgreSQL restarted after 11: all finished once")


def test_cancel_running(farm):
    api = farm.start("api")
    farm.start("worker")
    job = submit(api["base"], scene(64, 64, 1 << 16))
    deadline = time.time() + 30
    while time.time() < deadline and not running_owner(farm, job):
        time.sleep(0.05)
    # The worker writes its progressive image at heartbeats; any API node serves it.
    preview = None
    while time.time() < deadline and preview is None:
        status, raw, headers = request(api["base"], "GET", "/v1/jobs/%s/result?preview=true" % job)
        if status == 200:
            preview = raw
        time.sleep(0.2)
    check(preview is not None and preview[:4] == b"\x89PNG", "a preview of the running job")
    t0 = time.time()
    status, _, _ = request(api["base"], "DELETE", "/v1/jobs/" + job)
    check(status in (200, 202, 204), "cancel answered %d" % status)
    states = wait_states(api["base"], [job], 30)
    check(states[job] == "cancelled", "cancelled: %s" % states[job])
    print("cancel_running: preview served; cancelled %.2f s after DELETE" % (time.time() - t0))


def test_max_attempts(farm):
    # A worker that loses every task (killed each time it takes one) -> the job fails with why.
    api = farm.start("api")
    job = submit(api["base"], scene(64, 64, 1 << 16))
    for _ in range(farm.max_attempts):
        w = farm.start("worker")
        deadline = time.time() + 30
        while time.time() < deadline and not running_owner(farm, job):
            time.sleep(0.05)
        w["proc"].send_signal(signal.SIGKILL)
        w["proc"].wait()
        # Wait for the lease to expire before the next worker starts (it reaps, then claims).
        time.sleep(farm.lease + 0.5)
    farm.start("worker")
    states = wait_states(api["base"], [job], 30)
    check(states[job] == "failed", "failed: %s" % states[job])
    _, j = get_json(api["base"], "/v1/jobs/" + job)
    detail = json.dumps(j.get("error", {}))
    check("tried %d times" % farm.max_attempts in detail and "lease" in detail,
          "the reason: %s" % detail)
    print("max_attempts: failed after %d lost attempts: %s" % (farm.max_attempts, detail))


def test_assets_across_nodes(farm):
    # Uploaded through one API node, named by a job submitted through another, rendered by a
    # worker: the shared volume holds the files, every node's index learns them on first use.
    import hashlib
    a, b = farm.start("api"), farm.start("api")
    farm.start("worker")
    with open(os.path.join(REPO, "scenes", "meshes", "trefoil.ply"), "rb") as f:
        mesh = f.read()
    h = hashlib.sha256(mesh).hexdigest()
    status, _, _ = request(b["base"], "POST", "/v1/assets/missing", {"hashes": ["sha256:" + h]})
    check(status == 200, "missing answered")
    req = urllib.request.Request(a["base"] + "/v1/assets/" + h, data=mesh, method="PUT")
    req.add_header("Content-Type", "application/octet-stream")
    with urllib.request.urlopen(req, timeout=30) as r:
        check(r.status in (200, 201), "uploaded to the first node")
    status, raw, _ = request(b["base"], "POST", "/v1/assets/missing", {"hashes": ["sha256:" + h]})
    check(status == 200 and json.loads(raw)["missing"] == [], "the second node has it: %s" % raw)
    with open(os.path.join(REPO, "scenes", "mesh_file.json")) as f:
        s = json.load(f)
    s["render"].update({"width": 16, "height": 16, "spp": 1})
    job = submit(b["base"], {"scene": s, "assets": {"meshes/trefoil.ply": "sha256:" + h}})
    states = wait_states(a["base"], [job], 60)
    check(states[job] == "succeeded", "rendered: %s" % states[job])
    print("assets_across_nodes: uploaded to one API node, submitted to the other, rendered")


def test_events_stream(farm):
    # Submitted through one API node, watched through the other: the stream of state changes
    # comes from the jobs' version column (and NOTIFY), whichever worker renders.
    a, b = farm.start("api"), farm.start("api")
    farm.start("worker")
    blocker = submit(a["base"], scene(64, 64, 2048))
    job = submit(a["base"], scene(32, 32, 256))
    req = urllib.request.Request(b["base"] + "/v1/jobs/%s/events" % job)
    req.add_header("Accept", "text/event-stream")
    seen = []
    with urllib.request.urlopen(req, timeout=120) as stream:
        for line in stream:
            line = line.decode().strip()
            if line.startswith("event: "):
                state = line[len("event: "):]
                if not seen or seen[-1] != state:
                    seen.append(state)
                if state in ("succeeded", "failed", "cancelled"):
                    break
    check(seen[:1] == ["queued"] and "running" in seen and seen[-1] == "succeeded",
          "states streamed: %s" % seen)
    wait_states(a["base"], [blocker], 120)
    print("events_stream: %s" % " -> ".join(seen))


def test_retention(farm):
    # Finished jobs expire after --retention on the farm too: record, result files and all.
    api = farm.start("api", ["--retention", "2s"])
    farm.start("worker")
    job = submit(api["base"], scene())
    check(wait_states(api["base"], [job], 60)[job] == "succeeded", "rendered")
    check(any(f.startswith(job) for f in result_files(farm)), "its result is on the volume")
    deadline = time.time() + 10
    status = 200
    while time.time() < deadline and status != 404:
        status, _ = get_json(api["base"], "/v1/jobs/" + job)
        time.sleep(0.2)
    check(status == 404, "expired: %d" % status)
    check(not any(f.startswith(job) for f in result_files(farm)), "its files are gone")
    check(farm.psql("SELECT count(*) FROM jobs") == [["0"]], "its row is gone")
    print("retention: the job, its row and its files went after --retention 2s")


# --- Jobs of several tasks: a large still split into tiles, an animation's frames ------------


def big_scene(size=1024, spp=2, seed=7):
    """The cornell box with every output layer: the merge must place beauty and layers."""
    s = scene(size, size, spp, seed)
    s["render"]["outputs"] = ["albedo", "normal", "depth"]
    return s


LOCAL_RENDERS = {}


def render_locally(farm, scene_json, out, extra=()):
    """The single-machine render of the same scene and seed (`penumbra render`, all cores: the
    image does not depend on the thread count), kept for the next test that asks for it."""
    key = json.dumps([scene_json, list(extra)], sort_keys=True)
    if key in LOCAL_RENDERS and os.path.exists(LOCAL_RENDERS[key]):
        shutil.copyfile(LOCAL_RENDERS[key], out)
        return out
    path = os.path.join(farm.work, "local-%d.json" % random.randrange(1 << 30))
    with open(path, "w") as f:
        json.dump(scene_json, f)
    subprocess.check_call([farm.binary, "render", path, "-o", out, "-q", *extra],
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    kept = tempfile.mkstemp(prefix="penumbra-farm-local-", suffix=".exr")[1]
    shutil.copyfile(out, kept)
    LOCAL_RENDERS[key] = kept
    return out


def same_pixels(a, b, names_too=True):
    """Decoded EXR pixels of every channel (beauty and layers) equal bit for bit: idiff with no
    tolerance (which also refuses different channel counts), and the same channel names."""
    names = []
    for path in ((a, b) if names_too else ()):
        info = subprocess.run(["oiiotool", "--info", "-v", path], capture_output=True,
                              text=True).stdout
        m = re.search(r"channel list: (.*)", info)
        names.append(m.group(1).strip() if m else None)
    if names_too and (names[0] is None or names[0] != names[1]):
        return False
    return subprocess.call(["idiff", "-fail", "0", "-warn", "0", a, b],
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL) == 0


def fetch(base, path, out):
    status, raw, _ = request(base, "GET", path, timeout=120)
    check(status == 200, "GET %s answered %d: %s" % (path, status, raw[:200]))
    with open(out, "wb") as f:
        f.write(raw)
    return out


def tiles_by_worker(farm, job):
    rows = farm.psql("SELECT a.worker, t.params->>'window' FROM task_attempts a JOIN tasks t ON "
                     "t.id = a.task_id WHERE a.job_id = '%s' AND t.kind = 'tile' AND "
                     "a.outcome = 'succeeded'" % job)
    per = {}
    for worker, window in rows:
        per.setdefault(worker, []).append(window)
    return per


def split_job(farm, kill_one=False):
    api = farm.start("api")
    workers = [farm.start("worker") for _ in range(3)]
    # The kill needs a tile still rendering 0.3 s after it was seen running: at 2 spp a tile took
    # ~0.4 s, so the kill could land after it had committed (no attempt expired; failed CI once
    # the renderer got faster). At 32 spp a tile takes about two seconds.
    s = big_scene(spp=32 if kill_one else 2)
    t0 = time.time()
    job = submit(api["base"], s)
    kinds = farm.psql("SELECT kind, count(*) FROM tasks WHERE job_id = '%s' GROUP BY kind" % job)
    check(kinds == [["tile", "16"]], "a 1024x1024 frame is 16 tiles by default: %s" % kinds)
    if kill_one:
        # kill -9 of a worker while it renders a tile; a file of an attempt that never committed
        # is planted beside the tiles: the merge must take only committed tokens.
        deadline = time.time() + 60
        owner = None
        while time.time() < deadline and not owner:
            rows = farm.psql("SELECT lease_owner FROM tasks WHERE job_id = '%s' AND kind = 'tile' "
                             "AND state = 'running' LIMIT 1" % job)
            owner = rows[0][0] if rows else None
            time.sleep(0.05)
        check(owner, "a tile started")
        time.sleep(0.3)
        pid = int(owner.split("-")[-2])
        victim = [w for w in workers if w["proc"].pid == pid]
        check(victim, "the owner is one of our workers")
        victim[0]["proc"].send_signal(signal.SIGKILL)
        with open(os.path.join(farm.data, "results", job + "." + "f" * 24 + ".tile.exr"), "wb") as f:
            f.write(b"not an image: an orphan of a lost attempt")
    states = wait_states(api["base"], [job], 600)
    wall = time.time() - t0
    check(states[job] == "succeeded", "the split job finished: %s" % states[job])
    _, j = get_json(api["base"], "/v1/jobs/" + job)
    farm_exr = fetch(api["base"], "/v1/jobs/%s/result?format=exr" % job,
                     os.path.join(farm.work, "farm.exr"))
    t1 = time.time()
    local = render_locally(farm, s, os.path.join(farm.work, "local.exr"))
    local_seconds = time.time() - t1
    check(same_pixels(farm_exr, local), "the merged frame equals the single-machine render "
          "bit for bit (beauty and layers)")
    per = tiles_by_worker(farm, job)
    check(sum(len(v) for v in per.values()) == 16, "16 tiles committed: %s" % per)
    check(len(per) >= 2, "tiles rendered by at least 2 workers: %s" % list(per))
    kinds = dict((k, n) for k, n in farm.psql(
        "SELECT kind, count(*) FROM tasks WHERE job_id = '%s' AND state = 'done' GROUP BY kind" % job))
    check(kinds == {"tile": "16", "merge": "1"}, "16 tiles and one merge done: %s" % kinds)
    left = [f for f in result_files(farm) if f.endswith(".tile.exr") and f.startswith(job)]
    committed = {job + "." + token + ".tile.exr" for token, in farm.psql(
        "SELECT result_token FROM tasks WHERE job_id = '%s' AND kind = 'tile' AND state = 'done'" % job)}
    check(not committed & set(left), "the committed tiles' files are gone after the merge: %s"
          % sorted(committed & set(left)))
    # Files of attempts that never committed stay until the job's retention (split_retention):
    # the planted orphan, and the killed worker's own tile if it was written before the kill.
    planted = job + "." + "f" * 24 + ".tile.exr"
    check((planted in left) == kill_one, "the merge leaves uncommitted files alone: %s" % left)
    check(j["stats"].get("tasks") == 16, "the job's stats sum its tiles: %s" % j["stats"])
    if not kill_one:
        # Each worker reads and builds the scene once and renders all its tiles from it
        # (server/farm/scene_cache.h): a worker keeps it until it runs out of tiles.
        check(j["stats"].get("scene_builds") == len(per),
              "one scene build per worker (%d workers): %s" % (len(per), j["stats"]))
        built = farm.psql(
            "SELECT a.worker, count(*) FILTER (WHERE NOT (t.stats_json::jsonb->>'scene_reused')::"
            "boolean) FROM task_attempts a JOIN tasks t ON t.id = a.task_id WHERE a.job_id = '%s' "
            "AND t.kind = 'tile' AND a.outcome = 'succeeded' GROUP BY a.worker" % job)
        check(all(n == "1" for _, n in built), "each worker built the scene once: %s" % built)
        for w in workers:
            if w["proc"].poll() is not None:
                continue
            status, raw, _ = request(w["base"], "GET", "/metrics")
            counts = dict(re.findall(
                r'penumbra_farm_scene_preparations_total\{outcome="(\w+)"\} (\d+)', raw.decode()))
            mine = [v for k, v in per.items() if k.split("-")[-2] == str(w["proc"].pid)]
            check(counts.get("built") == ("1" if mine else "0") and
                  counts.get("reused") == str(len(mine[0]) - 1 if mine else 0) and
                  counts.get("failed") == "0",
                  "a worker's metrics count its scene built once, reused for its other tiles: %s"
                  % counts)
    # Where the wall time went: tiles (first start to last end), the merge, from the attempt log.
    (tiles_span, merge_span, tile_sum), = farm.psql(
        "SELECT extract(epoch FROM max(a.ended_at) FILTER (WHERE t.kind = 'tile') - "
        "min(a.started_at) FILTER (WHERE t.kind = 'tile')), extract(epoch FROM "
        "max(a.ended_at) FILTER (WHERE t.kind = 'merge') - min(a.started_at) FILTER (WHERE "
        "t.kind = 'merge')), extract(epoch FROM sum(a.ended_at - a.started_at) FILTER (WHERE "
        "t.kind = 'tile' AND a.outcome = 'succeeded')) FROM task_attempts a JOIN tasks t ON "
        "t.id = a.task_id WHERE a.job_id = '%s'" % job)
    print("  tiles %.2f s (first start to last end; %.2f s of tile attempts summed), merge and "
          "results %.2f s" % (float(tiles_span), float(tile_sum), float(merge_span)))
    return job, wall, local_seconds, per


def test_split_frame(farm):
    job, wall, local_seconds, per = split_job(farm)
    print("split_frame: 1024x1024, 16 tiles over 3 workers (1 thread each): %.1f s wall "
          "(single machine, all cores: %.1f s); tiles per worker %s; bit-identical"
          % (wall, local_seconds, sorted(len(v) for v in per.values())))


def test_split_frame_worker_kill(farm):
    job, wall, local_seconds, per = split_job(farm, kill_one=True)
    outcomes = sorted(set(r[0] for r in farm.psql(
        "SELECT outcome FROM task_attempts WHERE job_id = '%s'" % job)))
    check("lease_expired" in outcomes, "the killed worker's tile expired: %s" % outcomes)
    print("split_frame_worker_kill: a worker killed mid-tile; the tile ran again; %.1f s wall; "
          "bit-identical" % wall)


def test_split_progress_and_preview(farm):
    # Progress of a split job counts samples over all its tiles; the preview places the tiles'
    # previews in one frame; /v1/workers names each worker's tile.
    api = farm.start("api")
    farm.start("worker")
    farm.start("worker")
    job = submit(api["base"], scene(512, 512, 1 << 12))
    deadline = time.time() + 60
    seen_windows, fractions, preview = set(), [], None
    while time.time() < deadline and (len(fractions) < 3 or preview is None or not seen_windows):
        _, w = get_json(api["base"], "/v1/workers")
        for worker in w["workers"]:
            for t in worker["current_tasks"]:
                if t["kind"] == "tile" and t.get("window"):
                    seen_windows.add(tuple(t["window"]))
        _, j = get_json(api["base"], "/v1/jobs/" + job)
        if j and j["state"] == "running" and j["progress"] and j["eta_seconds"] is not None:
            fractions.append(j["progress"])
        status, raw, _ = request(api["base"], "GET", "/v1/jobs/%s/result?preview=true&format=exr" % job)
        if status == 200:
            preview = raw
        time.sleep(0.3)
    request(api["base"], "DELETE", "/v1/jobs/" + job)
    check(seen_windows, "/v1/workers shows the tiles' windows")
    check(len(fractions) >= 2 and fractions[-1] > fractions[0] and 0 < fractions[-1] < 1,
          "the progress of the split job grows: %s" % fractions)
    check(preview is not None, "a preview of the split job")
    path = os.path.join(farm.work, "preview.exr")
    with open(path, "wb") as f:
        f.write(preview)
    info = subprocess.run(["oiiotool", "--info", path], capture_output=True, text=True).stdout
    check("512 x  512" in info or "512 x 512" in info, "the preview is the whole frame: %s" % info)
    print("split_progress_and_preview: windows %s; fractions %s"
          % (sorted(seen_windows)[:3], ["%.3f" % f for f in fractions[:4]]))


def test_split_cancel(farm):
    # DELETE of a running split job: every tile stops or never starts, no merge.
    api = farm.start("api")
    farm.start("worker")
    farm.start("worker")
    job = submit(api["base"], scene(512, 512, 1 << 14))
    deadline = time.time() + 60
    while time.time() < deadline:
        if int(farm.psql("SELECT count(*) FROM tasks WHERE job_id = '%s' AND state = 'running'"
                         % job)[0][0]) == 2:
            break
        time.sleep(0.05)
    t0 = time.time()
    status, _, _ = request(api["base"], "DELETE", "/v1/jobs/" + job)
    check(status in (200, 202, 204), "cancel answered %d" % status)
    states = wait_states(api["base"], [job], 30)
    check(states[job] == "cancelled", "cancelled: %s" % states[job])
    deadline = time.time() + 10
    while time.time() < deadline:
        live = farm.psql("SELECT state, count(*) FROM tasks WHERE job_id = '%s' GROUP BY state"
                         % job)
        if all(s in ("cancelled",) for s, _ in live):
            break
        time.sleep(0.1)
    check(all(s == "cancelled" for s, _ in live), "every tile cancelled: %s" % live)
    # Only the two tiles under way at the DELETE ever started: the others never ran.
    attempts = farm.psql("SELECT count(*) FROM task_attempts WHERE job_id = '%s'" % job)
    check(attempts == [["2"]], "no tile started after the cancel: %s attempts" % attempts)
    time.sleep(farm.heartbeat * 2)
    check(farm.psql("SELECT count(*) FROM tasks WHERE job_id = '%s' AND kind = 'merge'" % job)
          == [["0"]], "no merge")
    _, w = get_json(api["base"], "/v1/workers")
    check(all(not x["current_tasks"] for x in w["workers"]), "the workers are idle: %s" % w)
    print("split_cancel: 16 tiles cancelled %.2f s after DELETE" % (time.time() - t0))


def test_split_denoise(farm):
    # A split job that asks for denoising: the tiles render the guides, the merge denoises the
    # whole frame (a window cannot be denoised alone); the result equals `penumbra render` of the
    # scene, denoised image, kept "noisy" layer and requested layers. --tile-pixels is the API
    # node's: a 128x128 frame in 4 tiles.
    api = farm.start("api", ["--tile-pixels", "4096"])
    farm.start("worker")
    farm.start("worker")
    s = scene(128, 128, 4, 5)
    s["render"]["denoise"] = True
    s["render"]["outputs"] = ["depth"]
    job = submit(api["base"], s)
    check(farm.psql("SELECT kind, count(*) FROM tasks WHERE job_id = '%s' GROUP BY kind" % job)
          == [["tile", "4"]], "4 tiles")
    check(wait_states(api["base"], [job], 120)[job] == "succeeded", "rendered")
    _, j = get_json(api["base"], "/v1/jobs/" + job)
    a = fetch(api["base"], "/v1/jobs/%s/result?format=exr" % job, os.path.join(farm.work, "d.exr"))
    b = render_locally(farm, s, os.path.join(farm.work, "dl.exr"))
    check(same_pixels(a, b), "the denoised merge equals the single-machine denoised render")
    print("split_denoise: 4 tiles merged then denoised (denoised: %s) == penumbra render"
          % j["stats"].get("denoised"))


def test_split_retention(farm):
    # A split job expires with every file of it: the result, and a tile file of an attempt that
    # never committed (planted: what a worker killed between writing and committing leaves).
    api = farm.start("api", ["--retention", "2s", "--tile-pixels", "4096"])
    farm.start("worker")
    job = submit(api["base"], scene(128, 128, 2))
    orphan = os.path.join(farm.data, "results", job + "." + "e" * 24 + ".tile.exr")
    with open(orphan, "wb") as f:
        f.write(b"left by a lost attempt")
    check(wait_states(api["base"], [job], 60)[job] == "succeeded", "rendered")
    deadline = time.time() + 10
    status = 200
    while time.time() < deadline and status != 404:
        status, _ = get_json(api["base"], "/v1/jobs/" + job)
        time.sleep(0.2)
    check(status == 404, "expired: %d" % status)
    left = [f for d in ("results", "previews") for f in os.listdir(os.path.join(farm.data, d))
            if f.startswith(job)]
    check(not left, "every file of the job is gone: %s" % left)
    print("split_retention: the split job's result and an orphan tile file went with it")


def animation_scene(frames=24):
    with open(os.path.join(REPO, "scenes", "motion_blur.json")) as f:
        s = json.load(f)
    s["camera"].pop("shutter", None)
    s["animation"] = {"frames": [1, frames], "fps": 24, "shutter": 0.5}
    # Frames of some tens of milliseconds, so that one worker cannot take all 24 before the
    # others have claimed theirs.
    s["render"].update({"width": 64, "height": 64, "spp": 8, "seed": 3,
                        "outputs": ["albedo", "depth"]})
    return s


def test_animation_frames(farm):
    api = farm.start("api")
    workers = [farm.start("worker") for _ in range(3)]
    deadline = time.time() + 30
    while len(farm.psql("SELECT id FROM workers WHERE stopped_at IS NULL")) < 3:
        check(time.time() < deadline, "3 workers registered")
        time.sleep(0.1)
    s = animation_scene()
    t0 = time.time()
    job = submit(api["base"], s)
    check(farm.psql("SELECT count(*), min((params->>'frame')::int), max((params->>'frame')::int) "
                    "FROM tasks WHERE job_id = '%s' AND kind = 'frame'" % job) == [["24", "1", "24"]],
          "one task per frame")
    states = wait_states(api["base"], [job], 300)
    check(states[job] == "succeeded", "the animation finished: %s" % states[job])
    wall = time.time() - t0
    check(farm.psql("SELECT frame_first, frame_last, frames_done FROM jobs WHERE id = '%s'" % job)
          == [["1", "24", "24"]], "frames counted")
    tokens = dict((int(f), t) for f, t in farm.psql(
        "SELECT params->>'frame', result_token FROM tasks WHERE job_id = '%s' AND kind = 'frame' "
        "AND state = 'done'" % job))
    per_worker = farm.psql("SELECT count(DISTINCT worker) FROM task_attempts WHERE job_id = '%s' "
                           "AND outcome = 'succeeded'" % job)[0][0]
    check(int(per_worker) >= 2, "frames rendered by several workers: %s" % per_worker)
    status, j = get_json(api["base"], "/v1/jobs/" + job)
    check(j["frames"] == {"first": 1, "last": 24, "done": 24},
          "the job JSON's frames (no single current frame on a farm): %s" % j.get("frames"))
    # Each frame through the API node (/result?frame=i), and all of them as one archive.
    path = os.path.join(farm.work, "anim.json")
    with open(path, "w") as f:
        json.dump(s, f)
    bad = []

    def compare(i):
        local = os.path.join(farm.work, "frame%d.exr" % i)
        subprocess.check_call([farm.binary, "render", path, "--frame", str(i), "-o", local, "-q",
                               "--threads", "1"], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
        served = fetch(api["base"], "/v1/jobs/%s/result?format=exr&frame=%d" % (job, i),
                       os.path.join(farm.work, "served%d.exr" % i))
        # What the route served is the committed task's file (open_result by the frame's token).
        with open(served, "rb") as a, open(os.path.join(
                farm.data, "results", "%s.%s.exr" % (job, tokens[i])), "rb") as b:
            if a.read() != b.read():
                bad.append(i)
                return
        # The channel names of every frame are the same task's writing; checked on the first.
        if not same_pixels(served, local, names_too=i == 1):
            bad.append(i)

    # Four single renders at a time (each its own process, one thread), to keep the label short.
    from concurrent.futures import ThreadPoolExecutor
    with ThreadPoolExecutor(4) as pool:
        list(pool.map(compare, range(1, 25)))
    bad.sort()
    check(not bad, "frames equal to `penumbra render --frame i`: differ %s" % bad)
    import io
    import tarfile
    status, raw, _ = request(api["base"], "GET", "/v1/jobs/%s/frames.tar" % job, timeout=120)
    check(status == 200, "frames.tar answered %d" % status)
    with tarfile.open(fileobj=io.BytesIO(raw)) as tar:
        names = tar.getnames()
        check(names == ["frame_%04d.exr" % i for i in range(1, 25)], "archive names: %s" % names)
        for i in range(1, 25):
            with open(os.path.join(farm.work, "served%d.exr" % i), "rb") as f:
                check(tar.extractfile("frame_%04d.exr" % i).read() == f.read(),
                      "archive member %d = /result?frame=%d" % (i, i))
    # Without a frame, the job's result is its first frame.
    first = fetch(api["base"], "/v1/jobs/%s/result?format=exr" % job,
                  os.path.join(farm.work, "first.exr"))
    check(same_pixels(first, os.path.join(farm.work, "frame1.exr")), "the result is frame 1")
    print("animation_frames: 24 frames over 3 workers in %.1f s, each bit-identical to "
          "penumbra render --frame i" % wall)


TESTS = {
    "retention": (test_retention, {}),
    "events_stream": (test_events_stream, {}),
    "assets_across_nodes": (test_assets_across_nodes, {}),
    "exactly_once": (test_exactly_once, {}),
    "worker_kill": (test_worker_kill, {"lease": 3.0, "heartbeat": 0.5}),
    "api_kill": (test_api_kill, {}),
    "postgres_restart": (test_postgres_restart, {"lease": 10.0, "heartbeat": 1.0}),
    "cancel_running": (test_cancel_running, {}),
    "max_attempts": (test_max_attempts, {"lease": 2.0, "heartbeat": 0.5, "max_attempts": 2}),
    "split_frame": (test_split_frame, {}),
    "split_frame_worker_kill": (test_split_frame_worker_kill, {"lease": 3.0, "heartbeat": 0.5}),
    "split_progress_and_preview": (test_split_progress_and_preview, {}),
    "split_cancel": (test_split_cancel, {}),
    "split_denoise": (test_split_denoise, {}),
    "split_retention": (test_split_retention, {}),
    "animation_frames": (test_animation_frames, {}),
}


def main():
    binary = os.path.abspath(sys.argv[1])
    names = sys.argv[2:] or list(TESTS)
    import glob
    if not glob.glob("/usr/lib/postgresql/*/bin/initdb") or not shutil.which("psql"):
        if os.environ.get("CI") == "true":
            print("farm_test: no PostgreSQL server or psql (scripts/install-deps.sh --farm)")
            return 1
        print("farm_test: skipped: no PostgreSQL server or psql (scripts/install-deps.sh --farm)")
        return 77
    failed = []
    for name in names:
        fn, kw = TESTS[name]
        farm = Farm(binary, **kw)
        t0 = time.time()
        try:
            fn(farm)
            print("PASS %s (%.1f s)" % (name, time.time() - t0))
        except Exception as e:  # noqa: BLE001 - report and go on to the next test
            print("FAIL", name, "-", e)
            for n in farm.procs:
                print("  log:", n["log"])
            failed.append(name)
            os.environ["PENUMBRA_KEEP_FARM"] = "1"  # the logs of a failure are kept
        finally:
            farm.close()
    for kept in LOCAL_RENDERS.values():
        os.unlink(kept)
    print("farm_test: %d passed, %d failed %s" % (len(names) - len(failed), len(failed), failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
