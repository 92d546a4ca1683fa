//! Engaged arcs on the tool circle in the angle convention of docs/spec/engagement.md §4.1: merging and
//! the numeric rules of §9, radial depth (§5.5), and the per-arc quantities of §5.4 and §5.10.

pub use crate::gcode::SpindleDirection;
use serde::{Deserialize, Serialize};

/// Two arc ends closer than this (degrees) touch.
const TOUCH_DEG: f64 = 1e-9;
/// Ends this close behind 0° or 180° snap onto it; shorter arcs are dropped (§5.3.3).
const SNAP_DEG: f64 = 0.01;
/// An end whose chip-thickness ratio sin θ is below this counts as zero thickness (§5.4 modes):
/// the exact engine's angle tolerance, sin 0.05°.
const ZERO_THICKNESS: f64 = 8.8e-4;

/// A closed arc of tool angles, degrees: `from` in [−180°, 180°), `to` in (`from`, `from` + 360°].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Arc {
    pub from: f64,
    pub to: f64,
}

impl Arc {
    /// Angular width, degrees.
    pub(crate) fn span(&self) -> f64 {
        self.to - self.from
    }

    /// Whether `angle` (any turn) lies on the arc, ends widened by `tolerance` (negative
    /// `tolerance` tests the interior).
    pub(crate) fn contains(&self, angle: f64, tolerance: f64) -> bool {
        let offset = modulo(angle - self.from, 360.0);
        if tolerance >= 0.0 {
            offset <= self.span() + tolerance || offset >= 360.0 - tolerance
        } else {
            offset > -tolerance && offset < self.span() + tolerance
        }
    }
}

/// `angle` modulo `period`, in [0, `period`): `rem_euclid` without its `fmod` call for the few
/// turns the engine's angles span (a tooth, an arc end), where it was a tenth of the run time.
pub(crate) fn modulo(angle: f64, period: f64) -> f64 {
    // Far turns and NaN take the exact library path.
    if angle.is_nan() || angle.abs() > 4.0 * period {
        return angle.rem_euclid(period);
    }
    let mut wrapped = angle;
    while wrapped < 0.0 {
        wrapped += period;
    }
    while wrapped >= period {
        wrapped -= period;
    }
    wrapped
}

/// Wraps an angle into [−180°, 180°).
pub(crate) fn wrap_deg(angle: f64) -> f64 {
    if (-180.0..180.0).contains(&angle) {
        return angle;
    }
    let wrapped = (angle + 180.0).rem_euclid(360.0) - 180.0;
    if wrapped >= 180.0 { -180.0 } else { wrapped }
}

/// Sorted, merged arcs: touching arcs (also across ±180°) join, a closed circle becomes
/// [−180°, 180°], ends just behind 0°/180° snap onto them, and arcs shorter than 0.01° go.
/// Works in the given buffer (once per sample: no allocation of its own).
pub(crate) fn normalise(mut arcs: Vec<Arc>) -> Vec<Arc> {
    arcs.retain(|a| a.to.is_finite() && a.from.is_finite() && a.to > a.from);
    for arc in &mut arcs {
        let from = wrap_deg(arc.from);
        let to = if from == arc.from { arc.to } else { from + arc.span() };
        *arc = Arc { from, to: to.min(from + 360.0) };
    }
    arcs.sort_by(|a, b| a.from.total_cmp(&b.from));
    let mut merged = 0;
    for index in 0..arcs.len() {
        let arc = arcs[index];
        if merged > 0 && arc.from <= arcs[merged - 1].to + TOUCH_DEG {
            arcs[merged - 1].to = arcs[merged - 1].to.max(arc.to);
        } else {
            arcs[merged] = arc;
            merged += 1;
        }
    }
    arcs.truncate(merged);
    // Close over ±180°: the last arc may reach round to the first ones.
    while arcs.len() > 1 {
        let (Some(first), Some(last)) = (arcs.first().copied(), arcs.last().copied()) else {
            break;
        };
        if last.to + TOUCH_DEG >= first.from + 360.0 {
            arcs.remove(0);
            if let Some(end) = arcs.last_mut() {
                end.to = end.to.max(first.to + 360.0);
            }
        } else {
            break;
        }
    }
    if arcs.iter().any(|arc| arc.span() >= 360.0 - TOUCH_DEG) {
        arcs.clear();
        arcs.push(Arc { from: -180.0, to: 180.0 });
        return arcs;
    }
    for arc in &mut arcs {
        if (-SNAP_DEG..0.0).contains(&arc.from) {
            arc.from = 0.0;
        }
        if arc.to > 180.0 && arc.to <= 180.0 + SNAP_DEG {
            arc.to = 180.0;
        }
    }
    arcs.retain(|arc| arc.span() >= SNAP_DEG);
    arcs
}

