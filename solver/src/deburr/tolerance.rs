//! Target points from the tolerance TA: the adaptive bisection of docs/spec/deburr.md §3, exactly as
//! specified (K = 8 sub-samples, depth ≤ 20, strict `>`, left first), so point counts match the
//! reference cases.
//!
//! With a block time (docs/spec/segment.md) the same bisection runs with a tolerance per interval:
//! the block-time rule's chord error at the interval's own radius of curvature, never coarser
//! than TA ([`Spacing::Rule`]).

use super::profile::Profile;
use crate::error::ErrorCode;
use crate::error::SolverError;
use crate::geometry::{Vec3, distance_squared_to_segment, distance_to_segment};
use crate::machine::BlockRule;

/// How far the bisection aims beyond the rule's target chord. Halving an interval whose chord
/// is just above what it aims at leaves two halves of just over half of it: aiming at 2.1 target
/// chords keeps every half at least one target chord long even where the two halves differ by up
/// to 4 %.
pub(crate) const BISECTION_REACH: f64 = 2.1;

/// How the bisection decides that an interval is fine enough.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Spacing {
    /// The fixed tolerance TA (docs/spec/deburr.md §3).
    Fixed(f64),
    /// The block-time rule: per interval the rule's chord error at the interval's radius.
    Rule(RuleSpacing),
}

/// The block-time spacing: the interval's radius of curvature is estimated from its chord c and
/// its deviation d (the circle through both ends with sagitta d: r = c²/8d + d/2); its tolerance
/// is `reach.tolerance_for(r, TA)`, which on that circle holds exactly the chords up to
/// `BISECTION_REACH` target chords, so the halves the bisection keeps are at least one target
/// chord (margin × feed × block time) long. Where the radius is too small for that, the plain
/// rule's chord error; where it is too small even for one block, TA. Never below `floor`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RuleSpacing {
    /// The rule with its margin times [`BISECTION_REACH`].
    pub reach: BlockRule,
    /// The rule itself.
    pub plain: BlockRule,
    /// TA.
    pub tolerance: f64,
    /// Smallest tolerance used (the smallest accepted TA, or TA when smaller).
    pub floor: f64,
}

/// Why an interval was accepted with its tolerance.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Limit {
    /// The fixed TA.
    Fixed,
    /// The rule (on the reach surface, or raised to `min_chord_error`).
    Rule,
    /// TA, finer than the rule's chord error: the accuracy bound forbids longer blocks.
    Tolerance,
    /// The radius is too small for the reach: the plain rule's chord error.
    Tight,
    /// The radius is too small for one block at the feed: TA.
    Infeasible,
}

impl Spacing {
    /// The spacing for TA `tolerance`, with the block-time rule when there is one.
    pub fn new(tolerance: f64, rule: Option<BlockRule>, floor: f64) -> Self {
        match rule {
            None => Self::Fixed(tolerance),
            Some(plain) => Self::Rule(RuleSpacing {
                reach: BlockRule { margin: plain.margin * BISECTION_REACH, ..plain },
                plain,
                tolerance,
                floor: floor.min(tolerance),
            }),
        }
    }

    /// TA.
    pub fn tolerance(&self) -> f64 {
        match self {
            Self::Fixed(tolerance) => *tolerance,
            Self::Rule(rule) => rule.tolerance,
        }
    }

    /// The tolerance of an interval with `chord` and `deviation`, and why.
    pub fn limit(&self, chord: f64, deviation: f64) -> (f64, Limit) {
        let Self::Rule(rule) = self else {
            return (self.tolerance(), Limit::Fixed);
        };
        let radius = estimated_radius(chord, deviation);
        let (limit, why) = match rule.reach.chord_error(radius) {
            Ok((chord_error, _)) if chord_error > rule.tolerance => (rule.tolerance, Limit::Tolerance),
            Ok((chord_error, _)) => (chord_error, Limit::Rule),
            Err(_) => match rule.plain.chord_error(radius) {
                Ok((chord_error, _)) if chord_error > rule.tolerance => (rule.tolerance, Limit::Tolerance),
                Ok((chord_error, _)) => (chord_error, Limit::Tight),
                Err(_) => (rule.tolerance, Limit::Infeasible),
            },
        };
        (limit.max(rule.floor), why)
    }
}

/// Radius of the circle through the ends of a chord of length `chord` whose arc is `deviation`
/// away from it at the middle: c²/8d + d/2 (infinite for a straight piece).
pub(crate) fn estimated_radius(chord: f64, deviation: f64) -> f64 {
    if deviation > 0.0 { chord * chord / (8.0 * deviation) + 0.5 * deviation } else { f64::INFINITY }
}

/// Deepest bisection level (§3).
const MAX_DEPTH: u32 = 20;

/// A machining target: a profile segment and the parameter s ∈ [0, 1] on it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Target {
    pub segment: usize,
    pub parameter: f64,
}

