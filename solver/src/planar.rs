//! Plane (2-D) geometry shared by the contour and engagement solvers (docs/spec/contour.md §3.3,
//! §3.10; docs/spec/engagement.md): vectors, orientation and area, point-in-polygon, segment
//! intersection and distance, line offsets and miter points, a uniform-grid segment index with a
//! simple-polygon check, convex clipping with exact disk areas, and arc chording.
//!
//! Conventions: points and vectors are [`Vec2`] in mm; angles in radians; a polygon is a slice of
//! its vertices without the closing repeat; positive signed area means counter-clockwise. The
//! predicates (which side of a line a point lies on, whether segments meet, whether a point is on
//! a polygon's boundary) take the exact sign of the orientation determinant from Shewchuk's
//! adaptive arithmetic ([`orientation`], the `robust` crate): a point exactly on a line is on it
//! and one a rounding error off is not, with no epsilon; callers decide their own tolerances.
//!
//! * this file: points, orientation, area, point-in-polygon, segment intersection and distance,
//!   line intersection, miter points and polyline offsets;
//! * [`grid`]: [`SegmentGrid`] (sparse uniform grid over segments, `O(n)` for ordinary polygons)
//!   and [`find_self_intersection`] (simple-polygon check for 100 000 vertices);
//! * [`area`]: half-plane clipping of convex polygons, exact area of a disk ∩ polygon, capsule
//!   (swept disk) ∩ convex polygon;
//! * [`arc`]: circumscribed chording of circular arcs (the polyline never enters the circle).

pub mod arc;
pub mod area;
pub mod grid;

pub use arc::{arc_max_step, arc_steps, circumscribed_arc, circumscribed_arc_steps};
pub use area::{capsule_convex_area, clip_half_plane, disk_polygon_area};
pub use grid::{CheckStopped, SegmentGrid, find_self_intersection};

use nalgebra::Vector2;

/// A 2-D point or free vector in millimetres.
pub type Vec2 = Vector2<f64>;

/// Converts `[x, y]` to a vector.
pub fn vec2(p: [f64; 2]) -> Vec2 {
    Vec2::new(p[0], p[1])
}

/// Converts a vector to `[x, y]`.
pub fn array2(v: &Vec2) -> [f64; 2] {
    [v.x, v.y]
}

