//! The exact deviation of a chord inside one knot span of a polynomial NURBS of degree ≤ 3 (a
//! plain B-spline, docs/spec/segment.md §2.9a: "reuse of span evaluations"), from the span's power form
//! instead of samples, so the fast search needs no sampled check of such chords.
//!
//! With the chord from t_a to t_b and its parameter-linear interpolation ℓ(t), P(t) − ℓ(t)
//! vanishes at both ends, so P(t) − ℓ(t) = (t − t_a)(t − t_b)·Q(t) with
//! Q(t) = a₂ + a₃·(t_a + t_b + t) for P(t) = Σ a_k·t^k. ℓ(t) lies on the chord's line, so the
//! distance from that line is |(t − t_a)(t − t_b)|·|Q(t) × d| for the chord's direction d. In
//! x = t − t_m (t_m the middle, w the half width) that is f(x) = (w² − x²)·|q₀ + x·q₁|, whose
//! square is a polynomial of degree 6: its interior maxima are roots of a cubic, found exactly.

use super::nurbs::CubicPiece;
use super::polynomial::{bracketed_root, quadratic_roots};
use crate::geometry::Vec3;

/// A root is found when a Newton step moves it less than this fraction of its bracket: f is
/// flat at its maximum, so the value is then exact to about the square of it, 1e-20.
const ROOT_WIDTH: f64 = 1e-10;

/// The largest distance of the curve over the piece from the segment joining its ends, or
/// `None` where a point of the piece might project beyond the segment's ends (then its distance
/// from the segment is not its distance from the line: the caller samples instead).
pub(crate) fn deviation(piece: &CubicPiece<'_>) -> Option<f64> {
    Some(Chord::of(piece)?.deviation)
}

/// [`deviation`] with what its rate of change needs as the chord's end `t_hi` moves along the
/// curve, per unit of the piece's parameter: the chord search steps to the chord error by Newton
/// with it.
///
/// The farthest point P* stays the farthest to first order (it is an interior maximum), so the
/// rate is that of the distance of the fixed P* from the line A–B as B moves with P′(t_hi):
/// with u = B − A, n = P* − A and m = n × u, D = |m|/|u| and
/// dD = m·(n × P′)/(|m|·|u|) − |m|·(u·P′)/|u|³ = m·(n × P′)/(D·|u|²) − D·(u·P′)/|u|².
/// `None` as for [`deviation`]; the rate itself is `None` where the piece is straight (D = 0:
/// the rate has no direction).
pub(crate) fn deviation_with_rate<'a>(piece: &CubicPiece<'a>) -> Option<(f64, RateInputs<'a>)> {
    let chord = Chord::of(piece)?;
    let along = chord.end - chord.start;
    let inputs =
        RateInputs { distance: chord.deviation, along, farthest: Farthest::OnPiece(*piece, chord.peak, chord.start) };
    Some((chord.deviation, inputs))
}

/// What the rate of a chord's deviation needs (see [`deviation_with_rate`]): the distance of the
/// farthest point from the chord's line, the chord B − A, and where the farthest point and the
/// curve's velocity at B come from. Kept rather than worked out, because the search's last trial,
/// the one that confirms the chord, needs the deviation alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RateInputs<'a> {
    distance: f64,
    along: Vec3,
    farthest: Farthest<'a>,
}

/// The farthest point less the chord's start, and the velocity at the chord's end.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Farthest<'a> {
    /// A chord inside one piece: the piece, the farthest point's parameter, the chord's start.
    OnPiece(CubicPiece<'a>, f64, Vec3),
    /// Found across a knot: the farthest point less the start, and the velocity.
    Known(Vec3, Vec3),
}

impl RateInputs<'_> {
    /// The rate of the distance as B moves with the velocity; `None` for a point on the line.
    pub(crate) fn rate(&self) -> Option<f64> {
        let length_squared = self.along.norm_squared();
        let distance = self.distance;
        if !(distance > 0.0 && length_squared > 0.0) {
            return None;
        }
        let (from_start, velocity) = match self.farthest {
            Farthest::OnPiece(piece, peak, start) => {
                let [_, a1, a2, a3] = *piece.coefficients;
                let t_hi = piece.t_hi;
                (piece.point(peak) - start, a1 + t_hi * (2.0 * a2 + 3.0 * a3 * t_hi))
            }
            Farthest::Known(from_start, velocity) => (from_start, velocity),
        };
        let m = from_start.cross(&self.along);
        let rate =
            (m.dot(&from_start.cross(&velocity)) / distance - distance * self.along.dot(&velocity)) / length_squared;
        rate.is_finite().then_some(rate)
    }
}

