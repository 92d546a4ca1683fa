//! The block-time rule: the target chord error C_ep from the local radius, the feed and the
//! controller's block processing time (docs/spec/segment.md §2.1–§2.7, Eqs. 1–15, embodiments 1–6).
//!
//! This is the building block every path-emitting solver uses to pick its point spacing: a chord
//! of sagitta C_ep on a circle of radius r is exactly `k_f·F·T_b/60000` long, so a polyline cut
//! with C_ep never asks the control for a block shorter than it can digest at feed F.

use serde::{Deserialize, Serialize};

use super::MachineProfile;
use crate::error::{SolverError, Warning};
use crate::validate::{Measure, finite, non_negative, positive};

/// Where the chord error comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from the tool's vibration mode in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = SegmentMode))]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    /// Per curvature window of length `window` (embodiments 1, 2 and 6; Fig. 7).
    #[default]
    Window,
    /// One value for the whole curve by `rule` (embodiments 3–5).
    Curve,
    /// Each chord's error from the smallest radius of curvature along it (docs/spec/segment.md §2.9a,
    /// revision 2): no block but a span's final remainder is shorter than margin × feed ×
    /// block time.
    Guarantee,
}

/// Milliseconds per minute: `F·T_b/MS_PER_MIN` is the distance (mm) travelled in one block time.
pub const MS_PER_MIN: f64 = 60_000.0;

/// Why a radius cannot be served at the rule's feed (docs/spec/segment.md §4, E3): no chord as long as one
/// block time at the feed fits in a circle of this radius.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Infeasible {
    /// The radius that failed (before the radius factor), mm.
    pub radius: f64,
    /// The largest feed at which a block still fits this radius, mm/min
    /// (`120000·r_eff/(k_f·T_b,eff)`, where the chord equals the diameter).
    pub feed_limit: f64,
}

/// How a chord error came about (docs/spec/segment.md §2.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChordStatus {
    /// On (or, with margins, just above) the chord-error surface.
    Surface,
    /// Raised to the lower bound `min_chord_error` (embodiment 6, E5).
    ClampedToMin,
}

/// The validated parameters of the block-time rule for one feed: everything
/// [`BlockRule::chord_error`] needs. Build it with [`BlockRule::new`] and the `with_` methods, or
/// from a request through the segment solver.
///
/// ```
/// use kerf_solver::machine::BlockRule;
/// // The patent's experiment: R50 at 10 000 mm/min on a control with a 4 ms block time.
/// let rule = BlockRule::new(10_000.0, 4.0).unwrap();
/// let cep = rule.chord_error(50.0).unwrap().0;
/// assert!((cep - 0.001_111_123_457).abs() < 1e-12);
/// assert!((rule.block_length() - 0.666_666_666_667).abs() < 1e-12);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BlockRule {
    /// Commanded feed F, mm/min (> 0).
    pub feed: f64,
    /// Block processing time T_b of the control, ms (> 0).
    pub block_time_ms: f64,
    /// k_f: margin factor on the feed (Eq. 5), ≥ 1 unless unsafe margins are allowed.
    pub margin: f64,
    /// k_ce: factor on the computed chord error, ≥ 1 (docs/spec/segment.md §2.4).
    pub chord_error_factor: f64,
    /// k_r: factor on the radius, in (0, 1] (a factor above 1 is the unsafe side, §8 Q4).
    pub radius_factor: f64,
    /// k_Tb: factor on the block time, ≥ 1.
    pub block_time_factor: f64,
    /// C_emin: lower bound of the chord error, mm (embodiment 6; 0 for none).
    pub min_chord_error: f64,
    /// Use the first-order sagitta h²/2r (Eq. 9) instead of the exact Eq. 8. Very slightly
    /// below the surface (relative h²/4r²); offered as an option only.
    pub sagitta_approximation: bool,
}

