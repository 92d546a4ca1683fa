//! The initial material W₀ (docs/spec/engagement.md §2.2): polygons with holes (even-odd, boundary
//! inclusive), a bit-packed bitmap, and material already removed by earlier cuts (§5.3.3, prior
//! operations); membership and the circle crossings the exact engine splits at.

use super::P2;
use super::bbox_tree::{BBox, BoxTree};
use super::outline::Outline;
use super::segments::{Shape, circle_segment};

/// Boundary tolerance of the stock outline, mm (docs/spec/engagement.md §5.3.2: ±1e-9).
pub(crate) const BOUNDARY_TOLERANCE: f64 = 1e-9;

/// Relative tolerance of "at least R from the swept path" (§5.3.3: R·(1 − 1e-9)).
pub(crate) const REACH_TOLERANCE: f64 = 1e-9;

/// How far beyond the tool circle, mm, a polygon outline must keep its edges for
/// [`Region::crossings`] to call the circle clear of it: a thousand times the boundary band, so
/// that rounding in the containment test cannot tell points of the disc apart.
pub(crate) const CLEAR_MARGIN: f64 = 1e-6;

/// Where a tool circle lies against a polygon outline.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum OutlineSide {
    /// An edge may come near the circle (or the stock is a bitmap): test every point.
    Near,
    /// No edge within [`CLEAR_MARGIN`] of the disc: every point of it is in the outline or
    /// every point is out.
    Clear,
}

/// How far, as a share of the lookup reach, the tool may move before [`Region::crossings`]
/// asks the outline's grid again.
const NEAR_EDGES_MARGIN: f64 = 0.25;

/// The outline edges whose boxes come within (1 + [`NEAR_EDGES_MARGIN`])·reach of where they
/// were looked up (repeats included). While the tool circle keeps the same reach and its centre
/// stays within NEAR_EDGES_MARGIN·reach of that point in x and y, every edge a lookup at the
/// centre would give is in the list (the grid's wider query visits a superset of cells), so the
/// grid, about 4 % of the exact bench's time when asked at every sample, is asked once per
/// quarter reach of travel.
#[derive(Debug, Default)]
pub(crate) struct NearEdges {
    /// Centre and reach of the lookup (`None`: nothing looked up yet).
    taken: Option<(P2, f64)>,
    edges: Vec<(P2, P2)>,
}

/// A bit-packed raster of material cells.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Bitmap {
    pub origin: P2,
    pub cell: f64,
    pub width: usize,
    pub height: usize,
    /// Row-major from the origin row upwards, most significant bit first.
    pub bytes: Vec<u8>,
}

impl Bitmap {
    /// Whether cell (column, row) holds material; outside the raster is empty.
    pub(crate) fn cell_is_material(&self, column: i64, row: i64) -> bool {
        if column < 0 || row < 0 {
            return false;
        }
        let (column, row) = (column as usize, row as usize);
        if column >= self.width || row >= self.height {
            return false;
        }
        let bit = row * self.width + column;
        self.bytes.get(bit / 8).is_some_and(|byte| byte & (0x80 >> (bit % 8)) != 0)
    }

    /// The cell containing `q`.
    pub(crate) fn cell_of(&self, q: P2) -> (i64, i64) {
        let column = ((q.x - self.origin.x) / self.cell).floor();
        let row = ((q.y - self.origin.y) / self.cell).floor();
        // Far-away points saturate to an index outside the raster.
        (column.clamp(-1.0, 1e15) as i64, row.clamp(-1.0, 1e15) as i64)
    }

    fn contains(&self, q: P2) -> bool {
        let (column, row) = self.cell_of(q);
        self.cell_is_material(column, row)
    }

    fn bbox(&self) -> BBox {
        BBox {
            min: self.origin,
            max: self.origin + P2::new(self.width as f64 * self.cell, self.height as f64 * self.cell),
        }
    }

