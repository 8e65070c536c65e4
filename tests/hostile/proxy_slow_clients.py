#!/usr/bin/env python3
"""Slow clients against the compose deployment's nginx proxy (issue 15; run by
scripts/container-smoke.sh): the same attack as tests/hostile/slow_clients_test.cpp makes on the
bare service, 100 connections that trickle a request head, 100 that trickle a body and 64 that do
not read a result, at about 1 byte/s, all from one client address.

    proxy_slow_clients.py PORT TOKEN JOB_PATH READY_FILE SECONDS

Opens the connections on 127.0.0.1:PORT, writes READY_FILE with what it opened (JSON), keeps
trickling for SECONDS, then closes everything and prints what the proxy did with them: how many
it cut (header and body timeouts) and how many it refused (per-address connection limit, 429).
The prober (another client address, inside the container network) is the caller's.
"""
import json
import socket
import sys
import time

HEADS, BODIES, READERS = 100, 100, 64


def connect(port, rcvbuf=None):
    s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    if rcvbuf:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, rcvbuf)
    s.connect(("127.0.0.1", port))
    s.setblocking(False)
    return s


def send(s, data):
    try:
        s.send(data)
        return True
    except (BlockingIOError, InterruptedError):
        return True
    except OSError:
        return False  # the proxy closed it


def answered(s):
    """The status code the proxy sent on `s`, 'closed', or None while it is silent."""
    try:
        data = s.recv(64, socket.MSG_PEEK)
    except (BlockingIOError, InterruptedError):
        return None
    except OSError:
        return "closed"
    if not data:
        return "closed"
    parts = data.split(b" ")
    return parts[1].decode() if len(parts) > 1 and data.startswith(b"HTTP/") else "other"


def main():
    port, token, job, ready_file, seconds = (int(sys.argv[1]), sys.argv[2], sys.argv[3],
                                             sys.argv[4], float(sys.argv[5]))
    auth = f"Authorization: Bearer {token}\r\n".encode()
    scene = json.dumps({"version": 1, "render": {"width": 8, "height": 8, "spp": 1},
                        "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]},
                        "materials": {"m": {"type": "diffuse", "color": [0.5, 0.5, 0.5]}},
                        "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1,
                                     "material": "m", "emission": [1, 1, 1]}]}).encode()
    heads, bodies, readers = [], [], []
    for _ in range(HEADS):
        s = connect(port)
        send(s, b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
        heads.append(s)
    for _ in range(BODIES):
        s = connect(port)
        send(s, b"POST /v1/jobs HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n" + auth +
             f"Content-Length: {len(scene)}\r\n\r\n".encode() + scene[:10])
        bodies.append(s)
    for _ in range(READERS):
        s = connect(port, rcvbuf=4096)
        send(s, f"GET {job}/result?format=exr HTTP/1.1\r\nHost: x\r\n".encode() + auth + b"\r\n")
        readers.append(s)
    with open(ready_file, "w") as f:
        json.dump({"heads": len(heads), "bodies": len(bodies), "readers": len(readers)}, f)

    start, k = time.time(), 0
    while time.time() - start < seconds:
        for s in heads:
            send(s, b"X")  # a header line that never ends
        for s in bodies:
            send(s, scene[10 + k % (len(scene) - 10):][:1])
        k += 1
        time.sleep(1.0)

    outcome = {}
    for name, group in (("heads", heads), ("bodies", bodies), ("readers", readers)):
        counts = {}
        for s in group:
            a = answered(s) or "open"
            counts[a] = counts.get(a, 0) + 1
            s.close()
        outcome[name] = counts
    print(json.dumps(outcome, sort_keys=True))


if __name__ == "__main__":
    main()