/// Φ, the total engaged angle, degrees.
pub(crate) fn engaged_deg(arcs: &[Arc]) -> f64 {
    // A fold from +0 so an empty set reads 0, not −0.
    arcs.iter().map(Arc::span).fold(0.0, |total, span| total + span)
}

/// sin of an angle in degrees, with the rounding residue at 0° and 180° (1e-16) cleared so a
/// tooth there reads exactly zero thickness.
pub(crate) fn sin_deg(angle: f64) -> f64 {
    let value = angle.to_radians().sin();
    if value.abs() < 1e-12 { 0.0 } else { value }
}

/// a_e: the measure of the union of the arcs' lateral projections R·cos θ (§5.5).
pub(crate) fn radial_depth(arcs: &[Arc], radius: f64) -> f64 {
    let mut spans: Vec<(f64, f64)> = arcs
        .iter()
        .map(|arc| {
            let (ca, cb) = (arc.from.to_radians().cos(), arc.to.to_radians().cos());
            let high = if arc.contains(0.0, 0.0) { 1.0 } else { ca.max(cb) };
            let low = if arc.contains(180.0, 0.0) { -1.0 } else { ca.min(cb) };
            (radius * low, radius * high)
        })
        .collect();
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    let mut current: Option<(f64, f64)> = None;
    for (low, high) in spans {
        current = match current {
            Some((a, b)) if low <= b => Some((a, b.max(high))),
            Some((a, b)) => {
                total += b - a;
                Some((low, high))
            }
            None => Some((low, high)),
        };
    }
    if let Some((a, b)) = current {
        total += b - a;
    }
    total.min(2.0 * radius)
}

/// The largest chip-thickness ratio max(0, sin θ) on the arcs (§11 item 3).
pub(crate) fn peak_thickness_ratio(arcs: &[Arc]) -> f64 {
    arcs.iter()
        .map(|arc| {
            if arc.contains(90.0, 0.0) {
                1.0
            } else {
                arc.from.to_radians().sin().max(arc.to.to_radians().sin()).max(0.0)
            }
        })
        .fold(0.0, f64::max)
}

/// Mean chip-thickness ratio over the engaged angles: ∫ max(0, sin θ) dθ / Φ (C2 part A:
/// h_m = f_z·(a_e/R)/φ for side milling).
pub(crate) fn mean_thickness_ratio(arcs: &[Arc]) -> f64 {
    let total = engaged_deg(arcs).to_radians();
    if total <= 0.0 {
        return 0.0;
    }
    let mut integral = 0.0;
    for arc in arcs {
        for turn in -1..=1 {
            let base = 360.0 * f64::from(turn);
            let low = arc.from.max(base);
            let high = arc.to.min(base + 180.0);
            if high > low {
                integral += low.to_radians().cos() - high.to_radians().cos();
            }
        }
    }
    integral / total
}

/// How a tooth passes through one engaged arc (§5.4, an extension of the spec).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum MillingMode {
    /// Full slot: zero thickness at both ends and 180° wide.
    Slot,
    /// Down (climb) milling: zero thickness at the exit only.
    Climb,
    /// Up (conventional) milling: zero thickness at the entry only.
    Conventional,
    /// Non-zero thickness at both ends: the tooth enters or leaves at a free face or an
    /// earlier cut (or both ends at zero without being a slot).
    Interior,
}

/// Entry, exit and the derived angles of one arc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ArcEnds {
    pub entry: f64,
    pub exit: f64,
    pub engage: f64,
    pub disengage: f64,
    pub entry_ratio: f64,
    pub exit_ratio: f64,
    pub mode: MillingMode,
}

