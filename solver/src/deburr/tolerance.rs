//! Target points from the tolerance TA: the adaptive bisection of deburr.md §3, exactly as
//! specified (K = 8 sub-samples, depth ≤ 20, strict `>`, left first), so point counts match the
//! reference cases.

use super::profile::Profile;
use crate::error::SolverError;
use crate::geometry::{Vec3, distance_to_segment};

/// Deepest bisection level (§3).
const MAX_DEPTH: u32 = 20;

/// A machining target: a profile segment and the parameter s ∈ [0, 1] on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Target {
    pub segment: usize,
    pub parameter: f64,
}

/// The targets in machining order, from the start of the first segment round to the same point
/// again (the closing point is included). `centre` gives the ball centre of a target (local
/// frame); the polyline through the returned centres is within `tolerance` of it at the 7
/// interior sub-samples of every interval. Fails with `E_TOL` when depth 20 is not enough, with
/// `E_TOO_MANY_POINTS` past `max_points`, or with `centre`'s own error.
pub(crate) fn targets<F>(
    profile: &Profile,
    tolerance: f64,
    max_points: usize,
    centre: F,
) -> Result<Vec<Target>, SolverError>
where
    F: FnMut(usize, f64) -> Result<Vec3, SolverError>,
{
    let mut bisection = Bisection { centre, tolerance, max_points, segment: 0, out: Vec::new() };
    bisection.out.push(Target { segment: 0, parameter: 0.0 });
    for (index, segment) in profile.segments.iter().enumerate() {
        bisection.segment = index;
        if segment.is_axial_line() {
            bisection.emit(1.0)?;
            continue;
        }
        let count = segment.initial_intervals();
        let mut start_centre = (bisection.centre)(index, 0.0)?;
        for k in 0..count {
            let (a, b) = (f64::from(k) / f64::from(count), f64::from(k + 1) / f64::from(count));
            let end_centre = (bisection.centre)(index, b)?;
            let inner = bisection.samples(a, b, [1, 2, 3, 4, 5, 6, 7], 8.0)?;
            bisection.split(a, b, &start_centre, &end_centre, &inner, 0)?;
            start_centre = end_centre;
        }
    }
    Ok(bisection.out)
}

struct Bisection<F> {
    centre: F,
    tolerance: f64,
    max_points: usize,
    segment: usize,
    out: Vec<Target>,
}

impl<F> Bisection<F>
where
    F: FnMut(usize, f64) -> Result<Vec3, SolverError>,
{
    fn samples<const N: usize>(
        &mut self,
        a: f64,
        b: f64,
        steps: [u32; N],
        parts: f64,
    ) -> Result<[Vec3; N], SolverError> {
        let mut out = [Vec3::zeros(); N];
        for (slot, step) in out.iter_mut().zip(steps) {
            *slot = (self.centre)(self.segment, a + f64::from(step) / parts * (b - a))?;
        }
        Ok(out)
    }

    fn emit(&mut self, parameter: f64) -> Result<(), SolverError> {
        if self.out.len() > self.max_points {
            return Err(SolverError::new(
                "E_TOO_MANY_POINTS",
                format!("the tolerance needs more than {} points; raise it", self.max_points),
            )
            .at("tolerance"));
        }
        self.out.push(Target { segment: self.segment, parameter });
        Ok(())
    }

    /// `rec(a, b, depth)` of §3. `inner` holds the centres at a + j/8·(b − a), j = 1..7; the
    /// halves reuse the even ones, so each split evaluates only 8 new centres.
    fn split(
        &mut self,
        a: f64,
        b: f64,
        start: &Vec3,
        end: &Vec3,
        inner: &[Vec3; 7],
        depth: u32,
    ) -> Result<(), SolverError> {
        let exceeds = inner.iter().any(|p| distance_to_segment(p, start, end) > self.tolerance);
        if !exceeds {
            return self.emit(b);
        }
        if depth >= MAX_DEPTH {
            return Err(SolverError::new(
                "E_TOL",
                format!("tolerance {} not reached after {MAX_DEPTH} bisections", self.tolerance),
            )
            .at("tolerance"));
        }
        let middle = 0.5 * (a + b);
        let left_new = self.samples(a, b, [1, 3, 5, 7], 16.0)?;
        let right_new = self.samples(a, b, [9, 11, 13, 15], 16.0)?;
        let left = [left_new[0], inner[0], left_new[1], inner[1], left_new[2], inner[2], left_new[3]];
        let right = [right_new[0], inner[4], right_new[1], inner[5], right_new[2], inner[6], right_new[3]];
        self.split(a, middle, start, &inner[3], &left, depth + 1)?;
        self.split(middle, b, &inner[3], end, &right, depth + 1)
    }
}

/// Largest distance of the ideal centre path from the polyline through the targets' centres,
/// sampled at `samples` interior points of every interval (the summary's `max_deviation`).
pub(crate) fn max_deviation<F>(
    targets: &[Target],
    centres: &[Vec3],
    samples: u32,
    mut centre: F,
) -> Result<f64, SolverError>
where
    F: FnMut(usize, f64) -> Result<Vec3, SolverError>,
{
    let mut worst = 0.0_f64;
    for (pair, ends) in targets.windows(2).zip(centres.windows(2)) {
        let (previous, current) = (pair[0], pair[1]);
        let start = if previous.segment == current.segment { previous.parameter } else { 0.0 };
        for j in 1..=samples {
            let s = start + f64::from(j) / f64::from(samples + 1) * (current.parameter - start);
            let point = centre(current.segment, s)?;
            worst = worst.max(distance_to_segment(&point, &ends[0], &ends[1]));
        }
    }
    Ok(worst)
}
