//! The exact deviation of a chord inside one knot span of a polynomial NURBS of degree ≤ 3 (a
//! plain B-spline, chord.md §2.9a: "reuse of span evaluations"), from the span's power form
//! instead of samples, so the fast search needs no sampled check of such chords (issue 14).
//!
//! With the chord from t_a to t_b and its parameter-linear interpolation ℓ(t), P(t) − ℓ(t)
//! vanishes at both ends, so P(t) − ℓ(t) = (t − t_a)(t − t_b)·Q(t) with
//! Q(t) = a₂ + a₃·(t_a + t_b + t) for P(t) = Σ a_k·t^k. ℓ(t) lies on the chord's line, so the
//! distance from that line is |(t − t_a)(t − t_b)|·|Q(t) × d| for the chord's direction d. In
//! x = t − t_m (t_m the middle, w the half width) that is f(x) = (w² − x²)·|q₀ + x·q₁|, whose
//! square is a polynomial of degree 6: its interior maxima are roots of a cubic, found exactly.

use super::nurbs::CubicPiece;
use crate::geometry::Vec3;

/// Most Newton or bisection steps for a root of the cubic (bisection alone halves the bracket
/// to 2⁻⁶⁰ of the chord).
const ROOT_STEPS: usize = 60;
/// A root is found when a Newton step moves it less than this fraction of its bracket: f is
/// flat at its maximum, so the value is then exact to about the square of it, 1e-20.
const ROOT_WIDTH: f64 = 1e-10;

/// The largest distance of the curve over the piece from the segment joining its ends, or
/// `None` where a point of the piece might project beyond the segment's ends (then its distance
/// from the segment is not its distance from the line: the caller samples instead).
pub(crate) fn deviation(piece: &CubicPiece) -> Option<f64> {
    let [_, _, a2, a3] = piece.coefficients;
    let point = |t: f64| {
        let [c0, c1, c2, c3] = piece.coefficients;
        c0 + t * (c1 + t * (c2 + t * c3))
    };
    let (t_a, t_b) = (piece.t_lo, piece.t_hi);
    let chord = point(t_b) - point(t_a);
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
    Some(largest_hump(half, q0.dot(&q0), q0.dot(&q1), q1.dot(&q1)))
}

/// max over |x| ≤ w of f(x) = (w² − x²)·√(α + 2βx + γx²): f vanishes at ±w, so the maximum is
/// at a root of the derivative's factor g(x) = −6γx³ − 10βx² + (2γw² − 4α)x + 2βw² (from
/// (f²)' = (w² − x²)·g(x)). g(−w) ≥ 0 ≥ g(w); g is split at its own turning points into pieces
/// where it is monotone, and each sign change is a root.
fn largest_hump(w: f64, alpha: f64, beta: f64, gamma: f64) -> f64 {
    let hump = |x: f64| (w * w - x * x) * (alpha + x * (2.0 * beta + gamma * x)).max(0.0).sqrt();
    let g =
        |x: f64| ((-6.0 * gamma * x - 10.0 * beta) * x + (2.0 * gamma * w * w - 4.0 * alpha)) * x + 2.0 * beta * w * w;
    let slope = |x: f64| (-18.0 * gamma * x - 20.0 * beta) * x + (2.0 * gamma * w * w - 4.0 * alpha);
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
    let mut best = 0.0_f64;
    for pair in breaks.windows(2) {
        let (left, right) = (pair[0], pair[1]);
        best = best.max(hump(left)).max(hump(right));
        let (g_left, g_right) = (g(left), g(right));
        if g_left.signum() * g_right.signum() > 0.0 {
            continue;
        }
        best = best.max(hump(root(&g, &slope, left, right, g_left)));
    }
    best
}

/// The real roots of a·x² + b·x + c (none, one or two, in no order); a linear equation when
/// a = 0.
fn quadratic_roots(a: f64, b: f64, c: f64) -> impl Iterator<Item = f64> {
    let mut roots = [f64::NAN; 2];
    if a == 0.0 {
        if b != 0.0 {
            roots[0] = -c / b;
        }
    } else {
        let discriminant = b * b - 4.0 * a * c;
        if discriminant >= 0.0 {
            // The form without cancellation: q = −(b + sign(b)·√D)/2, roots q/a and c/q.
            let q = -0.5 * (b + b.signum() * discriminant.sqrt());
            roots[0] = q / a;
            if q != 0.0 {
                roots[1] = c / q;
            }
        }
    }
    roots.into_iter().filter(|x| x.is_finite())
}

/// The root of a function monotone on [left, right] whose ends' values differ in sign (or one
/// is zero): Newton steps kept inside the bracket, bisection where a step leaves it.
fn root(g: &impl Fn(f64) -> f64, slope: &impl Fn(f64) -> f64, left: f64, right: f64, g_left: f64) -> f64 {
    let rising = g_left < 0.0;
    let (mut lo, mut hi) = (left, right);
    let mut x = 0.5 * (lo + hi);
    for _ in 0..ROOT_STEPS {
        let value = g(x);
        if value == 0.0 {
            return x;
        }
        if (value < 0.0) == rising {
            lo = x;
        } else {
            hi = x;
        }
        let step = value / slope(x);
        if step.abs() <= ROOT_WIDTH * (right - left) {
            return x; // converged: a smaller step could round onto a bracket end
        }
        let newton = x - step;
        x = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if hi - lo <= ROOT_WIDTH * (right - left) {
            return x;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The distance from the chord by brute force: many samples of the piece.
    fn sampled(piece: &CubicPiece) -> f64 {
        let point = |t: f64| {
            let [c0, c1, c2, c3] = piece.coefficients;
            c0 + t * (c1 + t * (c2 + t * c3))
        };
        let (a, b) = (point(piece.t_lo), point(piece.t_hi));
        (0..=100_000)
            .map(|k| {
                let t = piece.t_lo + (piece.t_hi - piece.t_lo) * f64::from(k) / 100_000.0;
                crate::geometry::distance_to_segment(&point(t), &a, &b)
            })
            .fold(0.0, f64::max)
    }

    #[test]
    fn a_parabola_peaks_at_the_middle() {
        // y = t² from −1 to 1: the chord y = 1, deviation 1 at t = 0.
        let piece =
            CubicPiece { coefficients: [Vec3::zeros(), Vec3::x(), Vec3::y(), Vec3::zeros()], t_lo: -1.0, t_hi: 1.0 };
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
            let piece = CubicPiece { coefficients, t_lo, t_hi };
            let exact = deviation(&piece).expect("projection inside");
            let dense = sampled(&piece);
            assert!(exact >= dense - 1e-15 && exact <= dense * (1.0 + 1e-8) + 1e-15, "{exact} vs {dense}");
        }
    }

    #[test]
    fn a_root_found_to_rounding_is_kept() {
        // Found by the chord property tests: the last Newton step rounded onto the bracket's end,
        // and the search fell back to the bracket's middle, far from the root.
        let hump = largest_hump(0.03871972443956874, 0.36262487493168816, 5.024123675499595, 69.60862437104088);
        assert!((hump - 0.000_960_557_651_682_66).abs() < 1e-15, "{hump}");
    }

    #[test]
    fn a_piece_bending_back_past_its_ends_is_left_to_sampling() {
        // A hairpin: points project beyond the chord's ends.
        let piece = CubicPiece {
            coefficients: [Vec3::zeros(), Vec3::x(), Vec3::new(0.0, 5.0, 0.0), Vec3::new(-3.0, 0.0, 0.0)],
            t_lo: 0.0,
            t_hi: 1.0,
        };
        assert_eq!(deviation(&piece), None);
    }
}
