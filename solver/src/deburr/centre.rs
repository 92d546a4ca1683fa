//! The ball centre for one ridge point: the patent's tangent-line construction (docs/spec/deburr.md §2.7,
//! the unified normal form) and kerf's exact variant, which puts the band edges on the true
//! surfaces. Everything here is in the local frame (§1.3): A1 is the y_L axis, the hole axis runs
//! along z_L through (f, 0).

use super::job::Job;
use super::profile::{Profile, ProfilePoint};
use super::request::Edge;
use crate::geometry::{Vec3, root_near};

/// The per-job constants of the construction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Construction {
    /// R1: radius of the deburred cylinder surface.
    pub cylinder_radius: f64,
    /// True for the inner ridge (material at r > R1).
    pub inner: bool,
    /// W/2: half the band width.
    pub half_width: f64,
    /// D: ball radius.
    pub ball_radius: f64,
    /// CM = √(D² − W²/4): distance from the band chord's midpoint to the centre.
    pub centre_to_chord: f64,
}

/// The construction at one ridge point (docs/spec/deburr.md §2.5, §2.7), local frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RidgeCentre {
    /// Ridge point P.
    pub target: Vec3,
    /// Ball centre C.
    pub centre: Vec3,
    /// Cylinder-surface normal into the material, m1.
    pub cylinder_normal: Vec3,
    /// Hole-wall normal into the material, m2.
    pub wall_normal: Vec3,
    /// Unit bisector u, into the material.
    pub bisector: Vec3,
    /// cos θ = m1·m2, where θ = π − β.
    pub cos_theta: f64,
    /// CL: signed distance from P to C along −u.
    pub centre_offset: f64,
}

/// The direction in VP from which [`Construction::circle_meets_surface`] starts: `near`'s
/// components along the plane's basis and the unit vector (cos, sin) they point along.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct CircleStart {
    along_b1: f64,
    along_b2: f64,
    cos: f64,
    sin: f64,
}

impl CircleStart {
    /// The start towards `near` in `plane`.
    pub(super) fn new(plane: (Vec3, Vec3), near: &Vec3) -> Self {
        let (b1, b2) = plane;
        let (along_b1, along_b2) = (near.dot(&b1), near.dot(&b2));
        let length = (along_b1 * along_b1 + along_b2 * along_b2).sqrt();
        Self { along_b1, along_b2, cos: along_b1 / length, sin: along_b2 / length }
    }
}

impl RidgeCentre {
    /// Wedge angle β = π − acos(m1·m2), radians.
    pub fn wedge_angle(&self) -> f64 {
        std::f64::consts::PI - self.cos_theta.acos()
    }

    /// The band edges G1 (on the cylinder-surface tangent) and G2 (on the hole-wall tangent).
    pub fn band_edges(&self, half_width: f64) -> (Vec3, Vec3) {
        let cos_wedge = self.cos_theta;
        let leg = half_width / (0.5 * self.wedge_angle()).sin();
        let along_cylinder = (self.wall_normal - cos_wedge * self.cylinder_normal).normalize();
        let along_wall = (self.cylinder_normal - cos_wedge * self.wall_normal).normalize();
        (self.target + leg * along_cylinder, self.target + leg * along_wall)
    }

    /// Unit vectors spanning the normal plane VP: the wall normal m2 and the wall tangent d3.
    pub(super) fn plane_basis(&self) -> (Vec3, Vec3) {
        let cos_wedge = self.cylinder_normal.dot(&self.wall_normal);
        (self.wall_normal, (self.cylinder_normal - cos_wedge * self.wall_normal).normalize())
    }
}

impl Construction {
    /// The constants of a validated job.
    pub fn for_job(job: &Job) -> Self {
        let ball = job.tool.radius;
        let half_width = job.width / 2.0;
        Self {
            cylinder_radius: job.cylinder_radius,
            inner: job.edge == Edge::Inner,
            half_width,
            ball_radius: ball,
            centre_to_chord: (ball * ball - half_width * half_width).sqrt(),
        }
    }

    /// The patent's construction at profile point `point` (docs/spec/deburr.md §2.7). The caller has checked
    /// |x| < R1.
    #[inline]
    pub fn tangent(&self, point: &ProfilePoint) -> RidgeCentre {
        let r1 = self.cylinder_radius;
        let z = (r1 * r1 - point.x * point.x).sqrt();
        let target = Vec3::new(point.x, point.y, z);
        let radial = Vec3::new(point.x / r1, 0.0, z / r1);
        let cylinder_normal = if self.inner { radial } else { -radial };
        let wall_normal = Vec3::new(point.normal_x, point.normal_y, 0.0);
        let cos_theta = cylinder_normal.dot(&wall_normal).clamp(-1.0, 1.0);
        // |m1 + m2| = √(2 + 2c) and |m1 − m2| = √(2 − 2c): one division serves the bisector and
        // L = (W/2)/tan(β/2) = (W/2)·|m1 − m2|/|m1 + m2| (§2.5), with no trigonometry.
        let inverse_half_sum = 1.0 / (1.0 + cos_theta).sqrt();
        let bisector = (cylinder_normal + wall_normal) * (inverse_half_sum * std::f64::consts::FRAC_1_SQRT_2);
        let chord_depth = self.half_width * (1.0 - cos_theta).sqrt() * inverse_half_sum;
        let centre_offset = self.centre_to_chord - chord_depth;
        RidgeCentre {
            target,
            centre: target - centre_offset * bisector,
            cylinder_normal,
            wall_normal,
            bisector,
            cos_theta,
            centre_offset,
        }
    }

