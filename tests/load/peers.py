#!/usr/bin/env python3
"""kerf against the library a user would call instead, on the same work, side by side in one run.

    python3 -m venv /tmp/venv-peers && /tmp/venv-peers/bin/pip install -r tests/load/requirements.txt
    cargo build --release -p kerf-server
    /tmp/venv-peers/bin/python tests/load/peers.py target/release/kerf [--rounds 7] [--only NAME,...]

Starts the given `kerf` on a fresh SQLite file with the answer cache off (`--answer-cache-mb 0`:
every request is solved), then runs every case `--rounds` times, interleaved (round 1 of every
case and its peer, then round 2, ...), after one warm-up round that is not counted:

* kerf: the CPU time of the kerf process (user + system from /proc/<pid>/stat, so per core on a
  shared machine) around one request, the answer read in full; JSON, and for the G-code column
  the same request with `?format=gcode`;
* the peer: this process's CPU time (`time.process_time`) around its call, its input already
  built (the curve object, the polygon, the grid), its output kept as the library gives it.

/proc counts CPU time in ticks of 10 ms: a request shorter than half a second is sent
several times in a row within one measurement, the figure being the CPU per request (a peer
whose call is as short is called as often; its clock is exact); the warm-up round chooses how
many.

It prints min and median of each, the ratio peer ÷ kerf (above 1: kerf is faster) and the G-code
answer's CPU ÷ the JSON answer's. The cases (`--only` takes their names):

* `bspline`: a cubic B-spline of 5 000 poles on a spiral, chord error 0.001 mm, about 100 000
  points, against Open CASCADE's `GCPnts_TangentialDeflection` (angular deflection 0.5 rad, which
  never binds here, curvature deflection 0.001 mm);
* `ellipse`: an ellipse 30 000 x 15 000 mm (semi-axes), chord error 1e-5 mm, about 100 000
  points, against the same;
* `star`, `wavy`: contour of a star of 50 tips in 100 layers and of a 20 000-vertex wavy outline
  in 8 layers, flat tool R3, against pyclipper (Clipper) offsetting the outline once by the tool
  radius (round joins, arc tolerance 0.001 mm) and copying the offset to every layer;
* `predict`: prediction of 3 721 passes of a ball R5 raster, sampling at N = 256 (0.039 mm
  pixels), against a vectorised numpy z-map (the ball stamped at every pixel step of every pass);
* `engagement`: 18 051 samples of a zig-zag clearing path, flat R5, 5 mm deep, against shapely (at every
  sample the tool circle intersected with the material left: the stock less the path before the
  sample within 2R, buffered by the tool radius).

Contour, prediction and engagement requests turn their `verification` off (the peers offset,
stamp or intersect, and cut no program); `--verified` leaves it on, as the service's default, to
measure what cutting the program costs.

Before the table, once: each segment case's point count and largest chord deviation, kerf's
(from its answer) and the peer's (sampled at 8 points inside every chord).

`--answers DIR` keeps kerf's answers of the warm-up round (JSON and G-code) in DIR, or where DIR
already holds a case's answers, says whether today's are byte for byte the same: a speed-up must
not change a byte (save with one binary, compare with the next).
"""

import argparse
import http.client
import json
import math
import os
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request

import numpy as np


def cpu_seconds(pid):
    """User + system CPU of process `pid`, seconds."""
    with open(f"/proc/{pid}/stat") as stat:
        fields = stat.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


class Kerf:
    """A release kerf on a fresh database, answer cache off."""

    def __init__(self, binary, directory):
        with socket.socket() as probe:
            probe.bind(("127.0.0.1", 0))
            self.port = probe.getsockname()[1]
        self.process = subprocess.Popen(
            [binary, "--bind", f"127.0.0.1:{self.port}", "--database", os.path.join(directory, "kerf.db"),
             "--answer-cache-mb", "0"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for _ in range(600):
            try:
                urllib.request.urlopen(f"http://127.0.0.1:{self.port}/healthz", timeout=1).read()
                break
            except OSError:
                time.sleep(0.1)
        self.connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=600)

    def send(self, method, path, body):
        """Status and the whole answer (on a new connection when the server closed the last one,
        as it does after a while idle)."""
        for attempt in (1, 2):
            try:
                self.connection.request(method, path, body=body, headers={"content-type": "application/json"})
                response = self.connection.getresponse()
                return response.status, response.read()
            except (ConnectionError, http.client.HTTPException):
                self.connection.close()
                self.connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=600)
                if attempt == 2:
                    raise

    def timed(self, path, body, repeats=1):
        """Server CPU seconds per request around `repeats` requests one after another, each answer
        read in full, and the last answer."""
        before = cpu_seconds(self.process.pid)
        for _ in range(repeats):
            status, answer = self.send("POST", path, body)
            if status != 200:
                raise RuntimeError(f"{path}: {status} {answer[:300]!r}")
        return (cpu_seconds(self.process.pid) - before) / repeats, answer

    def close(self):
        self.connection.close()
        self.process.terminate()
        self.process.wait()