impl CubicPiece<'_> {
    fn point(&self, t: f64) -> Vec3 {
        let [c0, c1, c2, c3] = *self.coefficients;
        c0 + t * (c1 + t * (c2 + t * c3))
    }
}

/// A chord of a piece measured exactly: its ends, its deviation and where the curve is farthest.
struct Chord {
    start: Vec3,
    end: Vec3,
    deviation: f64,
    /// Local parameter of the farthest point.
    peak: f64,
}

impl Chord {
    fn of(piece: &CubicPiece<'_>) -> Option<Self> {
        let [_, _, a2, a3] = *piece.coefficients;
        let (t_a, t_b) = (piece.t_lo, piece.t_hi);
        let (start, end) = (piece.point(t_a), piece.point(t_b));
        let chord = end - start;
        let length = chord.norm();
        if !(length > 0.0 && length.is_finite()) {
            return None;
        }
        let direction = chord / length;
        let q_of = |t: f64| a2 + a3 * (t_a + t_b + t);
        let width = t_b - t_a;
        // The projection of P(t) on the chord is L·τ − width²·τ(1 − τ)·(Q·d) with τ = (t − t_a)/width:
        // inside [0, L] for every τ when width²·max|Q·d| ≤ L (Q·d is affine: largest at an end).
        let along = q_of(t_a).dot(&direction).abs().max(q_of(t_b).dot(&direction).abs());
        if width * width * along > length {
            return None;
        }
        let half = 0.5 * width;
        let q0: Vec3 = q_of(t_a + half).cross(&direction);
        let q1: Vec3 = a3.cross(&direction);
        let (deviation, x) = largest_hump(half, q0.dot(&q0), q0.dot(&q1), q1.dot(&q1));
        Some(Self { start, end, deviation, peak: t_a + half + x })
    }
}

/// The largest distance from the segment `a`–`b` of a chord that crosses one knot: `first` runs
/// from `a` to the knot, `second` from the knot to `b`, each in its own span's power form.
/// `None` where a point might project beyond the segment's ends, or where a piece's distance might
/// have more than one hump (the caller samples instead).
///
/// Each piece is measured from the chord end it touches: expanded about that end, P − end =
/// x·(c₁ + c₂x + c₃x²) with x ≥ 0 running into the piece, so its squared distance from the
/// chord's line is h(x) = x²·|V(x)|², V = (c₁ + c₂x + c₃x²) × d, and h′ = 2x·q(x) with the quartic
/// q = |V|² + x·V·V′. The signs of q's Bernstein coefficients on the piece bound its roots
/// (variation diminishing): none, h grows to the knot; one, h peaks at q's one root there.
pub(crate) fn deviation_across_knot(
    first: &CubicPiece<'_>,
    second: &CubicPiece<'_>,
    a: &Vec3,
    b: &Vec3,
) -> Option<f64> {
    Some(across_knot(first, second, a, b)?.0)
}

/// [`deviation_across_knot`] with what its rate needs as the chord's end moves along `second`,
/// per unit of `second`'s parameter (as [`deviation_with_rate`]).
pub(crate) fn deviation_across_knot_with_rate(
    first: &CubicPiece<'_>,
    second: &CubicPiece<'_>,
    a: &Vec3,
    b: &Vec3,
) -> Option<(f64, RateInputs<'static>)> {
    let (distance, from_start, velocity) = across_knot(first, second, a, b)?;
    Some((distance, RateInputs { distance, along: b - a, farthest: Farthest::Known(from_start, velocity) }))
}

/// The deviation of [`deviation_across_knot`], the farthest point less `a`, and the curve's
/// velocity at `b` in `second`'s parameter.
fn across_knot(first: &CubicPiece<'_>, second: &CubicPiece<'_>, a: &Vec3, b: &Vec3) -> Option<(f64, Vec3, Vec3)> {
    let chord = b - a;
    let length = chord.norm();
    if !(length > 0.0 && length.is_finite()) {
        return None;
    }
    let direction = chord / length;
    // About t_a going forward; about t_b going backward (x = t_b − t flips the even powers, and
    // P − b = −x·(c₁ + c₂x + c₃x²)).
    let [_, a1, a2, a3] = *first.coefficients;
    let t = first.t_lo;
    let from_start = [a1 + t * (2.0 * a2 + 3.0 * a3 * t), a2 + 3.0 * a3 * t, a3];
    let [_, b1, b2, b3] = *second.coefficients;
    let t = second.t_hi;
    let from_end = [b1 + t * (2.0 * b2 + 3.0 * b3 * t), -(b2 + 3.0 * b3 * t), b3];
    let (near_start, x_start) = largest_from_end(from_start, &direction, first.t_hi - first.t_lo)?;
    let (near_end, x_end) = largest_from_end(from_end, &direction, second.t_hi - second.t_lo)?;
    let offset = |[c1, c2, c3]: [Vec3; 3], x: f64| x * (c1 + x * (c2 + x * c3));
    let peak_from_start =
        if near_start >= near_end { offset(from_start, x_start) } else { chord - offset(from_end, x_end) };
    Some((near_start.max(near_end).sqrt(), peak_from_start, from_end[0]))
}

