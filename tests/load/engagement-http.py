#!/usr/bin/env python3
"""Engagement over HTTP: samples per second of server CPU for the engagement
bench's request (1 m of zig-zag clearing path at a 0.01 mm step, exact engine, flat Ø10 tool),
answered as JSON.

    tests/load/engagement-http.py target/release/kerf [solves]

Starts the given `kerf` binary on a fresh SQLite file in a temporary directory, with the answer
cache off (every request is solved), registers tool 1 (flat, radius 5), sends the request `solves` times (default
10) one after another, and reports the server process's CPU time per solve from /proc (user +
system, so the figure is per core on a shared machine) and the client's wall time.
"""

import json
import os
import socket
import subprocess
import sys
import tempfile
import time
import urllib.request

STEP = 0.01
POCKET = 200.0
PATH_LENGTH = 1000.0


def zigzag():
    """The bench's path: rows 5 mm apart across the pocket, entering from outside, cut to 1 m."""
    points = [[-10.0, 5.0]]
    length = 0.0
    row = 0
    while True:
        y = 5.0 + 5.0 * row
        end_x = POCKET - 5.0 if row % 2 == 0 else 5.0
        x0 = points[-1][0]
        for target in ([x0, y], [end_x, y]):
            px, py = points[-1]
            piece = ((target[0] - px) ** 2 + (target[1] - py) ** 2) ** 0.5
            if piece == 0.0:
                continue
            if length + piece >= PATH_LENGTH:
                t = (PATH_LENGTH - length) / piece
                points.append([px + t * (target[0] - px), py + t * (target[1] - py)])
                return points
            length += piece
            points.append(target)
        row += 1


def cpu_seconds(pid):
    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def send(method, url, body):
    request = urllib.request.Request(url, data=json.dumps(body).encode(), method=method,
                                     headers={"content-type": "application/json"})
    with urllib.request.urlopen(request, timeout=600) as response:
        return response.status, response.read()


def main():
    binary = sys.argv[1]
    solves = int(sys.argv[2]) if len(sys.argv) > 2 else 10
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    with tempfile.TemporaryDirectory() as directory:
        server = subprocess.Popen(
            [binary, "--bind", f"127.0.0.1:{port}", "--database", os.path.join(directory, "kerf.db"),
             "--answer-cache-mb", "0"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        base = f"http://127.0.0.1:{port}"
        try:
            for _ in range(600):
                try:
                    urllib.request.urlopen(f"{base}/healthz", timeout=1).read()
                    break
                except OSError:
                    time.sleep(0.1)
            send("PUT", f"{base}/api/v1/tools/1", {"kind": "flat", "radius": 5})  # the bench's Ø10 flat end
            body = {
                "tool": 1,
                "stock": {"polygon": [[0, 0], [POCKET, 0], [POCKET, POCKET], [0, POCKET]]},
                "path": zigzag(),
                "spindle_rpm": 8000, "feed_per_tooth": 0.05, "flute_counts": [2, 3, 4],
                "thickness_limit": 0.08, "time_limit_s": 600, "step": STEP,
            }
            status, answer = send("POST", f"{base}/api/v1/engagement", body)  # warm-up, and the sample count
            samples = len(json.loads(answer)["samples"])
            before, started = cpu_seconds(server.pid), time.monotonic()
            for _ in range(solves):
                status, answer = send("POST", f"{base}/api/v1/engagement", body)
                assert status == 200, status
            cpu = (cpu_seconds(server.pid) - before) / solves
            wall = (time.monotonic() - started) / solves
            load = open("/proc/loadavg").read().split()[0]
            print(f"{samples} samples, {len(answer)} bytes of JSON: server CPU {cpu * 1e3:.0f} ms per solve "
                  f"({samples / cpu / 1e6:.2f} M samples/s), client wall {wall * 1e3:.0f} ms, load {load}")
        finally:
            server.terminate()
            server.wait()


if __name__ == "__main__":
    main()