    /// Angles about `c` where the circle crosses a cell edge between material and empty.
    fn crossings(&self, c: P2, radius: f64, out: &mut Vec<f64>) {
        let cell = self.cell;
        let first_column = ((c.x - radius - self.origin.x) / cell).ceil().max(0.0) as i64;
        let last_column = ((c.x + radius - self.origin.x) / cell).floor().min(self.width as f64) as i64;
        for column in first_column..=last_column {
            let x = self.origin.x + column as f64 * cell;
            let half = (radius * radius - (x - c.x) * (x - c.x)).max(0.0).sqrt();
            for y in [c.y - half, c.y + half] {
                let row = ((y - self.origin.y) / cell).floor() as i64;
                if self.cell_is_material(column - 1, row) != self.cell_is_material(column, row) {
                    out.push((y - c.y).atan2(x - c.x));
                }
            }
        }
        let first_row = ((c.y - radius - self.origin.y) / cell).ceil().max(0.0) as i64;
        let last_row = ((c.y + radius - self.origin.y) / cell).floor().min(self.height as f64) as i64;
        for row in first_row..=last_row {
            let y = self.origin.y + row as f64 * cell;
            let half = (radius * radius - (y - c.y) * (y - c.y)).max(0.0).sqrt();
            for x in [c.x - half, c.x + half] {
                let column = ((x - self.origin.x) / cell).floor() as i64;
                if self.cell_is_material(column, row - 1) != self.cell_is_material(column, row) {
                    out.push((y - c.y).atan2(x - c.x));
                }
            }
        }
    }
}

/// The outline of the initial material.
#[derive(Debug, Clone)]
pub(crate) enum Base {
    /// Rings under the even-odd rule.
    Polygons(Outline),
    /// A raster.
    Bitmap(Bitmap),
}

/// Material removed before this operation: everything within `radius` of `route`.
#[derive(Debug, Clone)]
pub(crate) struct Cut {
    pub shapes: Vec<Shape>,
    pub radius: f64,
    pub tree: BoxTree,
}

impl Cut {
    /// A cut along `shapes` by a cutter of `radius`.
    pub(crate) fn new(shapes: Vec<Shape>, radius: f64) -> Self {
        let boxes: Vec<BBox> = shapes.iter().map(Shape::bbox).collect();
        Self { tree: BoxTree::new(&boxes), shapes, radius }
    }

    /// Pieces that come within `reach` of `centre`.
    pub(crate) fn near(&self, centre: P2, reach: f64, out: &mut Vec<Shape>) {
        let limit = reach + self.radius;
        self.tree.query(&BBox::around(centre, limit), &mut |index| {
            if let Some(shape) = self.shapes.get(index)
                && shape.distance(centre) < limit
            {
                out.push(*shape);
            }
        });
    }

    /// Whether `q` is still material after this cut (closed: exactly `radius` away stays);
    /// adds the pieces examined to `work`.
    pub(crate) fn keeps(&self, q: P2, work: &mut u64) -> bool {
        let limit = self.radius * (1.0 - REACH_TOLERANCE);
        let mut kept = true;
        self.tree.query(&BBox::around(q, self.radius), &mut |index| {
            *work += 1;
            if kept
                && let Some(shape) = self.shapes.get(index)
                && shape.distance(q) < limit
            {
                kept = false;
            }
        });
        kept
    }
}

/// The material the operation starts from.
#[derive(Debug, Clone)]
pub(crate) struct Region {
    pub base: Base,
    pub cuts: Vec<Cut>,
}

impl Region {
    /// Whether `q` is material at the start of the operation (outline, less earlier cuts);
    /// adds the edges and pieces examined to `work`.
    pub(crate) fn contains(&self, q: P2, work: &mut u64) -> bool {
        self.in_outline(q, work) && self.kept_by_cuts(q, work)
    }

