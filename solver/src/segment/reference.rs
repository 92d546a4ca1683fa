//! The reference numerics of docs/spec/segment.md §2.9 (revision 2, §2.9a: a reference, not a requirement):
//! `greedy_end` in quarter steps of the circle-chord guess, each chord's deviation from 32
//! samples refined around the best, the crossing bracketed to 1e-12 mm. About 400 curve
//! evaluations per block; kept as the oracle the fast search (`search`) is tested against.

use super::cut::{CROSSING_WIDTH, EPS, Vertex};
use super::numeric::last_fitting;
use super::shape::Shape;
use crate::error::ErrorCode;
use crate::error::SolverError;

/// Fixed steps before the search for the crossing starts doubling its step (long straights).
const STEPS_BEFORE_GALLOP: usize = 32;

/// `greedy_end` of docs/spec/segment.md §2.9: the parameter of the end of the longest chord from `start`
/// whose deviation stays within `chord_error` (the first crossing), searched in steps of
/// `step_guess/4` of arc length (taken in the parameter with the local speed) up to `limit`.
pub(crate) fn greedy_end(
    shape: &Shape,
    start: &Vertex,
    chord_error: f64,
    limit: &Vertex,
    step_guess: f64,
) -> Result<f64, SolverError> {
    let allowed = chord_error + EPS;
    let quarter = step_guess / 4.0;
    if limit.s - start.s <= quarter && shape.deviation_against(start.u, limit.u, allowed) <= allowed {
        return Ok(limit.u);
    }
    let mut step = quarter.max(1e-9);
    let (mut lo_u, mut lo_dev) = (start.u, 0.0);
    let mut steps = 0;
    let (hi_u, hi_dev) = loop {
        let speed = shape.speed(lo_u);
        let ahead = if speed > 0.0 { lo_u + step / speed } else { limit.u };
        let hi_u = ahead.min(limit.u);
        let dev = shape.deviation_against(start.u, hi_u, allowed);
        if dev > allowed {
            break (hi_u, dev);
        }
        if hi_u >= limit.u {
            return Ok(limit.u);
        }
        (lo_u, lo_dev) = (hi_u, dev);
        steps += 1;
        if steps >= STEPS_BEFORE_GALLOP {
            step *= 2.0;
        }
    };
    // The deviation grows about with the square of the chord: its root is nearly linear in
    // the chord's end, which the root finder solves in a few steps.
    let root = allowed.sqrt();
    let g = |u: f64| shape.deviation(start.u, u).sqrt() - root;
    // Bracket to 1e-12 mm of arc length, converted with the bracket's mean speed (the speed
    // at one end may be zero: a cusp).
    let width = shape.s_at(hi_u) - shape.s_at(lo_u);
    let speed = width / (hi_u - lo_u);
    let tol = if speed > 0.0 {
        (CROSSING_WIDTH / speed).max(f64::MIN_POSITIVE)
    } else {
        f64::EPSILON * hi_u.abs().max(f64::MIN_POSITIVE)
    };
    last_fitting(g, lo_u, lo_dev.sqrt() - root, hi_u, hi_dev.sqrt() - root, tol).ok_or_else(|| {
        SolverError::new(
            ErrorCode::NumericFailure,
            format!("the chord search did not converge at s = {:.6} mm (E14)", start.s),
        )
        .at("curve")
    })
}
