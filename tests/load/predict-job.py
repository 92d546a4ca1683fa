#!/usr/bin/env python3
"""Passes per second of a prediction job over HTTP, the whole path of a realistic program.

Writes the job of solver/benches/predict.rs as a job file: a Ø10 ball end mill finishing a
double-wave surface (160 x 160 mm, slopes up to 26°) by a zig-zag raster, pick 0.5 mm, 0.5 mm
segments, 103 041 feed passes, modal stiffness and the force model, stock = surface + 0.2 mm as a
height grid, surface sampling at N = 256 (the patent's pixel size 0.039 mm). With a base URL it
submits the job, follows its progress and prints the job's timings and the server's CPU time.

Usage:
    cargo build --release -p kerf-server
    ./target/release/kerf serve --bind 127.0.0.1:18087 --database /tmp/bench.db &
    tests/load/predict-job.py /tmp/predict-job.json http://127.0.0.1:18087 $!
(RAYON_NUM_THREADS=1 in the server's environment gives the one-core figure; KERF_PREDICT_PICK sets the
pick and step, mm, e.g. 0.29963 for the patent's job size; tests/load/predict-cluster.sh runs the job
through SQLite and through PostgreSQL with one and two worker processes.)
"""
import json
import math
import os
import sys
import time
import urllib.request

SIZE, PICK, STEP, RADIUS = 160.0, 0.5, 0.5, 5.0
# The patent's job size (286 463 passes) is about PICK = STEP = 160 / 534: 535 x 535 = 286 225 passes.
PICK = STEP = float(os.environ.get("KERF_PREDICT_PICK", PICK))


def surface(x, y):
    amplitude, k = 25.0, math.pi / SIZE
    z = amplitude * math.sin(k * x) * math.sin(k * y)
    dx = amplitude * k * math.cos(k * x) * math.sin(k * y)
    dy = amplitude * k * math.sin(k * x) * math.cos(k * y)
    length = math.sqrt(dx * dx + dy * dy + 1)
    return z, (-dx / length, -dy / length, 1 / length)


def job():
    lines, points = round(SIZE / PICK) + 1, round(SIZE / STEP) + 1
    program = ["%", "O1000 (RASTER FINISHING)", "G21 G90 G17 G40 G49 G80", "T1 M06", "S6000 M03"]
    for line in range(lines):
        for k in range(points):
            i = k if line % 2 == 0 else points - 1 - k
            z, n = surface(i * STEP, line * PICK)
            tip = (i * STEP + RADIUS * n[0], line * PICK + RADIUS * n[1], z + RADIUS * n[2] - RADIUS)
            if line == 0 and k == 0:
                program += [f"G0 X{tip[0]:.4f} Y{tip[1]:.4f} Z60.0", f"G1 Z{tip[2]:.4f} F1200"]
            else:
                program.append(f"X{tip[0]:.4f} Y{tip[1]:.4f} Z{tip[2]:.4f}")
    program += ["G0 Z60.0", "M05", "M30", "%"]
    margin, spacing = 2 * RADIUS, 0.5
    count = round((SIZE + 2 * margin) / spacing) + 1
    heights = []
    for j in range(count):
        row = []
        for i in range(count):
            z, n = surface(-margin + i * spacing, -margin + j * spacing)
            row.append(round(z + 0.2 / n[2], 6))
        heights.append(row)
    mode = {"stiffness": 5000, "frequency_hz": 1370, "damping_ratio": 0.05}
    tool = {"number": 1, "kind": "ball", "radius": RADIUS,
            "shape_error": [{"angle_deg": 10 * k, "error": 0.003 + 0.004 * math.sin(math.radians(10 * k))}
                            for k in range(10)],
            "stiffness": {"kind": "modal", "x": [mode], "y": [mode]}}
    operation = {"operation": "predict", "tool": 1,
                 "stock": {"kind": "grid", "origin": [-margin, -margin], "spacing": spacing,
                           "heights": heights, "bottom": -100.0},
                 "path": {"kind": "gcode", "program": "\n".join(program) + "\n"},
                 "cutting": {"ktc": 2000, "krc": 800, "kac": 300}, "method": "sampling", "resolution": 256}
    return {"name": f"raster {SIZE:.0f} x {SIZE:.0f}, {lines * points} passes, sampling N = 256",
            "tools": [tool], "operations": [operation]}


def cpu_seconds(pid):
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def measure(path, base, pid):
    body = open(path, "rb").read()
    cpu, started = cpu_seconds(pid), time.time()
    request = urllib.request.Request(base + "/api/v1/jobs", data=body, headers={"content-type": "application/json"})
    submitted = json.load(urllib.request.urlopen(request))
    while True:
        state = json.load(urllib.request.urlopen(f"{base}/api/v1/jobs?limit=5"))
        record = next(j for j in state["jobs"] if j["id"] == submitted["id"])
        print(f"{time.time() - started:6.1f} s  {record['status']:8} {record['progress']:.3f}", flush=True)
        if record["status"] not in ("queued", "running"):
            break
        time.sleep(5)
    wall, cpu = time.time() - started, cpu_seconds(pid) - cpu
    result = json.load(urllib.request.urlopen(f"{base}/api/v1/jobs/{submitted['id']}"))["results"][0]["result"]
    timings, passes = result["timings"], result["summary"]["passes"]
    print(f"job: {passes} passes, {wall:.1f} s from upload to done; solve {timings['solve_ms'] / 1000:.1f} s = "
          f"{timings['passes_per_s']:.0f} passes/s ({0.070 * timings['passes_per_s']:.0f}x the patent's 0.070 s/pass); "
          f"server CPU {cpu:.1f} s = {cpu / passes * 1000:.3f} ms/pass per core "
          f"({0.070 / (cpu / passes):.0f}x the patent per core)")


if __name__ == "__main__":
    target = sys.argv[1] if len(sys.argv) > 1 else "predict-job.json"
    with open(target, "w") as out:
        json.dump(job(), out)
    if len(sys.argv) > 3:
        measure(target, sys.argv[2], int(sys.argv[3]))