    /// Whether `q` lies in the initial outline (earlier cuts not applied); adds the edges
    /// examined to `work`.
    pub(crate) fn in_outline(&self, q: P2, work: &mut u64) -> bool {
        match &self.base {
            Base::Polygons(outline) => outline.contains(q, BOUNDARY_TOLERANCE, work),
            Base::Bitmap(bitmap) => bitmap.contains(q),
        }
    }

    /// Whether no earlier cut has removed `q`; adds the pieces examined to `work`.
    pub(crate) fn kept_by_cuts(&self, q: P2, work: &mut u64) -> bool {
        self.cuts.iter().all(|cut| cut.keeps(q, work))
    }

    /// Where the dot grid is anchored: the bitmap's origin, else the coordinate origin.
    pub(crate) fn anchor(&self) -> P2 {
        match &self.base {
            Base::Polygons { .. } => P2::new(0.0, 0.0),
            Base::Bitmap(bitmap) => bitmap.origin,
        }
    }

    /// Bounding box of the outline.
    pub(crate) fn bbox(&self) -> Option<BBox> {
        match &self.base {
            Base::Polygons(outline) => {
                let mut points = outline.rings().iter().flatten();
                let first = *points.next()?;
                let mut bbox = BBox::of(first, first);
                for p in points {
                    bbox.include(*p);
                }
                Some(bbox)
            }
            Base::Bitmap(bitmap) => Some(bitmap.bbox()),
        }
    }

    /// Adds the polar angles about `c` where circle (`c`, `radius`) crosses the outline or the
    /// boundary of an earlier cut; `near` keeps the outline's edge lookup for the next samples
    /// (see [`NearEdges`]).
    ///
    /// Returns [`OutlineSide::Clear`] when a polygon outline has no edge within
    /// [`CLEAR_MARGIN`] beyond the circle: then the whole disc lies in one face of the outline,
    /// farther than the boundary band from every edge, so the even-odd test gives every point
    /// of it the same answer and one test at `c` stands for all of them.
    pub(crate) fn crossings(&self, c: P2, radius: f64, out: &mut Vec<f64>, near: &mut NearEdges) -> OutlineSide {
        let mut side = OutlineSide::Near;
        match &self.base {
            Base::Polygons(outline) => {
                let reach = radius * (1.0 + 1e-9);
                let margin = NEAR_EDGES_MARGIN * reach;
                let still_valid = near.taken.is_some_and(|(centre, taken_reach)| {
                    taken_reach == reach && (c.x - centre.x).abs() <= margin && (c.y - centre.y).abs() <= margin
                });
                if !still_valid {
                    let edges = &mut near.edges;
                    edges.clear();
                    outline.edges_near(c, reach + CLEAR_MARGIN + margin, |from, to| edges.push((from, to)));
                    near.taken = Some((c, reach));
                }
                // The box test `edges_near` itself makes at `reach`: the edges intersected are
                // those a lookup at `c` would give, plus at most some the wider grid query found
                // that lie beyond `reach` (no angle, or within circle_segment's end slack a split
                // where nothing changes, which the arcs' merge undoes). Repeated edges add the
                // same angles, which the engine merges.
                let (low, high) = (c.add_scalar(-reach), c.add_scalar(reach));
                let (clear_low, clear_high) = (low.add_scalar(-CLEAR_MARGIN), high.add_scalar(CLEAR_MARGIN));
                let mut clear = true;
                for &(from, to) in &near.edges {
                    let (min, max) = (from.inf(&to), from.sup(&to));
                    if max.x >= clear_low.x && min.x <= clear_high.x && max.y >= clear_low.y && min.y <= clear_high.y {
                        clear = false;
                    }
                    if max.x >= low.x && min.x <= high.x && max.y >= low.y && min.y <= high.y {
                        circle_segment(c, radius, from, to, out);
                    }
                }
                if clear {
                    side = OutlineSide::Clear;
                }
            }
            Base::Bitmap(bitmap) => bitmap.crossings(c, radius, out),
        }
        let mut near = Vec::new();
        for cut in &self.cuts {
            near.clear();
            cut.near(c, radius, &mut near);
            for shape in &near {
                shape.crossings(cut.radius, c, radius, out);
            }
        }
        side
    }
}

