//! The smallest radius of curvature of a NURBS on a stretch (docs/spec/segment.md §2.8 E10 window guard,
//! §2.9a `guarantee`, `radius_estimate: minimum`): every knot span's interior local minima are
//! found once, the first time a stretch reaches the span, so a window's smallest radius is the
//! least of its ends, its interior knots, the minima recorded inside it and eight samples of the
//! window itself: about ten radius evaluations per window instead of a fresh sampling of 16 per
//! window and knot span refined by Brent's method.
//!
//! On a plain B-spline of degree ≤ 3 the turns of each span's radius are found exactly, as the
//! roots of a polynomial (`polynomial`), and a stretch's smallest radius is the least of its
//! ends, its knots and the turns inside it, with no samples at all.

use std::cell::OnceCell;

use super::numeric::minimise;
use super::nurbs::Nurbs;
use super::polynomial::Polynomial;
use crate::geometry::Vec3;

/// Radius samples per knot span before the local minima among them are refined. The radius of a
/// span of degree ≤ 5 is a ratio of low-degree polynomials with few turns; the per-window
/// sampling this replaces took 16 per window and knot span.
const SPAN_SAMPLES: usize = 32;

/// Where the radius is probed next to an end, as a fraction of a sample step: far enough for
/// its change to stand above rounding, near enough to see a dip hugging a knot.
const INWARD_PROBE: f64 = 1e-6;

/// Pieces a stretch is sampled in on top of its span's minima, ends and knots.
const STRETCH_PIECES: usize = 8;

/// Radius of curvature |C'|³/|C'×C''| from a point and its first two derivatives (infinite
/// where straight).
pub(crate) fn radius_of([_, first, second]: [Vec3; 3]) -> f64 {
    radius_from(&first, &second)
}

/// Radius of curvature |C'|³/|C'×C''| from the first two derivatives in any parameter (the
/// scale cancels; infinite where straight).
pub(crate) fn radius_from(first: &Vec3, second: &Vec3) -> f64 {
    let bend = first.cross(second).norm();
    if bend == 0.0 { f64::INFINITY } else { first.norm().powi(3) / bend }
}

/// Radius of curvature at `u`; at a knot the smaller of both one-sided values (the curvature
/// of a degree-2 curve may jump there).
pub(crate) fn radius_at(nurbs: &Nurbs, u: f64) -> f64 {
    if let Some(radius) = nurbs.plain_radius_inside(u).or_else(|| nurbs.plain_radius_at_knot(u)) {
        return radius;
    }
    let right = radius_of(nurbs.derivatives(u));
    nurbs.derivatives_from_left(u).map_or(right, |left| right.min(radius_of(left)))
}

/// (u, radius of curvature there).
type RadiusAt = (f64, f64);

/// The interior local minima of the radius of curvature of each knot span, found on demand.
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct SpanMinima {
    /// Per knot span (index − degree): (u, radius) of each interior local minimum, increasing u
    /// (every interior turn of the radius where `exact`).
    spans: Vec<OnceCell<Box<[RadiusAt]>>>,
    /// Per knot span: the radius at its first knot (the smaller one-sided value), by the basis
    /// functions, found once (each knot lies in a few windows or chords' stretches).
    knot_radii: Vec<OnceCell<f64>>,
    /// The turns are exact (a plain cubic curve): a stretch needs no samples of its own.
    exact: bool,
}

impl SpanMinima {
    pub(crate) fn new(nurbs: &Nurbs) -> Self {
        Self {
            spans: nurbs.spans().map(|_| OnceCell::new()).collect(),
            knot_radii: nurbs.spans().map(|_| OnceCell::new()).collect(),
            exact: nurbs.is_plain_cubic(),
        }
    }

    /// The smallest radius of curvature on [lo, hi] (lo ≤ hi) and where it is: the least of the
    /// ends, the interior knots (both one-sided values), the spans' interior minima inside, and
    /// [`STRETCH_PIECES`] − 1 samples of the stretch itself, the lowest of which is refined when
    /// it is the least of all (a dip between two of the span's samples, on a span much longer
    /// than the stretch), as is an end that is the least where the radius falls going inward.
    pub(crate) fn smallest(&self, nurbs: &Nurbs, lo: f64, hi: f64) -> (f64, f64) {
        let mut best = (radius_at(nurbs, lo), lo);
        let mut consider = |radius: f64, u: f64| {
            if radius < best.0 {
                best = (radius, u);
            }
        };
        if hi <= lo || hi.is_nan() {
            return best;
        }
        consider(radius_at(nurbs, hi), hi);
        let first = nurbs.span(lo);
        let last = nurbs.span(hi).max(first);
        // The distinct knots strictly inside: each the first knot of a non-empty span after lo's.
        for span in first + 1..=last {
            let (knot, next) = nurbs.span_range(span);
            if next > knot && knot > lo && knot < hi {
                consider(self.knot_radius(nurbs, span), knot);
            }
        }
        for span in first..=last {
            for &(u, radius) in self.of_span(nurbs, span) {
                if u > lo && u < hi {
                    consider(radius, u);
                }
            }
        }
        if self.exact {
            // The radius is smooth inside each span, so its least value on the stretch is at an
            // end, a knot or a turn: all considered.
            return best;
        }
        let step = (hi - lo) / STRETCH_PIECES as f64;
        let mut lowest = (f64::INFINITY, lo);
        for j in 1..STRETCH_PIECES {
            let u = lo + step * j as f64;
            let radius = radius_at(nurbs, u);
            if radius < lowest.0 {
                lowest = (radius, u);
            }
        }
        // The bracket to refine: around the lowest sample when it is the least of all, or next
        // to an end that is the least where the radius still falls going inward.
        let bracket = if lowest.0 < best.0 {
            best = lowest;
            Some((lowest.1 - step, lowest.1 + step))
        } else if best.1 == lo && radius_at(nurbs, lo + INWARD_PROBE * step) < best.0 {
            Some((lo, lo + step))
        } else if best.1 == hi && radius_at(nurbs, hi - INWARD_PROBE * step) < best.0 {
            Some((hi - step, hi))
        } else {
            None
        };
        if let Some((from, to)) = bracket {
            let (u, refined) = minimise(|u| radius_at(nurbs, u), from, to, 1e-9 * (hi - lo));
            if refined < best.0 {
                best = (refined, u);
            }
        }
        best
    }

