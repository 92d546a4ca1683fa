//! Areas of regions bounded by lines and circles: half-plane clipping of convex polygons, the
//! exact area of a disk ∩ polygon, and of a capsule (a disk swept along a segment) ∩ a convex
//! polygon. Used for the material left and over-cut at corners (docs/spec/contour.md §3.10) and for the
//! engagement solver's tool/stock overlaps.

use super::{Vec2, cross, signed_area};

/// The part of a convex polygon (either orientation) where `(x − point)·normal ≥ 0`
/// (Sutherland–Hodgman with one clip line). Empty when nothing remains.
pub fn clip_half_plane(polygon: &[Vec2], point: &Vec2, normal: &Vec2) -> Vec<Vec2> {
    let side = |p: &Vec2| (p - point).dot(normal);
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for (index, current) in polygon.iter().enumerate() {
        let next = &polygon[(index + 1) % polygon.len()];
        let (s0, s1) = (side(current), side(next));
        if s0 >= 0.0 {
            out.push(*current);
        }
        if (s0 >= 0.0) != (s1 >= 0.0) {
            let t = s0 / (s0 - s1);
            out.push(current + t * (next - current));
        }
    }
    if out.len() < 3 { Vec::new() } else { out }
}

/// Area of the intersection of the disk (`centre`, `radius`) with a simple polygon, exact (sum
/// over the edges of the signed disk ∩ triangle areas). The result is non-negative whatever the
/// polygon's orientation.
pub fn disk_polygon_area(centre: &Vec2, radius: f64, polygon: &[Vec2]) -> f64 {
    if radius <= 0.0 || polygon.len() < 3 {
        return 0.0;
    }
    let total: f64 = polygon
        .iter()
        .enumerate()
        .map(|(index, p)| {
            let q = &polygon[(index + 1) % polygon.len()];
            disk_triangle_area(&(p - centre), &(q - centre), radius)
        })
        .sum();
    total.abs()
}

/// Signed area of the disk of `radius` about the origin ∩ the triangle (origin, p, q).
fn disk_triangle_area(p: &Vec2, q: &Vec2, radius: f64) -> f64 {
    let sector = |a: &Vec2, b: &Vec2| 0.5 * radius * radius * cross(a, b).atan2(a.dot(b));
    let triangle = |a: &Vec2, b: &Vec2| 0.5 * cross(a, b);
    let d = q - p;
    let (aa, bb, cc) = (d.dot(&d), p.dot(&d), p.dot(p) - radius * radius);
    if aa == 0.0 {
        return 0.0;
    }
    let discriminant = bb * bb - aa * cc;
    if discriminant <= 0.0 {
        // The line misses the disk (or touches it): the whole triangle is outside but the sector.
        return sector(p, q);
    }
    let root = discriminant.sqrt();
    let t0 = ((-bb - root) / aa).clamp(0.0, 1.0);
    let t1 = ((-bb + root) / aa).clamp(0.0, 1.0);
    let (e0, e1) = (p + t0 * d, p + t1 * d);
    sector(p, &e0) + triangle(&e0, &e1) + sector(&e1, q)
}

/// Area of the intersection of a convex polygon with the capsule of `radius` around the segment
/// `[a, b]` (every point within `radius` of the segment), exact: rectangle plus the two end
/// half-disks.
pub fn capsule_convex_area(a: &Vec2, b: &Vec2, radius: f64, convex: &[Vec2]) -> f64 {
    if radius <= 0.0 || convex.len() < 3 {
        return 0.0;
    }
    let axis = b - a;
    let length = axis.norm();
    if length == 0.0 {
        return disk_polygon_area(a, radius, convex);
    }
    let u = axis / length;
    let w = Vec2::new(-u.y, u.x);
    let rectangle = [a - radius * w, b - radius * w, b + radius * w, a + radius * w];
    let mut middle = convex.to_vec();
    for (point, normal) in [(a, u), (b, -u), (&rectangle[0], w), (&rectangle[2], -w)] {
        middle = clip_half_plane(&middle, point, &normal);
    }
    let behind_a = clip_half_plane(convex, a, &(-u));
    let beyond_b = clip_half_plane(convex, b, &u);
    signed_area(&middle).abs() + disk_polygon_area(a, radius, &behind_a) + disk_polygon_area(b, radius, &beyond_b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::PI;

    fn square(half: f64) -> Vec<Vec2> {
        vec![Vec2::new(-half, -half), Vec2::new(half, -half), Vec2::new(half, half), Vec2::new(-half, half)]
    }

    #[test]
    fn disk_areas_inside_partial_and_outside() {
        assert_abs_diff_eq!(disk_polygon_area(&Vec2::zeros(), 1.0, &square(5.0)), PI, epsilon = 1e-12);
        // A quarter disk: the square's corner at the centre.
        let quarter = vec![Vec2::zeros(), Vec2::new(5.0, 0.0), Vec2::new(5.0, 5.0), Vec2::new(0.0, 5.0)];
        assert_abs_diff_eq!(disk_polygon_area(&Vec2::zeros(), 2.0, &quarter), PI, epsilon = 1e-12);
        // Half-plane through the centre, clockwise polygon.
        let mut half: Vec<Vec2> =
            vec![Vec2::new(-5.0, 0.0), Vec2::new(5.0, 0.0), Vec2::new(5.0, 5.0), Vec2::new(-5.0, 5.0)];
        half.reverse();
        assert_abs_diff_eq!(disk_polygon_area(&Vec2::zeros(), 1.0, &half), PI / 2.0, epsilon = 1e-12);
        // Circle segment of height 0.5 on a unit disk.
        let cut = clip_half_plane(&square(5.0), &Vec2::new(0.5, 0.0), &Vec2::x());
        let expected = (0.5_f64).acos() - 0.5 * (1.0 - 0.25_f64).sqrt();
        assert_abs_diff_eq!(disk_polygon_area(&Vec2::zeros(), 1.0, &cut), expected, epsilon = 1e-12);
        assert_abs_diff_eq!(disk_polygon_area(&Vec2::new(20.0, 0.0), 1.0, &square(5.0)), 0.0);
    }

    #[test]
    fn capsule_area_is_rectangle_plus_disk() {
        let a = Vec2::new(-1.0, 0.0);
        let b = Vec2::new(1.0, 0.0);
        assert_abs_diff_eq!(capsule_convex_area(&a, &b, 0.5, &square(10.0)), 2.0 + PI * 0.25, epsilon = 1e-12);
        let upper = clip_half_plane(&square(10.0), &Vec2::zeros(), &Vec2::y());
        assert_abs_diff_eq!(capsule_convex_area(&a, &b, 0.5, &upper), 1.0 + PI * 0.125, epsilon = 1e-12);
    }
}