# ---------------------------------------------------------------- segment against Open CASCADE

def spiral_poles():
    """5 000 poles 20 mm apart along a spiral from radius 10 mm, 2 mm pitch, a 0.5 mm wave in z."""
    poles, angle = [], 0.0
    for _ in range(5000):
        radius = 10.0 + 2.0 * angle / math.tau
        poles.append([radius * math.cos(angle), radius * math.sin(angle), 0.5 * math.sin(3 * angle)])
        angle += 20.0 / radius
    return poles


def segment_body(curve, tolerance):
    """A segment request cut at the fixed chord error `tolerance`: a feed and block time whose rule
    wants far less, raised to it by `min_chord_error` and held to it by `tolerance`."""
    return json.dumps({"curve": curve, "mode": "curve", "feed": 1000, "block_time_ms": 1,
                       "min_chord_error": tolerance, "tolerance": tolerance}).encode()


class Occt:
    """A curve as Open CASCADE holds it, deflected by `GCPnts_TangentialDeflection`."""

    def __init__(self, curve, deflection):
        from OCP.GeomAdaptor import GeomAdaptor_Curve
        self.curve = curve
        self.adaptor = GeomAdaptor_Curve(curve)
        self.deflection = deflection

    def run(self):
        from OCP.GCPnts import GCPnts_TangentialDeflection
        return GCPnts_TangentialDeflection(self.adaptor, 0.5, self.deflection)

    def max_deviation(self, result):
        """Largest distance of the curve from its chords, 8 samples inside each chord."""
        count = result.NbPoints()
        params = np.array([result.Parameter(i) for i in range(1, count + 1)])
        ends = np.array([[p.X(), p.Y(), p.Z()] for p in (result.Value(i) for i in range(1, count + 1))])
        worst = 0.0
        for k in range(1, 9):
            u = params[:-1] + (params[1:] - params[:-1]) * k / 9
            inner = np.array([[p.X(), p.Y(), p.Z()] for p in map(self.curve.Value, u)])
            a, b = ends[:-1], ends[1:]
            chord = b - a
            t = np.clip(np.einsum("ij,ij->i", inner - a, chord) / np.einsum("ij,ij->i", chord, chord), 0, 1)
            worst = max(worst, float(np.max(np.linalg.norm(inner - a - t[:, None] * chord, axis=1))))
        return count, worst


def bspline_case():
    from OCP.collections import Array1_double, Array1_gp_Pnt, Array1_int
    from OCP.Geom import Geom_BSplineCurve
    from OCP.gp import gp_Pnt
    poles, degree = spiral_poles(), 3
    array = Array1_gp_Pnt(1, len(poles))
    for index, pole in enumerate(poles):
        array.SetValue(index + 1, gp_Pnt(*pole))
    # Clamped uniform on [0, 1], kerf's default knots.
    count = len(poles) - degree + 1
    knots, multiplicities = Array1_double(1, count), Array1_int(1, count)
    for index in range(count):
        knots.SetValue(index + 1, index / (count - 1))
        multiplicities.SetValue(index + 1, degree + 1 if index in (0, count - 1) else 1)
    curve = Geom_BSplineCurve(array, knots, multiplicities, degree)
    body = segment_body({"kind": "bspline", "degree": degree, "control_points": poles}, 0.001)
    return "/api/v1/segment", body, Occt(curve, 0.001)


