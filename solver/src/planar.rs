//! Plane (2-D) geometry shared by the contour and engagement solvers (docs/spec/contour.md §3.3,
//! §3.10; docs/spec/engagement.md): vectors, orientation and area, point-in-polygon, segment
//! intersection and distance, line offsets and miter points, a uniform-grid segment index with a
//! simple-polygon check, convex clipping with exact disk areas, and arc chording.
//!
//! Conventions: points and vectors are [`Vec2`] in mm; angles in radians; a polygon is a slice of
//! its vertices without the closing repeat; positive signed area means counter-clockwise. The
//! predicates use plain `f64` arithmetic with exact zero tests (no epsilon), so results are
//! deterministic; callers decide their own tolerances.
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
pub use grid::{GridBudgetExceeded, SegmentGrid, find_self_intersection};

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

/// Whether the closed segments `[a, b]` and `[c, d]` have a point in common.
pub fn segments_intersect(a: &Vec2, b: &Vec2, c: &Vec2, d: &Vec2) -> bool {
    let (o1, o2) = (orient(a, b, c), orient(a, b, d));
    let (o3, o4) = (orient(c, d, a), orient(c, d, b));
    if ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0)) && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0)) {
        return true;
    }
    (o1 == 0.0 && within_box(c, a, b))
        || (o2 == 0.0 && within_box(d, a, b))
        || (o3 == 0.0 && within_box(a, c, d))
        || (o4 == 0.0 && within_box(b, c, d))
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

/// Locates `p` relative to a closed polygon of either orientation (even-odd crossing rule, exact
/// boundary test).
pub fn point_in_polygon(p: &Vec2, polygon: &[Vec2]) -> Containment {
    let mut inside = false;
    for (index, a) in polygon.iter().enumerate() {
        let b = &polygon[(index + 1) % polygon.len()];
        if orient(a, b, p) == 0.0 && within_box(p, a, b) {
            return Containment::Boundary;
        }
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                inside = !inside;
            }
        }
    }
    if inside { Containment::Inside } else { Containment::Outside }
}

/// Intersection of the lines `p + s·dp` and `q + u·dq`, or `None` when they are parallel.
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
