//! Controller profiles (docs/spec/api.md, Machines; docs/spec/segment.md §2.1, §6.4): the block processing time and
//! limits of one control, stored by the server and used as defaults by any request that names it;
//! the block-time rule that turns them into chord errors ([`rule`]) and the block statistics of a
//! path ([`stats`]); the spindle's ratings ([`SpindleLimits`], docs/spec/engagement.md §11 item 4).
//! Every path-emitting capability uses them: segment, deburr, contour, engagement.

pub mod cycle;
pub mod rule;
mod spindle;
pub mod stats;
mod units;

pub use rule::{BlockRule, ChordStatus, Infeasible, Mode, RuleSettings, block_time_from_saturation, chord_length};
pub use spindle::SpindleLimits;
pub use stats::{BlockStats, PathBlocks, block_stats, path_blocks, short_block_warning};

use serde::{Deserialize, Serialize};

use crate::error::{SolverError, Warning};

use crate::gcode::Dialect;
use crate::validate::{Measure, non_negative, positive, positive_at_most};

/// Largest `max_jerk`, mm/s³ (10⁶ m/s³: far beyond any machine axis; more is a unit mistake).
pub const MAX_JERK: f64 = 1e9;

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
    /// run of short blocks: T_b = block length / saturated speed × 60000 (docs/spec/segment.md §2.1, Eq. 1).
    pub block_time_ms: f64,
    /// Highest programmable cutting feed, mm/min (> 0); the feed of a request that gives none.
    pub max_feed: f64,
    /// The post its programs are written for (`fanuc` default, `haas`, `linuxcnc`, `sinumerik`,
    /// `heidenhain`, `heidenhain_iso`, `grbl`; docs/guide/gcode.md).
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
    /// needs, docs/spec/segment.md §2.9a).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<Mode>,
    /// Rated spindle power, kW (> 0): engagement with Kienzle values warns where the cut needs
    /// more and its feed plan caps the feed to stay within it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_power_kw: Option<f64>,
    /// Rated spindle torque, N·m (> 0), used like `spindle_power_kw`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_torque_nm: Option<f64>,
    /// Highest spindle speed, rpm (> 0): no program is written faster (a contour, deburr or
    /// segment request, or an engagement program, at a faster `spindle_rpm` is refused at it),
    /// and engagement recommends no flute count at a faster spindle speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_spindle_rpm: Option<f64>,
    /// The spindle's power curve (S1, continuous duty): `[[rpm, kW], ...]`, 2–64 points, speeds
    /// rising from 0 or more, powers above 0. The power available at a request's spindle speed
    /// is interpolated linearly between the points and held beyond the ends; with
    /// `spindle_power_kw` too the lower of the two applies. The curve below a drive's base speed
    /// is how a constant-torque range is written (power rising with speed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_power_curve: Option<Vec<[f64; 2]>>,
    /// How programs for this control write circular moves unless the request says (`?arcs=`,
    /// `[output] arcs`): `g2g3` or `chords` (default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arcs: Option<crate::gcode::Arcs>,
    /// Feed of plunges (straight moves down the tool axis), mm/min (> 0), for tools without
    /// their own `plunge_feed`; default half the cutting feed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plunge_feed: Option<f64>,
    /// Largest path acceleration, mm/s² (> 0): with it, answers add a `cycle_time` with a
    /// trapezoidal feed profile.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_accel: Option<f64>,
    /// Largest path jerk, mm/s³ (> 0, at most 10⁹): with `max_accel`, `cycle_time` changes speed
    /// in jerk-limited S-curves instead of trapezoids.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_jerk: Option<f64>,
    /// Rapid traverse feed, mm/min (> 0; default `max_feed`), for `cycle_time`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rapid_feed: Option<f64>,
    /// Time of one tool change, s (≥ 0; default 0), for `cycle_time`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool_change_s: Option<f64>,
    /// The units of the requests that name this machine and give none (`mm` or `inch`; default
    /// `mm`), and so of their answers and programs (G20 for inch). The profile's own values are in
    /// mm and mm/min whatever this says.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
    /// Haas high-speed smoothing written by the Haas post after its safety block: `G187 P1`
    /// (rough), `P2` (medium) or `P3` (finish). Default none: the control's setting applies.
    /// Other posts ignore it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "schema", schema(minimum = 1, maximum = 3))]
    pub haas_smoothing: Option<u8>,
}

/// A feed the request asks for (`field`, mm/min) as the program may write it: capped by
/// `machine`'s `max_feed`, with `W_FEED_ABOVE_MACHINE_MAX` saying from what to what when it is
/// lowered. A machine caps a user's feed; it never raises it (a value at or below the machine's,
/// or one that is not a number, which validation refuses, comes back unchanged).
pub fn cap_feed(machine: Option<&MachineProfile>, field: &str, feed: f64, warnings: &mut Vec<Warning>) -> f64 {
    let Some(machine) = machine else { return feed };
    if feed > machine.max_feed {
        warnings.push(Warning::new(
            "W_FEED_ABOVE_MACHINE_MAX",
            format!(
                "{field} {feed} mm/min is above the machine's max_feed {max} mm/min: {field} capped from {feed} \
                 mm/min to {max} mm/min",
                max = machine.max_feed
            ),
        ));
        machine.max_feed
    } else {
        feed
    }
}

