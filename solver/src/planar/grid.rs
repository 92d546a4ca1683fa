//! A sparse uniform grid (docs/spec/contour.md §3.1 simplicity, §3.5.5 gouge check) over line
//! segments for near-neighbour and intersection queries, and the simple-polygon check built on it
//! (no `O(n²)` pair loop: each edge is tested only against the edges sharing its grid cells).
//!
//! The grid stores `(cell, segment)` entries sorted by cell, column-major, so that every column's
//! cells form one contiguous run found by binary search: memory is proportional to the number of
//! cells the segments cross, never to the bounding box. The cell size starts at the median segment
//! length (or the caller's query radius, if larger) and doubles until the entry count stays within
//! a budget, so long or clustered edges cannot blow up memory. Everything is deterministic.

use crate::control::Control;

use super::{Containment, Vec2, orientation, segment_segment_distance, segments_intersect, within_box};

/// Largest cell index per axis (cells are addressed by two 31-bit numbers).
const MAX_CELLS_PER_AXIS: f64 = 1_048_576.0;

/// Why a check of the grid stopped before its answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CheckStopped {
    /// It needed more work than its budget allows (a pathological input: very many edges
    /// crowded into the same cells).
    Budget,
    /// Its control's cancel flag was raised.
    Cancelled,
}

/// Line segments indexed by a sparse uniform grid.
#[derive(Debug, Clone)]
pub struct SegmentGrid {
    segments: Vec<(Vec2, Vec2)>,
    origin: Vec2,
    cell: f64,
    keys: Vec<u64>,
    items: Vec<u32>,
}

impl SegmentGrid {
    /// Indexes `segments`; `min_cell` is a lower bound on the cell size (use the typical query
    /// radius). Non-finite coordinates must be rejected before.
    pub fn new(segments: Vec<(Vec2, Vec2)>, min_cell: f64) -> Self {
        let mut low = Vec2::repeat(f64::INFINITY);
        let mut high = Vec2::repeat(f64::NEG_INFINITY);
        for (a, b) in &segments {
            low = low.inf(a).inf(b);
            high = high.sup(a).sup(b);
        }
        if segments.is_empty() {
            (low, high) = (Vec2::zeros(), Vec2::zeros());
        }
        let extent = (high - low).max().max(1e-9);
        let mut lengths: Vec<f64> = segments.iter().map(|(a, b)| (b - a).norm()).collect();
        let median = if lengths.is_empty() {
            0.0
        } else {
            let middle = lengths.len() / 2;
            *lengths.select_nth_unstable_by(middle, f64::total_cmp).1
        };
        let mut cell = min_cell.max(median).max(extent / MAX_CELLS_PER_AXIS).max(1e-9);
        let budget = 16.0 * segments.len() as f64 + 4096.0;
        loop {
            let estimate: f64 =
                segments.iter().map(|(a, b)| ((b.x - a.x).abs() + (b.y - a.y).abs()) / cell + 4.0).sum();
            // Coordinates past the float range (refused by every request's validation) would
            // double an infinite cell forever.
            if estimate <= budget || !estimate.is_finite() || cell.is_infinite() {
                break;
            }
            cell *= 2.0;
        }
        let mut grid = Self { segments, origin: low, cell, keys: Vec::new(), items: Vec::new() };
        let pad = cell * 1e-9;
        let mut entries: Vec<(u64, u32)> = Vec::new();
        for (index, (a, b)) in grid.segments.iter().enumerate() {
            let id = u32::try_from(index).unwrap_or(u32::MAX);
            grid.for_each_column(a, b, pad, |column, first, last| {
                for row in first..=last {
                    entries.push((key(column, row), id));
                }
            });
        }
        entries.sort_unstable();
        (grid.keys, grid.items) = entries.into_iter().unzip();
        grid
    }

    /// Number of segments.
    pub fn len(&self) -> usize {
        self.segments.len()
    }

    /// Whether the grid holds no segment.
    pub fn is_empty(&self) -> bool {
        self.segments.is_empty()
    }

