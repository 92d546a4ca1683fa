//! The cutting physics of a request (docs/spec/engagement.md §11 items 4, 5): the Kienzle values
//! from `kienzle` or the named material, and the force model of a path at its axial depth.

use super::super::arcs::SpindleDirection;
use super::super::force::ForceModel;
use super::super::heights::Loads;
use super::super::kienzle::SinPower;
use super::super::request::EngagementRequest;
use super::Physics;
use crate::error::SolverError;
use crate::machine::SpindleLimits;
use crate::material::{DEFAULT_RADIAL_RATIO, Kienzle};
use crate::tool::{Tool, ToolKind};

impl EngagementRequest {
    /// The Kienzle values from `kienzle` or the resolved `material`, and the spindle limits.
    pub(super) fn kienzle(&self, physics: &Physics) -> Result<(Option<Kienzle>, SpindleLimits), SolverError> {
        physics.spindle.validate()?;
        let kienzle = match (&self.kienzle, &self.material) {
            (Some(_), Some(_)) => {
                return Err(SolverError::input("material", "give material or kienzle, not both"));
            }
            (Some(values), None) => {
                values.validate("kienzle.")?;
                Some(*values)
            }
            (None, Some(name)) => {
                let values = physics.material.ok_or_else(|| {
                    SolverError::input(
                        "material",
                        format!("material {name:?} is not known here: give its Kienzle values as `kienzle` (kc11, mc)"),
                    )
                })?;
                values.validate("material.")?;
                Some(values)
            }
            (None, None) => None,
        };
        Ok((kienzle, physics.spindle))
    }
}

/// Kienzle's force model for a path cut `axial_depth` deep.
///
/// # Errors
/// `E_INPUT` at `axial_depth` without a depth: a_p is the chip width.
pub(super) fn force_model(
    kienzle: &Kienzle,
    tool: &Tool,
    axial_depth: Option<f64>,
    direction: SpindleDirection,
) -> Result<ForceModel, SolverError> {
    let axial_depth = axial_depth.ok_or_else(|| {
        SolverError::input(
            "axial_depth",
            "axial_depth (mm) is required with kienzle or material (or paths[i].axial_depth for every path), or the path's Z under the stock top (cut_z, with stock_top_z, default 0): a_p is the chip width",
        )
    })?;
    // Λ = 2·a_p·tan λ / D (docs/spec/engagement.md §11 item 5), radians.
    let helix_tan = tool.helix_deg.map_or(0.0, |helix| helix.to_radians().tan());
    let lag = axial_depth * helix_tan / tool.radius;
    let (table, table_next) = (SinPower::new(1.0 - kienzle.mc), SinPower::new(2.0 - kienzle.mc));
    let corner_radius = match tool.kind {
        ToolKind::Flat => 0.0,
        ToolKind::Ball => tool.radius,
        ToolKind::Bull => tool.corner_radius.unwrap_or(0.0).min(tool.radius),
    };
    let (force_width, torque_width) =
        ForceModel::end_widths(&table, &table_next, tool.radius, corner_radius, axial_depth);
    Ok(ForceModel {
        kc11: kienzle.kc11,
        mc: kienzle.mc,
        axial_depth,
        force_width,
        torque_width,
        lag_deg: lag.to_degrees(),
        radius: tool.radius,
        corner_radius,
        helix_tan,
        loads: (corner_radius > 0.0 && axial_depth > 0.0).then(|| Box::new(Loads::new(1.0 - kienzle.mc))),
        direction,
        radial_ratio: kienzle.radial_ratio.unwrap_or(DEFAULT_RADIAL_RATIO),
        table,
        table_next,
    })
}
