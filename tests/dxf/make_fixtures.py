"""Writes the DXF fixtures of kerf's DXF tests with ezdxf (a DXF library kerf did not write).

Run from the repository root: `python3 tests/dxf/make_fixtures.py` (needs `pip install
ezdxf==1.4.5`); the files are committed, so the tests do not need ezdxf.
"""
import math
import os

import ezdxf
from ezdxf import units

HERE = os.path.dirname(os.path.abspath(__file__))


def new(version, unit):
    doc = ezdxf.new(version)
    doc.header["$INSUNITS"] = unit
    return doc, doc.modelspace()


def save(doc, name, binary=False):
    path = os.path.join(HERE, name)
    if binary:
        doc.saveas(path, fmt="bin")
    else:
        doc.saveas(path)


# A 100 x 60 mm plate with 10 mm corner radii (an LWPOLYLINE with bulges), an island circle of
# radius 8 at (30, 30), and a slot from LINE and ARC entities written out of order and reversed.
doc, msp = new("R2018", units.MM)
bulge = math.tan(math.radians(90) / 4)  # a quarter turn counter-clockwise
msp.add_lwpolyline(
    [(10, 0, 0), (90, 0, bulge), (100, 10, 0), (100, 50, bulge), (90, 60, 0), (10, 60, bulge), (0, 50, 0), (0, 10, bulge)],
    format="xyb",
    close=True,
    dxfattribs={"layer": "CUT"},
)
msp.add_circle((30, 30), 8, dxfattribs={"layer": "CUT"})
msp.add_line((60, 25), (80, 25), dxfattribs={"layer": "CUT"})
msp.add_arc((80, 30), 5, -90, 90, dxfattribs={"layer": "CUT"})
msp.add_line((60, 35), (80, 35.0), dxfattribs={"layer": "CUT"})
msp.add_arc((60, 30), 5, 90, 270, dxfattribs={"layer": "CUT"})
msp.add_line((-20, -20), (-10, -20), dxfattribs={"layer": "NOTES"})
save(doc, "plate_mm.dxf")

# A 2 x 2 inch square as an R12 POLYLINE (R12 has no $INSUNITS: the reader must be told the units).
doc, msp = new("R12", units.IN)
msp.add_polyline2d([(0, 0), (2, 0), (2, 2), (0, 2)], close=True)
save(doc, "square_inch_r12.dxf")

# The same square in binary R12 and the plate's outline in binary R2010.
save(doc, "square_inch_r12_binary.dxf", binary=True)

# A closed cubic SPLINE through a rounded blob and an ELLIPSE island, binary R2010, in cm.
doc, msp = new("R2010", units.CM)
points = [(4 * math.cos(t), 3 * math.sin(t)) for t in [k * math.tau / 8 for k in range(8)]]
msp.add_spline_control_frame(points + [points[0]], degree=3)
msp.add_ellipse((0, 0), major_axis=(1, 0), ratio=0.5)
save(doc, "spline_ellipse_cm_binary.dxf", binary=True)

# A chain of lines with a 0.5 mm gap at (40, 30).
doc, msp = new("R2013", units.MM)
msp.add_line((0, 0), (40, 0))
msp.add_line((40, 0), (40, 30))
msp.add_line((40, 30.5), (0, 30))
msp.add_line((0, 30), (0, 0))
save(doc, "broken_chain.dxf")

# A drawing without units.
doc, msp = new("R2013", 0)
msp.add_lwpolyline([(0, 0), (10, 0), (10, 10), (0, 10)], close=True)
save(doc, "no_units.dxf")

# A bow tie: the outline crosses itself at (5, 5).
doc, msp = new("R2013", units.MM)
msp.add_lwpolyline([(0, 0), (10, 10), (10, 0), (0, 10)], close=True)
save(doc, "bow_tie.dxf")