    /// [`radius_at`] the first knot of span `span`, remembered.
    fn knot_radius(&self, nurbs: &Nurbs, span: usize) -> f64 {
        let knot = nurbs.span_range(span).0;
        let first = nurbs.spans().start;
        self.knot_radii
            .get(span - first)
            .map_or_else(|| radius_at(nurbs, knot), |cell| *cell.get_or_init(|| radius_at(nurbs, knot)))
    }

    fn of_span(&self, nurbs: &Nurbs, span: usize) -> &[RadiusAt] {
        let first = nurbs.spans().start;
        let exact = self.exact;
        self.spans.get(span - first).map_or(&[], |cell| {
            cell.get_or_init(|| if exact { span_turns(nurbs, span) } else { span_minima(nurbs, span) })
        })
    }
}

/// Every interior turn of the radius on knot span `span` of a plain cubic curve: with P′ and P″
/// in the span's parameter t, S = |P′|² and C = |P′ × P″|², the radius is (S³/C)^½, whose
/// derivative vanishes where 3·S′·C − S·C′ does (degree ≤ 7; the parameter's scale changes no
/// root). Maxima come along with the minima; the caller takes the least.
fn span_turns(nurbs: &Nurbs, span: usize) -> Box<[RadiusAt]> {
    let (start, end) = nurbs.span_range(span);
    let Some([_, a1, a2, a3]) = nurbs.plain_span_form(span).filter(|_| end > start) else {
        return Box::new([]);
    };
    // P′ = a₁ + 2a₂t + 3a₃t² and P′ × P″ = 2(a₁ × a₂) + 6(a₁ × a₃)t + 6(a₂ × a₃)t² (the
    // parallel terms cancel), so S and C are quartics: built directly, not by general products.
    let speed_squared = squared_norm([a1, 2.0 * a2, 3.0 * a3]);
    let bend_squared = squared_norm([2.0 * a1.cross(&a2), 6.0 * a1.cross(&a3), 6.0 * a2.cross(&a3)]);
    let derivative = |p: &[f64; 5]| [p[1], 2.0 * p[2], 3.0 * p[3], 4.0 * p[4]];
    let (speed_slope, bend_slope) = (derivative(&speed_squared), derivative(&bend_squared));
    let mut coefficients = [0.0; 8];
    for (i, (&ds, &dc)) in speed_slope.iter().zip(&bend_slope).enumerate() {
        for (j, (&c, &s)) in bend_squared.iter().zip(&speed_squared).enumerate() {
            coefficients[i + j] += 3.0 * ds * c - s * dc;
        }
    }
    let turning = Polynomial::new(&coefficients);
    let width = end - start;
    turning
        .roots_in(0.0, 1.0)
        .as_slice()
        .iter()
        .filter(|&&t| t > 0.0 && t < 1.0)
        .map(|&t| {
            let u = start + width * t;
            (u, radius_of(nurbs.derivatives_in(span, u)))
        })
        .filter(|&(u, _)| u > start && u < end)
        .collect()
}

/// |q₀ + q₁t + q₂t²|², lowest power first.
fn squared_norm([q0, q1, q2]: [Vec3; 3]) -> [f64; 5] {
    [q0.dot(&q0), 2.0 * q0.dot(&q1), q1.dot(&q1) + 2.0 * q0.dot(&q2), 2.0 * q1.dot(&q2), q2.dot(&q2)]
}