/// max over x ∈ [0, extent] of h(x) = x²·|(c₁ + c₂x + c₃x²) × d|² (see [`deviation_across_knot`])
/// and the x where it is; `None` when the piece does not move steadily away from its end along d (its projection on the
/// chord could leave the segment) or when q may have more than one root.
fn largest_from_end([c1, c2, c3]: [Vec3; 3], direction: &Vec3, extent: f64) -> Option<(f64, f64)> {
    if extent.is_nan() {
        return None;
    }
    if extent <= 0.0 {
        return Some((0.0, 0.0));
    }
    // The projection x·(c₁ + c₂x + c₃x²)·d must grow with x: its slope is a quadratic ≥ 0.
    let slope = [c1.dot(direction), 2.0 * c2.dot(direction), 3.0 * c3.dot(direction)];
    if !non_negative_quadratic(slope, extent) {
        return None;
    }
    let [v0, v1, v2] = [c1.cross(direction), c2.cross(direction), c3.cross(direction)];
    let h = |x: f64| {
        let v = v0 + x * (v1 + x * v2);
        x * x * v.norm_squared()
    };
    // q = |V|² + x·V·V′, lowest power first, then scaled to the piece (x = extent·s).
    let q =
        [v0.dot(&v0), 3.0 * v0.dot(&v1), 2.0 * v1.dot(&v1) + 4.0 * v0.dot(&v2), 5.0 * v1.dot(&v2), 3.0 * v2.dot(&v2)];
    let mut scale = 1.0;
    let scaled = q.map(|coefficient| {
        let value = coefficient * scale;
        scale *= extent;
        value
    });
    let [s0, s1, s2, s3, s4] = scaled;
    let bernstein =
        [s0, s0 + s1 / 4.0, s0 + s1 / 2.0 + s2 / 6.0, s0 + 0.75 * s1 + 0.5 * s2 + 0.25 * s3, s0 + s1 + s2 + s3 + s4];
    let mut changes = 0;
    let mut previous = 0.0_f64;
    for value in bernstein {
        if value != 0.0 {
            if previous != 0.0 && value.signum() != previous.signum() {
                changes += 1;
            }
            previous = value;
        }
    }
    let q_at = |x: f64| q[0] + x * (q[1] + x * (q[2] + x * (q[3] + x * q[4])));
    let q_slope = |x: f64| q[1] + x * (2.0 * q[2] + x * (3.0 * q[3] + x * 4.0 * q[4]));
    let at_extent = (h(extent), extent);
    match changes {
        0 => Some(at_extent),
        1 if q[0] > 0.0 && q_at(extent) < 0.0 => {
            let peak = bracketed_root(&q_at, &q_slope, 0.0, extent, q[0], ROOT_WIDTH);
            let at_peak = (h(peak), peak);
            Some(if at_peak.0 > at_extent.0 { at_peak } else { at_extent })
        }
        1 => Some(at_extent),
        _ => None,
    }
}

/// Whether p₀ + p₁x + p₂x² ≥ 0 on [0, extent].
fn non_negative_quadratic([p0, p1, p2]: [f64; 3], extent: f64) -> bool {
    let value = |x: f64| p0 + x * (p1 + x * p2);
    if value(0.0) < 0.0 || value(extent) < 0.0 {
        return false;
    }
    if p2 > 0.0 {
        let vertex = -p1 / (2.0 * p2);
        if vertex > 0.0 && vertex < extent && value(vertex) < 0.0 {
            return false;
        }
    }
    true
}

