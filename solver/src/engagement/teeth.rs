//! Summed chip thickness of k evenly spaced teeth, maximised exactly over the tooth phase, and
//! the number of teeth in the cut (docs/spec/engagement.md §5.6).
//!
//! The active set of teeth changes only where a tooth sits on an arc end (or at 0°/180°, where
//! the clamp max(0, sin θ) switches); between those breakpoints the sum is f_z·|C|·sin(β + arg C),
//! so its maximum lies at a breakpoint or at β* = 90° − arg C.

use super::arcs::{Arc, modulo};

/// Tolerance on arc ends, degrees (closed arcs: a tooth on an end counts, §9).
const END_TOLERANCE: f64 = 1e-9;

/// The maximised sum for one flute count at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ToothSum {
    /// max over β of Σ max(0, sin θ_j) over the teeth on the arcs: H_k / f_z,k.
    pub ratio: f64,
    /// max over β of the number of teeth strictly inside the arcs: n_k.
    pub teeth: u32,
}

fn on_arcs(arcs: &[Arc], angle: f64, tolerance: f64) -> bool {
    arcs.iter().any(|arc| arc.contains(angle, tolerance))
}

/// Breakpoints of one sample fit on the stack (4 + 2 per arc); more arcs take the heap.
const STACK_BREAKS: usize = 32;

/// H_k/f_z,k and n_k for `flutes` teeth on `arcs` (§5.6, exact maximisation).
///
/// Runs once per flute count and sample, so it allocates nothing for the usual few arcs and
/// takes the tooth directions by rotation instead of a sine and cosine per tooth.
pub(crate) fn tooth_sum(arcs: &[Arc], flutes: u32) -> ToothSum {
    if arcs.is_empty() || flutes == 0 {
        return ToothSum { ratio: 0.0, teeth: 0 };
    }
    let pitch = 360.0 / f64::from(flutes);
    let needed = 4 + 2 * arcs.len();
    let mut stack = [0.0_f64; STACK_BREAKS];
    let mut heap = Vec::new();
    let breaks: &mut [f64] = if needed <= STACK_BREAKS {
        &mut stack[..needed]
    } else {
        heap.resize(needed, 0.0);
        &mut heap
    };
    breaks[..4].copy_from_slice(&[0.0, pitch, 0.0, modulo(180.0, pitch)]);
    for (index, arc) in arcs.iter().enumerate() {
        breaks[4 + 2 * index] = modulo(arc.from, pitch);
        breaks[5 + 2 * index] = modulo(arc.to, pitch);
    }
    breaks.sort_unstable_by(f64::total_cmp);
    let mut kept = 1;
    for index in 1..breaks.len() {
        if (breaks[index] - breaks[kept - 1]).abs() > 1e-12 {
            breaks[kept] = breaks[index];
            kept += 1;
        }
    }
    let breaks = &breaks[..kept];

    let tooth = |phase: f64, j: u32| phase + f64::from(j) * pitch;
    let (pitch_sin, pitch_cos) = pitch.to_radians().sin_cos();
    // Σ sin θ_j over the teeth `counts`, the sines by rotation from tooth 0 at `phase`.
    let sine_sum = |phase: f64, counts: &dyn Fn(u32) -> bool| {
        let (mut sin, mut cos) = phase.to_radians().sin_cos();
        let mut sum = 0.0;
        for j in 0..flutes {
            if counts(j) {
                sum += sin.max(0.0);
            }
            (sin, cos) = (sin * pitch_cos + cos * pitch_sin, cos * pitch_cos - sin * pitch_sin);
        }
        sum
    };
    let mut best = 0.0_f64;
    let mut teeth = 0_u32;
    for &phase in breaks {
        best = best.max(sine_sum(phase, &|j| on_arcs(arcs, tooth(phase, j), END_TOLERANCE)));
    }
    // Teeth cutting throughout an interval: on an arc and in the front half (0° < θ < 180°; the
    // interval's middle is never on 0° or 180°, which are breaks).
    let active = |middle: f64, j: u32| {
        let angle = tooth(middle, j);
        on_arcs(arcs, angle, 0.0) && {
            let turn = modulo(angle, 360.0);
            turn > 0.0 && turn < 180.0
        }
    };
    for pair in breaks.windows(2) {
        let (low, high) = (pair[0], pair[1]);
        if high - low <= 1e-12 {
            continue;
        }
        let middle = 0.5 * (low + high);
        let inside = (0..flutes).filter(|&j| on_arcs(arcs, tooth(middle, j), -END_TOLERANCE)).count();
        teeth = teeth.max(u32::try_from(inside).unwrap_or(u32::MAX));
        // C = Σ e^{i·j·pitch} over the active teeth, the directions by rotation from tooth 0.
        let (mut cx, mut cy) = (0.0, 0.0);
        let (mut direction_cos, mut direction_sin) = (1.0, 0.0);
        for j in 0..flutes {
            if active(middle, j) {
                cx += direction_cos;
                cy += direction_sin;
            }
            (direction_cos, direction_sin) = (
                direction_cos * pitch_cos - direction_sin * pitch_sin,
                direction_sin * pitch_cos + direction_cos * pitch_sin,
            );
        }
        if cx.hypot(cy) <= 1e-12 {
            continue;
        }
        let peak = 90.0 - cy.atan2(cx).to_degrees();
        let phase = low + modulo(peak - low, 360.0);
        if phase < high {
            best = best.max(sine_sum(phase, &|j| active(middle, j)));
        }
    }
    ToothSum { ratio: best, teeth }
}

