//! The tool's shape-error table δ(θ) and its conversions (docs/spec/predict.md §3.13, S11):
//! linear interpolation in θ, clamped and flagged outside the table (§5 E14), and δ from measured
//! section radii of the rotating tool, exactly (the nominal normal line intersected with the
//! measured profile) or to first order (δ ≈ Δr(z(θ))·sin θ).

use crate::error::SolverError;

use crate::tool::ShapeErrorPoint;
use crate::validate::{Measure, finite, positive};

/// δ(θ) in mm at contact angle `theta_deg`, and whether the angle was outside the table.
pub(crate) fn delta(table: &[ShapeErrorPoint], theta_deg: f64) -> (f64, bool) {
    let (first, last) = (table[0], table[table.len() - 1]);
    if theta_deg <= first.angle_deg {
        return (first.error, theta_deg < first.angle_deg);
    }
    if theta_deg >= last.angle_deg {
        return (last.error, theta_deg > last.angle_deg);
    }
    let upper = table.partition_point(|row| row.angle_deg < theta_deg);
    let (a, b) = (table[upper - 1], table[upper]);
    let t = (theta_deg - a.angle_deg) / (b.angle_deg - a.angle_deg);
    (a.error + t * (b.error - a.error), false)
}

/// One measured section of the rotating tool: its envelope radius at a height above the nominal
/// tip.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    /// Height above the nominal tip, mm (0 ≤ height ≤ R).
    pub height: f64,
    /// Measured envelope radius of the rotating tool in that section, mm.
    pub radius: f64,
}

/// How to convert sections to δ(θ).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Conversion {
    /// Intersect the nominal normal line at θ with the measured profile (linear between
    /// sections).
    Exact,
    /// δ(θ) ≈ Δr(z(θ))·sin θ with z(θ) = R(1 − cos θ).
    FirstOrder,
}

/// Builds a shape-error table for `angles_deg` from measured sections of a ball of nominal
/// `radius`, sections sorted by height.
///
/// # Errors
/// `E_INPUT` for fewer than two sections, unsorted heights, bad numbers, or an angle whose
/// normal line does not meet the measured profile.
pub fn shape_error_from_sections(
    radius: f64,
    sections: &[Section],
    angles_deg: &[f64],
    conversion: Conversion,
) -> Result<Vec<ShapeErrorPoint>, SolverError> {
    positive("radius", radius, Measure::Length)?;
    if sections.len() < 2 {
        return Err(SolverError::input("sections", "give at least two sections"));
    }
    for (index, pair) in sections.windows(2).enumerate() {
        finite(&format!("sections[{index}].height"), pair[0].height)?;
        finite(&format!("sections[{index}].radius"), pair[0].radius)?;
        if pair[1].height <= pair[0].height {
            return Err(SolverError::input(
                format!("sections[{}].height", index + 1),
                "section heights must increase strictly",
            ));
        }
    }
    let profile = |z: f64| -> f64 {
        let upper = sections.partition_point(|s| s.height < z).clamp(1, sections.len() - 1);
        let (a, b) = (sections[upper - 1], sections[upper]);
        a.radius + (z - a.height) / (b.height - a.height) * (b.radius - a.radius)
    };
    let nominal = |z: f64| (radius * radius - (radius - z) * (radius - z)).max(0.0).sqrt();
    angles_deg
        .iter()
        .enumerate()
        .map(|(index, &angle)| {
            let field = format!("angles_deg[{index}]");
            let theta = finite(&field, angle)?.to_radians();
            if !(0.0..=std::f64::consts::FRAC_PI_2).contains(&theta) {
                return Err(SolverError::input(field, "angles must lie in [0, 90] degrees"));
            }
            let (sin, cos) = theta.sin_cos();
            let error = match conversion {
                Conversion::FirstOrder => {
                    let z = radius * (1.0 - cos);
                    (profile(z) - nominal(z)) * sin
                }
                Conversion::Exact => {
                    // Point at distance s from the centre along ê_r(θ): height R − s·cos θ,
                    // radius s·sin θ; find s where it lies on the measured profile.
                    let mismatch = |s: f64| s * sin - profile(radius - s * cos);
                    crate::geometry::root_near(mismatch, radius, 1e-4 * radius, 0.5 * radius, 1e-13)
                        .map(|s| s - radius)
                        .ok_or_else(|| {
                            SolverError::input(
                                field,
                                "the normal line at this angle does not meet the measured profile",
                            )
                        })?
                }
            };
            Ok(ShapeErrorPoint { angle_deg: angle, error })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_clamps_and_flags() {
        let table =
            [ShapeErrorPoint { angle_deg: 10.0, error: 0.01 }, ShapeErrorPoint { angle_deg: 50.0, error: 0.03 }];
        let (middle, outside) = delta(&table, 30.0);
        assert!((middle - 0.02).abs() < 1e-15 && !outside);
        assert_eq!(delta(&table, 5.0), (0.01, true));
        assert_eq!(delta(&table, 60.0), (0.03, true));
        assert_eq!(delta(&table, 50.0), (0.03, false));
    }
}