/// The interior local minima of the radius on knot span `span`: [`SPAN_SAMPLES`] samples of the
/// span's own polynomial (one-sided at its ends), each sample lower than its neighbours refined
/// by Brent's method between them. A minimum against a span end is the end's value, which
/// [`SpanMinima::smallest`] takes from the knot itself.
fn span_minima(nurbs: &Nurbs, span: usize) -> Box<[RadiusAt]> {
    let (start, end) = nurbs.span_range(span);
    if end <= start {
        return Box::new([]);
    }
    let radius = |u: f64| radius_of(nurbs.derivatives_in(span, u));
    let step = (end - start) / SPAN_SAMPLES as f64;
    let at = |j: usize| if j == SPAN_SAMPLES { end } else { start + step * j as f64 };
    let samples: Vec<f64> = (0..=SPAN_SAMPLES).map(|j| radius(at(j))).collect();
    let tol = 1e-9 * (end - start);
    let mut minima = Vec::new();
    for j in 0..=SPAN_SAMPLES {
        let here = samples[j];
        let below_left = j == 0 || here < samples[j - 1];
        let below_right = j == SPAN_SAMPLES || here <= samples[j + 1];
        if !here.is_finite() || !below_left || !below_right {
            continue;
        }
        let (from, to) = if j == 0 || j == SPAN_SAMPLES {
            // The lowest sample at a span end: the end's value is the knot's, unless the radius
            // falls going inward (a dip next to the knot, where the curvature may jump).
            let (inward, neighbour) = if j == 0 { (1.0, at(1)) } else { (-1.0, at(SPAN_SAMPLES - 1)) };
            let falls_inward = radius(at(j) + inward * INWARD_PROBE * step) < here;
            if !falls_inward {
                continue;
            }
            (at(j).min(neighbour), at(j).max(neighbour))
        } else {
            (at(j - 1), at(j + 1))
        };
        let (u, refined) = minimise(radius, from, to, tol);
        minima.push(if refined < here && u > start && u < end { (u, refined) } else { (at(j), here) });
    }
    minima.into_boxed_slice()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_cubic_turns_are_exact() {
        // A spiral with a z wave, as in the chord bench: stretches of a fifth of a span to three
        // spans, each checked against dense samples refined around the least.
        let mut control = Vec::new();
        let mut angle: f64 = 0.0;
        while control.len() < 40 {
            let radius = 50.0 + 12.0 * angle / std::f64::consts::TAU;
            control.push(Vec3::new(radius * angle.cos(), radius * angle.sin(), 0.5 * (3.0 * angle).sin()));
            angle += 10.0 / radius;
        }
        for degree in [2, 3] {
            let nurbs = Nurbs::new(degree, &control, None, None, "curve").unwrap();
            let minima = SpanMinima::new(&nurbs);
            let (start, end) = nurbs.domain();
            let span = (end - start) / (control.len() - degree) as f64;
            for k in 0..60 {
                let lo = start + (end - start) * f64::from(k) / 61.0;
                for width in [0.2, 1.0, 3.0] {
                    let hi = (lo + width * span).min(end);
                    let (radius, _) = minima.smallest(&nurbs, lo, hi);
                    let step = (hi - lo) / 2000.0;
                    let (best_u, _) = (0..=2000)
                        .map(|j| lo + step * f64::from(j))
                        .map(|u| (u, radius_at(&nurbs, u)))
                        .fold((lo, f64::INFINITY), |best, (u, r)| if r < best.1 { (u, r) } else { best });
                    let (_, refined) =
                        minimise(|u| radius_at(&nurbs, u), (best_u - step).max(lo), (best_u + step).min(hi), 1e-14);
                    let dense = refined.min(radius_at(&nurbs, best_u));
                    assert!(
                        radius <= dense * (1.0 + 1e-12) && radius >= dense * (1.0 - 1e-9),
                        "degree {degree} [{lo}, {hi}]: {radius} vs {dense}"
                    );
                }
            }
        }
    }

    #[test]
    fn the_smallest_radius_matches_dense_sampling() {
        // Rational and plain curves of degrees 2 to 5 with a wavy control polygon, stretches
        // inside a span, across knots and starting on one.
        let control: Vec<Vec3> = (0..9)
            .map(|k| {
                let k = f64::from(k);
                Vec3::new(10.0 * k, 6.0 * (1.3 * k).sin(), 2.0 * (0.7 * k).cos())
            })
            .collect();
        let weights = [1.0, 2.5, 0.4, 1.0, 3.0, 0.5, 1.0, 2.0, 1.0];
        for degree in 2..=5 {
            for rational in [false, true] {
                let nurbs = Nurbs::new(degree, &control, None, rational.then_some(&weights[..]), "curve").unwrap();
                let minima = SpanMinima::new(&nurbs);
                let (start, end) = nurbs.domain();
                for (lo, hi) in [(0.01, 0.05), (0.1, 0.45), (0.2, 0.2001), (start, end), (0.5, 0.93)] {
                    let (radius, at) = minima.smallest(&nurbs, lo, hi);
                    let dense = (0..=20_000)
                        .map(|j| radius_at(&nurbs, lo + (hi - lo) * f64::from(j) / 20_000.0))
                        .fold(f64::INFINITY, f64::min);
                    assert!(radius <= dense * (1.0 + 1e-9), "degree {degree} [{lo}, {hi}]: {radius} > {dense}");
                    assert!((radius_at(&nurbs, at) - radius).abs() <= 1e-9 * radius, "reported where it is");
                    assert!((lo..=hi).contains(&at));
                }
            }
        }
    }
}