/// The 2-D cross product `a.x·b.y − a.y·b.x` (positive when `b` lies counter-clockwise of `a`).
pub fn cross(a: &Vec2, b: &Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// `t` turned by +90° (the normal on the left of travel along `t`).
pub fn left_normal(t: &Vec2) -> Vec2 {
    Vec2::new(-t.y, t.x)
}

/// `t` turned by −90° (the normal on the right of travel along `t`).
pub fn right_normal(t: &Vec2) -> Vec2 {
    Vec2::new(t.y, -t.x)
}

/// The unit vector at `angle` radians from +x.
pub fn direction(angle: f64) -> Vec2 {
    let (s, c) = angle.sin_cos();
    Vec2::new(c, s)
}

/// Signed turn from direction `d1` to direction `d2`, in (−π, π] (counter-clockwise positive).
pub fn turn_angle(d1: &Vec2, d2: &Vec2) -> f64 {
    cross(d1, d2).atan2(d1.dot(d2))
}

/// Orientation of the triangle `a, b, c`: twice its signed area (positive counter-clockwise).
pub fn orient(a: &Vec2, b: &Vec2, c: &Vec2) -> f64 {
    cross(&(b - a), &(c - a))
}

/// The exact side of the line through `a` and `b` that `c` lies on: `Greater` when `a, b, c` turn
/// counter-clockwise (the sign of [`orient`] computed without rounding), `Equal` when the three
/// points are exactly collinear. Adaptive: as fast as [`orient`] unless the points are within
/// rounding error of a line.
pub fn orientation(a: &Vec2, b: &Vec2, c: &Vec2) -> std::cmp::Ordering {
    let coord = |p: &Vec2| robust::Coord { x: p.x, y: p.y };
    // −0.0 is collinear too; a NaN coordinate makes no turn either way.
    robust::orient2d(coord(a), coord(b), coord(c)).partial_cmp(&0.0).unwrap_or(std::cmp::Ordering::Equal)
}

/// Signed area of a closed polygon (shoelace formula, positive counter-clockwise). Coordinates are
/// taken relative to the first vertex, which keeps the sum accurate far from the origin.
pub fn signed_area(polygon: &[Vec2]) -> f64 {
    let Some(origin) = polygon.first() else {
        return 0.0;
    };
    let mut twice = 0.0;
    for (index, point) in polygon.iter().enumerate() {
        let next = polygon[(index + 1) % polygon.len()];
        twice += cross(&(point - origin), &(next - origin));
    }
    0.5 * twice
}

/// Area centroid of a closed polygon, or `None` when its area is zero.
pub fn centroid(polygon: &[Vec2]) -> Option<Vec2> {
    let origin = *polygon.first()?;
    let mut twice_area = 0.0;
    let mut moment = Vec2::zeros();
    for (index, point) in polygon.iter().enumerate() {
        let a = point - origin;
        let b = polygon[(index + 1) % polygon.len()] - origin;
        let w = cross(&a, &b);
        twice_area += w;
        moment += w * (a + b);
    }
    (twice_area != 0.0).then(|| origin + moment / (3.0 * twice_area))
}

/// Length of a closed polygon's boundary.
pub fn perimeter(polygon: &[Vec2]) -> f64 {
    polygon.iter().enumerate().map(|(index, point)| (polygon[(index + 1) % polygon.len()] - point).norm()).sum()
}

/// Distance from `p` to the closed segment `[a, b]` (a degenerate segment is a point).
pub fn point_segment_distance(p: &Vec2, a: &Vec2, b: &Vec2) -> f64 {
    (p - closest_on_segment(p, a, b)).norm()
}

/// The point of the closed segment `[a, b]` nearest to `p`.
pub fn closest_on_segment(p: &Vec2, a: &Vec2, b: &Vec2) -> Vec2 {
    let ab = b - a;
    let length_squared = ab.norm_squared();
    if length_squared == 0.0 {
        return *a;
    }
    let t = ((p - a).dot(&ab) / length_squared).clamp(0.0, 1.0);
    a + t * ab
}

/// Whether the closed segments `[a, b]` and `[c, d]` have a point in common (exactly: touching
/// and collinear overlapping segments do, segments a rounding error apart do not).
pub fn segments_intersect(a: &Vec2, b: &Vec2, c: &Vec2, d: &Vec2) -> bool {
    use std::cmp::Ordering::Equal;
    let (o1, o2) = (orientation(a, b, c), orientation(a, b, d));
    let (o3, o4) = (orientation(c, d, a), orientation(c, d, b));
    if o1 != Equal && o2 != Equal && o1 != o2 && o3 != Equal && o4 != Equal && o3 != o4 {
        return true;
    }
    (o1 == Equal && within_box(c, a, b))
        || (o2 == Equal && within_box(d, a, b))
        || (o3 == Equal && within_box(a, c, d))
        || (o4 == Equal && within_box(b, c, d))
}

/// Whether `p` (known to be collinear with `a`, `b`) lies within their bounding box.
pub(crate) fn within_box(p: &Vec2, a: &Vec2, b: &Vec2) -> bool {
    p.x >= a.x.min(b.x) && p.x <= a.x.max(b.x) && p.y >= a.y.min(b.y) && p.y <= a.y.max(b.y)
}

/// Distance between the closed segments `[a, b]` and `[c, d]` (0 when they intersect).
pub fn segment_segment_distance(a: &Vec2, b: &Vec2, c: &Vec2, d: &Vec2) -> f64 {
    if segments_intersect(a, b, c, d) {
        return 0.0;
    }
    point_segment_distance(a, c, d)
        .min(point_segment_distance(b, c, d))
        .min(point_segment_distance(c, a, b))
        .min(point_segment_distance(d, a, b))
}

/// Where a point lies relative to a closed polygon.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Containment {
    /// Strictly inside.
    Inside,
    /// On an edge or a vertex.
    Boundary,
    /// Strictly outside.
    Outside,
}

