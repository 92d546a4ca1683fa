//! The local frame of a cross hole and its map to machine coordinates (docs/spec/deburr.md §1.3, §1.4).

use crate::error::ErrorCode;
use nalgebra::Matrix3;

use crate::error::SolverError;
use crate::geometry::{Vec3, rotation_y, rotation_z};

/// Local frame: origin O on A1 at the hole station, y_L = A1, z_L = A2, x_L = y_L × z_L.
/// Machine point g = O + M·l with M = R_z(θ_A)·R_y(θ_P).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Frame {
    pub origin: Vec3,
    pub rotation: Matrix3<f64>,
}

impl Frame {
    /// Builds the frame from the workpiece origin (a point on A1), the two angles in degrees and
    /// the optional hole-axis point H and eccentricity f; returns the frame and the resolved f.
    /// H moves the origin to H's station on A1 and fixes f = (H − O)·a3 (§1.4).
    pub fn resolve(
        origin_on_axis: Vec3,
        arrangement_deg: f64,
        penetration_deg: f64,
        axis_point: Option<Vec3>,
        eccentricity: Option<f64>,
    ) -> Result<(Self, f64), SolverError> {
        let rotation = rotation_z(arrangement_deg.to_radians()) * rotation_y(penetration_deg.to_radians());
        let mut frame = Self { origin: origin_on_axis, rotation };
        let Some(hole_point) = axis_point else {
            return Ok((frame, eccentricity.unwrap_or(0.0)));
        };
        let axis = frame.vector(&Vec3::y());
        frame.origin += (hole_point - origin_on_axis).dot(&axis) * axis;
        let from_point = (hole_point - frame.origin).dot(&frame.vector(&Vec3::x()));
        if let Some(given) = eccentricity {
            let scale = origin_on_axis.norm().max(hole_point.norm()).max(1.0);
            if (given - from_point).abs() > 1e-6 * scale {
                return Err(SolverError::new(
                    ErrorCode::InconsistentEcc,
                    format!("eccentricity {given} mm disagrees with axis_point, which gives {from_point:.6} mm"),
                )
                .at("hole.eccentricity"));
            }
        }
        Ok((frame, from_point))
    }

    /// Local point to machine coordinates.
    pub fn point(&self, local: &Vec3) -> Vec3 {
        self.origin + self.rotation * local
    }

    /// Local free vector to machine coordinates.
    pub fn vector(&self, local: &Vec3) -> Vec3 {
        self.rotation * local
    }

    /// Machine vector to local coordinates.
    pub fn local_vector(&self, machine: &Vec3) -> Vec3 {
        self.rotation.transpose() * machine
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn axes_match_case_2() {
        let (frame, f) = Frame::resolve(Vec3::new(100.0, 50.0, -20.0), 30.0, 15.0, None, Some(12.0)).unwrap();
        assert_abs_diff_eq!(f, 12.0);
        assert_abs_diff_eq!(frame.vector(&Vec3::y()), Vec3::new(-0.5, 0.866_025_404, 0.0), epsilon = 1e-9);
        assert_abs_diff_eq!(
            frame.vector(&Vec3::z()),
            Vec3::new(0.224_143_868, 0.129_409_523, 0.965_925_826),
            epsilon = 1e-9
        );
        assert_abs_diff_eq!(
            frame.vector(&Vec3::x()),
            Vec3::new(0.836_516_304, 0.482_962_913, -0.258_819_045),
            epsilon = 1e-9
        );
    }

    #[test]
    fn axis_point_fixes_station_and_eccentricity() {
        let origin = Vec3::new(1.0, 2.0, 3.0);
        let (frame, _) = Frame::resolve(origin, 30.0, 15.0, None, None).unwrap();
        let hole_point = frame.point(&Vec3::new(4.0, 7.0, 20.0));
        let (moved, f) = Frame::resolve(origin, 30.0, 15.0, Some(hole_point), None).unwrap();
        assert_abs_diff_eq!(f, 4.0, epsilon = 1e-12);
        assert_abs_diff_eq!(moved.origin, frame.point(&Vec3::new(0.0, 7.0, 0.0)), epsilon = 1e-12);
        assert!(Frame::resolve(origin, 30.0, 15.0, Some(hole_point), Some(4.0)).is_ok());
        let error = Frame::resolve(origin, 30.0, 15.0, Some(hole_point), Some(3.0)).unwrap_err();
        assert_eq!(error.code(), ErrorCode::InconsistentEcc);
    }
}