/// §5.4 for one arc: θ_in = b, θ_out = a with `cw` (swapped for `ccw`); φ = acos(sin θ_in),
/// ψ = acos(sin θ_out); thickness ratios max(0, sin θ).
pub(crate) fn arc_ends(arc: &Arc, direction: SpindleDirection) -> ArcEnds {
    let (entry, exit) = match direction {
        SpindleDirection::Cw => (arc.to, arc.from),
        SpindleDirection::Ccw => (arc.from, arc.to),
    };
    let (sin_in, sin_out) = (sin_deg(entry), sin_deg(exit));
    let (entry_ratio, exit_ratio) = (sin_in.max(0.0), sin_out.max(0.0));
    let mode = match (entry_ratio <= ZERO_THICKNESS, exit_ratio <= ZERO_THICKNESS) {
        (true, true) if (arc.span() - 180.0).abs() <= 1.0 && arc.from > -1.0 => MillingMode::Slot,
        (false, true) => MillingMode::Climb,
        (true, false) => MillingMode::Conventional,
        _ => MillingMode::Interior,
    };
    // Ends are reported in (−180°, 180°] like θ itself (§4.1).
    let half_open = |angle: f64| {
        let wrapped = wrap_deg(angle);
        if wrapped == -180.0 { 180.0 } else { wrapped }
    };
    ArcEnds {
        entry: half_open(entry),
        exit: half_open(exit),
        engage: sin_in.clamp(-1.0, 1.0).acos().to_degrees(),
        disengage: sin_out.clamp(-1.0, 1.0).acos().to_degrees(),
        entry_ratio,
        exit_ratio,
        mode,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(from: f64, to: f64) -> Arc {
        Arc { from, to }
    }

    #[test]
    fn merging_wraps_and_snaps() {
        let merged = normalise(vec![arc(170.0, 180.0), arc(-180.0, -170.0), arc(10.0, 20.0)]);
        assert_eq!(merged, vec![arc(10.0, 20.0), arc(170.0, 190.0)]);
        assert_eq!(normalise(vec![arc(-0.005, 60.0), arc(100.0, 180.004)]), vec![arc(0.0, 60.0), arc(100.0, 180.0)]);
        assert_eq!(normalise(vec![arc(5.0, 5.004)]), vec![]);
        assert_eq!(normalise(vec![arc(-180.0, 0.0), arc(0.0, 180.0)]), vec![arc(-180.0, 180.0)]);
    }

    #[test]
    fn radial_depth_of_known_arcs() {
        assert!((radial_depth(&[arc(0.0, 180.0)], 5.0) - 10.0).abs() < 1e-12);
        assert!((radial_depth(&[arc(0.0, 60.0)], 5.0) - 2.5).abs() < 1e-12);
        // Two horns: both sides, 2(R − R cos T).
        let horns = radial_depth(&[arc(0.0, 30.0), arc(150.0, 180.0)], 5.0);
        assert!((horns - 2.0 * (5.0 - 5.0 * 30.0_f64.to_radians().cos())).abs() < 1e-12);
        // Front and back arcs over the same lateral band count once.
        assert!((radial_depth(&[arc(0.0, 60.0), arc(-60.0, 0.0)], 5.0) - 2.5).abs() < 1e-12);
    }

    #[test]
    fn ends_modes_and_mean_thickness() {
        let down = arc_ends(&arc(0.0, 60.0), SpindleDirection::Cw);
        assert_eq!(down.mode, MillingMode::Climb);
        assert!((down.disengage - 90.0).abs() < 1e-9 && (down.engage - 30.0).abs() < 1e-9);
        let up = arc_ends(&arc(90.0, 180.0), SpindleDirection::Cw);
        assert_eq!(up.mode, MillingMode::Conventional);
        assert!(up.disengage.abs() < 1e-9);
        assert_eq!(arc_ends(&arc(0.0, 180.0), SpindleDirection::Cw).mode, MillingMode::Slot);
        assert_eq!(arc_ends(&arc(0.0, 60.0), SpindleDirection::Ccw).mode, MillingMode::Conventional);
        // C2 part A: a_e = 2.5, R = 5: h_m / f_z = 0.5 / (π/3).
        let ratio = mean_thickness_ratio(&[arc(0.0, 60.0)]);
        assert!((ratio - 0.5 / (std::f64::consts::PI / 3.0)).abs() < 1e-12);
        assert!((peak_thickness_ratio(&[arc(0.0, 60.0)]) - 0.75_f64.sqrt()).abs() < 1e-12);
        assert!((peak_thickness_ratio(&[arc(30.0, 150.0)]) - 1.0).abs() < 1e-12);
    }
}