    /// Only the centre C of [`Self::tangent`], for the tolerance bisection's inner loop (inlined,
    /// so the other fields are never stored).
    #[inline]
    pub fn tangent_centre(&self, point: &ProfilePoint) -> Vec3 {
        self.tangent(point).centre
    }

    /// Cylinder-surface function: zero on the surface, positive away from A1.
    fn cylinder(&self, q: &Vec3) -> f64 {
        (q.x * q.x + q.z * q.z).sqrt() - self.cylinder_radius
    }

    /// Where the circle of radius `radius` around `centre` in VP meets the cylinder surface
    /// (`on_wall` false) or the hole wall (`on_wall` true), nearest to direction `near`.
    pub(super) fn circle_meets_surface(
        &self,
        profile: &Profile,
        plane: (Vec3, Vec3),
        centre: &Vec3,
        radius: f64,
        near: &Vec3,
        on_wall: bool,
    ) -> Option<Vec3> {
        self.circle_meets_surface_from(profile, plane, centre, radius, &CircleStart::new(plane, near), on_wall)
    }

    /// [`Self::circle_meets_surface`] from a start direction computed once: root searches over
    /// the radius keep `near` and the plane, so they need not normalise it again per radius.
    pub(super) fn circle_meets_surface_from(
        &self,
        profile: &Profile,
        plane: (Vec3, Vec3),
        centre: &Vec3,
        radius: f64,
        start: &CircleStart,
        on_wall: bool,
    ) -> Option<Vec3> {
        let (b1, b2) = plane;
        let at = |angle: f64| centre + radius * (angle.cos() * b1 + angle.sin() * b2);
        let surface = |q: Vec3| {
            if on_wall { profile.signed_distance(q.x, q.y).0 } else { self.cylinder(&q) }
        };
        // Newton from the tangent-line estimate converges in two or three steps. It turns the unit
        // vector (cos, sin) by each step instead of calling the trigonometric functions, which
        // would cost more than the rest of the construction; the bracketing search below is the
        // fallback for strongly curved cases.
        let (mut cos, mut sin) = (start.cos, start.sin);
        let mut turned = 0.0_f64;
        for _ in 0..12 {
            let q = centre + radius * (cos * b1 + sin * b2);
            // The value and its gradient from one evaluation (the wall's distance and the
            // cylinder's radius are computed once per step, not again for the slope).
            let (value, gradient) = if on_wall {
                let (distance, (gx, gy)) = profile.signed_distance(q.x, q.y);
                (distance, Vec3::new(gx, gy, 0.0))
            } else {
                let r = (q.x * q.x + q.z * q.z).sqrt();
                (r - self.cylinder_radius, Vec3::new(q.x / r, 0.0, q.z / r))
            };
            if value.abs() < 1e-14 {
                return Some(q);
            }
            let slope = gradient.dot(&(radius * (cos * b2 - sin * b1)));
            if slope.abs() < 1e-12 {
                break;
            }
            let step = -value / slope;
            turned += step;
            if turned.abs() > 1.0 {
                break;
            }
            let (step_sin, step_cos) = if step.abs() < 1e-3 {
                // Series to the terms that matter at |step| < 1e-3 (remainders below 1e-17).
                let squared = step * step;
                (step * (1.0 - squared / 6.0), 1.0 - squared / 2.0 + squared * squared / 24.0)
            } else {
                step.sin_cos()
            };
            (cos, sin) = (cos * step_cos - sin * step_sin, sin * step_cos + cos * step_sin);
        }
        let start_angle = start.along_b2.atan2(start.along_b1);
        let angle = root_near(|a| surface(at(a)), start_angle, 1e-3, 1.2, 1e-15)?;
        Some(at(angle))
    }

    /// The chamfer width the tangent-line centre really cuts: the distance between the points
    /// where the ball's section circle in VP meets the true cylinder surface and hole wall
    /// (docs/spec/deburr.md §2.9, W_APPROX). `None` if a circle misses a surface.
    pub fn true_width(&self, profile: &Profile, ridge: &RidgeCentre) -> Option<f64> {
        let (g1, g2) = ridge.band_edges(self.half_width);
        let plane = ridge.plane_basis();
        let c = ridge.centre;
        let on_cylinder = self.circle_meets_surface(profile, plane, &c, self.ball_radius, &(g1 - c), false)?;
        let on_wall = self.circle_meets_surface(profile, plane, &c, self.ball_radius, &(g2 - c), true)?;
        Some((on_cylinder - on_wall).norm())
    }

