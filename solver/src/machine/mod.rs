//! Controller profiles (api.md, Machines; chord.md §2.1, §6.4): the block processing time and
//! limits of one control, stored by the server and used as defaults by any request that names it;
//! the block-time rule that turns them into chord errors ([`rule`]) and the block statistics of a
//! path ([`stats`]). Every path-emitting capability uses them: segment, deburr, contour,
//! engagement.

pub mod cycle;
pub mod rule;
pub mod stats;

pub use rule::{BlockRule, ChordStatus, Infeasible, RuleSettings, block_time_from_saturation, chord_length};
pub use stats::{BlockStats, PathBlocks, block_stats, path_blocks, short_block_warning};

use serde::{Deserialize, Serialize};

use crate::error::SolverError;

use crate::gcode::Dialect;
use crate::validate::{non_negative, positive};

/// Longest machine name.
pub const MAX_NAME_CHARS: usize = 64;
/// Longest description.
pub const MAX_DESCRIPTION_CHARS: usize = 200;

/// A machine (controller profile): `PUT /api/v1/machines/{name}` stores it; a request with
/// `"machine": "name"` takes these values as defaults it can override.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct MachineProfile {
    /// The name it is registered under (`/api/v1/machines/{name}`; a body may repeat it, and a
    /// job file's `machines` entries need it). Not used by the solver.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// T_b: time the control needs to read and prepare one block, ms (> 0). Measure it with a
    /// run of short blocks: T_b = block length / saturated speed × 60000 (chord.md §2.1, Eq. 1).
    pub block_time_ms: f64,
    /// Highest programmable cutting feed, mm/min (> 0); the feed of a request that gives none.
    pub max_feed: f64,
    /// G-code dialect of the control (default `fanuc`).
    #[serde(default)]
    pub dialect: Dialect,
    /// k_f: margin factor on the feed for the block-time rule (≥ 1, e.g. 1.1; default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// C_emin: smallest chord error worth programming on this control, mm (≥ 0, e.g. 0.001).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_chord_error: Option<f64>,
    /// Free text: control model, mode the block time was measured in (axes, look-ahead,
    /// compensation), date (at most 200 characters).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub description: Option<String>,
    /// How segment requests on this control choose their chord error unless they say:
    /// `window` (the patent's, default), `curve` or `guarantee` (no block shorter than the control
    /// needs, chord.md §2.9a).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<crate::chord::Mode>,
    /// Rated spindle power, kW (> 0): engagement with Kienzle values warns where the cut needs
    /// more and its feed plan caps the feed to stay within it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_power_kw: Option<f64>,
    /// Rated spindle torque, N·m (> 0), used like `spindle_power_kw`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_torque_nm: Option<f64>,
    /// How programs for this control write circular moves unless the request says (`?arcs=`,
    /// `[output] arcs`): `g2g3` or `chords` (default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arcs: Option<crate::gcode::Arcs>,
    /// Feed of plunges (straight moves down the tool axis), mm/min (> 0), for tools without
    /// their own `plunge_feed`; default half the cutting feed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plunge_feed: Option<f64>,
    /// Largest path acceleration, mm/s² (> 0): with it, answers add a `cycle_time` with a
    /// trapezoidal feed profile (issue 15).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_accel: Option<f64>,
    /// Rapid traverse feed, mm/min (> 0; default `max_feed`), for `cycle_time`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rapid_feed: Option<f64>,
    /// Time of one tool change, s (≥ 0; default 0), for `cycle_time`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_change_s: Option<f64>,
}

impl MachineProfile {
    /// What [`cycle::cycle_time`] needs, when the profile has an acceleration.
    pub fn dynamics(&self) -> Option<cycle::Dynamics> {
        Some(cycle::Dynamics {
            max_accel: self.max_accel?,
            rapid_feed: self.rapid_feed.unwrap_or(self.max_feed),
            block_time_s: self.block_time_ms / 1000.0,
            tool_change_s: self.tool_change_s.unwrap_or(0.0),
        })
    }