def ellipse_case():
    from OCP.Geom import Geom_Ellipse
    from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt
    curve = Geom_Ellipse(gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1), gp_Dir(1, 0, 0)), 30000.0, 15000.0)
    body = segment_body({"kind": "ellipse", "centre": [0, 0], "semi_axes": [30000, 15000]}, 1e-5)
    return "/api/v1/segment", body, Occt(curve, 1e-5)


# ---------------------------------------------------------------- contour against Clipper

class ClipperOffset:
    """The outline offset outward once by the tool radius, copied to every layer as (x, y, z) rows."""

    def __init__(self, outline, radius, layers):
        self.outline, self.radius, self.layers = outline, radius, layers

    def run(self):
        import pyclipper
        scale = 1e6
        offset = pyclipper.PyclipperOffset(arc_tolerance=0.001 * scale)
        offset.AddPath(pyclipper.scale_to_clipper(self.outline, scale), pyclipper.JT_ROUND, pyclipper.ET_CLOSEDPOLYGON)
        paths = [np.asarray(path, dtype=float) / scale for path in offset.Execute(self.radius * scale)]
        copies = []
        for z in self.layers:
            for path in paths:
                copies.append(np.column_stack([path, np.full(len(path), z)]))
        return copies


def verification():
    """The requests' `verification`: off unless `--verified` (the peers cut no program; kerf's
    cut of its own, on by default, is measured on its own)."""
    return {"enabled": VERIFIED}


def contour_body(outline, layers):
    return json.dumps({"tool": {"kind": "flat", "radius": 3}, "contour": outline, "side": "outside",
                       "depths": {"top": 0, "bottom": -float(layers), "step": 1}, "feed": 1200,
                       "verification": verification()}).encode()


def star_case():
    outline = [[(50.0 if k % 2 == 0 else 25.0) * math.cos(math.pi * k / 50),
                (50.0 if k % 2 == 0 else 25.0) * math.sin(math.pi * k / 50)] for k in range(100)]
    layers = [-1.0 - k for k in range(100)]
    return "/api/v1/contour", contour_body(outline, 100), ClipperOffset(outline, 3.0, layers)


def wavy_case():
    count = 20000
    outline = []
    for k in range(count):
        angle = math.tau * k / count
        radius = 60.0 + 8.0 * math.sin(7 * angle)
        outline.append([radius * math.cos(angle), radius * math.sin(angle)])
    layers = [-1.0 - k for k in range(8)]
    return "/api/v1/contour", contour_body(outline, 8), ClipperOffset(outline, 3.0, layers)


# ---------------------------------------------------------------- prediction against a numpy z-map

SIZE, PICK, BALL = 30.0, 0.5, 5.0
PIXEL = 2 * BALL / 256


def wave(x, y):
    amplitude, k = 2.5, math.pi / SIZE
    z = amplitude * math.sin(k * x) * math.sin(k * y)
    dx = amplitude * k * math.cos(k * x) * math.sin(k * y)
    dy = amplitude * k * math.sin(k * x) * math.cos(k * y)
    length = math.sqrt(dx * dx + dy * dy + 1)
    return z, (-dx / length, -dy / length, 1 / length)


def raster_tips():
    """The tool tip at every point of a zig-zag raster over the surface, 61 x 61: 3 721 passes."""
    lines = round(SIZE / PICK) + 1
    tips = []
    for line in range(lines):
        for k in range(lines):
            i = k if line % 2 == 0 else lines - 1 - k
            z, n = wave(i * PICK, line * PICK)
            tips.append((i * PICK + BALL * n[0], line * PICK + BALL * n[1], z + BALL * n[2] - BALL))
    return tips