/// Locates `p` relative to a closed polygon of either orientation (even-odd crossing rule with the
/// ray cast towards +x; the boundary test and the side of each crossed edge are exact).
pub fn point_in_polygon(p: &Vec2, polygon: &[Vec2]) -> Containment {
    let mut inside = false;
    for (index, a) in polygon.iter().enumerate() {
        let b = &polygon[(index + 1) % polygon.len()];
        let side = orientation(a, b, p);
        if side == std::cmp::Ordering::Equal && within_box(p, a, b) {
            return Containment::Boundary;
        }
        // The edge crosses the ray when it spans p's height and p lies on its west side: the
        // left of an edge going up, the right of one going down.
        let upwards = b.y > p.y;
        if (a.y > p.y) != upwards && (side == std::cmp::Ordering::Greater) == upwards {
            inside = !inside;
        }
    }
    if inside { Containment::Inside } else { Containment::Outside }
}

/// Intersection of the lines `p + s·dp` and `q + u·dq`, or `None` when they are parallel (or so
/// nearly that their cross product rounds to zero). Exactly parallel directions always have a
/// zero cross product: its two terms are the same product, rounded alike.
pub fn line_intersection(p: &Vec2, dp: &Vec2, q: &Vec2, dq: &Vec2) -> Option<Vec2> {
    let denominator = cross(dp, dq);
    if denominator == 0.0 {
        return None;
    }
    let s = cross(&(q - p), dq) / denominator;
    Some(p + s * dp)
}

/// The corner point of two offset lines through `vertex`: line 1 with unit normal `n1` shifted by
/// `o1` along it, line 2 with `n2` and `o2` (docs/spec/contour.md O2 for equal offsets, O3 otherwise). `None`
/// for a reversal (n1 = −n2), or for parallel lines with different offsets.
pub fn miter_point(vertex: &Vec2, n1: &Vec2, o1: f64, n2: &Vec2, o2: f64) -> Option<Vec2> {
    if o1 == o2 {
        // O2: stable for nearly straight corners, where O3 divides by a tiny cross product.
        let denominator = 1.0 + n1.dot(n2);
        if denominator <= 1e-15 {
            return None;
        }
        return Some(vertex + o1 * (n1 + n2) / denominator);
    }
    let denominator = cross(n1, n2);
    if denominator.abs() <= 1e-15 {
        return None;
    }
    let w = Vec2::new(o1 * n2.y - o2 * n1.y, n1.x * o2 - n2.x * o1) / denominator;
    Some(vertex + w)
}

