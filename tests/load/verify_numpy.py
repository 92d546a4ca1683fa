#!/usr/bin/env python3
"""kerf's verify against a vectorised numpy z-map of the same finishing raster, in one run.

    python3 -m venv /tmp/venv-peers && /tmp/venv-peers/bin/pip install -r tests/load/requirements.txt
    cargo bench -p kerf-solver --bench verify --no-run     # prints the bench binary's path
    /tmp/venv-peers/bin/python tests/load/verify_numpy.py target/release/deps/verify-<hash> \\
        [--rows 500] [--spacing 0.05] [--rounds 3]

The program is the verify bench's (solver/benches/verify.rs): a Ø6 ball over a 100 × 100 × 40 mm
box stock, `--rows` raster rows over the middle 50 mm (500: 0.1 mm apart, 100 502 blocks), each
row 200 moves of 0.5 mm following a dome, so every move slopes. It is written to a file and cut:

* by kerf: the bench binary run with `KERF_BENCH_PROGRAM=<file>` and a filter that matches no
  criterion bench, so it cuts the program once and prints the solve's CPU time (the request
  parsed, the stock built, every move swept, the answer assembled) and the removed volume;
* by numpy: a z-map (one height per ray, the stock's top) on the same grid of rays, each move
  lowering the rays of its bounding rectangle to the ball's swept lower surface, computed in
  closed form as kerf does (the lowest point where the ray enters the capsule round the move's
  ball centres: the infinite cylinder's lower root where its foot falls on the move, else the end
  sphere), with `np.minimum`; timed by `time.process_time` around the moves.

Each is run `--rounds` times and the least time is taken (the machine is shared). Prints both
times, the ratio numpy ÷ kerf (above 1: kerf is faster) and both removed volumes, which must
agree within 0.5 % (exit status 1 otherwise).
"""

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time

import numpy as np

RADIUS = 3.0
STOCK_LO = (0.0, 0.0, -40.0)
STOCK_HI = (100.0, 100.0, 0.0)


def dome(x, y):
    """The dome's height at (x, y), as the bench has it."""
    r2 = ((x - 50.0) ** 2 + (y - 50.0) ** 2) / 2500.0
    return 5.0 * max(1.0 - r2, 0.0) - 6.0


def raster(rows):
    """The bench's program, character for character."""
    lines = ["G21 G90", "G0 X0 Y25 Z10", "F3000"]
    for row in range(rows):
        y = 25.0 + 50.0 * row / max(rows, 1)
        forward = row % 2 == 0
        for step in range(201):
            k = step if forward else 200 - step
            x = 0.5 * k
            lines.append(f"G1 X{x:.4f} Y{y:.4f} Z{dome(x, y):.4f}")
    lines += ["G0 Z50", "M30", ""]
    return "\n".join(lines)


def tip_path(program):
    """The tip positions the program's moves end at, in order (absolute, mm)."""
    position = [None, None, None]
    path = []
    for line in program.splitlines():
        words = dict((letter, float(value)) for letter, value in re.findall(r"([XYZ])(-?[0-9.]+)", line))
        if not words:
            continue
        for axis, letter in enumerate("XYZ"):
            if letter in words:
                position[axis] = words[letter]
        if None not in position:
            path.append(tuple(position))
    return path


def ball_lower(xs, ys, start, end, radius):
    """The lowest z the ball reaches on the rays at (xs, ys) moving its tip from `start` to
    `end`, +inf where it does not reach them."""
    ux, uy, vz = end[0] - start[0], end[1] - start[1], end[2] - start[2]
    uu = ux * ux + uy * uy
    px, py = xs - start[0], ys - start[1]
    pp = px * px + py * py
    r2 = radius * radius
    if uu < 1e-12:
        low = min(start[2], end[2]) + radius - np.sqrt(np.maximum(r2 - pp, 0.0))
        return np.where(pp <= r2, low, np.inf)
    pu = px * ux + py * uy
    room = r2 - (pp - pu * pu / uu)
    vv = uu + vz * vz
    sigma = (vz * pu - np.sqrt(np.maximum(vv * uu * room, 0.0))) / uu
    t = (pu + sigma * vz) / vv
    on_move = start[2] + radius + sigma
    d_end = pp - 2.0 * pu + uu
    at_start = np.where(pp <= r2, start[2] + radius - np.sqrt(np.maximum(r2 - pp, 0.0)), np.inf)
    at_end = np.where(d_end <= r2, end[2] + radius - np.sqrt(np.maximum(r2 - d_end, 0.0)), np.inf)
    low = np.where(t < 0.0, at_start, np.where(t > 1.0, at_end, on_move))
    return np.where(room >= 0.0, low, np.inf)


