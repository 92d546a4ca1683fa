//! Contour preparation (docs/spec/contour.md §3.1): closing, duplicate and collinear points, the
//! simple-polygon check and the orientation (counter-clockwise, docs/spec/api.md Contour).

use super::request::MAX_POINTS;
use crate::capability::Control;
use crate::error::ErrorCode;
use crate::error::{SolverError, Warning};
use crate::planar::{self, CheckStopped, Vec2, find_self_intersection, signed_area, turn_angle};
use crate::validate::coordinates;

/// Points closer than this are one point, mm (docs/spec/contour.md §1.4 `tol`).
pub const DUPLICATE_TOLERANCE: f64 = 1e-6;
pub use crate::validate::MAX_COORDINATE;
/// Vertices turning by at most this are straight and removed, radians (docs/spec/contour.md §3.1).
pub const STRAIGHT_TURN: f64 = 1e-9;

/// A prepared contour: a simple counter-clockwise polygon without duplicate or collinear
/// vertices, with the request index of every vertex.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Contour {
    /// Vertices, counter-clockwise.
    pub points: Vec<Vec2>,
    /// `source[j]`: index in the request's `contour` of vertex j.
    pub source: Vec<usize>,
    /// Whether the request's order was clockwise and has been reversed.
    pub reversed: bool,
    /// Number of points in the request.
    pub request_len: usize,
}

impl Contour {
    /// The prepared vertex that is `contour[k]`, if it was kept.
    pub fn vertex_of(&self, k: usize) -> Option<usize> {
        self.source.iter().position(|&s| s == k)
    }

    /// Prepared edge (from vertex e to e + 1) that contains request edge k (from `contour[k]` to
    /// `contour[k+1]`).
    pub fn edge_containing(&self, k: usize) -> usize {
        let m = self.points.len();
        // Edge i of the request order runs from given-order vertex i to i + 1.
        let given = |i: usize| {
            if self.reversed { self.source[m - 1 - i] } else { self.source[i] }
        };
        let mut edge = m - 1;
        for i in 0..m {
            if given(i) <= k {
                edge = i;
            }
        }
        if given(0) > k {
            edge = m - 1;
        }
        if self.reversed { (2 * m - 2 - edge) % m } else { edge }
    }

    /// The request edges merged into prepared edge `edge`.
    pub fn request_edges(&self, edge: usize, request_len: usize) -> Vec<usize> {
        let m = self.points.len();
        let (from, to) = if self.reversed {
            (self.source[(edge + 1) % m], self.source[edge])
        } else {
            (self.source[edge], self.source[(edge + 1) % m])
        };
        let mut edges = Vec::new();
        let mut k = from;
        loop {
            edges.push(k);
            k = (k + 1) % request_len;
            if k == to || edges.len() >= request_len {
                break;
            }
        }
        edges
    }
}

/// Prepares the request's polygon.
///
/// # Errors
/// `E_DEGENERATE` (fewer than 3 distinct points, zero area), `E_DUPLICATE_POINT`,
/// `E_SELF_INTERSECTION`, `E_ORIENTATION` (clockwise and not `fix_orientation`),
/// `E_TOO_MANY_POINTS`, `E_TOO_COMPLEX`, `E_INPUT` for non-finite coordinates.
pub(crate) fn prepare(
    points: &[[f64; 2]],
    fix_orientation: bool,
    control: Control<'_>,
) -> Result<(Contour, Vec<Warning>), SolverError> {
    check_points(points)?;
    control.check()?;
    let mut warnings = Vec::new();
    let (kept, mut removed, used) = distinct_points(points);
    control.check()?;
    if kept.len() < 3 {
        return Err(SolverError::new(
            ErrorCode::Degenerate,
            format!("the contour needs at least 3 distinct points (got {})", kept.len()),
        )
        .at("contour"));
    }
    check_duplicates(&kept)?;
    control.check()?;
    check_area(&kept)?;
    check_simple(&kept, control)?;
    control.check()?;
    let (kept, straight) = remove_straight(kept);
    removed.extend(straight);
    if kept.len() < 3 {
        return Err(SolverError::new(
            ErrorCode::Degenerate,
            "the contour has fewer than 3 corners once straight points are removed",
        )
        .at("contour"));
    }
    if !removed.is_empty() {
        removed.sort_unstable();
        warnings.push(Warning::new(
            "W_VERTEX_REMOVED",
            format!("{} duplicate or collinear points removed: {}", removed.len(), list_indices(&removed)),
        ));
    }
    let mut points: Vec<Vec2> = kept.iter().map(|(p, _)| *p).collect();
    let mut source: Vec<usize> = kept.iter().map(|(_, i)| *i).collect();
    let area = signed_area(&points);
    let reversed = area < 0.0;
    if reversed {
        if !fix_orientation {
            return Err(SolverError::new(
                ErrorCode::Orientation,
                format!(
                    "the contour runs clockwise (signed area {area:.6} mm²); give it counter-clockwise or set fix_orientation"
                ),
            )
            .at("contour"));
        }
        points.reverse();
        source.reverse();
        warnings.push(Warning::new("W_CONTOUR_REVERSED", "the contour ran clockwise and was reversed"));
    }
    Ok((Contour { points, source, reversed, request_len: used }, warnings))
}

