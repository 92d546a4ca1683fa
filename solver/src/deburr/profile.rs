//! The hole's cross-section seen from +z_L, as segments in machining order (docs/spec/deburr.md §2.8), and
//! its signed distance (used for the true-surface band edges and the access checks).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

/// A point of the hole profile with its outward (away from the hole) unit normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ProfilePoint {
    pub x: f64,
    pub y: f64,
    pub normal_x: f64,
    pub normal_y: f64,
    /// φ of the point on its corner/end circle, for arcs.
    pub phi: Option<f64>,
}

/// One piece of the profile.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Piece {
    /// Part of a circle of radius R2 around `(centre_x, centre_y)`, φ from `phi_start` to `phi_end`.
    Arc { centre_x: f64, centre_y: f64, phi_start: f64, phi_end: f64 },
    /// Straight side from `start` to `end` with outward normal `normal`.
    Line { start: (f64, f64), end: (f64, f64), normal: (f64, f64) },
}

/// A named piece of the profile (names as in docs/spec/deburr.md §2.8, lower case).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Segment {
    pub name: &'static str,
    pub piece: Piece,
}

impl Segment {
    /// The profile point at parameter `s` ∈ [0, 1].
    pub fn point(&self, radius: f64, s: f64) -> ProfilePoint {
        match self.piece {
            Piece::Arc { centre_x, centre_y, phi_start, phi_end } => {
                let phi = phi_start + s * (phi_end - phi_start);
                let (sin, cos) = phi.sin_cos();
                ProfilePoint {
                    x: centre_x + radius * cos,
                    y: centre_y + radius * sin,
                    normal_x: cos,
                    normal_y: sin,
                    phi: Some(phi),
                }
            }
            Piece::Line { start, end, normal } => ProfilePoint {
                x: start.0 + s * (end.0 - start.0),
                y: start.1 + s * (end.1 - start.1),
                normal_x: normal.0,
                normal_y: normal.1,
                phi: None,
            },
        }
    }

    /// Number of equal parameter intervals the tolerance bisection starts from (docs/spec/deburr.md §3):
    /// ⌈sweep/90°⌉ for arcs, 1 for lines.
    pub fn initial_intervals(&self) -> u32 {
        match self.piece {
            Piece::Arc { phi_start, phi_end, .. } => {
                // At most 4 quarter turns; the small slack keeps an exact quarter at 1.
                ((phi_end - phi_start).abs() / FRAC_PI_2 - 1e-9).ceil().max(1.0) as u32
            }
            Piece::Line { .. } => 1,
        }
    }

    /// True for sides parallel to A1, whose centre path is exactly straight: never split (§3).
    pub fn is_axial_line(&self) -> bool {
        matches!(self.piece, Piece::Line { normal, .. } if normal.1 == 0.0)
    }

    /// Length of the piece on a profile of corner radius `radius`.
    pub fn length(&self, radius: f64) -> f64 {
        match self.piece {
            Piece::Arc { phi_start, phi_end, .. } => radius * (phi_end - phi_start).abs(),
            Piece::Line { start, end, .. } => (end.0 - start.0).hypot(end.1 - start.1),
        }
    }
}

/// The hole profile: the set of points within `radius` of a core (a point, a segment along A1 or
/// a rectangle), plus its segments in machining order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Profile {
    /// R2: hole radius, slot half-width or corner radius.
    pub radius: f64,
    /// x of the core's centre (the eccentricity f).
    pub centre_x: f64,
    /// Half extent of the core along x_L (a) and along A1 (b); zero for a round hole.
    pub half_across: f64,
    pub half_along: f64,
    pub segments: Vec<Segment>,
}

impl Profile {
    /// A round hole, starting at `start` (radians from +x_L) and running counter-clockwise.
    pub fn round(radius: f64, centre_x: f64, start: f64) -> Self {
        let arc = Piece::Arc { centre_x, centre_y: 0.0, phi_start: start, phi_end: start + TAU };
        Self {
            radius,
            centre_x,
            half_across: 0.0,
            half_along: 0.0,
            segments: vec![Segment { name: "arc", piece: arc }],
        }
    }