# The typed polygon of the contour tests' L-shaped plate, as LINE entities in mm.
doc, msp = new("R2000", units.MM)
polygon = [(0, 0), (80, 0), (80, 30), (40, 30), (40, 60), (0, 60)]
for a, b in zip(polygon, polygon[1:] + polygon[:1]):
    msp.add_line(a, b)
save(doc, "l_plate_lines.dxf")

# An open cubic SPLINE, clamped, in mm: segment's exact curve (the same control points, knots
# and weights typed in give the same answer).
doc, msp = new("R2018", units.MM)
msp.add_open_spline([(0, 0), (20, 30), (50, -10), (80, 25), (100, 0)], degree=3)
save(doc, "spline_open_mm.dxf")

# A rational quadratic SPLINE (weights) in inch: a quarter circle of radius 2 in.
doc, msp = new("R2018", units.IN)
msp.add_rational_spline([(2, 0), (2, 2), (0, 2)], [1, math.sqrt(0.5), 1], degree=2, knots=[0, 0, 0, 1, 1, 1])
save(doc, "spline_rational_inch.dxf")

# A closed periodic cubic SPLINE (unclamped knots) round a 40 x 30 mm blob.
doc, msp = new("R2018", units.MM)
blob = [(20 * math.cos(t), 15 * math.sin(t)) for t in [k * math.tau / 8 for k in range(8)]]
spline = msp.add_spline(dxfattribs={"degree": 3})
spline.control_points = blob + blob[:3]
spline.knots = list(range(len(blob) + 3 + 3 + 1))
spline.closed = True
save(doc, "spline_periodic_mm.dxf")

# Blocks: a 120 x 80 plate of LINEs in block PLATE (base (10, 10), placed at (10, 10)); block
# HOLE, a radius-2 circle on layer 0 (it takes its INSERT's layer), placed twice inside block
# PAIR (at x = 0 and x = 20), and PAIR placed at (30, 40) scaled 1.5 and at (70, 20) turned 90°;
# block SLOT, an open slot of lines and arcs, placed at (100, 60) mirrored (x scale -1); one
# MINSERT-style array of HOLE 3 columns x 1 row spaced 10 at (20, 70); a TEXT on layer NOTES.
doc, msp = new("R2018", units.MM)
plate = doc.blocks.new("PLATE", base_point=(10, 10))
corners = [(10, 10), (130, 10), (130, 90), (10, 90)]
for a, b in zip(corners, corners[1:] + corners[:1]):
    plate.add_line(a, b, dxfattribs={"layer": "CUT"})
hole = doc.blocks.new("HOLE")
hole.add_circle((0, 0), 2)
pair = doc.blocks.new("PAIR")
pair.add_blockref("HOLE", (0, 0))
pair.add_blockref("HOLE", (20, 0))
slot = doc.blocks.new("SLOT")
slot.add_line((0, -3), (8, -3))
slot.add_arc((8, 0), 3, -90, 90)
slot.add_line((8, 3), (0, 3))
slot.add_arc((0, 0), 3, 90, 270)
msp.add_blockref("PLATE", (10, 10))
msp.add_blockref("PAIR", (30, 40), dxfattribs={"layer": "CUT", "xscale": 1.5, "yscale": 1.5})
msp.add_blockref("PAIR", (70, 20), dxfattribs={"layer": "CUT", "rotation": 90})
msp.add_blockref("SLOT", (100, 60), dxfattribs={"layer": "CUT", "xscale": -1})
msp.add_blockref(
    "HOLE", (20, 70), dxfattribs={"layer": "CUT", "column_count": 3, "row_count": 1, "column_spacing": 10}
)
msp.add_text("PLATE 1", dxfattribs={"layer": "NOTES"})
save(doc, "blocks_mm.dxf")
save(doc, "blocks_mm_binary.dxf", binary=True)

# A block that places itself.
doc, msp = new("R2018", units.MM)
loop = doc.blocks.new("LOOP")
loop.add_circle((0, 0), 1)
loop.add_blockref("LOOP", (5, 0))
msp.add_blockref("LOOP", (0, 0))
save(doc, "block_loop.dxf")