/// What a request says about the block-time rule; `None` takes the named machine's value, else
/// the default (`margin` 1, `min_chord_error` 0; `feed` falls back to the machine's `max_feed`,
/// `block_time_ms` has no default). Any path solver with `machine`, `feed` and `block_time_ms`
/// fields fills this and calls [`BlockRule::resolve`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RuleSettings {
    /// Feed, mm/min.
    pub feed: Option<f64>,
    /// Block processing time, ms.
    pub block_time_ms: Option<f64>,
    /// k_f.
    pub margin: Option<f64>,
    /// C_emin, mm.
    pub min_chord_error: Option<f64>,
}

impl BlockRule {
    /// The rule of a request: `settings` over `machine`'s defaults, validated (safe factors
    /// only). A feed above the machine's `max_feed` is capped to it (`W_FEED_ABOVE_MACHINE_MAX`,
    /// from what to what): the rule, and the program built on it, never asks for more.
    ///
    /// # Errors
    /// `E_INPUT` naming `feed`, `block_time_ms`, `margin` or `min_chord_error` for a missing or
    /// bad value, or `machine` when the stored profile is invalid.
    pub fn resolve(
        settings: &RuleSettings,
        machine: Option<&MachineProfile>,
    ) -> Result<(Self, Vec<Warning>), SolverError> {
        Self::resolve_with(settings, machine, |_| {}, false)
    }

    /// [`BlockRule::resolve`] with the other factors set by `adjust` before validation.
    pub(crate) fn resolve_with(
        settings: &RuleSettings,
        machine: Option<&MachineProfile>,
        adjust: impl FnOnce(&mut Self),
        allow_unsafe: bool,
    ) -> Result<(Self, Vec<Warning>), SolverError> {
        if let Some(profile) = machine {
            profile.validate().map_err(|error| {
                SolverError::input("machine", format!("the stored machine is invalid: {}", error.message()))
            })?;
        }
        let mut capped = Vec::new();
        let feed = match settings.feed {
            Some(feed) => super::cap_feed(machine, "feed", feed, &mut capped),
            None => machine.map(|m| m.max_feed).ok_or_else(|| {
                SolverError::input("feed", "feed is required (or name a machine: its max_feed is used)")
            })?,
        };
        let block_time_ms = settings.block_time_ms.or(machine.map(|m| m.block_time_ms)).ok_or_else(|| {
            SolverError::input("block_time_ms", "block_time_ms is required (or name a machine that has it)")
        })?;
        let mut rule = Self::new(feed, block_time_ms)?;
        rule.margin = settings.margin.or(machine.and_then(|m| m.margin)).unwrap_or(1.0);
        rule.min_chord_error = settings.min_chord_error.or(machine.and_then(|m| m.min_chord_error)).unwrap_or(0.0);
        adjust(&mut rule);
        let mut warnings = rule.validate(allow_unsafe)?;
        warnings.extend(capped);
        Ok((rule, warnings))
    }

    /// The plain rule (embodiment 1: on the surface, no margins, no lower bound) for `feed`
    /// (mm/min) and `block_time_ms`.
    ///
    /// # Errors
    /// `E_INPUT` naming `feed` or `block_time_ms` when one is not a positive finite number.
    pub fn new(feed: f64, block_time_ms: f64) -> Result<Self, SolverError> {
        Ok(Self {
            feed: positive("feed", feed, Measure::Feed)?,
            block_time_ms: positive("block_time_ms", block_time_ms, Measure::Number)?,
            margin: 1.0,
            chord_error_factor: 1.0,
            radius_factor: 1.0,
            block_time_factor: 1.0,
            min_chord_error: 0.0,
            sagitta_approximation: false,
        })
    }

    /// The same rule with the feed margin k_f (embodiment 2; e.g. 1.1).
    #[must_use]
    pub fn with_margin(self, margin: f64) -> Self {
        Self { margin, ..self }
    }

