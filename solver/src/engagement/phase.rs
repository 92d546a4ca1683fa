//! The largest sum over k evenly spaced teeth of a per-tooth load, over the tooth phase
//! (docs/spec/engagement.md §5.6 generalised to loads that are not f_z·sin θ: Kienzle's h^(1−m_c), the
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
    let breaks = breakpoints(flutes, ends);
    let mut best = breaks.iter().map(|&b| sum(b)).fold(0.0, f64::max);
    for pair in breaks.windows(2) {
        if pair[1] - pair[0] > 1e-9 {
            best = best.max(piece_peak(&sum, pair[0], pair[1]));
        }
    }
    best
}

/// The breakpoints of one pitch: its ends and every `ends` angle reduced into it, sorted, those
/// within 1e-12° of each other merged.
fn breakpoints(flutes: u32, ends: &[f64]) -> Vec<f64> {
    let pitch = 360.0 / f64::from(flutes);
    let mut breaks = vec![0.0, pitch];
    breaks.extend(ends.iter().map(|e| e.rem_euclid(pitch)));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|a, b| (*a - *b).abs() <= 1e-12);
    breaks
}

/// The largest value of `sum` inside the piece (low, high): the best of [`SCAN`] − 1 interior
/// points, refined by golden section around it (the ends are breakpoints, evaluated apart).
fn piece_peak(sum: &impl Fn(f64) -> f64, low: f64, high: f64) -> f64 {
    let step = (high - low) / SCAN as f64;
    let Some((centre, value)) = (1..SCAN)
        .map(|i| {
            let phase = low + step * i as f64;
            (phase, sum(phase))
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return 0.0;
    };
    value.max(golden(sum, centre - step, centre + step))
}

/// [`peak_of`] for sums with many breakpoints (the height bands of a rounded end): `bound(low,
/// high)` is an upper bound of `sum` on the open piece (low, high) between two breakpoints, and
/// the pieces are searched from the highest bound down until no bound can beat the largest value
/// found, so the answer is [`peak_of`]'s while most pieces cost one bound instead of a search.
pub(crate) fn peak_bounded(
    flutes: u32,
    ends: &[f64],
    sum: impl Fn(f64) -> f64,
    bound: impl Fn(f64, f64) -> f64,
) -> f64 {
    if flutes == 0 {
        return 0.0;
    }
    let breaks = breakpoints(flutes, ends);
    let mut best = breaks.iter().map(|&b| sum(b)).fold(0.0, f64::max);
    let mut pieces: Vec<(f64, f64, f64)> = breaks
        .windows(2)
        .filter(|pair| pair[1] - pair[0] > 1e-9)
        .map(|pair| (bound(pair[0], pair[1]), pair[0], pair[1]))
        .collect();
    pieces.sort_by(|a, b| b.0.total_cmp(&a.0));
    for (limit, low, high) in pieces {
        if limit <= best {
            break;
        }
        best = best.max(piece_peak(&sum, low, high));
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

    #[test]
    fn bounded_search_finds_what_the_full_one_does() {
        // Two narrow zones and a wide one, with a loose but valid bound (the sum of each tooth's
        // largest load over the piece).
        let zones = [(20.0, 35.0), (50.0, 140.0), (150.0, 152.0)];
        let load = |t: f64| {
            let t = t.rem_euclid(360.0);
            if zones.iter().any(|(a, b)| (*a..=*b).contains(&t)) {
                t.to_radians().sin().max(0.0).powf(0.8)
            } else {
                0.0
            }
        };
        let ends: Vec<f64> = zones.iter().flat_map(|(a, b)| [*a, *b]).chain([0.0, 180.0]).collect();
        for k in [1, 2, 3, 4, 7] {
            let pitch = 360.0 / f64::from(k);
            let bound = |low: f64, high: f64| {
                (0..k)
                    .map(|j| {
                        let (x, y) = (low + f64::from(j) * pitch, high + f64::from(j) * pitch);
                        let mut largest: f64 = 0.0;
                        for (a, b) in zones {
                            for turn in [-360.0, 0.0, 360.0] {
                                let (from, to) = ((a + turn).max(x), (b + turn).min(y));
                                if to >= from {
                                    let crest = (from..=to).contains(&90.0) || (from..=to).contains(&450.0);
                                    let sin =
                                        if crest { 1.0 } else { from.to_radians().sin().max(to.to_radians().sin()) };
                                    largest = largest.max(sin.max(0.0).powf(0.8));
                                }
                            }
                        }
                        largest
                    })
                    .sum::<f64>()
            };
            let full = peak(k, &ends, load);
            let sum = |phase: f64| (0..k).map(|j| load(phase + f64::from(j) * pitch)).sum::<f64>();
            assert_eq!(peak_bounded(k, &ends, sum, bound), full, "k {k}");
        }
    }
}