    /// Segment `index` as given to [`SegmentGrid::new`].
    pub fn segment(&self, index: usize) -> Option<(Vec2, Vec2)> {
        self.segments.get(index).copied()
    }

    /// The cell size chosen, mm.
    pub fn cell_size(&self) -> f64 {
        self.cell
    }

    /// Calls `f` with the index of every segment that may lie within `radius` of the segment
    /// `[a, b]` (a superset; a segment spanning several cells comes once per cell).
    pub fn visit(&self, a: &Vec2, b: &Vec2, radius: f64, mut f: impl FnMut(usize)) {
        let pad = radius.max(0.0) + self.cell * 1e-9;
        self.for_each_column(a, b, pad, |column, first, last| {
            let low = self.keys.partition_point(|k| *k < key(column, first));
            let high = self.keys.partition_point(|k| *k <= key(column, last));
            for &item in &self.items[low..high] {
                f(item as usize);
            }
        });
    }

    /// Appends to `out` the indices of every segment that may lie within `radius` of the segment
    /// `[a, b]` (a superset; sorted, without repeats).
    pub fn candidates(&self, a: &Vec2, b: &Vec2, radius: f64, out: &mut Vec<usize>) {
        let start = out.len();
        self.visit(a, b, radius, |i| out.push(i));
        out[start..].sort_unstable();
        let mut unique = start;
        for read in start..out.len() {
            if unique == start || out[read] != out[unique - 1] {
                out[unique] = out[read];
                unique += 1;
            }
        }
        out.truncate(unique);
    }

    /// The smallest distance from the segment `[a, b]` to an indexed segment within `radius`, with
    /// that segment's index; segments for which `skip` is true are ignored. `None` when no segment
    /// lies within `radius`.
    pub fn nearest(
        &self,
        a: &Vec2,
        b: &Vec2,
        radius: f64,
        scratch: &mut Vec<usize>,
        skip: impl Fn(usize) -> bool,
    ) -> Option<(f64, usize)> {
        scratch.clear();
        let (low, high) = (a.inf(b).add_scalar(-radius), a.sup(b).add_scalar(radius));
        let mut best: Option<(f64, usize)> = None;
        self.visit(a, b, radius, |index| {
            let (c, d) = self.segments[index];
            // Bounding boxes farther apart than the radius cannot hold a closer pair.
            if c.x.max(d.x) < low.x || c.x.min(d.x) > high.x || c.y.max(d.y) < low.y || c.y.min(d.y) > high.y {
                return;
            }
            if best.is_some_and(|(_, i)| i == index) || skip(index) {
                return;
            }
            let distance = segment_segment_distance(a, b, &c, &d);
            if distance <= radius && best.is_none_or(|(d0, i0)| distance < d0 || (distance == d0 && index < i0)) {
                best = Some((distance, index));
            }
        });
        best
    }

    /// Where `point` lies relative to the closed polygon whose edges this grid indexes (as
    /// [`super::point_in_polygon`], with the ray cast upwards): only the edges in the point's grid
    /// column are tested, so a query costs the column's edges, not the whole polygon's.
    /// `scratch` is reused between calls.
    pub fn containment(&self, point: &Vec2, scratch: &mut Vec<usize>) -> Containment {
        scratch.clear();
        let top = Vec2::new(point.x, self.origin.y + self.cell * 2.0 * MAX_CELLS_PER_AXIS);
        self.candidates(point, &top, 0.0, scratch);
        let mut inside = false;
        for &index in scratch.iter() {
            let (a, b) = self.segments[index];
            let side = orientation(&a, &b, point);
            if side == std::cmp::Ordering::Equal && within_box(point, &a, &b) {
                return Containment::Boundary;
            }
            // The edge crosses the ray when it spans the point's abscissa and the point lies
            // below it: on the right of an edge going +x, on the left of one going −x.
            let rightwards = b.x > point.x;
            if (a.x > point.x) != rightwards && (side == std::cmp::Ordering::Less) == rightwards {
                inside = !inside;
            }
        }
        if inside { Containment::Inside } else { Containment::Outside }
    }

