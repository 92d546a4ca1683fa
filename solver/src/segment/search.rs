//! The fast chord search (docs/spec/segment.md §2.9a, revision 2): the same chords as the reference greedy
//! of §2.9 up to its 1e-12 mm bracket, from a handful of deviation evaluations per block.
//!
//! * circular arcs: the chord end in closed form from the sagitta, dev = 2r·sin²(Δs/4r);
//! * polylines: placed on an edge where the first spanned vertex reaches C_ep (`polyline`);
//! * plain B-splines of degree ≤ 3 (a chord inside one knot span or across one knot) and
//!   ellipses (a chord of up to a quarter turn): Newton steps on √dev from the previous chord's
//!   step, with the deviation's rate in closed form (for the B-spline from the envelope theorem,
//!   `cubic`): two deviations per block nearly always, one to step and one to confirm; the
//!   bracketed secant below takes over where Newton does not settle;
//! * everything else: a bracketed secant (Illinois) on g(u) = √dev(u_a, u) − √C_ep, which is
//!   nearly linear in u because the deviation grows with the square of the chord. The first
//!   trial is the previous chord's parameter step (or the circle chord of the window radius),
//!   corrected by that model, so a smooth curve needs two to four deviations per block;
//!   ellipses evaluate dev in closed form, chords of a plain B-spline of degree ≤ 3 inside one
//!   span or across one knot exactly from the spans' power forms (`cubic`), other NURBS from a
//!   few samples per knot span ([`Shape::fast_deviation`]). Where the fast value is not exact (those samples, and
//!   ellipse chords over a quarter turn) the chord found is checked once with the reference's
//!   32 samples, and the reference search takes over if it does not fit; an exact value is the
//!   chord's reported deviation as it is.

use crate::error::ErrorCode;
use std::cell::Cell;

use super::cut::{CROSSING_WIDTH, EPS, Vertex};
use super::shape::Shape;
use super::{polyline, reference};
use crate::error::SolverError;

/// Most deviation evaluations of one search (docs/spec/segment.md E14 caps iterations at 200).
const EVALUATION_CAP: usize = 200;
/// Relative room left under the chord error by the fast search (see `chord_end`).
const AIM_INSIDE: f64 = 1e-8;
/// Largest growth of the trial step per expansion (the model may be far off on a straight).
const MAX_GROWTH: f64 = 4.0;
/// Most Newton steps of [`newton_end`] before the bracketed search takes over.
const NEWTON_STEPS: usize = 4;
/// Newton's chord end is aimed this fraction of the chord inside the root, the middle of the
/// stop's band (√dev within 1e-9 of √C_ep, below it): its own error is second order, far less.
const NEWTON_INSIDE: f64 = 5e-10;
/// The model's step is aimed this much past (expanding) or short of (shrinking) the root, so
/// the next trial brackets it.
const AIM: f64 = 1.02;

