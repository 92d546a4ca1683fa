//! Corner detection on an existing closed CL point list (corners.md §3.4, claims 8 and 9): the
//! patent's discrete curvature (a) with (b), (c, reading R2) and the protrusion condition (d),
//! its radial-difference measure (f), and the rotation-invariant turn-angle rule recommended as
//! the default.

use serde::{Deserialize, Serialize};

use crate::planar::{Vec2, centroid, turn_angle};

/// How corners are found on a point list.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum DetectMode {
    /// σφ_i ≥ ψ_min (rotation-invariant; the default).
    #[default]
    TurnAngle,
    /// Claim 8: κ_i ≥ κ_th and condition (d).
    PatentCurvature,
    /// Claim 9: ΔL_i / h_i ≥ λ_th.
    PatentDeltaL,
}

/// The measures of §3.4 at one point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointMeasures {
    /// κ_i of Eq. (a); `None` where a chord is vertical (the patent's formula is undefined).
    pub curvature: Option<f64>,
    /// Condition (d): farther from the centre than both neighbours.
    pub protrudes: bool,
    /// ΔL_i of Eq. (f), mm.
    pub delta_l: f64,
    /// ΔL_i / h_i with h_i the mean spacing at the point.
    pub delta_l_per_step: f64,
    /// φ_i: signed turn at the point, radians.
    pub turn: f64,
}

/// The centre (a, b) (the area centroid; the mean of the points for a degenerate list) and the
/// measures at every point of a closed point list.
pub fn measures(points: &[Vec2]) -> (Vec2, Vec<PointMeasures>) {
    let n = points.len();
    if n < 3 {
        return (Vec2::zeros(), Vec::new());
    }
    let centre = centroid(points).unwrap_or_else(|| points.iter().sum::<Vec2>() / n as f64);
    let radial = |p: &Vec2| (p - centre).norm();
    let list = (0..n)
        .map(|i| {
            let (before, here, after) = (points[(i + n - 1) % n], points[i], points[(i + 1) % n]);
            let curvature = {
                let (dx0, dx1, dx) = (here.x - before.x, after.x - here.x, after.x - before.x);
                (dx0 != 0.0 && dx1 != 0.0 && dx != 0.0).then(|| {
                    let slope_in = (here.y - before.y) / dx0;
                    let slope_out = (after.y - here.y) / dx1;
                    let second = 2.0 * (slope_out - slope_in) / dx;
                    let mean = 0.5 * (slope_in + slope_out);
                    second.abs() / (1.0 + mean * mean).powf(1.5)
                })
            };
            let (l0, l1, l2) = (radial(&before), radial(&here), radial(&after));
            let delta_l = 2.0 * l1 - l0 - l2;
            let spacing = 0.5 * ((here - before).norm() + (after - here).norm());
            PointMeasures {
                curvature,
                protrudes: l1 > l0 && l1 > l2,
                delta_l,
                delta_l_per_step: if spacing > 0.0 {
                    delta_l / spacing
                } else {
                    0.0
                },
                turn: turn_angle(&(here - before), &(after - here)),
            }
        })
        .collect();
    (centre, list)
}

/// Whether a point is a corner under `mode` (`threshold`: ψ_min in radians for `turn_angle`,
/// κ_th in 1/mm, λ_th); `sigma` = +1 with the material on the left.
pub fn is_corner(measure: &PointMeasures, mode: DetectMode, threshold: f64, sigma: f64) -> bool {
    match mode {
        DetectMode::TurnAngle => sigma * measure.turn >= threshold,
        DetectMode::PatentCurvature => {
            measure.protrudes && measure.curvature.is_some_and(|k| k >= threshold)
        }
        DetectMode::PatentDeltaL => measure.delta_l_per_step >= threshold,
    }
}