    fn cell_of(&self, value: f64, origin: f64) -> u32 {
        let index = ((value - origin) / self.cell).floor();
        // Clamped into the grid; a query outside the box simply maps to its border cells, which
        // only adds candidates.
        index.clamp(0.0, 2.0 * MAX_CELLS_PER_AXIS) as u32
    }

    /// Calls `f(column, first_row, last_row)` for every column whose cells may hold a point within
    /// `pad` of the segment `[a, b]`.
    fn for_each_column(&self, a: &Vec2, b: &Vec2, pad: f64, mut f: impl FnMut(u32, u32, u32)) {
        let (x_low, x_high) = (a.x.min(b.x), a.x.max(b.x));
        let first = self.cell_of(x_low - pad, self.origin.x);
        let last = self.cell_of(x_high + pad, self.origin.x);
        for column in first..=last {
            let slab_low = self.origin.x + f64::from(column) * self.cell - pad;
            let slab_high = slab_low + self.cell + 2.0 * pad;
            let (y_low, y_high) = if b.x == a.x {
                (a.y.min(b.y), a.y.max(b.y))
            } else {
                let at = |x: f64| {
                    let t = ((x - a.x) / (b.x - a.x)).clamp(0.0, 1.0);
                    a.y + t * (b.y - a.y)
                };
                let (y0, y1) = (at(slab_low.max(x_low)), at(slab_high.min(x_high)));
                (y0.min(y1), y0.max(y1))
            };
            let row_first = self.cell_of(y_low - pad, self.origin.y);
            let row_last = self.cell_of(y_high + pad, self.origin.y);
            f(column, row_first, row_last);
        }
    }
}

fn key(column: u32, row: u32) -> u64 {
    (u64::from(column) << 32) | u64::from(row)
}

/// The first pair of edges `(i, j)`, `i < j`, of a closed polygon that meet where they should
/// not (edge `i` runs from vertex `i` to vertex `i + 1`): non-adjacent edges that touch or cross,
/// or adjacent edges that fold back onto each other. `Ok(None)` for a simple polygon. The pair is
/// the lexicographically smallest, so the answer does not depend on the grid.
///
/// # Errors
/// [`CheckStopped::Budget`] when more than `64·n + 10⁶` edge pairs would need testing,
/// [`CheckStopped::Cancelled`] once `control`'s cancel flag is raised (looked at every 1 024 edges:
/// a contour of 200 000 points takes about 0.1 s).
pub fn find_self_intersection(polygon: &[Vec2], control: Control<'_>) -> Result<Option<(usize, usize)>, CheckStopped> {
    let n = polygon.len();
    if n < 3 {
        return Ok(None);
    }
    let edges: Vec<(Vec2, Vec2)> = (0..n).map(|i| (polygon[i], polygon[(i + 1) % n])).collect();
    let grid = SegmentGrid::new(edges, 0.0);
    let budget = 64 * n + 1_000_000;
    let mut tests = 0usize;
    let mut candidates = Vec::new();
    for i in 0..n {
        if control.check_at(i).is_err() {
            return Err(CheckStopped::Cancelled);
        }
        let (a, b) = (polygon[i], polygon[(i + 1) % n]);
        candidates.clear();
        grid.candidates(&a, &b, 0.0, &mut candidates);
        let mut hit: Option<usize> = None;
        for &j in candidates.iter().filter(|&&j| j > i) {
            tests += 1;
            if tests > budget {
                return Err(CheckStopped::Budget);
            }
            let (c, d) = (polygon[j], polygon[(j + 1) % n]);
            let meets = if j == i + 1 {
                folds_back(&b, &a, &d)
            } else if i == 0 && j == n - 1 {
                folds_back(&a, &b, &c)
            } else {
                segments_intersect(&a, &b, &c, &d)
            };
            if meets && hit.is_none_or(|h| j < h) {
                hit = Some(j);
            }
        }
        if let Some(j) = hit {
            return Ok(Some((i, j)));
        }
    }
    Ok(None)
}

