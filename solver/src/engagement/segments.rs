//! The tool-centre path as lines and arcs (G1/G2/G3): lengths, points, tangents, distances, the
//! boundary crossings the exact engine needs, and the sampling of docs/spec/engagement.md §5.2.

use std::f64::consts::{PI, TAU};

use super::P2;
use super::bbox_tree::{BBox, BoxTree};
use crate::machine::{BlockRule, Infeasible};
use crate::planar::point_segment_distance;

/// One geometric piece of a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Shape {
    /// Straight move.
    Line { from: P2, to: P2 },
    /// Circular move: `start` angle (rad) about `centre`, signed `sweep` (rad, positive ccw).
    Arc { centre: P2, radius: f64, start: f64, sweep: f64 },
}

impl Shape {
    /// Length in mm.
    pub(crate) fn length(&self) -> f64 {
        match *self {
            Self::Line { from, to } => (to - from).norm(),
            Self::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    /// The point `local` mm along the piece.
    pub(crate) fn point(&self, local: f64) -> P2 {
        match *self {
            Self::Line { from, to } => {
                let length = (to - from).norm();
                if length == 0.0 { from } else { from + (to - from) * (local / length).clamp(0.0, 1.0) }
            }
            Self::Arc { centre, radius, start, sweep } => {
                let angle = start + sweep.signum() * (local / radius).clamp(0.0, sweep.abs());
                centre + radius * P2::new(angle.cos(), angle.sin())
            }
        }
    }

    /// The unit direction of motion `local` mm along the piece.
    pub(crate) fn tangent(&self, local: f64) -> P2 {
        match *self {
            Self::Line { from, to } => {
                let d = to - from;
                let length = d.norm();
                if length == 0.0 { P2::new(1.0, 0.0) } else { d / length }
            }
            Self::Arc { radius, start, sweep, .. } => {
                let angle = start + sweep.signum() * (local / radius).clamp(0.0, sweep.abs());
                sweep.signum() * P2::new(-angle.sin(), angle.cos())
            }
        }
    }

    /// First point.
    pub(crate) fn start_point(&self) -> P2 {
        self.point(0.0)
    }

    /// Last point.
    pub(crate) fn end_point(&self) -> P2 {
        match *self {
            Self::Line { to, .. } => to,
            Self::Arc { .. } => self.point(self.length()),
        }
    }

    /// The first `local` mm of the piece.
    pub(crate) fn truncated(&self, local: f64) -> Self {
        self.portion(0.0, local)
    }

    /// The part of the piece from `from` to `to` mm along it.
    pub(crate) fn portion(&self, from: f64, to: f64) -> Self {
        match *self {
            Self::Line { .. } => Self::Line { from: self.point(from), to: self.point(to) },
            Self::Arc { centre, radius, start, sweep } => {
                let first = (from / radius).clamp(0.0, sweep.abs());
                let last = (to / radius).clamp(first, sweep.abs());
                Self::Arc {
                    centre,
                    radius,
                    start: start + sweep.signum() * first,
                    sweep: sweep.signum() * (last - first),
                }
            }
        }
    }

    /// Whether the polar angle `angle` about an arc's centre lies within its sweep.
    fn in_sweep(start: f64, sweep: f64, angle: f64) -> bool {
        let offset = if sweep >= 0.0 { (angle - start).rem_euclid(TAU) } else { (start - angle).rem_euclid(TAU) };
        offset <= sweep.abs() || sweep.abs() >= TAU
    }

    /// Euclidean distance from `q` to the piece (docs/spec/engagement.md §5.3.3, distance helpers).
    pub(crate) fn distance(&self, q: P2) -> f64 {
        match *self {
            Self::Line { from, to } => point_segment_distance(&q, &from, &to),
            Self::Arc { centre, radius, start, sweep } => {
                let d = q - centre;
                let ends = (q - self.start_point()).norm().min((q - self.end_point()).norm());
                if d.norm_squared() > 0.0 && Self::in_sweep(start, sweep, d.y.atan2(d.x)) {
                    (d.norm() - radius).abs().min(ends)
                } else if d.norm_squared() == 0.0 {
                    radius
                } else {
                    ends
                }
            }
        }
    }

    /// Bounding box.
    pub(crate) fn bbox(&self) -> BBox {
        match *self {
            Self::Line { from, to } => BBox::of(from, to),
            Self::Arc { centre, radius, start, sweep } => {
                let mut bbox = BBox::of(self.start_point(), self.end_point());
                for quarter in 0..4 {
                    let angle = f64::from(quarter) * PI / 2.0;
                    if Self::in_sweep(start, sweep, angle) {
                        bbox.include(centre + radius * P2::new(angle.cos(), angle.sin()));
                    }
                }
                bbox
            }
        }
    }

    /// Adds to `out` the polar angles (about `centre`, rad) of the points of the circle
    /// (`centre`, `radius`) lying at distance `reach` from this piece: every place where the
    /// circle can enter or leave the piece's `reach`-neighbourhood (extra angles do no harm).
    pub(crate) fn crossings(&self, reach: f64, centre: P2, radius: f64, out: &mut Vec<f64>) {
        match *self {
            Self::Line { from, to } => {
                let d = to - from;
                let length = d.norm();
                if length > 0.0 {
                    let normal = P2::new(-d.y, d.x) / length * reach;
                    circle_segment(centre, radius, from + normal, to + normal, out);
                    circle_segment(centre, radius, from - normal, to - normal, out);
                }
                circle_circle(centre, radius, from, reach, out);
                circle_circle(centre, radius, to, reach, out);
            }
            Self::Arc { centre: arc_centre, radius: arc_radius, .. } => {
                circle_circle(centre, radius, arc_centre, arc_radius + reach, out);
                if arc_radius > reach {
                    circle_circle(centre, radius, arc_centre, arc_radius - reach, out);
                }
                circle_circle(centre, radius, self.start_point(), reach, out);
                circle_circle(centre, radius, self.end_point(), reach, out);
            }
        }
    }

    /// Number of chords [`Self::flatten`] gives for `sagitta` (1 for a line).
    pub(crate) fn chord_count(&self, sagitta: f64) -> f64 {
        match *self {
            Self::Line { .. } => 1.0,
            Self::Arc { radius, sweep, .. } => {
                let half_angle = if sagitta >= radius { PI / 2.0 } else { (1.0 - sagitta / radius).acos() };
                (sweep.abs() / (2.0 * half_angle.max(1e-9))).ceil().max(1.0)
            }
        }
    }

    /// Points along the piece (first and last included) whose chords stay within `sagitta` of
    /// it; a line gives its two ends. Callers bound the count with [`Self::chord_count`].
    pub(crate) fn flatten(&self, sagitta: f64) -> Vec<P2> {
        self.flatten_into(self.chord_count(sagitta).min(1e8) as usize)
    }

    /// Points along the piece (first and last included) in `count` equal chords; a line gives its
    /// two ends.
    pub(crate) fn flatten_into(&self, count: usize) -> Vec<P2> {
        match *self {
            Self::Line { from, to } => vec![from, to],
            Self::Arc { .. } => {
                let count = count.max(1);
                let length = self.length();
                (0..=count).map(|i| self.point(length * i as f64 / count as f64)).collect()
            }
        }
    }

    /// Chords of an arc under the block-time rule `rule`: as few as keep each chord's sagitta
    /// within the rule's chord error (the floor: every chord at least one block long), and at
    /// least as many as `tolerance` needs (the ceiling there: the accuracy bound wins, and the
    /// second value says so). A line is one chord.
    ///
    /// # Errors
    /// [`Infeasible`] when the arc cannot hold one block at the rule's feed (docs/spec/segment.md E3).
    pub(crate) fn rule_chords(&self, rule: &BlockRule, tolerance: f64) -> Result<(usize, bool), Infeasible> {
        let Self::Arc { radius, sweep, .. } = *self else { return Ok((1, false)) };
        let (chord_error, _) = rule.chord_error(radius)?;
        let tolerance_chords = self.chord_count(tolerance) as usize;
        let half_angle = if chord_error >= radius { PI / 2.0 } else { (1.0 - chord_error / radius).acos() };
        // Saturating float → integer conversion; the program caps the count.
        let block_chords = ((sweep.abs() / (2.0 * half_angle.max(1e-9))).floor() as usize).max(1);
        Ok((block_chords.max(tolerance_chords), tolerance_chords > block_chords))
    }
}

/// Adds the polar angles about `c` of the points where circle (`c`, `radius`) meets the segment
/// `[p0, p1]` (tangency included, with a little slack at the ends).
pub(crate) fn circle_segment(c: P2, radius: f64, p0: P2, p1: P2, out: &mut Vec<f64>) {
    let d = p1 - p0;
    let length_squared = d.norm_squared();
    if length_squared == 0.0 {
        return;
    }
    let t_foot = (c - p0).dot(&d) / length_squared;
    let foot = p0 + t_foot * d;
    let offset = foot - c;
    let distance_squared = offset.norm_squared();
    let limit = radius * radius;
    if distance_squared > limit * (1.0 + 1e-9) {
        return;
    }
    let half = (limit - distance_squared).max(0.0).sqrt() / length_squared.sqrt();
    let slack = 1e-9;
    for t in [t_foot - half, t_foot + half] {
        if (-slack..=1.0 + slack).contains(&t) {
            let q = p0 + t * d - c;
            out.push(q.y.atan2(q.x));
        }
    }
}

/// Adds the polar angles about `c` of the points where circle (`c`, `radius`) meets circle
/// (`other`, `other_radius`) (tangency included; concentric circles add nothing).
pub(crate) fn circle_circle(c: P2, radius: f64, other: P2, other_radius: f64, out: &mut Vec<f64>) {
    let between = other - c;
    let distance = between.norm();
    let scale = radius + other_radius;
    if distance <= 1e-12 * scale {
        return;
    }
    let slack = 1e-9 * scale;
    if distance > scale + slack || distance < (radius - other_radius).abs() - slack {
        return;
    }
    let along = (distance * distance + radius * radius - other_radius * other_radius) / (2.0 * distance);
    let across = (radius * radius - along * along).max(0.0).sqrt();
    let axis = between / distance;
    let normal = P2::new(-axis.y, axis.x);
    for sign in [-1.0, 1.0] {
        let q = along * axis + sign * across * normal;
        out.push(q.y.atan2(q.x));
    }
}

/// One piece of a path with its place along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Piece {
    pub shape: Shape,
    /// Path length before the piece.
    pub start_s: f64,
    /// Feed length (rapids excluded) before the piece.
    pub start_feed: f64,
    /// Positioning move: does not cut, not timed (docs/spec/engagement.md §5.8).
    pub rapid: bool,
    /// Index of the segment in the request (for a point list: the segment from point i).
    pub source: usize,
}

impl Piece {
    /// Path length at the piece's end.
    pub(crate) fn end_s(&self) -> f64 {
        self.start_s + self.shape.length()
    }
}

/// A whole path: its pieces in order and a tree over them.
#[derive(Debug, Clone)]
pub(crate) struct Route {
    pub pieces: Vec<Piece>,
    pub tree: BoxTree,
    pub length: f64,
    pub feed_length: f64,
}

/// How far, as a share of the reach, the tool may move before [`Route::swept_before`] asks the
/// tree again.
const NEAR_MARGIN: f64 = 0.25;

/// The earlier pieces whose boxes overlap the square of half-side (1 + [`NEAR_MARGIN`])·reach
/// around where they were looked up, most recent first. While the tool stays on the same piece
/// within NEAR_MARGIN·reach of that point (in x and in y), every piece whose box overlaps its
/// own square of half-side reach is in the list, so the tree (about 4 % of the exact bench's
/// time when asked at every sample) is asked once per quarter reach of travel; the exact
/// distance test that follows decides as before.
#[derive(Debug, Default)]
pub(crate) struct NearPieces {
    /// Centre, current piece and reach of the lookup (`None`: nothing looked up yet).
    taken: Option<(P2, usize, f64)>,
    earlier: Vec<usize>,
}

/// Where the tool is at one sample (docs/spec/engagement.md §5.2: stored as piece and local offset).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Station {
    pub piece: usize,
    pub local: f64,
    pub s: f64,
    /// Feed length up to here (the time axis).
    pub feed_s: f64,
    pub centre: P2,
    pub tangent: P2,
}