/// The parameter of the end of a chord from `start` whose deviation is at most `chord_error`
/// (+1e-12 mm) and within the bracket width of the longest such chord; `limit.u` when the
/// whole rest fits, with the chord's reference deviation where it was checked (see
/// [`Shape::checked_deviation`]). `last_step` holds the parameter step of the previous chord (0: none) and
/// is updated; `step_guess` is the circle-chord length in mm for the first chord.
pub(crate) fn chord_end(
    shape: &Shape,
    start: &Vertex,
    chord_error: f64,
    limit: &Vertex,
    step_guess: f64,
    last_step: &Cell<f64>,
) -> Result<(f64, Option<f64>), SolverError> {
    let allowed = chord_error + EPS;
    if let Shape::Arc(arc) = shape {
        // dev = 2r·sin²(Δs/4r) = allowed, on the whole circle (sin² grows up to Δs = 2πr).
        let half_sine = (allowed / (2.0 * arc.radius)).sqrt();
        let step = if half_sine >= 1.0 { f64::INFINITY } else { 4.0 * arc.radius * half_sine.asin() };
        return Ok(((start.u + step).min(limit.u), None));
    }
    if let Shape::Polyline(line) = shape {
        let step = last_step.get();
        let predicted = if step > 0.0 { step } else { step_guess };
        if let Some((end, deviation)) = polyline::chord_end(line, start, allowed, limit, predicted) {
            last_step.set(end - start.u);
            return Ok((end, Some(deviation)));
        }
    }
    // On NURBS aim a hair (1e-8) inside the bound: the reference check of the chord found
    // refines its maximum a little differently, and must not reject a chord for that alone.
    let aim = if matches!(shape, Shape::Spline(_)) { allowed * (1.0 - AIM_INSIDE) } else { allowed };
    let root = aim.sqrt();
    // g and, where the fast deviation is exact, the deviation itself (the chord then needs no
    // check: the answer reports that value).
    let g = |u: f64| {
        let (deviation, exact) = shape.fast_deviation(start.u, u, aim);
        (deviation.sqrt() - root, exact.then_some(deviation))
    };
    // The speed at the start only where the previous chord's step does not give the first
    // trial, or the bracket's width is needed (not by Newton).
    let start_speed = std::cell::OnceCell::new();
    let speed = || *start_speed.get_or_init(|| shape.speed(start.u));
    let mut step = last_step.get();
    if step.is_nan() || step <= 0.0 {
        step = if speed() > 0.0 && step_guess > 0.0 { step_guess / speed() } else { limit.u - start.u };
    }
    match newton_end(shape, start, limit.u, root, start.u + step) {
        Ok((end, deviation)) => {
            last_step.set(end - start.u);
            return Ok((end, Some(deviation)));
        }
        Err(Some(estimate)) => step = estimate - start.u,
        Err(None) => {}
    }
    let speed = speed();
    // Bracket to 1e-12 mm, but never below a few units in the last place of u: a long curve
    // on a unit parameter range has 1e-12 mm under one ulp, where rounding of the distances
    // (1e-16 of the coordinates) is all the root finder would see.
    let ulps = 4.0 * f64::EPSILON * start.u.abs().max(limit.u.abs()).max(f64::MIN_POSITIVE);
    let tol = if speed > 0.0 { (CROSSING_WIDTH / speed).max(ulps) } else { 4.0 * ulps };
    let mut evaluations = 0;
    // Bracket: lo fits (g ≤ 0), hi does not.
    let (mut lo, mut g_lo, mut known_at_lo) = (start.u, -root, None);
    let mut trial = (start.u + step).min(limit.u);
    let (mut hi, mut g_hi) = loop {
        let (value, known) = g(trial);
        evaluations += 1;
        if value > 0.0 {
            break (trial, value);
        }
        (lo, g_lo, known_at_lo) = (trial, value, known);
        if trial >= limit.u {
            last_step.set(trial - start.u);
            return checked(shape, start, chord_error, limit, step_guess, (limit.u, known));
        }
        if evaluations >= EVALUATION_CAP {
            return Err(failure(start));
        }
        // √dev ≈ k·Δu: aim a little past where the model puts the root.
        let reach = value + root;
        let growth = if reach > 0.0 { (AIM * root / reach).clamp(1.0 + 1e-3, MAX_GROWTH) } else { MAX_GROWTH };
        trial = (start.u + (trial - start.u) * growth).min(limit.u);
    };
    // Regula falsi with the Illinois modification: superlinear, and the answer stays on the
    // side that fits.
    let mut side = 0_i8;
    let mut fit = g_lo;
    loop {
        // Done when bracketed to 1e-12 mm, or when the chord that fits is within 1e-9 of the
        // longest (its √dev within 1e-9 of √C_ep; the distances' own rounding is near 1e-10).
        if hi - lo <= tol || fit >= -1e-9 * root {
            break;
        }
        if evaluations >= EVALUATION_CAP {
            return Err(failure(start));
        }
        let mut x = lo - g_lo * (hi - lo) / (g_hi - g_lo);
        // A secant step that rounds onto an end of the bracket puts the root within rounding
        // of it: try half the bracket width inside, which ends the search when it fits (else
        // Illinois would only halve the far side's value, one bisection per step).
        if x >= hi {
            x = hi - 0.5 * tol;
        } else if x <= lo {
            x = lo + 0.5 * tol;
        }
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
            if !(x > lo && x < hi) {
                break; // adjacent floats
            }
        }
        let (value, known) = g(x);
        evaluations += 1;
        if value > 0.0 {
            (hi, g_hi) = (x, value);
            if side == 1 {
                g_lo *= 0.5;
            }
            side = 1;
        } else {
            (lo, g_lo, fit, known_at_lo) = (x, value, value, known);
            if side == -1 {
                g_hi *= 0.5;
            }
            side = -1;
        }
    }
    // Bracketed to its width without the deviation settling at C_ep: a jump in it, as at a
    // kink the curve turns at. A chord to the kink that fits ends there exactly.
    if fit < -1e-9 * root
        && let Some(kink) = shape.kink_between(lo, hi)
        && kink > lo
    {
        let (value, known) = g(kink);
        if value <= 0.0 {
            (lo, known_at_lo) = (kink, known);
        }
    }
    last_step.set(lo - start.u);
    if lo <= start.u {
        return Ok((lo, None));
    }
    checked(shape, start, chord_error, limit, step_guess, (lo, known_at_lo))
}