/// Whether two edges leaving the shared vertex `shared` towards `p` and `q` overlap.
fn folds_back(shared: &Vec2, p: &Vec2, q: &Vec2) -> bool {
    orientation(shared, p, q) == std::cmp::Ordering::Equal && (p - shared).dot(&(q - shared)) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planar::vec2;

    fn polygon(points: &[[f64; 2]]) -> Vec<Vec2> {
        points.iter().copied().map(vec2).collect()
    }

    #[test]
    fn containment_agrees_with_the_full_scan() {
        use crate::planar::point_in_polygon;
        // A star with 400 spikes and points on a fine lattice over it, some on its vertices.
        let star: Vec<Vec2> = (0..800)
            .map(|k| {
                let angle = std::f64::consts::TAU * f64::from(k) / 800.0;
                let radius = if k % 2 == 0 { 30.0 } else { 27.0 };
                Vec2::new(radius * angle.cos(), radius * angle.sin())
            })
            .collect();
        let grid = SegmentGrid::new((0..star.len()).map(|k| (star[k], star[(k + 1) % star.len()])).collect(), 0.0);
        let mut scratch = Vec::new();
        let mut points: Vec<Vec2> = star.iter().step_by(7).copied().collect();
        for i in -70..=70 {
            for j in -70..=70 {
                points.push(Vec2::new(f64::from(i) * 0.47, f64::from(j) * 0.45));
            }
        }
        for point in &points {
            assert_eq!(grid.containment(point, &mut scratch), point_in_polygon(point, &star), "{point:?}");
        }
    }

    #[test]
    fn simple_and_crossing_polygons() {
        let square = polygon(&[[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
        assert_eq!(find_self_intersection(&square, Control::default()), Ok(None));
        let bow_tie = polygon(&[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]);
        assert_eq!(find_self_intersection(&bow_tie, Control::default()), Ok(Some((0, 2))));
        let spike = polygon(&[[0.0, 0.0], [2.0, 0.0], [1.0, 0.0], [1.0, 1.0]]);
        assert_eq!(find_self_intersection(&spike, Control::default()), Ok(Some((0, 1))));
        let touching = polygon(&[[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [2.0, 0.0], [0.0, 4.0]]);
        assert!(find_self_intersection(&touching, Control::default()).unwrap().is_some());
    }

    #[test]
    fn large_circle_is_simple_and_a_dent_is_found() {
        let n = 20_000;
        let mut points: Vec<Vec2> = (0..n)
            .map(|i| {
                let angle = std::f64::consts::TAU * f64::from(i) / f64::from(n);
                Vec2::new(angle.cos(), angle.sin()) * 100.0
            })
            .collect();
        assert_eq!(find_self_intersection(&points, Control::default()), Ok(None));
        points[5000] = Vec2::new(0.0, -150.0);
        let (i, _) = find_self_intersection(&points, Control::default()).unwrap().unwrap();
        assert!((4990..=5000).contains(&i));
    }

    #[test]
    fn nearest_finds_the_closest_segment_within_the_radius() {
        let segments = vec![
            (Vec2::new(0.0, 0.0), Vec2::new(10.0, 0.0)),
            (Vec2::new(0.0, 3.0), Vec2::new(10.0, 3.0)),
            (Vec2::new(50.0, 50.0), Vec2::new(60.0, 50.0)),
        ];
        let grid = SegmentGrid::new(segments, 1.0);
        let mut scratch = Vec::new();
        let found = grid.nearest(&Vec2::new(5.0, 1.0), &Vec2::new(6.0, 1.0), 5.0, &mut scratch, |_| false);
        assert_eq!(found, Some((1.0, 0)));
        let skipped = grid.nearest(&Vec2::new(5.0, 1.0), &Vec2::new(6.0, 1.0), 5.0, &mut scratch, |i| i == 0);
        assert_eq!(skipped, Some((2.0, 1)));
        assert!(grid.nearest(&Vec2::new(30.0, 30.0), &Vec2::new(31.0, 30.0), 5.0, &mut scratch, |_| false).is_none());
    }
}
