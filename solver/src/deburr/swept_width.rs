//! The chamfer width the emitted moves really cut (docs/spec/deburr.md §2.9, measured "on the
//! swept-sphere characteristic circle"): the ball swept along the straight moves between the
//! centres removes everything within D of the centre polyline, so in the ridge's normal plane VP
//! at a ridge point the band edges are where the true cylinder surface and the true hole wall,
//! cut by VP, come to distance D from the polyline. Measured at targets and in the middle of the
//! intervals between them, where the moves stray furthest from the ideal centre path.

use crate::error::ErrorCode;
use std::cell::Cell;

use super::centre::{CircleStart, Construction, RidgeCentre};
use super::profile::Profile;
use super::tolerance::{IntervalLimit, Refined, Target, interval_deviation};
use crate::error::SolverError;
use crate::geometry::{Segment, Vec3, root_near};

/// Most intervals of a loop at which the swept width is measured (at its end target and its
/// middle); denser loops are measured at intervals spread evenly.
const MAX_MEASURED_INTERVALS: usize = 1024;

/// Most rounds of [`refine_for_width`]: each halves the offending intervals, cutting their sag
/// to a quarter.
const MAX_WIDTH_ROUNDS: usize = 4;

/// How much a straight move's sag can change the swept width, at most, per mm of sag: the band
/// edges move by the sag over the sine of the angle at which the ball meets a surface, on both
/// edges. Intervals whose sag times this stays inside the band are not measured.
const SAG_TO_WIDTH: f64 = 4.0;

/// The TA placement measured on the swept result: a straight move cuts the corner of
/// the ideal centre path by up to TA, which narrows the swept chamfer between targets. Intervals
/// whose middle is swept more than `band` off W while their end targets are not are halved
/// (at most [`MAX_WIDTH_ROUNDS`] times), so the moves keep W ± band wherever the ideal path does.
/// Returns how many targets were added.
///
/// # Errors
/// `E_TOO_MANY_POINTS` past `max_points`, or `centre`'s own error.
pub(crate) fn refine_for_width<F>(
    construction: &Construction,
    profile: &Profile,
    refined: &mut Refined,
    band: f64,
    max_points: usize,
    mut centre: F,
) -> Result<usize, SolverError>
where
    F: FnMut(usize, f64) -> Result<Vec3, SolverError>,
{
    let width = 2.0 * construction.half_width;
    let mut added = 0;
    for _ in 0..MAX_WIDTH_ROUNDS {
        // Whether the swept width at `parameter` of `at` is off by more than the band; `near` is
        // a vertex near it.
        let off = |at: usize, parameter: f64, polyline: &Polyline<'_>, near: usize| {
            let point = profile.segments[at].point(profile.radius, parameter);
            width_at(construction, profile, &construction.tangent(&point), polyline, near)
                .is_some_and(|swept| (swept - width).abs() > band)
        };
        let mut splits = Vec::new();
        {
            let polyline = Polyline::new(&refined.centres);
            for index in 0..refined.targets.len() - 1 {
                if refined.limits[index].deviation * SAG_TO_WIDTH <= band {
                    continue;
                }
                let (previous, current) = (refined.targets[index], refined.targets[index + 1]);
                let start = if previous.segment == current.segment { previous.parameter } else { 0.0 };
                let (at, middle) = (current.segment, 0.5 * (start + current.parameter));
                if off(at, middle, &polyline, index)
                    && !off(at, start, &polyline, index)
                    && !off(at, current.parameter, &polyline, index + 1)
                {
                    splits.push((index, start, middle));
                }
            }
        }
        if splits.is_empty() {
            break;
        }
        if refined.targets.len() + splits.len() > max_points {
            return Err(SolverError::new(
                ErrorCode::TooManyPoints,
                format!("the chamfer width needs more than {max_points} points; raise the tolerance"),
            )
            .at("tolerance"));
        }
        // Insert from the end so the earlier indices stay valid.
        for &(index, start, middle) in splits.iter().rev() {
            let current = refined.targets[index + 1];
            let (from, to) = (refined.centres[index], refined.centres[index + 1]);
            let halfway = centre(current.segment, middle)?;
            let left = interval_deviation(current.segment, start, middle, &from, &halfway, None, &mut centre)?;
            let right =
                interval_deviation(current.segment, middle, current.parameter, &halfway, &to, None, &mut centre)?;
            let limit = refined.limits[index];
            refined.targets.insert(index + 1, Target { segment: current.segment, parameter: middle });
            refined.centres.insert(index + 1, halfway);
            refined.limits[index] = IntervalLimit { deviation: left, ..limit };
            refined.limits.insert(index + 1, IntervalLimit { deviation: right, ..limit });
        }
        added += splits.len();
        refined.max_deviation = refined.limits.iter().map(|l| l.deviation).fold(0.0, f64::max);
    }
    Ok(added)
}