/// `E_TOO_MANY_POINTS` over the limit; `E_INPUT` for a coordinate that is not finite or out of
/// bounds.
fn check_points(points: &[[f64; 2]]) -> Result<(), SolverError> {
    if points.len() > MAX_POINTS {
        return Err(SolverError::new(
            ErrorCode::TooManyPoints,
            format!("the contour has {} points; the limit is {MAX_POINTS}", points.len()),
        )
        .at("contour"));
    }
    for (index, point) in points.iter().enumerate() {
        if !point.iter().all(|value| value.is_finite() && value.abs() <= MAX_COORDINATE) {
            coordinates(&format!("contour[{index}]"), *point)?;
        }
    }
    Ok(())
}

/// The points without a closing repeat of the first and without repeated consecutive points
/// (also round the end), each with its request index; the indices removed; and how many request
/// points the contour uses (all but a closing repeat).
fn distinct_points(points: &[[f64; 2]]) -> (Vec<(Vec2, usize)>, Vec<usize>, usize) {
    let mut kept: Vec<(Vec2, usize)> = Vec::with_capacity(points.len());
    let mut removed: Vec<usize> = Vec::new();
    let closing = points.len() > 1
        && points
            .first()
            .zip(points.last())
            .is_some_and(|(first, last)| (planar::vec2(*first) - planar::vec2(*last)).norm() <= DUPLICATE_TOLERANCE);
    let used = if closing { points.len() - 1 } else { points.len() };
    for (index, point) in points.iter().take(used).enumerate() {
        let p = planar::vec2(*point);
        match kept.last() {
            Some((last, _)) if (p - last).norm() <= DUPLICATE_TOLERANCE => removed.push(index),
            _ => kept.push((p, index)),
        }
    }
    while kept.len() > 1
        && kept.first().zip(kept.last()).is_some_and(|(first, last)| (first.0 - last.0).norm() <= DUPLICATE_TOLERANCE)
    {
        if let Some((_, index)) = kept.pop() {
            removed.push(index);
        }
    }
    (kept, removed, used)
}

/// `E_SELF_INTERSECTION` when two edges meet; `E_TOO_COMPLEX` when the check cannot finish in
/// bounded time.
fn check_simple(kept: &[(Vec2, usize)], control: Control<'_>) -> Result<(), SolverError> {
    let polygon: Vec<Vec2> = kept.iter().map(|(p, _)| *p).collect();
    match find_self_intersection(&polygon, control) {
        Ok(None) => {}
        Ok(Some((i, j))) => {
            let (first, second) = (kept[i].1, kept[j].1);
            return Err(SolverError::new(
                ErrorCode::SelfIntersection,
                format!(
                    "the contour is not a simple polygon: the edge from contour[{first}] meets the edge from contour[{second}]"
                ),
            )
            .at(format!("contour[{second}]")));
        }
        Err(CheckStopped::Cancelled) => return control.check(),
        Err(CheckStopped::Budget) => {
            return Err(SolverError::new(
                ErrorCode::TooComplex,
                "the contour's edges are too crowded to check for self-intersection in bounded time",
            )
            .at("contour"));
        }
    }
    Ok(())
}

/// `E_DUPLICATE_POINT` when two non-consecutive points coincide (the polygon touches itself).
fn check_duplicates(kept: &[(Vec2, usize)]) -> Result<(), SolverError> {
    let mut order: Vec<usize> = (0..kept.len()).collect();
    order.sort_by(|&a, &b| kept[a].0.x.total_cmp(&kept[b].0.x).then(kept[a].0.y.total_cmp(&kept[b].0.y)));
    for pair in order.windows(2) {
        let (a, b) = (&kept[pair[0]], &kept[pair[1]]);
        if (a.0 - b.0).norm() <= DUPLICATE_TOLERANCE {
            let (first, second) = (a.1.min(b.1), a.1.max(b.1));
            return Err(SolverError::new(
                ErrorCode::DuplicatePoint,
                format!("contour[{second}] repeats contour[{first}]: the polygon touches itself"),
            )
            .at(format!("contour[{second}]")));
        }
    }
    Ok(())
}

