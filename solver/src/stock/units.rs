//! Lengths of a stock, for the request's units (docs/spec/api.md, Units).

use super::Stock;
use crate::units::{Scale, Scaling};

/// A stock's corners, points, radii, spacing and heights; a `mesh` stock's file is in the
/// request's units unless it names its own, which it then names.
impl Scale for Stock {
    fn scale(&mut self, scaling: Scaling) {
        match self {
            Self::Box { min, max } => {
                min.scale(scaling);
                max.scale(scaling);
            }
            Self::Plane { point, normal: _, min, max } => {
                point.scale(scaling);
                min.scale(scaling);
                max.scale(scaling);
            }
            Self::Cylinder { start, end, radius } => {
                start.scale(scaling);
                end.scale(scaling);
                radius.scale(scaling);
            }
            Self::Grid { origin, spacing, heights, bottom } => {
                origin.scale(scaling);
                spacing.scale(scaling);
                heights.scale(scaling);
                bottom.scale(scaling);
            }
            Self::Mesh { units } => {
                units.get_or_insert(scaling.units());
            }
        }
    }
}