    /// The same rule with the lower bound C_emin in mm (embodiment 6; e.g. 0.001).
    #[must_use]
    pub fn with_min_chord_error(self, min_chord_error: f64) -> Self {
        Self { min_chord_error, ..self }
    }

    /// Checks every factor (docs/spec/segment.md §4, E6), naming the request field at fault: the margins
    /// must be finite and positive; factors on the safe side only (`margin`, `chord_error_factor`,
    /// `block_time_factor` ≥ 1, `radius_factor` ≤ 1) unless `allow_unsafe` is set, in which case a
    /// `W_UNSAFE_MARGIN` warning is returned for each one below the surface.
    ///
    /// # Errors
    /// `E_INPUT` for a bad number or an unsafe factor that is not allowed.
    pub fn validate(&self, allow_unsafe: bool) -> Result<Vec<Warning>, SolverError> {
        positive("feed", self.feed, Measure::Feed)?;
        positive("block_time_ms", self.block_time_ms, Measure::Number)?;
        non_negative("min_chord_error", self.min_chord_error, Measure::Length)?;
        let mut warnings = Vec::new();
        let factors = [
            ("margin", self.margin, true),
            ("chord_error_factor", self.chord_error_factor, true),
            ("block_time_factor", self.block_time_factor, true),
            ("radius_factor", self.radius_factor, false),
        ];
        for (field, value, at_least_one) in factors {
            positive(field, value, Measure::Number)?;
            let unsafe_side = if at_least_one { value < 1.0 } else { value > 1.0 };
            if !unsafe_side {
                continue;
            }
            let bound = if at_least_one { "below 1" } else { "above 1" };
            let why = format!(
                "{field} {value} is {bound}: the chord error falls below the block-time surface and blocks get \
                 shorter than the control can process at the feed"
            );
            if !allow_unsafe {
                return Err(SolverError::input(field, format!("{why}; set allow_unsafe_margin to use it anyway")));
            }
            warnings.push(Warning::new("W_UNSAFE_MARGIN", why));
        }
        Ok(warnings)
    }

    /// T_b,eff = k_Tb·T_b, ms.
    pub fn effective_block_time_ms(&self) -> f64 {
        self.block_time_ms * self.block_time_factor
    }

    /// h = k_f·F·T_b,eff/120000 = √α·F: half the chord that lasts one (margined) block time, mm.
    pub fn half_chord(&self) -> f64 {
        self.margin * self.feed * self.effective_block_time_ms() / (2.0 * MS_PER_MIN)
    }

    /// α = (k_f·T_b,eff)²/1.44·10¹⁰, min² (Eq. 6).
    pub fn alpha(&self) -> f64 {
        let scaled = self.margin * self.effective_block_time_ms() / (2.0 * MS_PER_MIN);
        scaled * scaled
    }

    /// F·T_b/60000: the distance travelled in one block time at the feed, mm, without margins. A
    /// block shorter than this starves the control (docs/spec/segment.md §1.1, E8/E9).
    pub fn block_length(&self) -> f64 {
        self.feed * self.block_time_ms / MS_PER_MIN
    }

    /// The chord the rule aims at on a circle: `2·h` = k_f·F·T_b,eff/60000, mm.
    pub fn target_chord(&self) -> f64 {
        2.0 * self.half_chord()
    }