/// Newton steps on g(u) = √dev(u) − `root` from `trial`, while the chord's deviation and the
/// deviation's rate are exact ([`Shape::deviation_with_rate`]): from the previous chord's step
/// two deviations nearly always (one to step, one to confirm), against three or four for the
/// bracketed search. The chord end and its deviation once g is within the bracketed search's
/// stop (−1e-9·root ≤ g ≤ 0); else `Err` with the last estimate inside the limit, if any, for
/// the bracketed search to start from (a chord over more than one knot or a quarter turn, to the
/// limit, on a piece where g does not rise, other curves).
fn newton_end(shape: &Shape, start: &Vertex, limit: f64, root: f64, mut trial: f64) -> Result<(f64, f64), Option<f64>> {
    let mut estimate = None;
    for _ in 0..NEWTON_STEPS {
        if !(trial > start.u && trial < limit) {
            return Err(estimate);
        }
        estimate = Some(trial);
        let Some((deviation, rate)) = shape.deviation_with_rate(start.u, trial) else {
            return Err(estimate);
        };
        let value = deviation.sqrt() - root;
        if value <= 0.0 && value >= -1e-9 * root {
            return Ok((trial, deviation));
        }
        let Some(rate) = rate.per_u() else {
            return Err(estimate);
        };
        // g′ = dev′/(2√dev).
        let slope = rate / (2.0 * deviation.sqrt());
        if !(slope > 0.0 && slope.is_finite()) {
            return Err(estimate);
        }
        let next = trial - value / slope;
        trial = start.u + (next - start.u) * (1.0 - NEWTON_INSIDE);
    }
    Err(estimate)
}

/// The chord to `end` if its reference deviation fits; else a hump lay between the fast
/// samples (curvature changing fast inside the chord) and the reference search decides. A chord
/// whose fast deviation was exact (`known`) is taken with it.
fn checked(
    shape: &Shape,
    start: &Vertex,
    chord_error: f64,
    limit: &Vertex,
    step_guess: f64,
    (end, known): (f64, Option<f64>),
) -> Result<(f64, Option<f64>), SolverError> {
    if known.is_some() {
        return Ok((end, known));
    }
    match shape.checked_deviation(start.u, end) {
        Some(deviation) if deviation > chord_error + EPS => {
            Ok((reference::greedy_end(shape, start, chord_error, limit, step_guess)?, None))
        }
        deviation => Ok((end, deviation)),
    }
}

fn failure(start: &Vertex) -> SolverError {
    SolverError::new(
        ErrorCode::NumericFailure,
        format!("the chord search did not converge at s = {:.6} mm (E14)", start.s),
    )
    .at("curve")
}