    /// The spindle's rated power and torque, as engagement checks a cut against them.
    pub fn spindle(&self) -> crate::engagement::SpindleLimits {
        crate::engagement::SpindleLimits {
            spindle_power_kw: self.spindle_power_kw,
            spindle_torque_nm: self.spindle_torque_nm,
        }
    }

    /// Checks every value, naming the field as written in the machine's JSON.
    ///
    /// # Errors
    /// `E_INPUT` for a bad name, a block time or feed that is not positive, a margin below 1, a
    /// negative minimum chord error or a description over 200 characters.
    pub fn validate(&self) -> Result<(), SolverError> {
        if let Some(name) = &self.name {
            validate_machine_name(name)?;
        }
        positive("block_time_ms", self.block_time_ms)?;
        positive("max_feed", self.max_feed)?;
        self.spindle().validate()?;
        if let Some(margin) = self.margin
            && positive("margin", margin)? < 1.0
        {
            return Err(SolverError::input(
                "margin",
                format!(
                    "margin must be at least 1 (got {margin}): below 1 blocks get shorter than the control can process"
                ),
            ));
        }
        if let Some(plunge_feed) = self.plunge_feed {
            positive("plunge_feed", plunge_feed)?;
        }
        if let Some(max_accel) = self.max_accel {
            positive("max_accel", max_accel)?;
        }
        if let Some(rapid_feed) = self.rapid_feed {
            positive("rapid_feed", rapid_feed)?;
        }
        if let Some(tool_change_s) = self.tool_change_s {
            non_negative("tool_change_s", tool_change_s)?;
        }
        if let Some(min_chord_error) = self.min_chord_error {
            non_negative("min_chord_error", min_chord_error)?;
        }
        if let Some(description) = &self.description {
            crate::validate::text("description", description, MAX_DESCRIPTION_CHARS)?;
        }
        Ok(())
    }
}

/// Checks a machine name for the registry path `/api/v1/machines/{name}`: 1–64 characters of
/// letters, digits, `-`, `_` and `.`, not starting with `.`.
///
/// # Errors
/// `E_INPUT` at `name` otherwise.
pub fn validate_machine_name(name: &str) -> Result<(), SolverError> {
    let allowed = |c: char| c.is_ascii_alphanumeric() || matches!(c, '-' | '_' | '.');
    if name.is_empty() || name.chars().count() > MAX_NAME_CHARS || name.starts_with('.') || !name.chars().all(allowed) {
        return Err(SolverError::input(
            "name",
            format!(
                "a machine name has 1 to {MAX_NAME_CHARS} letters, digits, '-', '_' or '.', and does not start with '.'"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profiles_round_trip_and_validate() {
        let json = r#"{"block_time_ms": 4, "max_feed": 12000, "dialect": "linuxcnc", "margin": 1.1}"#;
        let machine: MachineProfile = serde_json::from_str(json).unwrap();
        assert_eq!(machine.dialect, Dialect::Linuxcnc);
        machine.validate().unwrap();
        let text = serde_json::to_string(&machine).unwrap();
        assert_eq!(serde_json::from_str::<MachineProfile>(&text).unwrap(), machine);
        let bad = MachineProfile { margin: Some(0.9), ..machine.clone() };
        assert_eq!(bad.validate().unwrap_err().field(), Some("margin"));
        let bad = MachineProfile { block_time_ms: 0.0, ..machine.clone() };
        assert_eq!(bad.validate().unwrap_err().field(), Some("block_time_ms"));
        let bad = MachineProfile { name: Some("a b".to_owned()), ..machine };
        assert_eq!(bad.validate().unwrap_err().field(), Some("name"));
        assert!(serde_json::from_str::<MachineProfile>(r#"{"block_time_ms": 4, "max_feed": 1, "x": 1}"#).is_err());
    }

    #[test]
    fn names_are_path_safe() {
        assert!(validate_machine_name("dmu-50_hsc.2").is_ok());
        for bad in ["", ".hidden", "a/b", "with space", &"x".repeat(65)] {
            assert!(validate_machine_name(bad).is_err(), "{bad}");
        }
    }
}