/// A spindle speed the request asks for (`field`, rpm), refused above the machine's
/// `max_spindle_rpm` (`max`, none without a machine or a maximum): a control clamps the speed it
/// cannot reach and keeps the programmed feeds, so every tooth would cut a thicker chip than the
/// request planned (a feed is capped instead, [`cap_feed`]: a slower feed only thins the chip).
///
/// # Errors
/// `E_INPUT` at `field`.
pub fn spindle_within(max: Option<f64>, field: &str, rpm: f64) -> Result<f64, SolverError> {
    match max {
        Some(max) if rpm > max => Err(SolverError::input(
            field,
            format!(
                "{field} {rpm} rpm is above the machine's max_spindle_rpm {max} rpm: its control would run the \
                 spindle slower under the same feeds, a thicker chip than planned; ask for at most {max} rpm"
            ),
        )),
        _ => Ok(rpm),
    }
}

impl MachineProfile {
    /// What [`cycle::cycle_time`] needs, when the profile has an acceleration.
    pub fn dynamics(&self) -> Option<cycle::Dynamics> {
        Some(cycle::Dynamics {
            max_accel: self.max_accel?,
            max_jerk: self.max_jerk,
            rapid_feed: self.rapid_feed.unwrap_or(self.max_feed),
            block_time_s: self.block_time_ms / 1000.0,
            tool_change_s: self.tool_change_s.unwrap_or(0.0),
        })
    }

    /// The spindle's rated power and torque, as engagement checks a cut against them.
    pub fn spindle(&self) -> SpindleLimits {
        SpindleLimits { spindle_power_kw: self.spindle_power_kw, spindle_torque_nm: self.spindle_torque_nm }
    }

