#!/usr/bin/env python3
"""Renders through the farm that scripts/kube-smoke.sh brought up with `podman kube play`.

Jobs go in through both API nodes alternately; a worker pod is killed (SIGKILL) while it renders
one; every job must still succeed, each result must be readable through the other API node, the
workers' counters must add up to one successful render per job, and the killed worker's job must
have run again elsewhere. Prints the recovery time (kill → that job succeeded). Standard library
only. Exit status 0 on success.
"""
import argparse
import json
import shlex
import subprocess
import sys
import time
import urllib.error
import urllib.request


def call(base, method, path, token, body=None, headers=None, timeout=30):
    h = {"Authorization": "Bearer " + token}
    h.update(headers or {})
    data = None
    if body is not None:
        data = json.dumps(body).encode()
        h["Content-Type"] = "application/json"
    req = urllib.request.Request(base + path, data=data, method=method, headers=h)
    try:
        with urllib.request.urlopen(req, timeout=timeout) as res:
            return res.status, res.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()


def get_json(base, path, token):
    status, body = call(base, "GET", path, token)
    if status != 200:
        raise RuntimeError("GET %s%s: %d %s" % (base, path, status, body[:300]))
    return json.loads(body)


def check(cond, what):
    if not cond:
        print("FAIL:", what, file=sys.stderr)
        sys.exit(1)
    print("   ok:", what)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--token", required=True)
    p.add_argument("--scene", required=True)
    p.add_argument("--api", action="append", required=True)
    p.add_argument("--kill-worker", required=True,
                   help="command that kills the worker whose host is penumbra-worker-pod-0")
    p.add_argument("--jobs", type=int, default=9)
    p.add_argument("--timeout", type=float, default=300)
    a = p.parse_args()
    api = a.api
    with open(a.scene, encoding="utf-8") as f:
        scene = json.load(f)
    # Small frames, but long enough (a few seconds each) that the kill lands mid-render.
    scene["render"].update({"width": 96, "height": 96, "spp": 48})

    ids = []
    for i in range(a.jobs):
        body = dict(scene)
        body["render"] = dict(scene["render"], seed=i)
        status, res = call(api[i % 2], "POST", "/v1/jobs", a.token, body,
                           {"Idempotency-Key": "kube-smoke-%d" % i})
        if status != 202:
            print("FAIL: job %d: %d %s" % (i, status, res[:300]), file=sys.stderr)
            sys.exit(1)
        ids.append(json.loads(res)["id"])
    print("   ok: %d jobs accepted through both API nodes" % len(ids))

    # Kill the worker on pod 0 once it is rendering a job.
    deadline = time.time() + a.timeout
    victim_job, killed_at = None, None
    while time.time() < deadline and victim_job is None:
        for w in get_json(api[0], "/v1/workers", a.token)["workers"]:
            if w.get("host") == "penumbra-worker-pod-0" and w.get("current_tasks") and w.get("alive"):
                victim_job = w["current_tasks"][0]["job"]
                break
        if victim_job is None:
            time.sleep(0.2)
    check(victim_job is not None, "worker pod 0 took a task")
    subprocess.run(shlex.split(a.kill_worker), check=True, stdout=subprocess.DEVNULL)
    killed_at = time.time()
    print("   killed worker pod 0 while it rendered job", victim_job)

    pending, recovered = set(ids), None
    while pending and time.time() < deadline:
        for job in sorted(pending):
            doc = get_json(api[1], "/v1/jobs/" + job, a.token)
            if doc["state"] in ("failed", "cancelled"):
                check(False, "job %s %s: %s" % (job, doc["state"], doc.get("error")))
            if doc["state"] == "succeeded":
                pending.discard(job)
                if job == victim_job:
                    recovered = time.time() - killed_at
        time.sleep(0.5)
    check(not pending, "all %d jobs succeeded (%d pending)" % (len(ids), len(pending)))
    check(recovered is not None, "the killed worker's job ran again elsewhere")
    print("   [ figures ] recovery after kill -9 of a worker: job done %.1f s later" % recovered)

    for i, job in enumerate(ids):
        status, png = call(api[(i + 1) % 2], "GET", "/v1/jobs/%s/result?format=png" % job, a.token)
        if status != 200 or not png.startswith(b"\x89PNG\r\n\x1a\n"):
            check(False, "result of %s through the other API node: %d" % (job, status))
    check(True, "every result read through the API node that did not take the job")

    workers = get_json(api[0], "/v1/workers", a.token)["workers"]
    render = workers  # the farm lists its render workers (the API nodes render nothing)
    check(len({w["id"] for w in render}) >= 3, "%d render workers registered" % len(render))
    done = sum(w.get("tasks_succeeded", 0) for w in render)
    check(done == len(ids), "one successful render per job (workers count %d)" % done)
    busy = sum(1 for w in render if w.get("tasks_succeeded", 0) > 0)
    check(busy >= 2, "the jobs were spread over %d workers" % busy)
    return 0


if __name__ == "__main__":
    sys.exit(main())
