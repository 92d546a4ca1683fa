//! Shared geometry: vector aliases, rotations, the sense of travel, point-to-segment distance
//! and a safeguarded one-dimensional root finder.

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// Sense of travel round a loop or along an arc, seen from the side the field using it names
/// (+Z for curves and arcs in XY).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Counter-clockwise (increasing angle; G3 for an arc).
    #[default]
    Ccw,
    /// Clockwise (G2 for an arc).
    Cw,
}

impl Direction {
    /// +1 counter-clockwise, −1 clockwise.
    pub fn sign(self) -> f64 {
        match self {
            Self::Ccw => 1.0,
            Self::Cw => -1.0,
        }
    }
}

/// A 3-D point or free vector in millimetres.
pub type Vec3 = Vector3<f64>;

/// Converts `[x, y, z]` to a vector.
pub fn vec3(p: [f64; 3]) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

/// Converts a vector to `[x, y, z]`.
pub fn array3(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// Serde for an optional vector as `[x, y, z]` (nalgebra is built without serde): every
/// coordinate exactly, for values kept between a job's parts.
pub(crate) mod optional_vec3 {
    use super::{Vec3, array3, vec3};
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub(crate) fn serialize<S: Serializer>(value: &Option<Vec3>, serializer: S) -> Result<S::Ok, S::Error> {
        value.as_ref().map(array3).serialize(serializer)
    }

    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<Vec3>, D::Error> {
        Ok(Option::<[f64; 3]>::deserialize(deserializer)?.map(vec3))
    }
}

/// Right-handed rotation about +Z by `angle` radians.
pub fn rotation_z(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Right-handed rotation about +Y by `angle` radians.
pub fn rotation_y(angle: f64) -> Matrix3<f64> {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Distance from `p` to the closed segment `[a, b]` (a degenerate segment is a point).
pub fn distance_to_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    distance_squared_to_segment(p, a, b).sqrt()
}

/// The square of [`distance_to_segment`]: the farthest of many points needs one square root,
/// not one per point (the square root is monotone, so the result is the same to the bit).
pub fn distance_squared_to_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    Segment::new(*a, *b).distance_squared(p)
}

/// A closed segment with its vector and squared length computed once, for measuring many points
/// against it (a polyline's moves, a chord against the vertices it spans).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Start.
    pub from: Vec3,
    /// End − start.
    pub along: Vec3,
    /// |end − start|².
    pub length_squared: f64,
}

impl Segment {
    /// The segment from `from` to `to`.
    pub fn new(from: Vec3, to: Vec3) -> Self {
        let along = to - from;
        Self { from, along, length_squared: along.norm_squared() }
    }

    /// [`distance_squared_to_segment`] of `point` (a degenerate segment is a point).
    pub fn distance_squared(&self, point: &Vec3) -> f64 {
        if self.length_squared == 0.0 {
            return (point - self.from).norm_squared();
        }
        let t = ((point - self.from).dot(&self.along) / self.length_squared).clamp(0.0, 1.0);
        (point - (self.from + t * self.along)).norm_squared()
    }
}

/// Finds a root of `f` near `start`: steps outwards in both directions (first `step`, growing by
/// half each time, up to `reach` away) until the sign changes, then bisects the bracket to `tol`.
/// Returns `None` when no sign change lies within `reach`. Deterministic; never returns NaN.
pub fn root_near(f: impl Fn(f64) -> f64, start: f64, step: f64, reach: f64, tol: f64) -> Option<f64> {
    let f_start = f(start);
    if f_start == 0.0 {
        return Some(start);
    }
    if !f_start.is_finite() {
        return None;
    }
    let mut offset = 0.0;
    let mut stride = step;
    let (mut below, mut above) = (start, start);
    let (mut f_below, mut f_above) = (f_start, f_start);
    while offset < reach {
        offset = (offset + stride).min(reach);
        stride *= 1.5;
        for (side, last, f_last) in [(-1.0, &mut below, &mut f_below), (1.0, &mut above, &mut f_above)] {
            let x = start + side * offset;
            let fx = f(x);
            if fx.is_finite() && fx * *f_last <= 0.0 {
                return Some(bisect(&f, *last, *f_last, x, tol));
            }
            *last = x;
            *f_last = fx;
        }
    }
    None
}

/// Bisection on a bracket `[a, b]` with `f(a) = fa` and a sign change somewhere inside.
fn bisect(f: &impl Fn(f64) -> f64, mut a: f64, mut fa: f64, mut b: f64, tol: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if (b - a).abs() <= tol {
            return mid;
        }
        let fm = f(mid);
        if fm == 0.0 {
            return mid;
        }
        if fm * fa < 0.0 {
            b = mid;
        } else {
            a = mid;
            fa = fm;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn segment_distance_covers_interior_and_ends() {
        let a = Vec3::new(0.0, 0.0, 0.0);
        let b = Vec3::new(2.0, 0.0, 0.0);
        assert_abs_diff_eq!(distance_to_segment(&Vec3::new(1.0, 1.0, 0.0), &a, &b), 1.0);
        assert_abs_diff_eq!(distance_to_segment(&Vec3::new(3.0, 0.0, 0.0), &a, &b), 1.0);
        assert_abs_diff_eq!(distance_to_segment(&Vec3::new(-3.0, 4.0, 0.0), &a, &b), 5.0);
        assert_abs_diff_eq!(distance_to_segment(&Vec3::new(0.0, 2.0, 0.0), &a, &a), 2.0);
    }

    #[test]
    fn root_near_finds_the_nearest_sign_change() {
        let root = root_near(|x| x.cos(), 1.0, 0.01, 3.0, 1e-14).unwrap();
        assert_abs_diff_eq!(root, std::f64::consts::FRAC_PI_2, epsilon = 1e-12);
        let left = root_near(|x| x * x - 4.0, -1.5, 0.01, 3.0, 1e-14).unwrap();
        assert_abs_diff_eq!(left, -2.0, epsilon = 1e-12);
        assert!(root_near(|x| x * x + 1.0, 0.0, 0.1, 5.0, 1e-12).is_none());
    }

    #[test]
    fn rotations_are_right_handed() {
        let x = Vec3::x();
        assert_abs_diff_eq!(rotation_z(std::f64::consts::FRAC_PI_2) * x, Vec3::y(), epsilon = 1e-15);
        assert_abs_diff_eq!(rotation_y(std::f64::consts::FRAC_PI_2) * Vec3::z(), x, epsilon = 1e-15);
    }
}