    /// The target chord error C_ep for a local radius of curvature `radius` (mm; `f64::INFINITY`
    /// for a straight piece), docs/spec/segment.md §2.7: the smaller root of Eq. 5 in the cancellation-free
    /// form `h²/(r + √(r² − h²))`, times k_ce, then raised to C_emin.
    ///
    /// # Errors
    /// [`Infeasible`] with the largest feasible feed when `r·k_r < h` (E3). Never returns NaN.
    pub fn chord_error(&self, radius: f64) -> Result<(f64, ChordStatus), Infeasible> {
        let half = self.half_chord();
        let effective_radius = radius * self.radius_factor;
        let on_surface = if effective_radius == f64::INFINITY {
            0.0
        } else if effective_radius.is_nan() || effective_radius < half {
            // A radius that is not a number is never feasible.
            return Err(Infeasible { radius, feed_limit: self.feed_limit(radius) });
        } else if self.sagitta_approximation {
            half * half / (2.0 * effective_radius)
        } else {
            let root = ((effective_radius - half) * (effective_radius + half)).sqrt();
            half * half / (effective_radius + root)
        };
        let chord_error = on_surface * self.chord_error_factor;
        if chord_error < self.min_chord_error {
            Ok((self.min_chord_error, ChordStatus::ClampedToMin))
        } else {
            Ok((chord_error, ChordStatus::Surface))
        }
    }

    /// The chord tolerance a path solver should cut with at a point of local radius `radius`:
    /// the rule's C_ep, but never coarser than the accuracy bound `tolerance` (mm) when one is
    /// given. This is "pick the point spacing by the block-time rule, never coarser than the
    /// tolerance" in one call.
    ///
    /// # Errors
    /// [`Infeasible`] as for [`BlockRule::chord_error`].
    pub fn tolerance_for(&self, radius: f64, tolerance: Option<f64>) -> Result<f64, Infeasible> {
        let (chord_error, _) = self.chord_error(radius)?;
        Ok(tolerance.map_or(chord_error, |limit| chord_error.min(limit)))
    }

    /// Chord error of the whole-curve rule of embodiment 5 (Eq. 15): `(α/2)·A_n,max` with
    /// A_n,max = F²/(r_min·k_r), times k_ce, then raised to C_emin. `min_radius` is the smallest
    /// radius of curvature of the curve (mm).
    ///
    /// # Errors
    /// [`Infeasible`] when even the smallest radius cannot hold one block (E3).
    pub fn normal_accel_chord_error(&self, min_radius: f64) -> Result<(f64, ChordStatus), Infeasible> {
        Self { sagitta_approximation: true, ..*self }.chord_error(min_radius)
    }

    /// Largest feed (mm/min) at which one block still fits in a circle of `radius`: there the
    /// chord equals the diameter, `120000·r·k_r/(k_f·T_b,eff)` (E3). Infinite for a straight piece.
    pub fn feed_limit(&self, radius: f64) -> f64 {
        2.0 * MS_PER_MIN * radius * self.radius_factor / (self.margin * self.effective_block_time_ms())
    }

    /// Largest feed (mm/min) at which the rule's chord error at `radius` stays within the accuracy
    /// bound `tolerance` (E4): `√((2·r·C_tol − C_tol²)/α)`, with the chord-error factor and the
    /// radius factor applied as in [`BlockRule::chord_error`].
    pub fn feed_for_tolerance(&self, radius: f64, tolerance: f64) -> f64 {
        let surface_tolerance = tolerance / self.chord_error_factor;
        let effective_radius = radius * self.radius_factor;
        if effective_radius == f64::INFINITY {
            return f64::INFINITY;
        }
        let capped = surface_tolerance.min(effective_radius);
        let half_chord_squared = if self.sagitta_approximation {
            2.0 * effective_radius * capped
        } else {
            capped * (2.0 * effective_radius - capped)
        };
        (half_chord_squared / self.alpha()).sqrt()
    }
}

/// Chord length on a circle of `radius` with sagitta `chord_error`: `2√(2rC − C²)` (docs/spec/segment.md §2.2),
/// or the diameter when the sagitta reaches the radius. Infinite for a straight piece.
pub fn chord_length(radius: f64, chord_error: f64) -> f64 {
    if radius == f64::INFINITY {
        return f64::INFINITY;
    }
    let capped = chord_error.min(radius);
    2.0 * (capped * (2.0 * radius - capped)).max(0.0).sqrt()
}

