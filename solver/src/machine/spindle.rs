//! The spindle's power and torque ratings of a machine profile, and the largest cutting torque
//! they allow at a spindle speed (docs/spec/engagement.md §11 item 4).

use serde::{Deserialize, Serialize};

use crate::error::SolverError;
use crate::validate::{Measure, positive};

/// The spindle's ratings, from the machine profile (docs/spec/engagement.md §11 item 4). The cut is
/// compared through its torque averaged over the tooth phase: that is the load the spindle
/// drive carries, its rotor's inertia smoothing the tooth-by-tooth peaks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct SpindleLimits {
    /// Rated spindle power, kW (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_power_kw: Option<f64>,
    /// Rated spindle torque, N·m (> 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_torque_nm: Option<f64>,
}

impl SpindleLimits {
    /// Checks both values, naming the fields as in a machine profile.
    ///
    /// # Errors
    /// `E_INPUT` for a value that is not positive and finite.
    pub fn validate(&self) -> Result<(), SolverError> {
        if let Some(power) = self.spindle_power_kw {
            positive("spindle_power_kw", power, Measure::Number)?;
        }
        if let Some(torque) = self.spindle_torque_nm {
            positive("spindle_torque_nm", torque, Measure::Number)?;
        }
        Ok(())
    }

    /// Whether either limit is given.
    pub fn any(&self) -> bool {
        self.spindle_power_kw.is_some() || self.spindle_torque_nm.is_some()
    }

    /// The largest phase-mean torque both limits allow at `spindle_rpm`, N·m, and whether power
    /// (rather than torque) sets it.
    pub(crate) fn torque_cap(&self, spindle_rpm: f64) -> Option<(f64, bool)> {
        // P = 2πN·M/60 ⇒ M = 60·P/(2πN), P in W.
        let from_power = self.spindle_power_kw.map(|p| 60.0 * p * 1000.0 / (std::f64::consts::TAU * spindle_rpm));
        match (from_power, self.spindle_torque_nm) {
            (Some(p), Some(t)) => Some(if p <= t { (p, true) } else { (t, false) }),
            (Some(p), None) => Some((p, true)),
            (None, Some(t)) => Some((t, false)),
            (None, None) => None,
        }
    }
}