/// The targets in machining order with their centres, from the start of the first segment round
/// to the same point again (the closing point is included). `centre` gives the ball centre of a target (local
/// frame); the polyline through the returned centres is within `tolerance` of it at the 7
/// interior sub-samples of every interval. Fails with `E_TOL` when depth 20 is not enough, with
/// `E_TOO_MANY_POINTS` past `max_points`, or with `centre`'s own error.
pub(crate) fn targets<F>(
    profile: &Profile,
    spacing: &Spacing,
    max_points: usize,
    centre: F,
) -> Result<Bisected, SolverError>
where
    F: FnMut(usize, f64) -> Result<Vec3, SolverError>,
{
    let mut bisection = Bisection { centre, spacing: *spacing, max_points, segment: 0, out: Bisected::default() };
    let first = (bisection.centre)(0, 0.0)?;
    bisection.out.targets.push(Target { segment: 0, parameter: 0.0 });
    bisection.out.centres.push(first);
    bisection.out.samples.push(None);
    bisection.out.deviations.push(0.0);
    for (index, segment) in profile.segments.iter().enumerate() {
        bisection.segment = index;
        if segment.is_axial_line() {
            let end = (bisection.centre)(index, 1.0)?;
            bisection.emit(1.0, end, None, 0.0)?;
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

/// What the bisection found: targets, their centres, and for each target the centres at the
/// 7 sub-samples j/8 of the interval that ends there (none for the start and straight sides).
#[derive(Debug, Default)]
pub(crate) struct Bisected {
    pub targets: Vec<Target>,
    pub centres: Vec<Vec3>,
    pub samples: Vec<Option<[Vec3; 7]>>,
    /// For each target, the largest distance of those sub-samples from the interval's chord
    /// (0 for the start and for the exactly straight sides).
    pub deviations: Vec<f64>,
}

struct Bisection<F> {
    centre: F,
    spacing: Spacing,
    max_points: usize,
    segment: usize,
    out: Bisected,
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

    fn emit(
        &mut self,
        parameter: f64,
        centre: Vec3,
        samples: Option<[Vec3; 7]>,
        deviation: f64,
    ) -> Result<(), SolverError> {
        if self.out.targets.len() > self.max_points {
            return Err(SolverError::new(
                ErrorCode::TooManyPoints,
                format!("the tolerance needs more than {} points; raise it", self.max_points),
            )
            .at("tolerance"));
        }
        self.out.targets.push(Target { segment: self.segment, parameter });
        self.out.centres.push(centre);
        self.out.samples.push(samples);
        self.out.deviations.push(deviation);
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
        // The farthest sub-sample by squared distance, then one square root (monotone: the same
        // bits as the largest of seven distances).
        let deviation = inner.iter().map(|p| distance_squared_to_segment(p, start, end)).fold(0.0, f64::max).sqrt();
        let limit = match self.spacing {
            Spacing::Fixed(tolerance) => tolerance,
            Spacing::Rule(_) => self.spacing.limit((end - start).norm(), deviation).0,
        };
        if deviation <= limit {
            return self.emit(b, *end, Some(*inner), deviation);
        }
        if depth >= MAX_DEPTH {
            return Err(SolverError::new(
                ErrorCode::Tol,
                format!("tolerance {} mm not reached after {MAX_DEPTH} bisections", self.spacing.tolerance()),
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

/// Samples per interval of the dense check (at j/16, j = 1..15, plus a parabolic peak refinement).
const DENSE_SAMPLES: u32 = 16;

/// The dense check that follows the bisection: measures every interval's deviation at 15 points
/// and refines the peak by a parabola through the largest sample and its neighbours; an interval
/// still above `tolerance` (a peak between the 7 sub-samples of §3) is halved until it is not.
/// Returns the refined targets and centres, the largest deviation (the summary's
/// `max_deviation`) and how each interval's tolerance came about. For the reference cases
/// nothing is refined, so their counts stay those of §3.
pub(crate) fn refine<F>(
    bisected: &Bisected,
    spacing: &Spacing,
    max_points: usize,
    mut centre: F,
) -> Result<Refined, SolverError>
where
    F: FnMut(usize, f64) -> Result<Vec3, SolverError>,
{
    let tolerance = spacing.tolerance();
    let mut limits = Vec::with_capacity(bisected.targets.len());
    let (targets, centres) = (&bisected.targets, &bisected.centres);
    let mut out_targets = Vec::with_capacity(targets.len());
    let mut out_centres = Vec::with_capacity(centres.len());
    out_targets.push(targets[0]);
    out_centres.push(centres[0]);
    let mut worst = 0.0_f64;
    for (index, (pair, ends)) in targets.windows(2).zip(centres.windows(2)).enumerate() {
        let (previous, current) = (pair[0], pair[1]);
        let start = if previous.segment == current.segment { previous.parameter } else { 0.0 };
        // To leading order an interval's deviation from its chord is a parabola, and the 7
        // sub-samples at j/8 find its peak within 4·(1/16)² ≈ 1.6 %. So only an interval sampled
        // above TA/1.016 can hide a violation; below 0.9·TA the sampled value stands (with the
        // block-time rule, 0.9 times the interval's own tolerance).
        let sampled = bisected.deviations[index + 1];
        let chord = (ends[1] - ends[0]).norm();
        let (limit, why) = spacing.limit(chord, sampled);
        if sampled <= 0.9 * limit {
            worst = worst.max(sampled);
            limits.push(IntervalLimit { why, limit, radius: estimated_radius(chord, sampled), deviation: sampled });
            out_targets.push(current);
            out_centres.push(ends[1]);
            continue;
        }
        let mut known = bisected.samples[index + 1].as_ref();
        let mut stack = vec![(start, current.parameter, ends[0], ends[1], 0_u32)];
        // Depth-first, left half first, so the refined targets come out in order.
        while let Some((a, b, start_centre, end_centre, depth)) = stack.pop() {
            let deviation =
                interval_deviation(current.segment, a, b, &start_centre, &end_centre, known.take(), &mut centre)?;
            let chord = (end_centre - start_centre).norm();
            let (limit, why) = spacing.limit(chord, deviation);
            if deviation > limit && depth < MAX_DEPTH {
                let middle = 0.5 * (a + b);
                let middle_centre = centre(current.segment, middle)?;
                stack.push((middle, b, middle_centre, end_centre, depth + 1));
                stack.push((a, middle, start_centre, middle_centre, depth + 1));
                continue;
            }
            if deviation > limit {
                return Err(SolverError::new(
                    ErrorCode::Tol,
                    format!("tolerance {tolerance} mm not reached after {MAX_DEPTH} bisections"),
                )
                .at("tolerance"));
            }
            worst = worst.max(deviation);
            limits.push(IntervalLimit { why, limit, radius: estimated_radius(chord, deviation), deviation });
            if out_targets.len() > max_points {
                return Err(SolverError::new(
                    ErrorCode::TooManyPoints,
                    format!("the tolerance needs more than {max_points} points; raise it"),
                )
                .at("tolerance"));
            }
            out_targets.push(Target { segment: current.segment, parameter: b });
            out_centres.push(end_centre);
        }
    }
    Ok(Refined { targets: out_targets, centres: out_centres, max_deviation: worst, limits })
}

/// The tolerance of one final interval and why.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct IntervalLimit {
    pub why: Limit,
    /// The tolerance it was accepted with, mm.
    pub limit: f64,
    /// Its estimated radius of curvature, mm.
    pub radius: f64,
    /// Its deviation from the ideal centre path as measured, mm.
    pub deviation: f64,
}

/// What [`refine`] returns.
#[derive(Debug)]
pub(crate) struct Refined {
    pub targets: Vec<Target>,
    pub centres: Vec<Vec3>,
    /// Largest deviation of the ideal centre path from the polyline (dense check).
    pub max_deviation: f64,
    /// One per interval (between consecutive targets).
    pub limits: Vec<IntervalLimit>,
}

/// Largest distance of the ideal centre path on `[a, b]` of `segment` from the chord between its
/// end centres: 15 samples, then a parabola through the largest and its neighbours. `known` are
/// the centres at j/8 from the bisection, which are the even sixteenths.
pub(crate) fn interval_deviation<F>(
    segment: usize,
    a: f64,
    b: f64,
    start: &Vec3,
    end: &Vec3,
    known: Option<&[Vec3; 7]>,
    centre: &mut F,
) -> Result<f64, SolverError>
where
    F: FnMut(usize, f64) -> Result<Vec3, SolverError>,
{
    let step = (b - a) / f64::from(DENSE_SAMPLES);
    let mut samples = [0.0_f64; DENSE_SAMPLES as usize + 1];
    for j in 1..DENSE_SAMPLES {
        let point = match known {
            Some(eighths) if j % 2 == 0 => eighths[(j / 2 - 1) as usize],
            _ => centre(segment, a + f64::from(j) * step)?,
        };
        samples[j as usize] = distance_to_segment(&point, start, end);
    }
    let (peak, &largest) = samples.iter().enumerate().max_by(|x, y| x.1.total_cmp(y.1)).unwrap_or((0, &0.0));
    if peak == 0 || peak == DENSE_SAMPLES as usize {
        return Ok(largest);
    }
    let (left, right) = (samples[peak - 1], samples[peak + 1]);
    let curvature = left - 2.0 * largest + right;
    if curvature >= 0.0 {
        return Ok(largest);
    }
    let offset = 0.5 * (left - right) / curvature;
    let vertex = a + (peak as f64 + offset) * step;
    let refined = distance_to_segment(&centre(segment, vertex)?, start, end);
    Ok(largest.max(refined))
}
