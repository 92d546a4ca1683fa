//! What the tool allows (docs/spec/engagement.md §11 item 9): the tooth-passing frequency N·k/60
//! against the tool's natural frequencies. The spindle's power and torque limits (§11 item 4) are
//! the machine's, [`crate::machine::SpindleLimits`].

use crate::tool::{Stiffness, Tool};

/// Relative distance of the tooth-passing frequency from a natural frequency that is warned
/// about ("within 5 %").
pub const RESONANCE_BAND: f64 = 0.05;

/// The tool's natural frequencies, Hz, with the direction they belong to: every mode of a modal
/// stiffness; for a measured table the frequency of its largest compliance; none for a static
/// stiffness.
pub(crate) fn natural_frequencies(tool: &Tool) -> Vec<(f64, &'static str)> {
    match &tool.stiffness {
        None | Some(Stiffness::Static { .. }) => Vec::new(),
        Some(Stiffness::Modal { x, y }) => {
            x.iter().map(|m| (m.frequency_hz, "x")).chain(y.iter().map(|m| (m.frequency_hz, "y"))).collect()
        }
        Some(Stiffness::Frf { x, y }) => [(x, "x"), (y, "y")]
            .into_iter()
            .filter_map(|(rows, axis)| {
                rows.iter()
                    .filter(|r| r.frequency_hz > 0.0)
                    .max_by(|a, b| a.real.hypot(a.imag).total_cmp(&b.real.hypot(b.imag)))
                    .map(|r| (r.frequency_hz, axis))
            })
            .collect(),
    }
}

/// Tooth-passing frequency N·k/60, Hz.
pub(crate) fn tooth_passing_hz(spindle_rpm: f64, flutes: u32) -> f64 {
    spindle_rpm * f64::from(flutes) / 60.0
}

/// The natural frequency the tooth-passing frequency lies within [`RESONANCE_BAND`] of, if any.
pub(crate) fn resonance(passing_hz: f64, natural: &[(f64, &'static str)]) -> Option<(f64, &'static str)> {
    natural.iter().copied().find(|(f, _)| (passing_hz - f).abs() <= RESONANCE_BAND * f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::SpindleLimits;

    #[test]
    fn power_and_torque_caps() {
        let limits = SpindleLimits { spindle_power_kw: Some(5.0), spindle_torque_nm: Some(20.0) };
        // 5 kW at 6000 rpm is 7.96 N·m: power sets the cap.
        let (cap, by_power) = limits.torque_cap(6000.0).unwrap();
        assert!(by_power && (super::super::force::power_kw(cap, 6000.0) - 5.0).abs() < 1e-12);
        // At 1000 rpm 5 kW would allow 47.7 N·m: the torque limit sets it.
        assert_eq!(limits.torque_cap(1000.0), Some((20.0, false)));
        assert_eq!(SpindleLimits::default().torque_cap(1000.0), None);
    }

    #[test]
    fn resonance_band_is_five_percent() {
        let natural = [(1000.0, "x")];
        assert!(resonance(1049.0, &natural).is_some());
        assert!(resonance(951.0, &natural).is_some());
        assert!(resonance(1051.0, &natural).is_none());
        assert!(resonance(949.0, &natural).is_none());
        assert!((tooth_passing_hz(6000.0, 4) - 400.0).abs() < 1e-12);
    }
}