/// Offsets a closed polygon edge by edge: edge `k` (from vertex `k` to `k + 1`) moves by
/// `offsets[k]` along its left normal (`left = true`) or right normal, and vertex `k` of the result
/// is the miter point of the offset edges `k − 1` and `k`. Returns the index of the first vertex
/// where two offset lines do not meet (a reversal, or parallel lines with different offsets).
///
/// This is the raw miter construction: whether edges collapse or cross is for the caller to check
/// ([`find_self_intersection`], edge directions).
pub fn miter_offset(polygon: &[Vec2], offsets: &[f64], left: bool) -> Result<Vec<Vec2>, usize> {
    let n = polygon.len();
    let normal = |k: usize| {
        let t = (polygon[(k + 1) % n] - polygon[k]).normalize();
        if left { left_normal(&t) } else { right_normal(&t) }
    };
    let offset = |k: usize| offsets.get(k).copied().unwrap_or(0.0);
    (0..n)
        .map(|k| {
            let previous = (k + n - 1) % n;
            miter_point(&polygon[k], &normal(previous), offset(previous), &normal(k), offset(k)).ok_or(k)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn square() -> Vec<Vec2> {
        [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]].into_iter().map(vec2).collect()
    }

    #[test]
    fn area_centroid_and_orientation() {
        let mut polygon = square();
        assert_abs_diff_eq!(signed_area(&polygon), 4.0);
        assert_abs_diff_eq!(centroid(&polygon).unwrap(), Vec2::new(1.0, 1.0));
        assert_abs_diff_eq!(perimeter(&polygon), 8.0);
        polygon.reverse();
        assert_abs_diff_eq!(signed_area(&polygon), -4.0);
        assert!(centroid(&[Vec2::zeros(), Vec2::x(), 2.0 * Vec2::x()]).is_none());
    }

    #[test]
    fn point_in_polygon_has_three_answers() {
        let polygon = square();
        assert_eq!(point_in_polygon(&Vec2::new(1.0, 1.0), &polygon), Containment::Inside);
        assert_eq!(point_in_polygon(&Vec2::new(2.0, 1.0), &polygon), Containment::Boundary);
        assert_eq!(point_in_polygon(&Vec2::new(0.0, 0.0), &polygon), Containment::Boundary);
        assert_eq!(point_in_polygon(&Vec2::new(3.0, 1.0), &polygon), Containment::Outside);
    }

    #[test]
    fn segments_touching_crossing_and_apart() {
        let p = |x, y| Vec2::new(x, y);
        assert!(segments_intersect(&p(0.0, 0.0), &p(2.0, 2.0), &p(0.0, 2.0), &p(2.0, 0.0)));
        assert!(segments_intersect(&p(0.0, 0.0), &p(2.0, 0.0), &p(1.0, 0.0), &p(1.0, 1.0)));
        assert!(segments_intersect(&p(0.0, 0.0), &p(2.0, 0.0), &p(1.0, 0.0), &p(3.0, 0.0)));
        assert!(!segments_intersect(&p(0.0, 0.0), &p(1.0, 0.0), &p(2.0, 0.0), &p(3.0, 0.0)));
        assert_abs_diff_eq!(
            segment_segment_distance(&p(0.0, 0.0), &p(1.0, 0.0), &p(2.0, 1.0), &p(3.0, 5.0)),
            2.0_f64.sqrt()
        );
    }

    /// Three points exactly on the line y = 3x (each y is 3x without rounding) whose orientation,
    /// computed in plain floats, rounds to a small non-zero number whichever point is the pivot.
    fn collinear_off_by_rounding() -> (Vec2, Vec2, Vec2) {
        let a = Vec2::new(0.813679185267957, 2.441037555803871);
        let b = Vec2::new(10.94123456229218, 32.82370368687654);
        let c = Vec2::new(3.7306113636207296, 11.191834090862189);
        for (x, y) in [a, b, c].map(|p| (p.x, p.y)) {
            assert_eq!(3.0 * x, y);
        }
        assert!(orient(&a, &b, &c) < 0.0 && orient(&b, &a, &c) < 0.0, "plain floats see no line");
        (a, b, c)
    }

    #[test]
    fn an_exactly_collinear_point_is_on_the_line() {
        let (a, b, c) = collinear_off_by_rounding();
        for (p, q, r) in [(a, b, c), (b, a, c), (c, a, b), (a, c, b)] {
            assert_eq!(orientation(&p, &q, &r), std::cmp::Ordering::Equal);
        }
        assert_eq!(orientation(&a, &b, &(c + Vec2::new(-1e-15, 0.0))), std::cmp::Ordering::Greater);
        assert_eq!(orientation(&a, &b, &(c + Vec2::new(1e-15, 0.0))), std::cmp::Ordering::Less);
    }

    #[test]
    fn an_edge_ending_exactly_on_another_touches_it() {
        let (a, b, c) = collinear_off_by_rounding();
        // [c, d] leaves [a, b] towards the side plain floats put c on.
        let d = c + Vec2::new(3.0, -1.0);
        assert!(segments_intersect(&a, &b, &c, &d));
        assert!(segments_intersect(&c, &d, &b, &a));
        assert_eq!(segment_segment_distance(&a, &b, &c, &d), 0.0);
    }

    #[test]
    fn an_edge_a_rounding_error_off_another_does_not_touch_it() {
        // c lies one unit in the last place above the line y = 3x through a and b, where the
        // plain-float orientation of a, b, c is exactly zero.
        let a = Vec2::new(0.42507094125014566, 1.275212823750437);
        let b = Vec2::new(11.659560571297455, 34.978681713892364);
        let c = Vec2::new(2.3113171858661428, 6.933951557598429);
        assert_eq!(orient(&a, &b, &c), 0.0);
        assert!(3.0 * c.x < c.y);
        let d = c + Vec2::new(-3.0, 1.0);
        assert!(!segments_intersect(&a, &b, &c, &d));
        assert!(!segments_intersect(&c, &d, &a, &b));
        assert!(segment_segment_distance(&a, &b, &c, &d) > 0.0);
    }

    #[test]
    fn a_point_exactly_on_an_edge_is_on_the_boundary() {
        let (a, b, c) = collinear_off_by_rounding();
        let mut triangle = vec![a, Vec2::new(b.x, a.y), b];
        assert_eq!(point_in_polygon(&c, &triangle), Containment::Boundary);
        triangle.reverse();
        assert_eq!(point_in_polygon(&c, &triangle), Containment::Boundary);
        let edges: Vec<(Vec2, Vec2)> =
            (0..triangle.len()).map(|k| (triangle[k], triangle[(k + 1) % triangle.len()])).collect();
        assert_eq!(SegmentGrid::new(edges, 0.0).containment(&c, &mut Vec::new()), Containment::Boundary);
        // Either side of the diagonal, off it by about 1e-15 mm.
        let (inside, outside) = (c + Vec2::new(2e-15, 0.0), c - Vec2::new(2e-15, 0.0));
        assert_eq!(point_in_polygon(&inside, &triangle), Containment::Inside);
        assert_eq!(point_in_polygon(&outside, &triangle), Containment::Outside);
    }

    #[test]
    fn a_polygon_touching_itself_exactly_is_not_simple() {
        let (a, b, c) = collinear_off_by_rounding();
        // The vertex c of edges 2 and 3 lies on edge 0, both edges on its right.
        let polygon = [a, b, Vec2::new(30.0, 20.0), c, Vec2::new(20.0, 0.0)];
        assert_eq!(find_self_intersection(&polygon, crate::control::Control::default()).unwrap(), Some((0, 2)));
    }

    #[test]
    fn miter_points_match_o1_and_o3() {
        // O1: |PV| = o / sin(α/2) for a 90° corner.
        let v = Vec2::new(20.0, 0.0);
        let p = miter_point(&v, &Vec2::new(0.0, -1.0), 1.0, &Vec2::new(1.0, 0.0), 1.0).unwrap();
        assert_abs_diff_eq!(p, Vec2::new(21.0, -1.0), epsilon = 1e-15);
        // O3 with different offsets (docs/spec/contour.md §3.9.2 example, as a right-hand corner).
        let v = Vec2::new(20.0, 20.0);
        let p = miter_point(&v, &Vec2::new(1.0, 0.0), 1.015427, &Vec2::new(0.0, 1.0), 1.154701).unwrap();
        assert_abs_diff_eq!(p, Vec2::new(21.015427, 21.154701), epsilon = 1e-12);
        assert!(miter_point(&v, &Vec2::x(), 1.0, &(-Vec2::x()), 1.0).is_none());
    }

    #[test]
    fn miter_offset_grows_a_square() {
        let grown = miter_offset(&square(), &[1.0; 4], false).unwrap();
        assert_abs_diff_eq!(grown[0], Vec2::new(-1.0, -1.0), epsilon = 1e-15);
        assert_abs_diff_eq!(grown[2], Vec2::new(3.0, 3.0), epsilon = 1e-15);
        assert_abs_diff_eq!(signed_area(&grown), 16.0, epsilon = 1e-12);
    }
}