/// `E_DEGENERATE` when every point lies on one line (zero area).
fn check_area(kept: &[(Vec2, usize)]) -> Result<(), SolverError> {
    let origin = kept[0].0;
    let far = kept
        .iter()
        .map(|(p, _)| *p)
        .max_by(|a, b| (a - origin).norm().total_cmp(&(b - origin).norm()))
        .unwrap_or(origin);
    let axis = far - origin;
    let length = axis.norm();
    let spread = kept.iter().map(|(p, _)| planar::cross(&axis, &(p - origin)).abs() / length).fold(0.0, f64::max);
    if length == 0.0 || spread <= DUPLICATE_TOLERANCE {
        return Err(SolverError::new(
            ErrorCode::Degenerate,
            "the contour has zero area: all its points lie on one line",
        )
        .at("contour"));
    }
    Ok(())
}

/// Removes vertices where the contour runs straight on; returns the rest and the removed
/// request indices.
fn remove_straight(points: Vec<(Vec2, usize)>) -> (Vec<(Vec2, usize)>, Vec<usize>) {
    let straight = |a: &Vec2, b: &Vec2, c: &Vec2| turn_angle(&(b - a), &(c - b)).abs() <= STRAIGHT_TURN;
    let mut removed = Vec::new();
    let mut kept: Vec<(Vec2, usize)> = Vec::with_capacity(points.len());
    for point in points {
        kept.push(point);
        while kept.len() >= 3 {
            let n = kept.len();
            if straight(&kept[n - 3].0, &kept[n - 2].0, &kept[n - 1].0) {
                removed.push(kept.remove(n - 2).1);
            } else {
                break;
            }
        }
    }
    loop {
        let n = kept.len();
        if n < 3 {
            break;
        }
        if straight(&kept[n - 2].0, &kept[n - 1].0, &kept[0].0) {
            if let Some((_, index)) = kept.pop() {
                removed.push(index);
            }
        } else if straight(&kept[n - 1].0, &kept[0].0, &kept[1].0) {
            removed.push(kept.remove(0).1);
        } else {
            break;
        }
    }
    (kept, removed)
}

/// `contour[3], contour[7], ...` for at most ten indices.
pub(crate) fn list_indices(indices: &[usize]) -> String {
    let mut text = indices.iter().take(10).map(|i| format!("contour[{i}]")).collect::<Vec<_>>().join(", ");
    if indices.len() > 10 {
        text.push_str(&format!(" and {} more", indices.len() - 10));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn closing_duplicates_and_collinear_points_are_removed() {
        let points = [[0.0, 0.0], [5.0, 0.0], [10.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0], [0.0, 0.0]];
        let (contour, warnings) = prepare(&points, false, Control::default()).unwrap();
        assert_eq!(contour.source, vec![0, 2, 4, 5]);
        assert_eq!(warnings[0].code, "W_VERTEX_REMOVED");
        assert_eq!(contour.edge_containing(0), 0);
        assert_eq!(contour.edge_containing(1), 0);
        assert_eq!(contour.edge_containing(4), 2);
        assert_eq!(contour.request_edges(0, 6), vec![0, 1]);
        assert_eq!(contour.vertex_of(4), Some(2));
        assert_eq!(contour.vertex_of(1), None);
    }

    #[test]
    fn clockwise_contours_are_refused_or_reversed() {
        let points = [[0.0, 0.0], [0.0, 10.0], [10.0, 10.0], [10.0, 0.0]];
        assert_eq!(prepare(&points, false, Control::default()).unwrap_err().code(), ErrorCode::Orientation);
        let (contour, warnings) = prepare(&points, true, Control::default()).unwrap();
        assert!(contour.reversed);
        assert_eq!(contour.source, vec![3, 2, 1, 0]);
        assert!(signed_area(&contour.points) > 0.0);
        assert_eq!(warnings[0].code, "W_CONTOUR_REVERSED");
        // Request edge 0 runs (0,0)→(0,10): the prepared edge from vertex 3 (=(0,10)) to 0.
        let edge = contour.edge_containing(0);
        assert_eq!(contour.points[edge], planar::vec2([0.0, 10.0]));
        assert_eq!(contour.request_edges(edge, 4), vec![0]);
    }

    #[test]
    fn bad_polygons_have_their_codes() {
        let code = |points: &[[f64; 2]]| prepare(points, false, Control::default()).unwrap_err().code();
        assert_eq!(code(&[[0.0, 0.0], [1.0, 0.0]]), ErrorCode::Degenerate);
        assert_eq!(code(&[[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), ErrorCode::Degenerate);
        assert_eq!(code(&[[0.0, 0.0], [1.0, 1.0], [1.0, 0.0], [0.0, 1.0]]), ErrorCode::SelfIntersection);
        assert_eq!(
            code(&[[0.0, 0.0], [4.0, 0.0], [2.0, 2.0], [4.0, 4.0], [0.0, 4.0], [2.0, 2.0]]),
            ErrorCode::DuplicatePoint
        );
        assert_eq!(code(&[[0.0, 0.0], [f64::NAN, 0.0], [1.0, 1.0]]), ErrorCode::Input);
    }
}