    /// A rounded rectangle with corner centres at (f ± a, ± b); a = 0 gives a slot along A1 and
    /// a = b = 0 a round hole split into half circles. Zero-length sides are left out.
    pub fn rounded_rect(radius: f64, centre_x: f64, half_across: f64, half_along: f64, slot_names: bool) -> Self {
        let (f, a, b, r) = (centre_x, half_across, half_along, radius);
        let arc = |name, cx: f64, cy: f64, from: f64, to: f64| Segment {
            name,
            piece: Piece::Arc { centre_x: cx, centre_y: cy, phi_start: from, phi_end: to },
        };
        let line = |name, start, end, normal| Segment { name, piece: Piece::Line { start, end, normal } };
        let mut segments = Vec::with_capacity(8);
        if b > 0.0 {
            segments.push(line("line_y+x", (f + a + r, -b), (f + a + r, b), (1.0, 0.0)));
        }
        if slot_names {
            segments.push(arc("arc_cs2", f, b, 0.0, PI));
        } else {
            segments.push(arc("arc_q1", f + a, b, 0.0, FRAC_PI_2));
            if a > 0.0 {
                segments.push(line("line_x+y", (f + a, b + r), (f - a, b + r), (0.0, 1.0)));
            }
            segments.push(arc("arc_q2", f - a, b, FRAC_PI_2, PI));
        }
        if b > 0.0 {
            segments.push(line("line_y-x", (f - a - r, b), (f - a - r, -b), (-1.0, 0.0)));
        }
        if slot_names {
            segments.push(arc("arc_cs1", f, -b, PI, TAU));
        } else {
            segments.push(arc("arc_q3", f - a, -b, PI, 1.5 * PI));
            if a > 0.0 {
                segments.push(line("line_x-y", (f - a, -b - r), (f + a, -b - r), (0.0, -1.0)));
            }
            segments.push(arc("arc_q4", f + a, -b, 1.5 * PI, TAU));
        }
        Self { radius, centre_x, half_across, half_along, segments }
    }

    /// Largest |x| over the profile: the ridge exists only while this stays below R1 (§4).
    pub fn max_abs_x(&self) -> f64 {
        self.centre_x.abs() + self.half_across + self.radius
    }

    /// Radius of the largest circle that fits in the hole (its half-width).
    pub fn inscribed_radius(&self) -> f64 {
        self.radius + self.half_across.min(self.half_along)
    }

    /// Signed distance of (x, y) from the hole wall (negative inside the hole) and its gradient.
    pub fn signed_distance(&self, x: f64, y: f64) -> (f64, (f64, f64)) {
        let dx = x - self.centre_x;
        let (qx, qy) = (dx.abs() - self.half_across, y.abs() - self.half_along);
        let (ox, oy) = (qx.max(0.0), qy.max(0.0));
        let outside = (ox * ox + oy * oy).sqrt();
        if outside > 0.0 {
            let gradient = (ox / outside * dx.signum(), oy / outside * y.signum());
            (outside - self.radius, gradient)
        } else if qx > qy {
            // Inside the core rectangle: the nearest core side decides.
            (qx - self.radius, (dx.signum(), 0.0))
        } else {
            (qy - self.radius, (0.0, y.signum()))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn segment_points_lie_on_the_wall_with_outward_normals() {
        for profile in [
            Profile::round(5.0, 1.0, 0.3),
            Profile::rounded_rect(4.0, 2.0, 0.0, 15.0, true),
            Profile::rounded_rect(4.0, -3.0, 10.0, 15.0, false),
        ] {
            for segment in &profile.segments {
                for k in 0..=10 {
                    let p = segment.point(profile.radius, f64::from(k) / 10.0);
                    let (distance, gradient) = profile.signed_distance(p.x, p.y);
                    assert_abs_diff_eq!(distance, 0.0, epsilon = 1e-12);
                    assert_abs_diff_eq!(gradient.0, p.normal_x, epsilon = 1e-12);
                    assert_abs_diff_eq!(gradient.1, p.normal_y, epsilon = 1e-12);
                }
            }
        }
    }

    #[test]
    fn segments_join_end_to_start_and_close() {
        let profile = Profile::rounded_rect(4.0, 5.0, 10.0, 15.0, false);
        let names: Vec<_> = profile.segments.iter().map(|s| s.name).collect();
        assert_eq!(names, ["line_y+x", "arc_q1", "line_x+y", "arc_q2", "line_y-x", "arc_q3", "line_x-y", "arc_q4"]);
        let count = profile.segments.len();
        for (i, segment) in profile.segments.iter().enumerate() {
            let end = segment.point(4.0, 1.0);
            let next = profile.segments[(i + 1) % count].point(4.0, 0.0);
            assert_abs_diff_eq!(end.x, next.x, epsilon = 1e-12);
            assert_abs_diff_eq!(end.y, next.y, epsilon = 1e-12);
        }
        assert_eq!(profile.segments[1].initial_intervals(), 1);
        assert!(profile.segments[0].is_axial_line());
        assert!(!profile.segments[2].is_axial_line());
        assert_eq!(Profile::round(1.0, 0.0, 0.0).segments[0].initial_intervals(), 4);
    }

    #[test]
    fn signed_distance_is_negative_inside() {
        let slot = Profile::rounded_rect(6.0, -8.0, 0.0, 15.0, true);
        assert_abs_diff_eq!(slot.signed_distance(-8.0, 0.0).0, -6.0);
        assert_abs_diff_eq!(slot.signed_distance(-8.0, 25.0).0, 4.0);
        assert_abs_diff_eq!(slot.inscribed_radius(), 6.0);
        assert_abs_diff_eq!(slot.max_abs_x(), 14.0);
    }
}