class ZMap:
    """A z-map of the stock at the pixel size, the ball's lower half stamped at every pixel step."""

    def __init__(self, tips, spacing, heights, origin):
        self.tips = tips
        low = -BALL - 2.0
        count = int(round((SIZE + 2 * BALL + 4.0) / PIXEL)) + 1
        self.origin, self.count = low, count
        axis = low + PIXEL * np.arange(count)
        gx = (axis - origin) / spacing
        # The stock's grid, sampled bilinearly onto the pixels (once: the stock as given).
        grid = np.asarray(heights)
        i0 = np.clip(np.floor(gx).astype(int), 0, grid.shape[0] - 2)
        f = np.clip(gx - i0, 0, 1)
        rows = grid[i0] * (1 - f)[:, None] + grid[i0 + 1] * f[:, None]
        self.stock = rows[:, i0] * (1 - f)[None, :] + rows[:, i0 + 1] * f[None, :]
        half = int(math.ceil(BALL / PIXEL))
        offsets = PIXEL * np.arange(-half, half + 1)
        d2 = offsets[None, :] ** 2 + offsets[:, None] ** 2
        self.half = half
        self.stamp = np.where(d2 <= BALL * BALL, BALL - np.sqrt(np.maximum(BALL * BALL - d2, 0)), np.inf)

    def run(self):
        zmap = self.stock.copy()
        half, stamp = self.half, self.stamp
        for (x0, y0, z0), (x1, y1, z1) in zip(self.tips, self.tips[1:]):
            steps = max(1, int(math.ceil(math.hypot(x1 - x0, y1 - y0) / PIXEL)))
            for k in range(steps + 1):
                t = k / steps
                x, y, z = x0 + t * (x1 - x0), y0 + t * (y1 - y0), z0 + t * (z1 - z0)
                j, i = int(round((x - self.origin) / PIXEL)), int(round((y - self.origin) / PIXEL))
                window = zmap[i - half:i + half + 1, j - half:j + half + 1]
                np.minimum(window, z + stamp, out=window)
        return zmap


def predict_case(kerf):
    tips = raster_tips()
    program = ["%", "O1000 (RASTER FINISHING)", "G21 G90 G17 G40 G49 G80", "T1 M06", "S6000 M03",
               f"G0 X{tips[0][0]:.4f} Y{tips[0][1]:.4f} Z30.0", f"G1 Z{tips[0][2]:.4f} F1200"]
    program += [f"X{x:.4f} Y{y:.4f} Z{z:.4f}" for x, y, z in tips[1:]]
    program += ["G0 Z30.0", "M05", "M30", "%"]
    margin, spacing = 2 * BALL, 0.5
    count = round((SIZE + 2 * margin) / spacing) + 1
    heights = []
    for j in range(count):
        row = []
        for i in range(count):
            z, n = wave(-margin + i * spacing, -margin + j * spacing)
            row.append(round(z + 0.2 / n[2], 6))
        heights.append(row)
    mode = {"stiffness": 5000, "frequency_hz": 1370, "damping_ratio": 0.05}
    tool = {"kind": "ball", "radius": BALL,
            "shape_error": [{"angle_deg": 10 * k, "error": 0.003 + 0.004 * math.sin(math.radians(10 * k))}
                            for k in range(10)],
            "stiffness": {"kind": "modal", "x": [mode], "y": [mode]}}
    status, answer = kerf.send("PUT", "/api/v1/tools/1", json.dumps(tool).encode())
    assert status in (200, 201), (status, answer)
    body = json.dumps({"tool": 1, "stock": {"kind": "grid", "origin": [-margin, -margin], "spacing": spacing,
                                            "heights": heights, "bottom": -100.0},
                       "path": {"kind": "gcode", "program": "\n".join(program) + "\n"},
                       "cutting": {"ktc": 2000, "krc": 800, "kac": 300}, "method": "sampling",
                       "resolution": 256, "verification": verification()}).encode()
    # The program's y rows are the z-map's rows: heights[j][i] is at (x_i, y_j).
    return "/api/v1/predict", body, ZMap(tips, spacing, np.asarray(heights).T.T, -margin)


# ---------------------------------------------------------------- engagement against shapely

POCKET, STEP = 200.0, 0.01
ENGAGEMENT_LENGTH = 180.5


def zigzag():
    """Rows 5 mm apart across the pocket, entering from outside, cut to 180.5 mm: 18 051 samples."""
    points, length, row = [[-10.0, 5.0]], 0.0, 0
    while True:
        y = 5.0 + 5.0 * row
        end_x = POCKET - 5.0 if row % 2 == 0 else 5.0
        for target in ([points[-1][0], y], [end_x, y]):
            px, py = points[-1]
            piece = math.hypot(target[0] - px, target[1] - py)
            if piece == 0.0:
                continue
            if length + piece >= ENGAGEMENT_LENGTH:
                t = (ENGAGEMENT_LENGTH - length) / piece
                points.append([px + t * (target[0] - px), py + t * (target[1] - py)])
                return points
            length += piece
            points.append(target)
        row += 1


