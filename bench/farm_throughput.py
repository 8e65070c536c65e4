#!/usr/bin/env python3
"""Throughput of the render service by store and number of workers (docs/scale-out.md,
"Throughput, measured" and "A model for 10, 100, 1000 workers").

    bench/farm_throughput.py [PENUMBRA_BINARY] [--rounds N] [--tiny-jobs N] [--small-jobs N]
                             [--big SIZE] [--csv FILE]

For each configuration (the SQLite store on one node; the PostgreSQL store with one API node and
1 or 2 worker processes; every render on one thread), it submits a stream of jobs from 4 client
threads and times the stream from the first submission to the last job's end:
  - tiny:  16x16 Cornell box, 2 spp: almost nothing but the per-job overhead of the service;
  - small: 64x64, 16 spp: a short render, as a product configurator's thumbnails;
  - big:   one SIZE x SIZE frame, 8 spp (split into window tasks by the farm, --tile-pixels).
Besides wall time (noisy on a shared machine) it reads CPU time, which other load barely moves:
of the serve processes and of the PostgreSQL cluster (every process of its postmaster, from
/proc), and PostgreSQL's committed transactions (pg_stat_database), each per job. Those per-job
costs of the database are what the scaling model extrapolates from. The configurations of a
round run one after another and the rounds repeat, so drift in machine load hits all alike;
medians are printed as a Markdown table and all samples go to the CSV.
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import threading
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(REPO, "tests", "farm"))
import farm_test  # noqa: E402  (the farm tests' process and PostgreSQL helpers)

TICKS = os.sysconf("SC_CLK_TCK")


def cpu_seconds(pids):
    total = 0.0
    for pid in pids:
        try:
            with open("/proc/%d/stat" % pid) as f:
                fields = f.read().rsplit(")", 1)[1].split()
            # utime, stime, cutime, cstime (fields 14-17 of proc(5), after the comm field)
            total += sum(int(x) for x in fields[11:15]) / TICKS
        except (FileNotFoundError, ProcessLookupError):
            pass
    return total


def children_of(pid):
    out = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True)
    return [int(x) for x in out.stdout.split()]


class SqliteNode:
    """One `penumbra serve` with the default store, WORKERS render slots of one thread each."""

    def __init__(self, binary, workers):
        import re
        import tempfile
        self.work = tempfile.mkdtemp(prefix="penumbra-bench-")
        self.proc = subprocess.Popen(
            [binary, "serve", "--port", "0", "--data-dir", os.path.join(self.work, "data"),
             "--workers", str(workers), "--render-threads", "1", "--max-queue", "5000",
             "--drain", "0"],
            stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
        self.base = None
        while True:
            line = self.proc.stdout.readline()
            if not line:
                raise RuntimeError("serve did not start")
            m = re.match(r"listening on (http://\S+)", line)
            if m:
                self.base = m.group(1)
                break
        threading.Thread(target=lambda: self.proc.stdout.read(), daemon=True).start()

    def server_pids(self):
        return [self.proc.pid]

    def db_pids(self):
        return []

    def db_transactions(self):
        return 0, 0

    def close(self):
        import shutil
        self.proc.terminate()
        self.proc.wait(timeout=30)
        shutil.rmtree(self.work, ignore_errors=True)


class FarmNodes:
    """PostgreSQL, one API node and WORKERS worker processes (one render thread each)."""

    def __init__(self, binary, workers, tile_pixels=None):
        self.farm = farm_test.Farm(binary, lease=30, heartbeat=5)
        extra = ("--tile-pixels", str(tile_pixels)) if tile_pixels else ()
        self.api = self.farm.start("api", extra)
        for _ in range(workers):
            self.farm.start("worker", extra)
        self.base = self.api["base"]
        with open(os.path.join(self.farm.pg_dir, "data", "postmaster.pid")) as f:
            self.postmaster = int(f.readline())

    def server_pids(self):
        return [n["proc"].pid for n in self.farm.procs]

    def db_pids(self):
        return [self.postmaster] + children_of(self.postmaster)

    def db_transactions(self):
        # (write transactions begun, WAL bytes written) so far: the next transaction id is not
        # taken by asking for it, and pg_stat_database's counters lag by up to a few seconds.
        rows = self.farm.psql("SELECT txid_snapshot_xmax(txid_current_snapshot()), "
                              "pg_current_wal_lsn() - '0/0'::pg_lsn")
        return int(rows[0][0]), int(float(rows[0][1]))

    def close(self):
        self.farm.close()


def run_stream(nodes, bodies, timeout):
    """Submits BODIES from 4 threads; returns (wall seconds, server CPU s, db CPU s, db xacts)."""
    ids, lock = [], threading.Lock()
    server_cpu0 = cpu_seconds(nodes.server_pids())
    db_pids = nodes.db_pids()
    db_cpu0 = cpu_seconds(db_pids)
    xact0 = nodes.db_transactions()
    t0 = time.time()

    def client(k):
        for body in bodies[k::4]:
            i = farm_test.submit(nodes.base, body, retries=20)
            with lock:
                ids.append(i)

    threads = [threading.Thread(target=client, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    # Jobs finish roughly in submission order: wait on the oldest unfinished one at a time, so
    # the polling itself stays a small share of the API node's work.
    deadline = time.time() + timeout
    for i in ids:
        while True:
            status, j = farm_test.get_json(nodes.base, "/v1/jobs/" + i)
            if status == 200 and j["state"] in ("succeeded", "failed", "cancelled"):
                if j["state"] != "succeeded":
                    raise AssertionError("job %s %s: %s" % (i, j["state"], j.get("error")))
                break
            if time.time() > deadline:
                raise AssertionError("timed out waiting for job " + i)
            time.sleep(0.02)
    wall = time.time() - t0
    # Backends come and go with connections: those that ended are in the postmaster's cutime,
    # those that began meanwhile are read at the end (all of their time fell in the stream).
    db_cpu1 = cpu_seconds(sorted(set(db_pids) | set(nodes.db_pids())))
    xact1 = nodes.db_transactions()
    return (wall, cpu_seconds(nodes.server_pids()) - server_cpu0, db_cpu1 - db_cpu0,
            xact1[0] - xact0[0], xact1[1] - xact0[1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary", nargs="?", default=os.path.join(REPO, "build", "app", "penumbra"))
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--tiny-jobs", type=int, default=200)
    ap.add_argument("--small-jobs", type=int, default=40)
    ap.add_argument("--big", type=int, default=1024, help="the big frame's size (0: none)")
    ap.add_argument("--tile-pixels", type=int, default=None,
                    help="passed to the farm nodes (when the binary splits frames)")
    ap.add_argument("--csv", default=None)
    args = ap.parse_args()

    def bodies(n, size, spp):
        return [farm_test.scene(width=size, height=size, spp=spp, seed=k) for k in range(n)]

    workloads = [("tiny", bodies(args.tiny_jobs, 16, 2)), ("small", bodies(args.small_jobs, 64, 16))]
    if args.big:
        workloads.append(("big", bodies(1, args.big, 8)))
    configs = [("sqlite", 1), ("sqlite", 2), ("postgres", 1), ("postgres", 2)]
    samples = []
    for r in range(args.rounds):
        for store, workers in configs:
            nodes = (SqliteNode(args.binary, workers) if store == "sqlite"
                     else FarmNodes(args.binary, workers, args.tile_pixels))
            try:
                # One discarded warm-up job (first connections, page cache, pool start).
                run_stream(nodes, bodies(4, 16, 1), 120)
                for name, work in workloads:
                    wall, scpu, dcpu, xacts, wal = run_stream(nodes, work, 1800)
                    n = len(work)
                    row = {"round": r, "store": store, "workers": workers, "workload": name,
                           "jobs": n, "wall_s": wall, "jobs_per_min": 60 * n / wall,
                           "server_cpu_ms_per_job": 1000 * scpu / n,
                           "db_cpu_ms_per_job": 1000 * dcpu / n,
                           "db_write_xacts_per_job": xacts / n,
                           "db_wal_kb_per_job": wal / n / 1024}
                    samples.append(row)
                    print(json.dumps(row), file=sys.stderr, flush=True)
            finally:
                nodes.close()
    if args.csv:
        with open(args.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(samples[0].keys()))
            w.writeheader()
            w.writerows(samples)

    print("| workload | store | workers | jobs | wall (s) | jobs/min | serve CPU ms/job "
          "| PostgreSQL CPU ms/job | write transactions/job | WAL kB/job |")
    print("| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, work in workloads:
        for store, workers in configs:
            rows = [s for s in samples if s["workload"] == name and s["store"] == store
                    and s["workers"] == workers]
            med = {k: statistics.median(s[k] for s in rows)
                   for k in ("wall_s", "jobs_per_min", "server_cpu_ms_per_job",
                             "db_cpu_ms_per_job", "db_write_xacts_per_job",
                             "db_wal_kb_per_job")}
            pg = store == "postgres"
            db = ("%.2f" % med["db_cpu_ms_per_job"]) if pg else "–"
            xa = ("%.1f" % med["db_write_xacts_per_job"]) if pg else "–"
            wk = ("%.1f" % med["db_wal_kb_per_job"]) if pg else "–"
            print("| %s | %s | %d | %d | %.2f | %.0f | %.1f | %s | %s | %s |" % (
                name, store, workers, len(work), med["wall_s"], med["jobs_per_min"],
                med["server_cpu_ms_per_job"], db, xa, wk))


if __name__ == "__main__":
    main()