def numpy_zmap(path, spacing):
    """Cuts the path's moves into a z-map; its removed volume and the CPU time of the moves."""
    nx = int(np.ceil((STOCK_HI[0] - STOCK_LO[0]) / spacing))
    ny = int(np.ceil((STOCK_HI[1] - STOCK_LO[1]) / spacing))
    xs = STOCK_LO[0] + (np.arange(nx) + 0.5) * spacing
    ys = STOCK_LO[1] + (np.arange(ny) + 0.5) * spacing
    top = np.full((ny, nx), STOCK_HI[2])
    started = time.process_time()
    # The first move is swept from its end only (its start is not yet known).
    moves = [(path[0], path[0])] + list(zip(path, path[1:]))
    for start, end in moves:
        lo_x, hi_x = min(start[0], end[0]) - RADIUS, max(start[0], end[0]) + RADIUS
        lo_y, hi_y = min(start[1], end[1]) - RADIUS, max(start[1], end[1]) + RADIUS
        i0 = max(int(np.ceil((lo_x - STOCK_LO[0]) / spacing - 0.5)), 0)
        i1 = min(int(np.floor((hi_x - STOCK_LO[0]) / spacing - 0.5)) + 1, nx)
        j0 = max(int(np.ceil((lo_y - STOCK_LO[1]) / spacing - 0.5)), 0)
        j1 = min(int(np.floor((hi_y - STOCK_LO[1]) / spacing - 0.5)) + 1, ny)
        if i0 >= i1 or j0 >= j1:
            continue
        low = ball_lower(xs[np.newaxis, i0:i1], ys[j0:j1, np.newaxis], start, end, RADIUS)
        window = top[j0:j1, i0:i1]
        np.minimum(window, np.maximum(low, STOCK_LO[2]), out=window)
    seconds = time.process_time() - started
    removed = float(np.sum(STOCK_HI[2] - top)) * spacing * spacing
    return removed, seconds


def kerf_cut(binary, program_file, rows, spacing):
    """Runs the bench binary on the program; (solve CPU seconds, removed mm³, the line printed)."""
    env = dict(os.environ, KERF_BENCH_PROGRAM=program_file, KERF_BENCH_SPACING=str(spacing),
               KERF_BENCH_ROWS=str(rows))
    output = subprocess.run([binary, "--bench", "no-criterion-bench-matches-this"], env=env,
                            capture_output=True, text=True, check=True).stdout
    line = next(line for line in output.splitlines() if line.startswith("verify raster"))
    removed = float(re.search(r"removed ([0-9.]+) mm³", line).group(1))
    seconds = float(re.search(r"CPU ([0-9.]+) s", line).group(1))
    return seconds, removed, line


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("bench", help="the verify bench binary (cargo bench --bench verify --no-run)")
    parser.add_argument("--rows", type=int, default=500)
    parser.add_argument("--spacing", type=float, default=0.05)
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    program = raster(args.rows)
    path = tip_path(program)
    with tempfile.TemporaryDirectory() as directory:
        program_file = os.path.join(directory, "raster.nc")
        with open(program_file, "w") as out:
            out.write(program)
        kerf_runs, numpy_runs = [], []
        for _ in range(args.rounds):
            kerf_runs.append(kerf_cut(args.bench, program_file, args.rows, args.spacing))
            numpy_runs.append(numpy_zmap(path, args.spacing))
    kerf_seconds = min(run[0] for run in kerf_runs)
    kerf_removed = kerf_runs[0][1]
    numpy_removed = numpy_runs[0][0]
    numpy_seconds = min(run[1] for run in numpy_runs)
    blocks = sum(1 for line in program.splitlines() if line.startswith("G1"))
    print(kerf_runs[0][2])
    print(f"raster: {blocks} feed moves, spacing {args.spacing} mm, {args.rounds} rounds, least time")
    print(f"kerf  : {kerf_seconds:8.2f} s CPU (the solve), removed {kerf_removed:.1f} mm³")
    print(f"numpy : {numpy_seconds:8.2f} s CPU (the moves), removed {numpy_removed:.1f} mm³")
    print(f"ratio numpy ÷ kerf: {numpy_seconds / kerf_seconds:.1f}")
    difference = abs(kerf_removed / numpy_removed - 1.0)
    print(f"removed volumes differ by {100.0 * difference:.3f} %")
    if difference > 0.005:
        print("the removed volumes differ by more than 0.5 %", file=sys.stderr)
        sys.exit(1)


if __name__ == "__main__":
    main()