class Shapely:
    """At every sample: the tool circle's arc inside the material left, the stock less the tool
    swept along the path before the sample (near it: the path within 2R, buffered by R)."""

    def __init__(self, path):
        from shapely.geometry import LineString
        self.line = LineString(path)
        count = int(round(self.line.length / STEP)) + 1
        self.samples = [self.line.interpolate(min(k * STEP, self.line.length)) for k in range(count)]

    def run(self):
        from shapely import clip_by_rect
        from shapely.geometry import Polygon
        from shapely.ops import substring
        stock = Polygon([(0, 0), (POCKET, 0), (POCKET, POCKET), (0, POCKET)])
        engaged = []
        for index, point in enumerate(self.samples):
            inside = point.buffer(5.0).exterior.intersection(stock)
            if index > 0:
                before = clip_by_rect(substring(self.line, 0, (index - 1) * STEP),
                                      point.x - 10, point.y - 10, point.x + 10, point.y + 10)
                if not before.is_empty:
                    inside = inside.difference(before.buffer(5.0))
            engaged.append(inside.length / 5.0)
        return engaged


def engagement_case(kerf):
    status, answer = kerf.send("PUT", "/api/v1/tools/2", json.dumps({"kind": "flat", "radius": 5}).encode())
    assert status in (200, 201), (status, answer)
    path = zigzag()
    body = json.dumps({"tool": 2, "stock": {"polygon": [[0, 0], [POCKET, 0], [POCKET, POCKET], [0, POCKET]]},
                       "path": path, "spindle_rpm": 8000, "feed_per_tooth": 0.05, "flute_counts": [2, 3, 4],
                       "thickness_limit": 0.08, "time_limit_s": 600, "step": STEP,
                       "axial_depth": 5, "verification": verification()}).encode()
    return "/api/v1/engagement", body, Shapely(path)


# ---------------------------------------------------------------- the run

# The shortest a measurement of kerf is made by repeating the request, seconds.
MEASURED_S = 0.5
# Whether contour, prediction and engagement requests ask for the verification section (`--verified`).
VERIFIED = False

CASES = {
    "bspline": ("B-spline, 5 000 poles, δ 0.001 mm", "OCCT TangentialDeflection", lambda kerf: bspline_case()),
    "ellipse": ("ellipse 30 000 × 15 000, δ 1e-5 mm", "OCCT TangentialDeflection", lambda kerf: ellipse_case()),
    "star": ("contour, star of 50 tips, 100 layers", "pyclipper offset once + copy", lambda kerf: star_case()),
    "wavy": ("contour, 20 000-vertex wavy outline, 8 layers", "pyclipper offset once + copy",
             lambda kerf: wavy_case()),
    "predict": ("prediction, 3 721 passes, 0.039 mm pixels", "numpy z-map", predict_case),
    "engagement": ("engagement, 18 051 samples", "shapely", engagement_case),
}


def describe(name, answer, peer, result):
    """What the case computed, once: counts and (segment) the largest chord deviation."""
    data = json.loads(answer)
    if name in ("bspline", "ellipse"):
        count, worst = peer.max_deviation(result)
        return (f"kerf {len(data['points'])} points, max deviation {data['max_deviation']:.6g} mm; "
                f"OCCT {count} points, max deviation {worst:.6g} mm (sampled)")
    if name in ("star", "wavy"):
        moves = sum(len(layer["moves"]) for layer in data["layers"])
        return f"kerf {len(data['layers'])} layers, {moves} moves; Clipper {sum(len(p) for p in result)} points"
    if name == "predict":
        return f"kerf {data['summary']['passes']} passes; z-map {result.shape[0]} x {result.shape[1]} pixels"
    samples = sum(len(c["samples"]) for c in data.get("candidates", [data]))
    return f"kerf {samples} samples; shapely {len(result)} samples"