    /// The spindle's limits at `spindle_rpm`: the rated power, lowered to the power curve's
    /// value at that speed when the profile has a curve (a speed that is not a positive finite
    /// number, which the request's validation refuses, gets the rated values).
    pub fn spindle_at(&self, spindle_rpm: f64) -> SpindleLimits {
        let rated = self.spindle();
        let Some(curve) = self.spindle_power_curve.as_deref().filter(|c| !c.is_empty()) else { return rated };
        if !(spindle_rpm.is_finite() && spindle_rpm > 0.0) {
            return rated;
        }
        let on_curve = power_on_curve(curve, spindle_rpm);
        SpindleLimits {
            spindle_power_kw: Some(rated.spindle_power_kw.map_or(on_curve, |power| power.min(on_curve))),
            ..rated
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
        positive("block_time_ms", self.block_time_ms, Measure::Number)?;
        positive("max_feed", self.max_feed, Measure::Feed)?;
        self.spindle().validate()?;
        if let Some(curve) = &self.spindle_power_curve {
            validate_power_curve(curve)?;
        }
        if let Some(margin) = self.margin
            && positive("margin", margin, Measure::Number)? < 1.0
        {
            return Err(SolverError::input(
                "margin",
                format!(
                    "margin must be at least 1 (got {margin}): below 1 blocks get shorter than the control can process"
                ),
            ));
        }
        if let Some(speed) = self.max_spindle_rpm {
            positive("max_spindle_rpm", speed, Measure::Number)?;
        }
        if let Some(plunge_feed) = self.plunge_feed {
            positive("plunge_feed", plunge_feed, Measure::Feed)?;
        }
        if let Some(max_accel) = self.max_accel {
            positive("max_accel", max_accel, Measure::Number)?;
        }
        if let Some(max_jerk) = self.max_jerk {
            positive_at_most("max_jerk", max_jerk, MAX_JERK, Measure::Number)?;
        }
        if let Some(rapid_feed) = self.rapid_feed {
            positive("rapid_feed", rapid_feed, Measure::Feed)?;
        }
        if let Some(tool_change_s) = self.tool_change_s {
            non_negative("tool_change_s", tool_change_s, Measure::Number)?;
        }
        if let Some(min_chord_error) = self.min_chord_error {
            non_negative("min_chord_error", min_chord_error, Measure::Length)?;
        }
        if let Some(description) = &self.description {
            crate::validate::text("description", description, MAX_DESCRIPTION_CHARS)?;
        }
        if let Some(level) = self.haas_smoothing
            && !(1..=3).contains(&level)
        {
            return Err(SolverError::input(
                "haas_smoothing",
                format!("haas_smoothing is G187's P: 1 (rough), 2 (medium) or 3 (finish), not {level}"),
            ));
        }
        Ok(())
    }
}

/// Most points of a spindle power curve.
pub const MAX_CURVE_POINTS: usize = 64;

/// Checks a power curve: 2–64 points, speeds finite, at least 0 and rising, powers positive.
fn validate_power_curve(curve: &[[f64; 2]]) -> Result<(), SolverError> {
    if !(2..=MAX_CURVE_POINTS).contains(&curve.len()) {
        return Err(SolverError::input(
            "spindle_power_curve",
            format!("a power curve has 2 to {MAX_CURVE_POINTS} points [rpm, kW] (got {})", curve.len()),
        ));
    }
    for (index, [rpm, power]) in curve.iter().enumerate() {
        let speed_field = format!("spindle_power_curve[{index}][0]");
        non_negative(&speed_field, *rpm, Measure::Number)?;
        positive(&format!("spindle_power_curve[{index}][1]"), *power, Measure::Number)?;
        if index > 0 && *rpm <= curve[index - 1][0] {
            return Err(SolverError::input(
                speed_field,
                format!("the speeds of a power curve must rise (got {rpm} rpm after {} rpm)", curve[index - 1][0]),
            ));
        }
    }
    Ok(())
}

/// The power of `curve` at `spindle_rpm`, kW: linear between points, held beyond the ends.
fn power_on_curve(curve: &[[f64; 2]], spindle_rpm: f64) -> f64 {
    let (first, last) = (curve[0], curve[curve.len() - 1]);
    if spindle_rpm <= first[0] {
        return first[1];
    }
    if spindle_rpm >= last[0] {
        return last[1];
    }
    let upper = curve.partition_point(|point| point[0] <= spindle_rpm);
    let ([n0, p0], [n1, p1]) = (curve[upper - 1], curve[upper]);
    p0 + (p1 - p0) * (spindle_rpm - n0) / (n1 - n0)
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
    fn a_machine_caps_a_feed_and_never_raises_one() {
        let machine: MachineProfile = serde_json::from_str(r#"{"block_time_ms": 4, "max_feed": 600}"#).unwrap();
        let mut warnings = Vec::new();
        assert_eq!(cap_feed(Some(&machine), "loop_feed", 2400.0, &mut warnings), 600.0);
        assert_eq!(warnings.len(), 1);
        assert_eq!(warnings[0].code, "W_FEED_ABOVE_MACHINE_MAX");
        assert!(
            warnings[0].message.contains("loop_feed capped from 2400 mm/min to 600 mm/min"),
            "{}",
            warnings[0].message
        );
        assert_eq!(cap_feed(Some(&machine), "feed", 300.0, &mut warnings), 300.0, "never raised");
        assert_eq!(cap_feed(Some(&machine), "feed", 600.0, &mut warnings), 600.0);
        assert_eq!(cap_feed(None, "feed", 2400.0, &mut warnings), 2400.0, "no machine, no cap");
        assert_eq!(warnings.len(), 1, "a kept feed says nothing");
    }

    #[test]
    fn power_curve_interpolates_and_holds_its_ends() {
        let json = r#"{"block_time_ms": 4, "max_feed": 12000, "spindle_torque_nm": 50,
                       "spindle_power_curve": [[0, 0.5], [1000, 5], [8000, 5], [12000, 3]]}"#;
        let machine: MachineProfile = serde_json::from_str(json).unwrap();
        machine.validate().unwrap();
        let power = |rpm: f64| machine.spindle_at(rpm).spindle_power_kw.unwrap();
        assert!((power(500.0) - 2.75).abs() < 1e-12);
        assert!((power(1000.0) - 5.0).abs() < 1e-12);
        assert!((power(10_000.0) - 4.0).abs() < 1e-12);
        assert!((power(20_000.0) - 3.0).abs() < 1e-12, "held beyond the last point");
        assert_eq!(machine.spindle_at(500.0).spindle_torque_nm, Some(50.0));
        // A rated power below the curve wins where it is lower.
        let rated = MachineProfile { spindle_power_kw: Some(4.0), ..machine.clone() };
        assert!((rated.spindle_at(500.0).spindle_power_kw.unwrap() - 2.75).abs() < 1e-12);
        assert_eq!(rated.spindle_at(5000.0).spindle_power_kw, Some(4.0));
        assert_eq!(rated.spindle_at(f64::NAN).spindle_power_kw, Some(4.0));

        let field = |curve: Vec<[f64; 2]>| {
            let bad = MachineProfile { spindle_power_curve: Some(curve), ..machine.clone() };
            bad.validate().unwrap_err().field().map(str::to_owned)
        };
        assert_eq!(field(vec![[0.0, 1.0]]).as_deref(), Some("spindle_power_curve"));
        assert_eq!(field(vec![[0.0, 1.0]; 65]).as_deref(), Some("spindle_power_curve"));
        assert_eq!(field(vec![[0.0, 1.0], [0.0, 2.0]]).as_deref(), Some("spindle_power_curve[1][0]"));
        assert_eq!(field(vec![[-1.0, 1.0], [10.0, 2.0]]).as_deref(), Some("spindle_power_curve[0][0]"));
        assert_eq!(field(vec![[0.0, 1.0], [10.0, 0.0]]).as_deref(), Some("spindle_power_curve[1][1]"));
    }

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
        for jerk in [0.0, -1.0, f64::NAN, 2e9] {
            let bad = MachineProfile { max_jerk: Some(jerk), ..machine.clone() };
            assert_eq!(bad.validate().unwrap_err().field(), Some("max_jerk"), "{jerk}");
        }
        MachineProfile { max_jerk: Some(5e4), ..machine.clone() }.validate().unwrap();
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