impl Route {
    /// A route through `shapes` (each with its rapid flag and source index), none of zero length.
    pub(crate) fn new(shapes: Vec<(Shape, bool, usize)>) -> Self {
        let mut pieces = Vec::with_capacity(shapes.len());
        let (mut s, mut feed) = (0.0, 0.0);
        for (shape, rapid, source) in shapes {
            pieces.push(Piece { shape, start_s: s, start_feed: feed, rapid, source });
            s += shape.length();
            if !rapid {
                feed += shape.length();
            }
        }
        let boxes: Vec<BBox> = pieces.iter().map(|p| p.shape.bbox()).collect();
        Self { tree: BoxTree::new(&boxes), pieces, length: s, feed_length: feed }
    }

    /// Bounding box of the pieces (feed and rapid).
    pub(crate) fn bbox(&self) -> Option<BBox> {
        self.pieces.iter().map(|p| p.shape.bbox()).reduce(|a, b| a.union(&b))
    }

    /// Number of samples `stations(step)` gives, without building them.
    pub(crate) fn station_count(&self, step: f64) -> f64 {
        (self.length / step).floor() + 1.0 + self.pieces.len() as f64
    }

    /// s_m = m·Δs plus every vertex and the end, each vertex in its incoming piece (§5.2).
    pub(crate) fn stations(&self, step: f64) -> Vec<Station> {
        let mut stations = Vec::new();
        let Some(first) = self.pieces.first() else {
            return stations;
        };
        stations.push(Self::station(0, 0.0, first));
        let mut m = 1.0_f64;
        for (index, piece) in self.pieces.iter().enumerate() {
            let end = piece.end_s();
            while m * step < end - 1e-9 {
                let s = m * step;
                if s > piece.start_s + 1e-9 {
                    stations.push(Self::station(index, s - piece.start_s, piece));
                }
                m += 1.0;
            }
            if (m * step - end).abs() <= 1e-9 {
                m += 1.0;
            }
            stations.push(Self::station(index, piece.shape.length(), piece));
        }
        stations
    }