/// max over |x| ≤ w of f(x) = (w² − x²)·√(α + 2βx + γx²): f vanishes at ±w, so the maximum is
/// at a root of the derivative's factor g(x) = −6γx³ − 10βx² + (2γw² − 4α)x + 2βw² (from
/// (f²)' = (w² − x²)·g(x)). g(−w) ≥ 0 ≥ g(w); g is split at its own turning points into pieces
/// where it is monotone, and each sign change is a root.
fn largest_hump(w: f64, alpha: f64, beta: f64, gamma: f64) -> (f64, f64) {
    let hump = |x: f64| (w * w - x * x) * (alpha + x * (2.0 * beta + gamma * x)).max(0.0).sqrt();
    let g =
        |x: f64| ((-6.0 * gamma * x - 10.0 * beta) * x + (2.0 * gamma * w * w - 4.0 * alpha)) * x + 2.0 * beta * w * w;
    let slope = |x: f64| (-18.0 * gamma * x - 20.0 * beta) * x + (2.0 * gamma * w * w - 4.0 * alpha);
    // Nearly always g falls over all of [−w, w] (its slope stays below 20|β|w + 2γw² − 4α there,
    // γ ≥ 0): its one root there is the peak, found from the middle as below, without the
    // turns of g or its values at the ends.
    if 20.0 * beta.abs() * w + 2.0 * gamma * w * w < 4.0 * alpha {
        let peak = bracketed_root(&g, &slope, -w, w, 1.0, ROOT_WIDTH);
        return (hump(peak), peak);
    }
    // −w, the turns of g inside (at most two, put in order by hand: a sort call cost more than
    // the rest of this function on the chord bench), w.
    let mut breaks = [-w, w, w, w];
    let mut count = 1;
    for turn in quadratic_roots(-18.0 * gamma, -20.0 * beta, 2.0 * gamma * w * w - 4.0 * alpha) {
        if turn > -w && turn < w {
            breaks[count] = turn;
            count += 1;
        }
    }
    if count == 3 && breaks[1] > breaks[2] {
        breaks.swap(1, 2);
    }
    breaks[count] = w;
    let breaks = &breaks[..=count];
    let mut best = (0.0_f64, 0.0_f64);
    let mut keep = |x: f64| {
        let value = hump(x);
        if value > best.0 {
            best = (value, x);
        }
    };
    for pair in breaks.windows(2) {
        let (left, right) = (pair[0], pair[1]);
        keep(left);
        keep(right);
        let (g_left, g_right) = (g(left), g(right));
        if g_left.signum() * g_right.signum() > 0.0 {
            continue;
        }
        keep(bracketed_root(&g, &slope, left, right, g_left, ROOT_WIDTH));
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::nurbs::{CubicStretch, Nurbs};

    /// The distance from the chord by brute force: many samples of the piece.
    fn sampled(piece: &CubicPiece<'_>) -> f64 {
        let (a, b) = (piece.point(piece.t_lo), piece.point(piece.t_hi));
        (0..=100_000)
            .map(|k| {
                let t = piece.t_lo + (piece.t_hi - piece.t_lo) * f64::from(k) / 100_000.0;
                crate::geometry::distance_to_segment(&piece.point(t), &a, &b)
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_parabola_peaks_at_the_middle() {
        // y = t² from −1 to 1: the chord y = 1, deviation 1 at t = 0.
        let piece =
            CubicPiece { coefficients: &[Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::zeros()], t_lo: -1.0, t_hi: 1.0 };
        assert!((deviation(&piece).unwrap() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn cubic_pieces_match_dense_sampling() {
        // An S (the chord crosses the curve: two humps), a 3-D twist, a nearly straight piece.
        let cases = [
            ([Vec3::zeros(), Vec3::x(), Vec3::zeros(), Vec3::new(0.0, 1.0, 0.0)], -0.5, 0.6),
            ([Vec3::zeros(), Vec3::new(1.0, 0.2, 0.0), Vec3::new(0.0, 0.7, 0.1), Vec3::new(0.05, -0.3, 0.4)], 0.1, 0.6),
            (
                [
                    Vec3::new(3.0, 1.0, 2.0),
                    Vec3::new(4.0, 0.0, 1.0),
                    Vec3::new(0.0, 1e-6, 0.0),
                    Vec3::new(0.0, 0.0, 1e-7),
                ],
                0.0,
                1.0,
            ),
        ];
        for (coefficients, t_lo, t_hi) in cases {
            let piece = CubicPiece { coefficients: &coefficients, t_lo, t_hi };
            let exact = deviation(&piece).expect("projection inside");
            let dense = sampled(&piece);
            assert!(exact >= dense - 1e-15 && exact <= dense * (1.0 + 1e-8) + 1e-15, "{exact} vs {dense}");
        }
    }

    #[test]
    fn the_rate_matches_a_difference_of_deviations() {
        // A bend, a 3-D twist, an S whose farthest point is off the middle.
        let cases = [
            ([Vec3::zeros(), Vec3::x(), Vec3::new(0.0, 0.3, 0.0), Vec3::zeros()], 0.1, 0.4),
            ([Vec3::zeros(), Vec3::new(1.0, 0.2, 0.0), Vec3::new(0.0, 0.7, 0.1), Vec3::new(0.05, -0.3, 0.4)], 0.1, 0.6),
            ([Vec3::zeros(), Vec3::x(), Vec3::new(0.0, 0.2, 0.0), Vec3::new(0.0, 0.5, 0.0)], 0.0, 0.5),
        ];
        for (coefficients, t_lo, t_hi) in cases {
            let piece = CubicPiece { coefficients: &coefficients, t_lo, t_hi };
            let (value, inputs) = deviation_with_rate(&piece).expect("bends inside");
            let rate = inputs.rate().expect("a rate");
            assert!((value - deviation(&piece).unwrap()).abs() < 1e-15);
            let step = 1e-6;
            let moved = |t_hi: f64| deviation(&CubicPiece { t_hi, ..piece }).unwrap();
            let difference = (moved(t_hi + step) - moved(t_hi - step)) / (2.0 * step);
            assert!((rate - difference).abs() <= 1e-6 * difference.abs(), "{rate} vs {difference}");
        }
    }

    #[test]
    fn a_straight_piece_has_no_rate() {
        let piece =
            CubicPiece { coefficients: &[Vec3::zeros(), Vec3::x(), Vec3::x(), Vec3::zeros()], t_lo: 0.0, t_hi: 1.0 };
        assert_eq!(deviation(&piece), Some(0.0));
        assert_eq!(deviation_with_rate(&piece).and_then(|(_, inputs)| inputs.rate()), None);
    }

    #[test]
    fn a_root_found_to_rounding_is_kept() {
        // Found by the chord property tests: the last Newton step rounded onto the bracket's end,
        // and the search fell back to the bracket's middle, far from the root.
        let (hump, _) = largest_hump(0.03871972443956874, 0.36262487493168816, 5.024123675499595, 69.60862437104088);
        assert!((hump - 0.000_960_557_651_682_66).abs() < 1e-15, "{hump}");
    }

    #[test]
    fn chords_across_a_knot_match_dense_sampling() {
        // Plain B-splines of degree 2 and 3 through a wavy 3-D control polygon, chords of a tenth
        // to nine tenths of a span starting anywhere; those crossing one knot are measured.
        let control: Vec<Vec3> = (0..12)
            .map(|k| {
                let k = f64::from(k);
                Vec3::new(10.0 * k, 6.0 * (0.9 * k).sin(), 2.0 * (0.5 * k).cos())
            })
            .collect();
        for degree in [2, 3] {
            let curve = Nurbs::new(degree, &control, None, None, "curve").unwrap();
            let (start, end) = curve.domain();
            let span = (end - start) / (control.len() - degree) as f64;
            let mut measured = 0;
            for k in 0..200 {
                let lo = start + (end - start) * f64::from(k) / 200.0;
                for width in [0.1, 0.4, 0.9] {
                    let hi = (lo + width * span).min(end);
                    let Some((CubicStretch::AcrossKnot(first, second), _)) = curve.cubic_stretch(lo, hi) else {
                        continue;
                    };
                    let (a, b) = (curve.point(lo), curve.point(hi));
                    let Some(exact) = deviation_across_knot(&first, &second, &a, &b) else { continue };
                    let dense = (0..=20_000)
                        .map(|j| {
                            let u = lo + (hi - lo) * f64::from(j) / 20_000.0;
                            crate::geometry::distance_to_segment(&curve.point(u), &a, &b)
                        })
                        .fold(0.0, f64::max);
                    assert!(
                        exact >= dense - 1e-12 && exact <= dense * (1.0 + 1e-6) + 1e-12,
                        "degree {degree}, [{lo}, {hi}]: {exact} vs {dense}"
                    );
                    measured += 1;
                }
            }
            assert!(measured > 100, "degree {degree}: only {measured} chords measured");
        }
    }

    #[test]
    fn a_piece_bending_back_past_its_ends_is_left_to_sampling() {
        // A hairpin: points project beyond the chord's ends.
        let piece = CubicPiece {
            coefficients: &[Vec3::zeros(), Vec3::x(), Vec3::new(0.0, 5.0, 0.0), Vec3::new(-3.0, 0.0, 0.0)],
            t_lo: 0.0,
            t_hi: 1.0,
        };
        assert_eq!(deviation(&piece), None);
    }
}
