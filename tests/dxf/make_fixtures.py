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