/// Block processing time from a saturation test (Eq. 1): blocks of `test_block_length` mm run at
/// a real speed that saturates at `saturated_feed` mm/min take `length/V_sat·60000` ms each.
///
/// # Errors
/// `E_INPUT` when an argument is not a positive finite number.
pub fn block_time_from_saturation(test_block_length: f64, saturated_feed: f64) -> Result<f64, SolverError> {
    let length = positive("test_block_length", test_block_length, Measure::Length)?;
    let feed = positive("saturated_feed", saturated_feed, Measure::Feed)?;
    finite("block_time_ms", length / feed * MS_PER_MIN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn eq1_gives_the_patent_block_time() {
        assert_relative_eq!(block_time_from_saturation(0.1, 1500.0).unwrap(), 4.0);
    }

    #[test]
    fn on_surface_chord_is_one_block_long() {
        for radius in [2.0, 25.0, 50.0, 200.0] {
            let rule = BlockRule::new(10_000.0, 4.0).unwrap().with_margin(1.1);
            let (cep, status) = rule.chord_error(radius).unwrap();
            assert_eq!(status, ChordStatus::Surface);
            assert_relative_eq!(chord_length(radius, cep), 1.1 * 10_000.0 * 4.0 / 60_000.0, max_relative = 1e-12);
        }
    }

    #[test]
    fn margin_on_feed_equals_margin_on_block_time() {
        let on_feed = BlockRule::new(10_000.0, 4.0).unwrap().with_margin(1.1);
        let on_time = BlockRule { block_time_factor: 1.1, ..BlockRule::new(10_000.0, 4.0).unwrap() };
        assert_relative_eq!(
            on_feed.chord_error(50.0).unwrap().0,
            on_time.chord_error(50.0).unwrap().0,
            max_relative = 1e-15
        );
    }

    #[test]
    fn embodiment_4_and_5_numbers() {
        let rule = BlockRule::new(10_000.0, 4.0).unwrap().with_margin(1.1);
        assert_relative_eq!(rule.chord_error(25.0).unwrap().0, 0.002_689_033_506_912_914_4, max_relative = 1e-12);
        assert_relative_eq!(
            rule.normal_accel_chord_error(25.0).unwrap().0,
            0.002_688_888_888_888_889,
            max_relative = 1e-12
        );
    }

    #[test]
    fn infeasible_radius_reports_the_feed_limit() {
        let rule = BlockRule::new(10_000.0, 4.0).unwrap();
        let error = rule.chord_error(0.3).unwrap_err();
        assert_relative_eq!(error.feed_limit, 9000.0, max_relative = 1e-12);
        assert!(rule.chord_error(f64::NAN).is_err());
    }

    #[test]
    fn tolerance_feed_matches_e4() {
        let rule = BlockRule::new(10_000.0, 4.0).unwrap();
        assert_relative_eq!(rule.feed_for_tolerance(50.0, 0.0005), 6_708.187_168_669_395, max_relative = 1e-9);
        // At that feed the rule's chord error is the tolerance.
        let slower = BlockRule::new(rule.feed_for_tolerance(50.0, 0.0005), 4.0).unwrap();
        assert_relative_eq!(slower.chord_error(50.0).unwrap().0, 0.0005, max_relative = 1e-12);
        assert_relative_eq!(rule.tolerance_for(50.0, Some(0.0005)).unwrap(), 0.0005);
    }

    #[test]
    fn unsafe_factors_are_refused_or_warned() {
        let rule = BlockRule::new(10_000.0, 4.0).unwrap().with_margin(0.9);
        assert_eq!(rule.validate(false).unwrap_err().field(), Some("margin"));
        let warnings = rule.validate(true).unwrap();
        assert_eq!(warnings[0].code, "W_UNSAFE_MARGIN");
        let radius = BlockRule { radius_factor: 1.2, ..BlockRule::new(10_000.0, 4.0).unwrap() };
        assert_eq!(radius.validate(false).unwrap_err().field(), Some("radius_factor"));
    }
}