    fn station(index: usize, local: f64, piece: &Piece) -> Station {
        Station {
            piece: index,
            local,
            s: piece.start_s + local,
            feed_s: piece.start_feed + if piece.rapid { 0.0 } else { local },
            centre: piece.shape.point(local),
            tangent: piece.shape.tangent(local),
        }
    }

    /// The cutting pieces that can come within `reach` of `centre` before the tool is at
    /// `station` (the current piece truncated there), most recent first.
    ///
    /// The tree query behind it is kept in `near` for the following samples (see
    /// [`NearPieces`]); the pieces given are the same either way.
    pub(crate) fn swept_before(&self, station: &Station, reach: f64, out: &mut Vec<Shape>, near: &mut NearPieces) {
        out.clear();
        if let Some(current) = self.pieces.get(station.piece)
            && !current.rapid
            && station.local > 0.0
        {
            out.push(current.shape.truncated(station.local));
        }
        let margin = NEAR_MARGIN * reach;
        let still_valid = near.taken.is_some_and(|(centre, piece, taken_reach)| {
            piece == station.piece
                && taken_reach == reach
                && (station.centre.x - centre.x).abs() <= margin
                && (station.centre.y - centre.y).abs() <= margin
        });
        if !still_valid {
            let earlier = &mut near.earlier;
            earlier.clear();
            self.tree.query(&BBox::around(station.centre, reach + margin), &mut |index| {
                if index < station.piece {
                    earlier.push(index);
                }
            });
            earlier.sort_unstable_by(|a, b| b.cmp(a));
            near.taken = Some((station.centre, station.piece, reach));
        }
        for &index in &near.earlier {
            if let Some(piece) = self.pieces.get(index)
                && !piece.rapid
                && piece.shape.distance(station.centre) < reach
            {
                out.push(piece.shape);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc_quarter() -> Shape {
        Shape::Arc { centre: P2::new(0.0, 0.0), radius: 2.0, start: 0.0, sweep: PI / 2.0 }
    }

    #[test]
    fn arc_points_tangents_and_distances() {
        let arc = arc_quarter();
        assert!((arc.length() - PI).abs() < 1e-12);
        assert!((arc.end_point() - P2::new(0.0, 2.0)).norm() < 1e-12);
        assert!((arc.tangent(0.0) - P2::new(0.0, 1.0)).norm() < 1e-12);
        assert!((arc.distance(P2::new(3.0, 3.0)) - (18.0_f64.sqrt() - 2.0)).abs() < 1e-12);
        // Outside the sweep the nearest point is an end.
        assert!((arc.distance(P2::new(0.0, -1.0)) - 5.0_f64.sqrt()).abs() < 1e-12);
        let cw = Shape::Arc { centre: P2::new(0.0, 0.0), radius: 2.0, start: PI / 2.0, sweep: -PI / 2.0 };
        assert!((cw.tangent(0.0) - P2::new(1.0, 0.0)).norm() < 1e-12);
        assert!((cw.end_point() - P2::new(2.0, 0.0)).norm() < 1e-12);
        let bbox = arc.bbox();
        assert!((bbox.max.x - 2.0).abs() < 1e-12 && (bbox.max.y - 2.0).abs() < 1e-12);
    }

    #[test]
    fn crossings_bracket_every_change_of_side() {
        let centre = P2::new(0.7, 0.4);
        let (radius, reach) = (1.5, 1.0);
        for shape in [arc_quarter(), Shape::Line { from: P2::new(-1.0, 0.0), to: P2::new(2.0, 0.5) }] {
            let mut angles = Vec::new();
            shape.crossings(reach, centre, radius, &mut angles);
            let side = |angle: f64| {
                let q = centre + radius * P2::new(angle.cos(), angle.sin());
                shape.distance(q) < reach
            };
            let steps = 20_000;
            let mut changes = 0;
            for i in 0..steps {
                let a = -PI + TAU * f64::from(i) / f64::from(steps);
                let b = a + TAU / f64::from(steps);
                if side(a) != side(b) {
                    changes += 1;
                    let near = angles.iter().any(|c| {
                        let d = (c - a).rem_euclid(TAU);
                        d <= b - a + 1e-12 || d >= TAU - 1e-12
                    });
                    assert!(near, "{shape:?}: change between {a} and {b} not in {angles:?}");
                }
            }
            assert!(changes >= 2, "{shape:?}");
        }
    }

    #[test]
    fn stations_include_vertices_once() {
        let route = Route::new(vec![
            (Shape::Line { from: P2::new(0.0, 0.0), to: P2::new(1.0, 0.0) }, false, 0),
            (Shape::Line { from: P2::new(1.0, 0.0), to: P2::new(1.0, 0.25) }, false, 1),
        ]);
        let stations = route.stations(0.5);
        let s: Vec<f64> = stations.iter().map(|st| st.s).collect();
        assert_eq!(s, vec![0.0, 0.5, 1.0, 1.25]);
        assert_eq!(stations[2].piece, 0);
        assert!(route.station_count(0.5) >= stations.len() as f64);
    }
}
