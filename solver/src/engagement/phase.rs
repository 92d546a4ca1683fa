//! The largest sum over k evenly spaced teeth of a per-tooth load, over the tooth phase
//! (engagement.md §5.6 generalised to loads that are not f_z·sin θ: Kienzle's h^(1−m_c), the
//! helix window, the arc-feed factor; §11 items 4–6).
//!
//! Between breakpoints (a tooth on a place where the load jumps or bends) the sum is smooth; a
//! scan of each piece and a golden-section refinement around its best point find the maximum,
//! exactly when the piece is concave (a sum of concave loads, as sin^a is on [0°, 180°]).

/// Scan points per breakpoint interval before the refinement.
const SCAN: usize = 4;
/// Golden-section steps: the bracket shrinks to 0.618^28 ≈ 1.4e-6 of a scan step, so the value
/// misses a smooth peak by about 1e-12 of it.
const GOLDEN_STEPS: usize = 28;

/// max over β of Σ_j load(β + j·360°/k), with `ends` (degrees, any turn) the tooth angles where
/// the load jumps or bends.
pub(crate) fn peak(flutes: u32, ends: &[f64], load: impl Fn(f64) -> f64) -> f64 {
    if flutes == 0 {
        return 0.0;
    }
    let pitch = 360.0 / f64::from(flutes);
    peak_of(flutes, ends, |phase: f64| (0..flutes).map(|j| load(phase + f64::from(j) * pitch)).sum::<f64>())
}

/// max over β of `sum(β)`, a function of the phase of k teeth (period 360°/k) that is smooth
/// between the breakpoints `ends` (mod the pitch).
pub(crate) fn peak_of(flutes: u32, ends: &[f64], sum: impl Fn(f64) -> f64) -> f64 {
    if flutes == 0 {
        return 0.0;
    }
    let pitch = 360.0 / f64::from(flutes);
    let mut breaks = vec![0.0, pitch];
    breaks.extend(ends.iter().map(|e| e.rem_euclid(pitch)));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-12);
    let mut best = breaks.iter().map(|&b| sum(b)).fold(0.0, f64::max);
    for pair in breaks.windows(2) {
        let (low, high) = (pair[0], pair[1]);
        if high - low <= 1e-9 {
            continue;
        }
        let step = (high - low) / SCAN as f64;
        // Interior scan points; the ends are breakpoints, already evaluated.
        let Some((centre, value)) = (1..SCAN)
            .map(|i| {
                let phase = low + step * i as f64;
                (phase, sum(phase))
            })
            .max_by(|a, b| a.1.total_cmp(&b.1))
        else {
            continue;
        };
        best = best.max(value).max(golden(&sum, centre - step, centre + step));
    }
    best
}

/// Largest value of `f` found by golden-section search on [a, b] (exact for a unimodal f).
fn golden(f: &impl Fn(f64) -> f64, mut a: f64, mut b: f64) -> f64 {
    let ratio = 0.5 * (5.0_f64.sqrt() - 1.0);
    let mut c = b - ratio * (b - a);
    let mut d = a + ratio * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_STEPS {
        if fc >= fd {
            b = d;
            d = c;
            fd = fc;
            c = b - ratio * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + ratio * (b - a);
            fd = f(d);
        }
    }
    fc.max(fd)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_sinusoid_peak_of_a_full_slot() {
        // §5.6 table: Σ sin over a slot, k = 4 → √2, k = 5 → 1.618034.
        let load =
            |t: f64| if (0.0..=180.0).contains(&t.rem_euclid(360.0)) { t.to_radians().sin().max(0.0) } else { 0.0 };
        assert!((peak(4, &[0.0, 180.0], load) - std::f64::consts::SQRT_2).abs() < 1e-12);
        assert!((peak(5, &[0.0, 180.0], load) - 1.618034).abs() < 1e-6);
    }
}