/// The tooth sums of the previous sample, reused when a sample's arcs are the same to the bit:
/// along a straight cut at constant engagement consecutive samples have the same arcs, and
/// [`tooth_sum`] is a pure function of them, so reusing it changes nothing.
#[derive(Debug, Default)]
pub(crate) struct ToothSums {
    arcs: Vec<Arc>,
    flute_counts: Vec<u32>,
    sums: Vec<ToothSum>,
}

impl ToothSums {
    /// [`tooth_sum`] of `arcs` for each of `flute_counts`.
    pub(crate) fn of(&mut self, arcs: &[Arc], flute_counts: &[u32]) -> &[ToothSum] {
        let same = self.flute_counts == flute_counts
            && self.arcs.len() == arcs.len()
            && self
                .arcs
                .iter()
                .zip(arcs)
                .all(|(old, new)| old.from.to_bits() == new.from.to_bits() && old.to.to_bits() == new.to.to_bits());
        if !same {
            self.arcs.clear();
            self.arcs.extend_from_slice(arcs);
            self.flute_counts.clear();
            self.flute_counts.extend_from_slice(flute_counts);
            self.sums.clear();
            self.sums.extend(flute_counts.iter().map(|&k| tooth_sum(arcs, k)));
        }
        &self.sums
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn arc(from: f64, to: f64) -> Arc {
        Arc { from, to }
    }

    fn clamped_sin(angle_deg: f64) -> f64 {
        angle_deg.to_radians().sin().max(0.0)
    }

    /// Brute-force phase scan, for comparison.
    fn sampled(arcs: &[Arc], flutes: u32, steps: u32) -> f64 {
        let pitch = 360.0 / f64::from(flutes);
        (0..steps)
            .map(|i| {
                let phase = pitch * f64::from(i) / f64::from(steps);
                (0..flutes)
                    .map(|j| phase + f64::from(j) * pitch)
                    .filter(|&a| on_arcs(arcs, a, END_TOLERANCE))
                    .map(clamped_sin)
                    .sum::<f64>()
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn full_slot_closed_forms() {
        // docs/spec/engagement.md §5.6 table, k = 1…10.
        let expected = [1.0, 1.0, 1.0, std::f64::consts::SQRT_2, 1.618034, 2.0, 2.246980, 2.613126, 2.879385, 3.236068];
        for (k, value) in (1..=10).zip(expected) {
            let sum = tooth_sum(&[arc(0.0, 180.0)], k);
            assert!((sum.ratio - value).abs() < 1e-6, "k = {k}: {}", sum.ratio);
        }
        assert_eq!(tooth_sum(&[arc(0.0, 180.0)], 4).teeth, 2);
        assert_eq!(tooth_sum(&[arc(0.0, 180.0)], 8).teeth, 4);
    }

    #[test]
    fn down_milling_sixty_degrees() {
        // §5.6: φ = 60°: k ≤ 6 → 0.866025; k = 7 → 1.015068; k = 8 → 1.124844; k = 10 → 1.272762.
        for (k, value) in [(3, 0.866025), (6, 0.866025), (7, 1.015068), (8, 1.124844), (10, 1.272762)] {
            let sum = tooth_sum(&[arc(0.0, 60.0)], k);
            assert!((sum.ratio - value).abs() < 1e-6, "k = {k}: {}", sum.ratio);
        }
    }

    #[test]
    fn agrees_with_a_phase_scan_including_back_arcs() {
        let cases = [
            vec![arc(-40.0, 20.0), arc(100.0, 130.0)],
            vec![arc(16.26, 23.07), arc(156.93, 163.74)],
            vec![arc(170.0, 250.0)],
        ];
        for arcs in &cases {
            for k in 1..=10 {
                let exact = tooth_sum(arcs, k).ratio;
                let scan = sampled(arcs, k, 200_000);
                assert!(exact >= scan - 1e-12, "{arcs:?} k = {k}: {exact} < {scan}");
                assert!(exact - scan < 1e-3, "{arcs:?} k = {k}: {exact} vs {scan}");
            }
        }
    }

    #[test]
    fn reused_sums_equal_fresh_ones() {
        let mut memo = ToothSums::default();
        let samples = [
            vec![arc(0.0, 60.0)],
            vec![arc(0.0, 60.0)],
            vec![arc(0.0, 60.000_000_000_000_01)],
            vec![arc(0.0, 60.0), arc(100.0, 130.0)],
            vec![],
            vec![arc(0.0, 60.0)],
        ];
        for counts in [vec![2, 3, 4], vec![5], vec![2, 3, 4], vec![5, 6, 7]] {
            for arcs in &samples {
                let fresh: Vec<ToothSum> = counts.iter().map(|&k| tooth_sum(arcs, k)).collect();
                assert_eq!(memo.of(arcs, &counts), fresh.as_slice(), "{arcs:?} {counts:?}");
            }
        }
    }

    #[test]
    fn empty_arcs_give_zero() {
        assert_eq!(tooth_sum(&[], 4), ToothSum { ratio: 0.0, teeth: 0 });
    }
}