    /// kerf's exact variant: band edges G1 on the true cylinder surface and G2 on the true hole
    /// wall, both in VP, at equal distances from P and W apart; C on the air side at distance D
    /// from both. Returns the centre and the band edges, or `None` when no such edges exist near
    /// the tangent-line solution.
    pub fn exact(&self, profile: &Profile, ridge: &RidgeCentre) -> Option<(Vec3, Vec3, Vec3)> {
        let plane = ridge.plane_basis();
        let p = ridge.target;
        let (tangent_g1, tangent_g2) = ridge.band_edges(self.half_width);
        let (start_g1, start_g2) =
            (CircleStart::new(plane, &(tangent_g1 - p)), CircleStart::new(plane, &(tangent_g2 - p)));
        let edges = |leg: f64| -> Option<(Vec3, Vec3)> {
            let g1 = self.circle_meets_surface_from(profile, plane, &p, leg, &start_g1, false)?;
            let g2 = self.circle_meets_surface_from(profile, plane, &p, leg, &start_g2, true)?;
            Some((g1, g2))
        };
        let width_error = |leg: f64| edges(leg).map_or(f64::NAN, |(g1, g2)| (g1 - g2).norm() - 2.0 * self.half_width);
        let tangent_leg = (tangent_g1 - p).norm();
        // Secant steps from the tangent-line leg, which is within a few per cent of the answer.
        let (mut leg_a, mut leg_b) = (tangent_leg, tangent_leg * 1.01);
        let (mut error_a, mut error_b) = (width_error(leg_a), width_error(leg_b));
        let mut leg = f64::NAN;
        for _ in 0..30 {
            if !(error_a.is_finite() && error_b.is_finite()) || error_b == error_a {
                break;
            }
            let next = leg_b - error_b * (leg_b - leg_a) / (error_b - error_a);
            if !(next > 0.0 && next < 4.0 * tangent_leg) {
                break;
            }
            (leg_a, error_a) = (leg_b, error_b);
            leg_b = next;
            error_b = width_error(leg_b);
            if error_b.abs() < 1e-13 {
                leg = leg_b;
                break;
            }
        }
        if !leg.is_finite() {
            leg = root_near(width_error, tangent_leg, tangent_leg * 1e-3, tangent_leg * 0.9, 1e-15)?;
        }
        let (g1, g2) = edges(leg)?;
        let midpoint = 0.5 * (g1 + g2);
        // In VP, the unit normal of G1G2 on the air side (against the bisector).
        let chord = (g2 - g1).normalize();
        let normal_axis = ridge.bisector - ridge.bisector.dot(&chord) * chord;
        let away = -normal_axis.normalize();
        Some((midpoint + self.centre_to_chord * away, g1, g2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn case1() -> (Construction, Profile) {
        let w = 0.5 * 2f64.sqrt();
        let construction = Construction {
            cylinder_radius: 50.0,
            inner: false,
            half_width: w / 2.0,
            ball_radius: 3.0,
            centre_to_chord: (9.0 - w * w / 4.0).sqrt(),
        };
        (construction, Profile::round(10.0, 0.0, 0.0))
    }

    #[test]
    fn hand_check_at_phi_zero() {
        let (construction, profile) = case1();
        let ridge = construction.tangent(&profile.segments[0].point(10.0, 0.0));
        assert_abs_diff_eq!(ridge.wedge_angle().to_degrees(), 78.463_040_967, epsilon = 1e-8);
        assert_abs_diff_eq!(ridge.centre_offset, 2.546_081_12, epsilon = 1e-8);
        assert_abs_diff_eq!(ridge.centre, Vec3::new(8.389_716_911, 0.0, 50.961_980_811), epsilon = 1e-8);
    }

    #[test]
    fn exact_edges_lie_on_the_true_surfaces() {
        let (construction, profile) = case1();
        for k in 0..8 {
            let point = profile.segments[0].point(10.0, f64::from(k) / 8.0);
            let ridge = construction.tangent(&point);
            let (centre, g1, g2) = construction.exact(&profile, &ridge).unwrap();
            assert_abs_diff_eq!(construction.cylinder(&g1), 0.0, epsilon = 1e-10);
            assert_abs_diff_eq!(profile.signed_distance(g2.x, g2.y).0, 0.0, epsilon = 1e-10);
            assert_abs_diff_eq!((g1 - g2).norm(), 2.0 * construction.half_width, epsilon = 1e-10);
            assert_abs_diff_eq!((g1 - ridge.target).norm(), (g2 - ridge.target).norm(), epsilon = 1e-10);
            assert_abs_diff_eq!((centre - g1).norm(), 3.0, epsilon = 1e-10);
            assert_abs_diff_eq!((centre - g2).norm(), 3.0, epsilon = 1e-10);
            let tangent = ridge.cylinder_normal.cross(&ridge.wall_normal).normalize();
            assert_abs_diff_eq!((centre - ridge.target).dot(&tangent), 0.0, epsilon = 1e-10);
            // The patent's approximation is off by well under a per cent of W here (§2.9).
            let true_width = construction.true_width(&profile, &ridge).unwrap();
            assert!((true_width / (2.0 * construction.half_width) - 1.0).abs() < 0.01);
        }
    }
}
