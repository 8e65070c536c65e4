#!/usr/bin/env python3
"""Status-poll latency of `penumbra serve` while jobs are submitted as fast as possible and a
render runs: the figure of docs/http-api.md, "Status polls during a burst of submissions".

Each run starts a fresh server (loopback, ephemeral port, fresh data dir on disk), starts one
long render, waits until it runs, then at once
  - a submitter process posts JOBS small scenes (4 keep-alive connections, as fast as they go;
    the worker is busy, so they stay queued and each submit is one SQLite commit), and
  - this process polls GET /v1/jobs/{id} of the running job on one keep-alive connection,
    timing each request and response, until the submitter is done (at most MAX_POLLS polls
    and DEADLINE seconds: it always stops by itself).
Then the server gets SIGTERM and the data dir is removed. Several binaries (before/after a
change) are run alternately, the order flipping every round, so drift in the load of a shared
machine hits them alike. Standard library only; the submitter is a separate process so the
poller never waits for it on Python's GIL. The poller is closed-loop: a server that answers
faster is polled more often (and its submissions then compete with more polls for the cores).

  bench/poll_latency.py --binary before=/tmp/penumbra-before --binary after=build/app/penumbra \
      [--rounds 6] [--jobs 100] [--render-threads 1] [--data-root DIR]
"""
import argparse
import http.client
import json
import math
import multiprocessing
import os
import pathlib
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
MAX_POLLS = 50000
DEADLINE_SECONDS = 120.0
SUBMIT_CONNECTIONS = 4


def scene(width, height, spp, seed=0, time_limit=None):
    s = json.loads((ROOT / "scenes" / "cornell_box.json").read_text())
    s["render"].update(width=width, height=height, spp=spp, seed=seed)
    if time_limit:
        s["render"]["time_limit"] = time_limit
    return json.dumps(s)


def request(conn, method, path, body=None):
    headers = {"Content-Type": "application/json"} if body is not None else {}
    conn.request(method, path, body=body, headers=headers)
    res = conn.getresponse()
    return res.status, res.read()


def start_server(binary, data_dir, render_threads):
    args = [binary, "serve", "--port", "0", "--data-dir", data_dir, "--workers", "1",
            "--render-threads", str(render_threads), "--max-queue", "1000", "--drain", "0s"]
    proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    line = proc.stdout.readline()  # "listening on http://127.0.0.1:PORT"
    if "listening on http://" not in line:
        proc.kill()
        raise RuntimeError(f"{binary}: no listening line: {line!r}")
    # Keep the pipe drained so the server never blocks on a full stdout.
    threading.Thread(target=proc.stdout.read, daemon=True).start()
    return proc, int(line.rsplit(":", 1)[1])


def submitter(port, jobs, go, done, accepted):
    """Runs in its own process: posts `jobs` scenes over SUBMIT_CONNECTIONS connections."""
    go.wait()
    counts = []

    def post(first, count):
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
        ok = 0
        for i in range(first, first + count):
            status, _ = request(conn, "POST", "/v1/jobs", scene(8, 8, 1, seed=i))
            ok += status == 202
        counts.append(ok)

    per = math.ceil(jobs / SUBMIT_CONNECTIONS)
    threads = [threading.Thread(target=post, args=(k * per, min(per, jobs - k * per)))
               for k in range(SUBMIT_CONNECTIONS) if jobs - k * per > 0]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    accepted.value = sum(counts)
    done.set()


def percentile(sorted_values, p):
    """Nearest-rank percentile."""
    return sorted_values[max(0, math.ceil(p / 100 * len(sorted_values)) - 1)]


def one_run(binary, jobs, render_threads, data_root):
    data_dir = tempfile.mkdtemp(prefix="penumbra-poll-", dir=data_root)
    proc = None
    try:
        proc, port = start_server(binary, data_dir, render_threads)
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
        status, body = request(conn, "POST", "/v1/jobs", scene(64, 64, 1 << 16, time_limit=60))
        assert status == 202, (status, body)
        job = json.loads(body)["id"]
        for _ in range(500):  # bounded: 10 s
            _, body = request(conn, "GET", f"/v1/jobs/{job}")
            if json.loads(body)["state"] == "running":
                break
            time.sleep(0.02)
        go, done = multiprocessing.Event(), multiprocessing.Event()
        accepted = multiprocessing.Value("i", -1)
        sub = multiprocessing.Process(target=submitter, args=(port, jobs, go, done, accepted))
        sub.start()
        latencies = []
        start = time.perf_counter()
        go.set()
        while not done.is_set() and len(latencies) < MAX_POLLS and \
                time.perf_counter() - start < DEADLINE_SECONDS:
            t0 = time.perf_counter_ns()
            status, body = request(conn, "GET", f"/v1/jobs/{job}")
            latencies.append((time.perf_counter_ns() - t0) / 1e6)
            assert status == 200, (status, body)
        seconds = time.perf_counter() - start
        sub.join(timeout=60)
        state = json.loads(request(conn, "GET", f"/v1/jobs/{job}")[1])["state"]
        latencies.sort()
        return {"latencies": latencies, "polls": len(latencies), "p50": percentile(latencies, 50),
                "p99": percentile(latencies, 99), "max": latencies[-1], "seconds": seconds,
                "accepted": accepted.value, "render_state": state}
    finally:
        if proc:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        shutil.rmtree(data_dir, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", action="append", required=True, metavar="LABEL=PATH")
    ap.add_argument("--rounds", type=int, default=6)
    ap.add_argument("--jobs", type=int, default=100)
    ap.add_argument("--render-threads", type=int, default=1,
                    help="threads of the running render (1 leaves a core to HTTP on 2 cores)")
    ap.add_argument("--data-root", default=None,
                    help="where the data dirs go; must be a real disk, not tmpfs (default: TMPDIR)")
    args = ap.parse_args()
    binaries = [b.split("=", 1) for b in args.binary]
    results = {label: [] for label, _ in binaries}
    for r in range(args.rounds):
        order = binaries if r % 2 == 0 else binaries[::-1]
        for label, path in order:
            res = one_run(path, args.jobs, args.render_threads, args.data_root)
            results[label].append(res)
            print(f"round {r + 1} {label:>8}: {res['polls']:5d} polls in {res['seconds']:.2f} s while "
                  f"{res['accepted']}/{args.jobs} submits were accepted (render {res['render_state']}): "
                  f"p50 {res['p50']:.2f} ms, p99 {res['p99']:.2f} ms, max {res['max']:.2f} ms", flush=True)
            if res["accepted"] != args.jobs or res["render_state"] != "running":
                print("  (a submit was refused or the render was not running the whole time)", flush=True)
    print(f"median over {args.rounds} rounds ({args.jobs} submits, render on {args.render_threads} thread(s), "
          f"{os.cpu_count()} cores):")
    for label, runs in results.items():
        pooled = sorted(v for x in runs for v in x["latencies"])
        print(f"  {label:>8}: p50 {statistics.median(x['p50'] for x in runs):.2f} ms, "
              f"p99 {statistics.median(x['p99'] for x in runs):.2f} ms, "
              f"max {max(x['max'] for x in runs):.2f} ms; all {len(pooled)} polls together: "
              f"p50 {percentile(pooled, 50):.2f} ms, p99 {percentile(pooled, 99):.2f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