def keep_or_compare(directory, name, answer, gcode):
    """Keeps a case's answers in `directory`, or compares them with those kept there."""
    os.makedirs(directory, exist_ok=True)
    for suffix, text in (("json", answer), ("gcode", gcode)):
        kept = os.path.join(directory, f"{name}.{suffix}")
        if not os.path.exists(kept):
            with open(kept, "wb") as out:
                out.write(text)
            print(f"{name}: {suffix} answer kept in {kept}", flush=True)
            continue
        with open(kept, "rb") as before:
            same = before.read() == text
        print(f"{name}: {suffix} answer {'byte for byte the same as' if same else 'DIFFERS from'} {kept}",
              flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("binary")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--only", default=",".join(CASES))
    parser.add_argument("--answers", metavar="DIR",
                        help="keep the answers in DIR, or compare them with those kept there")
    parser.add_argument("--verified", action="store_true",
                        help="contour, prediction and engagement answers cut their own program (the service's default; the peers do not)")
    arguments = parser.parse_args()
    global VERIFIED
    VERIFIED = arguments.verified
    names = [name for name in arguments.only.split(",") if name]
    for name in names:
        if name not in CASES:
            sys.exit(f"unknown case {name}: one of {', '.join(CASES)}")
    with tempfile.TemporaryDirectory() as directory:
        kerf = Kerf(arguments.binary, directory)
        try:
            built = {name: CASES[name][2](kerf) for name in names}
            figures = {name: {"kerf": [], "peer": [], "gcode": []} for name in names}
            print(f"load (1 min) at start: {open('/proc/loadavg').read().split()[0]}")
            repeats, peer_repeats = {}, {}
            for round_ in range(arguments.rounds + 1):
                for name in names:
                    path, body, peer = built[name]
                    cpu, answer = kerf.timed(path, body, repeats.get(name, 1))
                    if round_ == 0:
                        # The CPU clock of /proc ticks in 10 ms: a short request is repeated
                        # until one measurement spans some 50 ticks, as the warm-up shows.
                        estimate, _ = kerf.timed(path, body, 3)
                        repeats[name] = min(200, max(1, math.ceil(MEASURED_S / max(estimate, 1e-3))))
                    if round_ == 0:
                        started = time.process_time()
                        result = peer.run()
                        # The peer's clock is exact: it is called as often only when short.
                        once = time.process_time() - started
                        peer_repeats[name] = repeats[name] if once < MEASURED_S else 1
                    started = time.process_time()
                    for _ in range(peer_repeats[name]):
                        result = peer.run()
                    peer_cpu = (time.process_time() - started) / peer_repeats[name]
                    gcode_cpu, gcode_answer = kerf.timed(path + "?format=gcode", body, repeats[name])
                    if round_ == 0 and arguments.answers:
                        keep_or_compare(arguments.answers, name, answer, gcode_answer)
                    if round_ == 0:
                        print(f"{name}: {describe(name, answer, peer, result)}; JSON {len(answer)} bytes; "
                              f"{repeats[name]} requests and {peer_repeats[name]} calls per measurement", flush=True)
                        continue
                    figures[name]["kerf"].append(cpu)
                    figures[name]["peer"].append(peer_cpu)
                    figures[name]["gcode"].append(gcode_cpu)
            print(f"load (1 min) at end: {open('/proc/loadavg').read().split()[0]}")
        finally:
            kerf.close()
    print(f"\nCPU seconds, {arguments.rounds} interleaved rounds (min / median); ratio = peer ÷ kerf "
          "(above 1: kerf faster); G-code ÷ JSON = kerf's CPU for ?format=gcode ÷ for JSON\n")
    print("| work | peer | kerf JSON | peer | ratio (min, median) | kerf G-code | G-code ÷ JSON |")
    print("|---|---|---|---|---|---|---|")
    for name in names:
        work, peer_name, _ = CASES[name]
        kerf_cpu, peer_cpu, gcode = (figures[name][key] for key in ("kerf", "peer", "gcode"))
        k_min, k_med = min(kerf_cpu), statistics.median(kerf_cpu)
        p_min, p_med = min(peer_cpu), statistics.median(peer_cpu)
        g_min, g_med = min(gcode), statistics.median(gcode)
        print(f"| {work} | {peer_name} | {k_min * 1e3:.1f} / {k_med * 1e3:.1f} ms | {p_min * 1e3:.1f} / "
              f"{p_med * 1e3:.1f} ms | {p_min / k_min:.2f}, {p_med / k_med:.2f} | {g_min * 1e3:.1f} / "
              f"{g_med * 1e3:.1f} ms | {g_min / k_min:.2f}, {g_med / k_med:.2f} |")


if __name__ == "__main__":
    main()
