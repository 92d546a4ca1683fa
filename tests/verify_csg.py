"""Removed volume of a verify case by constructive solid geometry with manifold3d, a library kerf
did not write: each straight move of the tool sweeps the convex hull of the cutter at its two
ends (exact for a convex body moved along a line), the union of those hulls is intersected with
the stock box, and its volume is what the program removes.

Reads JSON on stdin: {"stock": {"min": [x, y, z], "max": [x, y, z]},
"tool": {"kind": "flat" | "ball", "radius": R, "length": L},
"paths": [[[x, y, z], ...], ...]} (each path a polyline of tip positions) and writes
{"removed_mm3": V} on stdout. Run by tests/tests/api/verify.rs.
"""

import json
import sys

from manifold3d import Manifold, OpType

SEGMENTS = 128


def cutter(tool):
    """The cutter with its tip at the origin, pointing down."""
    radius, length = tool["radius"], tool["length"]
    if tool["kind"] == "flat":
        return Manifold.cylinder(length, radius, radius, SEGMENTS)
    if tool["kind"] == "ball":
        ball = Manifold.sphere(radius, SEGMENTS).translate((0, 0, radius))
        shank = Manifold.cylinder(length - radius, radius, radius, SEGMENTS).translate((0, 0, radius))
        return Manifold.batch_hull([ball, shank])
    raise ValueError(f"tool kind {tool['kind']}")


def main():
    case = json.load(sys.stdin)
    body = cutter(case["tool"])
    swept = []
    for path in case["paths"]:
        for start, end in zip(path, path[1:]):
            swept.append(Manifold.batch_hull([body.translate(tuple(start)), body.translate(tuple(end))]))
    sweep = Manifold.batch_boolean(swept, OpType.Add)
    low, high = case["stock"]["min"], case["stock"]["max"]
    stock = Manifold.cube([high[k] - low[k] for k in range(3)]).translate(tuple(low))
    removed = Manifold.batch_boolean([stock, sweep], OpType.Intersect)
    json.dump({"removed_mm3": removed.volume()}, sys.stdout)


if __name__ == "__main__":
    main()