/// The range of the swept width and where it is furthest from W.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct SweptWidths {
    pub min: f64,
    pub max: f64,
    /// The measurement furthest from W: segment, parameter and width.
    pub worst: Option<(usize, f64, f64)>,
}

/// The closed centre polyline (local frame; the last centre repeats the first).
struct Polyline<'a> {
    centres: &'a [Vec3],
    /// Move k, from centre k to centre k + 1, with its vector and squared length computed once:
    /// every evaluation of the swept width's root searches measures four moves.
    moves: Vec<Segment>,
}

impl<'a> Polyline<'a> {
    fn new(centres: &'a [Vec3]) -> Self {
        let moves = centres.windows(2).map(|pair| Segment::new(pair[0], pair[1])).collect();
        Self { centres, moves }
    }

    /// Distance from `point` to the polyline near vertex `hint`, which moves to the nearest vertex.
    /// Only the local part of the loop counts: a far part within reach is E_FAR_GOUGE's business.
    fn distance(&self, point: &Vec3, hint: &Cell<usize>) -> f64 {
        let count = self.centres.len() - 1;
        // Indices wrap by a comparison, not `%`: this runs for every evaluation of the swept
        // width's root searches, and an integer division per vertex showed in the profile.
        let next = |k: usize| if k + 1 == count { 0 } else { k + 1 };
        let previous = |k: usize| if k == 0 { count - 1 } else { k - 1 };
        let squared = |k: usize| (self.centres[k] - point).norm_squared();
        let mut index = hint.get() % count;
        let mut here = squared(index);
        loop {
            let ahead = squared(next(index));
            if ahead >= here {
                break;
            }
            (index, here) = (next(index), ahead);
        }
        loop {
            let behind = squared(previous(index));
            if behind >= here {
                break;
            }
            (index, here) = (previous(index), behind);
        }
        hint.set(index);
        // Two moves either side of the nearest vertex: a long straight move next to short ones
        // can hold the nearest point while its far end is not the nearest vertex. The nearest by
        // squared distance, then one square root: the root is monotone, so the same bits.
        let mut from = previous(previous(index));
        let mut nearest = f64::INFINITY;
        for _ in 0..4 {
            nearest = nearest.min(self.moves[from].distance_squared(point));
            from = next(from);
        }
        nearest.sqrt()
    }
}

/// The swept width at one ridge point: where the true section curves in VP leave the cut
/// volume. `None` when a band edge cannot be found (a section circle misses its surface).
fn width_at(
    construction: &Construction,
    profile: &Profile,
    ridge: &RidgeCentre,
    polyline: &Polyline<'_>,
    hint: usize,
) -> Option<f64> {
    width_from(construction, profile, ridge, polyline, hint, &mut [None; 2])
}