/// Decodes standard base64 (padding optional, whitespace ignored); `None` on a bad character.
pub(crate) fn decode_base64(text: &str) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(text.len() * 3 / 4);
    let mut buffer = 0_u32;
    let mut bits = 0;
    for byte in text.bytes() {
        let value = match byte {
            b'A'..=b'Z' => byte - b'A',
            b'a'..=b'z' => byte - b'a' + 26,
            b'0'..=b'9' => byte - b'0' + 52,
            b'+' => 62,
            b'/' => 63,
            b'=' | b' ' | b'\n' | b'\r' | b'\t' => continue,
            _ => return None,
        };
        buffer = (buffer << 6) | u32::from(value);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((buffer >> bits) as u8);
            buffer &= (1 << bits) - 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trip_of_known_text() {
        assert_eq!(decode_base64("TWFu").as_deref(), Some(&b"Man"[..]));
        assert_eq!(decode_base64("TWE=").as_deref(), Some(&b"Ma"[..]));
        assert_eq!(decode_base64("TQ").as_deref(), Some(&b"M"[..]));
        assert_eq!(decode_base64("/w==").as_deref(), Some(&[255_u8][..]));
        assert!(decode_base64("T*Q").is_none());
    }

    #[test]
    fn a_clear_circle_is_all_in_or_all_out() {
        // A square with a square hole: circles inside the material, in the hole, outside and
        // across edges.
        let square =
            |low: f64, high: f64| vec![P2::new(low, low), P2::new(high, low), P2::new(high, high), P2::new(low, high)];
        let radius = 1.5;
        let region = Region {
            base: Base::Polygons(Outline::new(vec![square(0.0, 20.0), square(8.0, 12.0)], radius)),
            cuts: Vec::new(),
        };
        let mut near = NearEdges::default();
        let (mut clear, mut crossing) = (0, 0);
        for step in 0..600 {
            // A walk with small steps (the kept edge list is reused) and jumps.
            let t = f64::from(step);
            let centre = P2::new(10.0 + 13.0 * (0.013 * t).sin(), 10.0 + 13.0 * (0.021 * t + 0.4).cos());
            let mut angles = Vec::new();
            let side = region.crossings(centre, radius, &mut angles, &mut near);
            let inside = region.in_outline(centre, &mut 0);
            let agree = (0..64).all(|k| {
                let angle = f64::from(k) * std::f64::consts::TAU / 64.0;
                region.in_outline(centre + radius * P2::new(angle.cos(), angle.sin()), &mut 0) == inside
            });
            if side == OutlineSide::Clear {
                clear += 1;
                assert!(angles.is_empty() && agree, "{centre:?}");
            } else if !agree {
                crossing += 1;
                assert!(!angles.is_empty(), "{centre:?}");
            }
        }
        assert!(clear > 100 && crossing > 100, "{clear} clear, {crossing} crossing");
    }

    #[test]
    fn bitmap_cells_and_crossings() {
        // 4 × 2 raster, material in columns 1 and 2 of row 0 only: 0110 0000.
        let bitmap = Bitmap { origin: P2::new(0.0, 0.0), cell: 1.0, width: 4, height: 2, bytes: vec![0b0110_0000] };
        assert!(bitmap.contains(P2::new(1.5, 0.5)));
        assert!(!bitmap.contains(P2::new(0.5, 0.5)));
        assert!(!bitmap.contains(P2::new(1.5, 1.5)));
        assert!(!bitmap.contains(P2::new(-3.0, 0.5)));
        let mut angles = Vec::new();
        bitmap.crossings(P2::new(2.0, 1.0), 0.8, &mut angles);
        // The circle crosses x = 2 (inside the material row: no change), y = 1 at x = 1.2 and
        // 2.8 (material below, empty above): two crossings.
        assert_eq!(angles.len(), 2);
    }
}