/// [`width_at`] starting the leg searches from `legs` where given (a neighbouring measurement's
/// legs, which saves secant steps), and leaving the legs found there.
fn width_from(
    construction: &Construction,
    profile: &Profile,
    ridge: &RidgeCentre,
    polyline: &Polyline<'_>,
    hint: usize,
    legs: &mut [Option<f64>; 2],
) -> Option<f64> {
    let plane = ridge.plane_basis();
    let target = ridge.target;
    let (tangent_g1, tangent_g2) = ridge.band_edges(construction.half_width);
    let ball = construction.ball_radius;
    let mut edges = [Vec3::zeros(); 2];
    for ((edge, known), (near, on_wall)) in
        edges.iter_mut().zip(legs.iter_mut()).zip([(tangent_g1 - target, false), (tangent_g2 - target, true)])
    {
        let hint = Cell::new(hint);
        // The leg last evaluated and its point: the secant search ends on an evaluation at the
        // leg it returns, so the band edge there is the point already found, not a new
        // intersection solve (the same computation, so the same bits).
        let last: Cell<Option<(f64, Option<Vec3>)>> = Cell::new(None);
        // The point of the true section curve at `leg` from P, and how far outside the cut it is.
        let start = CircleStart::new(plane, &near);
        let on_curve = |leg: f64| construction.circle_meets_surface_from(profile, plane, &target, leg, &start, on_wall);
        let outside = |leg: f64| {
            let point = on_curve(leg);
            last.set(Some((leg, point)));
            point.map_or(f64::NAN, |q| polyline.distance(&q, &hint) - ball)
        };
        let tangent_leg = near.norm();
        let first_leg = known.unwrap_or(tangent_leg);
        let leg = secant_root(&outside, first_leg)
            .or_else(|| root_near(outside, tangent_leg, 0.05 * tangent_leg, 0.95 * tangent_leg, 1e-14 * tangent_leg));
        *known = leg;
        let leg = leg?;
        *edge = match last.get() {
            Some((evaluated, point)) if evaluated.to_bits() == leg.to_bits() => point?,
            _ => on_curve(leg)?,
        };
    }
    Some((edges[0] - edges[1]).norm())
}

/// Root of `f` by secant steps from `start` and 1.01·start; `None` unless it converges.
fn secant_root(f: &impl Fn(f64) -> f64, start: f64) -> Option<f64> {
    let (mut a, mut b) = (start, start * 1.01);
    let (mut fa, mut fb) = (f(a), f(b));
    for _ in 0..40 {
        if !(fa.is_finite() && fb.is_finite()) || fa == fb {
            return None;
        }
        let next = b - fb * (b - a) / (fb - fa);
        if !(next > 0.0 && next < 4.0 * start) {
            return None;
        }
        (a, fa) = (b, fb);
        b = next;
        fb = f(b);
        if fb.abs() < 1e-13 * start.max(1.0) || (b - a).abs() < 1e-15 * start {
            return Some(b);
        }
    }
    None
}

/// The swept width of the loop through `centres` (in machining order, counter-clockwise, local
/// frame, closed) at the targets and interval middles, and the place furthest from W.
pub(crate) fn swept_widths(
    construction: &Construction,
    profile: &Profile,
    targets: &[Target],
    centres: &[Vec3],
) -> SweptWidths {
    let polyline = Polyline::new(centres);
    let width = 2.0 * construction.half_width;
    let intervals = targets.len() - 1;
    let stride = intervals.div_ceil(MAX_MEASURED_INTERVALS).max(1);
    let mut out = SweptWidths { min: f64::INFINITY, max: f64::NEG_INFINITY, worst: None };
    let mut legs = [None; 2];
    for index in (0..intervals).step_by(stride) {
        let (previous, current) = (targets[index], targets[index + 1]);
        let start = if previous.segment == current.segment { previous.parameter } else { 0.0 };
        for parameter in [0.5 * (start + current.parameter), current.parameter] {
            let point = profile.segments[current.segment].point(profile.radius, parameter);
            let ridge = construction.tangent(&point);
            let Some(swept) = width_from(construction, profile, &ridge, &polyline, index + 1, &mut legs) else {
                continue;
            };
            out.min = out.min.min(swept);
            out.max = out.max.max(swept);
            if out.worst.is_none_or(|(_, _, w)| (swept - width).abs() > (w - width).abs()) {
                out.worst = Some((current.segment, parameter, swept));
            }
        }
    }
    if !out.min.is_finite() {
        (out.min, out.max) = (width, width);
    }
    out
}
