//! Chord error from the controller's block processing time (spec: chord.md; seed 001,
//! JP 2019-148931 A).
//!
//! A control needs a fixed time T_b to read and prepare each block. A G01 block shorter than
//! F·T_b/60000 at feed F starves it: the real feed drops and oscillates. The rule picks the
//! *smallest* chord error C_ep that keeps every chord at least that long on the local radius r,
//! C_ep = h²/(r + √(r² − h²)) with h = k_f·F·T_b/120000, and the curve is cut into greedy maximal
//! chords with it. The result is the densest polygon the control can still digest at full feed.
//!
//! * [`rule`]: C_ep for a radius (Eqs. 1–15, margins, the lower clamp): the building block for
//!   every path solver ([`BlockRule::tolerance_for`]);
//! * `shape`, `nurbs`, `arclength`: the curves (circle, arc, ellipse, polyline, NURBS) by arc
//!   length, chord deviation, radius of curvature, corners;
//! * `segment`: greedy chords, the window procedure with carry-over and progress rule, the
//!   single-value run (§2.9);
//! * [`stats`]: block figures of any polyline ([`block_stats`]);
//! * [`machine`]: controller profiles; [`mod@program`]: G-code.
//!
//! # Calling it
//!
//! * `POST /api/v1/segment`: parse a [`SegmentRequest`], resolve its `machine` name to a
//!   [`MachineProfile`] (404 if unknown), call [`solve`]`(&request, machine.as_ref())` and answer
//!   the [`SegmentAnswer`] as JSON, or [`fn@program`]`(&answer, &`[`Post`]`)` for G-code (the dialect
//!   from the query, else the machine's). Errors: `E_INPUT`, `E_DEGENERATE_CURVE`,
//!   `E_INFEASIBLE_FEED_FOR_RADIUS`, `E_TOO_MANY_BLOCKS`, `E_TOO_MANY_POINTS`,
//!   `E_NUMERIC_FAILURE`: all 422.
//! * Machines: store a validated ([`MachineProfile::validate`]) profile as JSON under a name
//!   checked by [`validate_machine_name`].
//! * Another path solver (deburr, contour) with `machine`, `feed`, `block_time_ms` and a
//!   `tolerance`: [`BlockRule::resolve`] gives the rule; [`BlockRule::tolerance_for`]`(r, tol)`
//!   the chord tolerance at a local radius (never coarser than `tol`), or for the whole path
//!   `tolerance_for(r_min, tol)` (embodiment 4); [`block_stats`] reports any polyline's blocks,
//!   shortest block, short blocks and block-limited time. To cut its own curve by the rule,
//!   sample it densely (≤ 1/10 of [`BlockRule::target_chord`] apart), send the samples as a
//!   [`Curve::Polyline`] through [`SegmentRequest::new`] and [`solve`], and map each answer
//!   point back by its `s` (arc length along the samples).
//!
//! # Choices where the spec is open (chord.md §8)
//!
//! The window radius is the 3-point circumradius by default (the patent), held within 1.1 times
//! the smallest radius of curvature inside the window (E10: near flat points and inflections the
//! 3-point circle can be orders of magnitude too large, making C_ep tiny and the blocks far too
//! short; with the guard a margin of 1.08 keeps every block at least feed × block time, and case
//! C is unchanged); `radius_estimate: minimum` is the conservative option that keeps every block
//! at least margin × feed × block time. The feed is constant along the curve. A polyline is its own true
//! curve: chords end on its edges, and points much sparser than the chords get
//! `W_SPARSE_POLYLINE`. Corners (direction change above `corner_angle_deg`, default 20°) split the
//! path; the remainders there and at the path end count as span ends, apart from `short_blocks`.
//! The accuracy bound `tolerance` wins over the rule and over `min_chord_error`. The greedy step
//! doubles after 32 fixed steps (long straights) and is taken in the curve parameter with the
//! local speed, which changes nothing on convex pieces. Window mode's default window is 5 target
//! chords. The G-code program plunges to the start at the cutting feed.

mod answer;
mod arclength;
pub mod machine;
mod numeric;
mod nurbs;
pub mod program;
pub mod request;
pub mod rule;
mod segment;
mod shape;
pub mod stats;

pub use answer::{Comparison, SegmentAnswer, SegmentWindow, WindowStatus};
pub use machine::{MachineProfile, validate_machine_name};
pub use nurbs::{MAX_CONTROL_POINTS, MAX_DEGREE};
pub use program::{Post, program};
pub use request::{Curve, CurveRule, Direction, Mode, RadiusEstimate, SegmentRequest};
pub use rule::{
    BlockRule, ChordStatus, Infeasible, RuleSettings, block_time_from_saturation, chord_length,
};
pub use stats::{BlockStats, block_stats};

use request::{Job, Plan};
use segment::{Cut, CutError, Cutter, InfeasibleAt, Status};

use crate::error::{SolverError, Warning};
use crate::geometry::Vec3;

/// Most blocks one cut may have (`E_TOO_MANY_BLOCKS`).
pub const MAX_BLOCKS: usize = 1_000_000;

/// Least increment of the G-code (4 decimals), mm; a chord error below 5 of them is
/// resolution-limited (E13).
const LEAST_INCREMENT: f64 = 1e-4;

/// Solves a segment request. `machine` is the profile the request names (resolved by the
/// server; `None` when it names none): its values are the defaults the request overrides.
///
/// # Errors
/// `E_INPUT` (bad or missing numbers, bad knots or weights, unsafe margins), `E_DEGENERATE_CURVE`
/// (no length), `E_INFEASIBLE_FEED_FOR_RADIUS` (E3: the message gives the largest feasible
/// feed), `E_TOO_MANY_BLOCKS` (over [`MAX_BLOCKS`]), `E_TOO_MANY_POINTS` (arc-length table over
/// its limit), `E_NUMERIC_FAILURE` (E14).
pub fn solve(
    request: &SegmentRequest,
    machine: Option<&MachineProfile>,
) -> Result<SegmentAnswer, SolverError> {
    let job = request.validate(machine)?;
    let rule = &job.rule;
    let limit_field = if job.tolerance.is_some() {
        "tolerance"
    } else {
        "min_chord_error"
    };
    let cutter = Cutter {
        shape: &job.shape,
        spans: &job.spans,
        max_blocks: MAX_BLOCKS,
        limit_field,
    };
    let cut = match job.plan {
        Plan::Window { length, estimate } => cutter
            .windows(rule, job.tolerance, length, estimate)
            .map_err(|error| cut_error(&job, error))?,
        Plan::Max { length, estimate } => {
            let radii = cutter.tiled_radii(length, estimate, rule.target_chord())?;
            let mut worst: Option<(f64, f64, rule::ChordStatus)> = None;
            for (s, radius) in radii {
                let (chord_error, status) = rule
                    .chord_error(radius)
                    .map_err(|infeasible| infeasible_error(&job, InfeasibleAt { s, infeasible }))?;
                if worst.is_none_or(|(largest, _, _)| chord_error > largest) {
                    worst = Some((chord_error, radius, status));
                }
            }
            let (chord_error, radius, status) = worst.unwrap_or((
                rule.min_chord_error,
                f64::INFINITY,
                rule::ChordStatus::Surface,
            ));
            single_value(&job, &cutter, chord_error, radius, status)?
        }
        Plan::Extremes { min_radius } | Plan::NormalAccel { min_radius } => {
            let (radius, s) = match min_radius {
                Some(radius) => (radius, 0.0),
                None => curve_min_radius(&job),
            };
            let value = if matches!(job.plan, Plan::NormalAccel { .. }) {
                rule.normal_accel_chord_error(radius)
            } else {
                rule.chord_error(radius)
            };
            let (chord_error, status) = value.map_err(|infeasible| {
                let error = infeasible_error(&job, InfeasibleAt { s, infeasible });
                if min_radius.is_some() {
                    error.at("min_radius")
                } else {
                    error
                }
            })?;
            single_value(&job, &cutter, chord_error, radius, status)?
        }
    };
    answer(&job, request, &cut)
}

/// The cut of a whole-curve chord error, as one window.
fn single_value(
    job: &Job,
    cutter: &Cutter<'_>,
    rule_chord_error: f64,
    radius: f64,
    surface: rule::ChordStatus,
) -> Result<Cut, SolverError> {
    let (chord_error, status) = segment::classify(rule_chord_error, surface, radius, job.tolerance);
    let mut cut = cutter.constant(chord_error, radius)?;
    let length = job.shape.length();
    cut.windows.push(segment::WindowRecord {
        s_start: 0.0,
        s_end: length,
        radius,
        rule_chord_error,
        chord_error,
        status,
        spread: 1.0,
        blocks: cut.vertices.len().saturating_sub(1),
    });
    Ok(cut)
}

/// The smallest radius of curvature along the whole curve, and the arc length where it is.
fn curve_min_radius(job: &Job) -> (f64, f64) {
    let shape = &job.shape;
    let scale = job.rule.target_chord();
    let mut best = (f64::INFINITY, 0.0);
    for &(u_start, u_end) in &job.spans {
        let pieces = shape.radius_pieces(u_start, u_end, scale);
        for pair in pieces.windows(2) {
            let (radius, u) = shape.min_radius(pair[0], pair[1], scale);
            if radius < best.0 {
                best = (radius, u);
            }
        }
    }
    (best.0, shape.s_at(best.1))
}

fn cut_error(job: &Job, error: CutError) -> SolverError {
    match error {
        CutError::Solver(error) => error,
        CutError::Infeasible(at) => infeasible_error(job, at),
    }
}

/// E3: the feed cannot be met on a radius. The message gives the largest feasible feed for the
/// whole curve (from its smallest radius, which also bounds the window estimates).
fn infeasible_error(job: &Job, at: InfeasibleAt) -> SolverError {
    let rule = &job.rule;
    let (curve_radius, curve_s) = curve_min_radius(job);
    let (radius, s) = if curve_radius < at.infeasible.radius {
        (curve_radius, curve_s)
    } else {
        (at.infeasible.radius, at.s)
    };
    let limit = rule.feed_limit(radius);
    // Rounded down, so the feed named is feasible.
    let feasible = if limit >= 100.0 {
        format!("{:.0}", limit.floor())
    } else if limit >= 0.1 {
        format!("{:.1}", (limit * 10.0).floor() / 10.0)
    } else {
        let exponent = limit.log10().floor();
        let mantissa = (limit / 10f64.powf(exponent) * 100.0).floor() / 100.0;
        format!("{mantissa:.2}e{exponent}")
    };
    SolverError::new(
        "E_INFEASIBLE_FEED_FOR_RADIUS",
        format!(
            "feed {} mm/min is too high for the radius {} mm at s = {:.3} mm: one block of {} ms at this feed \
             (margin {}) is {:.4} mm, longer than any chord of a circle of radius {} mm. The largest feasible feed \
             is {feasible} mm/min (smallest radius of the curve {} mm at s = {s:.3} mm); or use arc or spline \
             output, or a faster control mode",
            rule.feed,
            length(at.infeasible.radius),
            at.s,
            rule.block_time_ms,
            rule.margin,
            rule.target_chord(),
            length(at.infeasible.radius * rule.radius_factor),
            length(radius),
        ),
    )
    .at("feed")
}

/// A length for a message: 4 decimals, or 3 significant digits below a micrometre.
fn length(value: f64) -> String {
    if value >= 1e-3 {
        format!("{value:.4}")
    } else {
        format!("{value:.3e}")
    }
}

fn status_of(status: Status) -> WindowStatus {
    match status {
        Status::Surface => WindowStatus::Ok,
        Status::Straight => WindowStatus::Straight,
        Status::ClampedToMin => WindowStatus::ClampedToMinChordError,
        Status::LimitedByTolerance => WindowStatus::LimitedByTolerance,
    }
}

fn coordinates(point: &Vec3, dimension: usize) -> Vec<f64> {
    let all = [point.x, point.y, point.z];
    all[..dimension.min(3)].to_vec()
}

fn finite_or_none(value: f64) -> Option<f64> {
    value.is_finite().then_some(value)
}

/// Largest deviation of the curve from the chords of a cut.
fn max_deviation(job: &Job, cut: &Cut) -> f64 {
    cut.vertices
        .windows(2)
        .map(|pair| job.shape.deviation(pair[0].u, pair[1].u))
        .fold(0.0, f64::max)
}

fn answer(job: &Job, request: &SegmentRequest, cut: &Cut) -> Result<SegmentAnswer, SolverError> {
    let rule = &job.rule;
    let positions: Vec<Vec3> = cut.vertices.iter().map(|v| v.point).collect();
    let stats = stats::stats_with_ends(&positions, rule.feed, rule.block_time_ms, &cut.span_ends);
    let windows: Vec<SegmentWindow> = cut
        .windows
        .iter()
        .map(|w| SegmentWindow {
            s_start: w.s_start,
            s_end: w.s_end,
            radius: finite_or_none(w.radius),
            chord_error: w.chord_error,
            rule_chord_error: w.rule_chord_error,
            status: status_of(w.status),
            blocks: w.blocks,
        })
        .collect();
    let chord_error = cut
        .windows
        .iter()
        .map(|w| w.chord_error)
        .fold(0.0, f64::max);
    let min_window_chord_error = cut
        .windows
        .iter()
        .map(|w| w.chord_error)
        .fold(f64::INFINITY, f64::min);
    let min_radius = cut
        .windows
        .iter()
        .map(|w| w.radius)
        .fold(f64::INFINITY, f64::min);
    let tolerance_feed = job.tolerance.map(|tolerance| {
        cut.windows
            .iter()
            .map(|w| rule.feed_for_tolerance(w.radius, tolerance))
            .fold(f64::INFINITY, f64::min)
    });

    let mut warnings = job.warnings.clone();
    warnings.extend(sparse_polyline(job));
    warnings.extend(window_warnings(job, cut));
    warnings.extend(block_warnings(job, cut, &stats));

    let comparison = match job.compare_tolerance {
        Some(tolerance) => {
            let cutter = Cutter {
                shape: &job.shape,
                spans: &job.spans,
                max_blocks: MAX_BLOCKS,
                limit_field: "compare_tolerance",
            };
            let fixed = cutter.constant(tolerance, min_radius)?;
            let fixed_points: Vec<Vec3> = fixed.vertices.iter().map(|v| v.point).collect();
            Some(Comparison {
                tolerance,
                max_deviation: max_deviation(job, &fixed),
                stats: stats::stats_with_ends(
                    &fixed_points,
                    rule.feed,
                    rule.block_time_ms,
                    &fixed.span_ends,
                ),
            })
        }
        None => None,
    };

    let highest = positions
        .iter()
        .map(|p| p.z)
        .fold(f64::NEG_INFINITY, f64::max);
    let safe_z = match job.safe_z {
        Some(z) if z < highest => {
            return Err(SolverError::input(
                "safe_z",
                format!("safe_z {z} is below the curve's highest point z = {highest}"),
            ));
        }
        Some(z) => z,
        None => highest + request::DEFAULT_CLEARANCE,
    };
    let description = describe(job, request, chord_error, min_window_chord_error, &stats);
    Ok(SegmentAnswer {
        chord_error,
        min_window_chord_error: if min_window_chord_error.is_finite() {
            min_window_chord_error
        } else {
            0.0
        },
        windows,
        points: positions
            .iter()
            .map(|p| coordinates(p, job.dimension))
            .collect(),
        s: cut.vertices.iter().map(|v| v.s).collect(),
        max_deviation: max_deviation(job, cut),
        stats,
        curve_length: job.shape.length(),
        min_radius: finite_or_none(min_radius),
        feed_limit: finite_or_none(rule.feed_limit(min_radius)),
        tolerance_feed: tolerance_feed.and_then(finite_or_none),
        feed: rule.feed,
        block_time_ms: rule.block_time_ms,
        margin: rule.margin,
        min_chord_error: rule.min_chord_error,
        comparison,
        warnings,
        description,
        spindle_rpm: job.spindle_rpm,
        safe_z,
    })
}

/// A polyline is its own true curve: where its points are not much closer than the chords, its
/// corners (not the curve they sample) decide the chord lengths.
fn sparse_polyline(job: &Job) -> Option<Warning> {
    let shape::Shape::Polyline(line) = &job.shape else {
        return None;
    };
    // Edges next to a bend that is not a corner (corners split the path and are kept).
    let corner = |station: f64| {
        let index = job.spans.partition_point(|&(start, _)| start < station);
        job.spans
            .get(index)
            .is_some_and(|&(start, _)| start == station)
    };
    let mut longest = 0.0_f64;
    for (k, three) in line.vertices.windows(3).enumerate() {
        let (before, after) = (three[1] - three[0], three[2] - three[1]);
        let bends = before.cross(&after).norm() > 1e-12 * before.norm() * after.norm();
        if bends && !corner(line.stations[k + 1]) {
            longest = longest.max(before.norm()).max(after.norm());
        }
    }
    let target = job.rule.target_chord();
    (longest > 0.25 * target).then(|| {
        Warning::new(
            "W_SPARSE_POLYLINE",
            format!(
                "the polyline's points are up to {longest:.4} mm apart, more than a quarter of the {target:.4} mm \
                 chord the rule aims at: its own corners limit the chords, so blocks may come out shorter; send \
                 denser points or the curve itself (arc, ellipse, bspline)"
            ),
        )
    })
}

/// Warnings about the windows: clamps, straights, the accuracy bound, unreliable radius
/// estimates, resolution (E1, E4, E5, E10, E13).
fn window_warnings(job: &Job, cut: &Cut) -> Vec<Warning> {
    let rule = &job.rule;
    let mut warnings = Vec::new();
    let count = |status: Status| cut.windows.iter().filter(|w| w.status == status).count();
    let total = cut.windows.len();
    let clamped = count(Status::ClampedToMin);
    if clamped > 0 {
        warnings.push(Warning::new(
            "I_CLAMPED_TO_CEMIN",
            format!(
                "{clamped} of {total} windows use min_chord_error {} mm: the rule asked for less (E5)",
                rule.min_chord_error
            ),
        ));
    }
    let straight = count(Status::Straight);
    if straight > 0 {
        warnings.push(Warning::new(
            "I_STRAIGHT",
            format!("{straight} of {total} windows are straight: their chords run to the end of the straight (E1)"),
        ));
    }
    if let Some(tolerance) = job.tolerance {
        let limited: Vec<_> = cut
            .windows
            .iter()
            .filter(|w| w.status == Status::LimitedByTolerance)
            .collect();
        if !limited.is_empty() {
            let largest = limited
                .iter()
                .map(|w| w.rule_chord_error)
                .fold(0.0, f64::max);
            let feed = limited
                .iter()
                .map(|w| rule.feed_for_tolerance(w.radius, tolerance))
                .fold(f64::INFINITY, f64::min);
            let advice = if rule.min_chord_error > tolerance {
                format!(
                    "min_chord_error {} mm is above the tolerance; lower it",
                    rule.min_chord_error
                )
            } else {
                format!(
                    "at feed {:.0} mm/min the rule meets the tolerance with blocks of one block time",
                    feed.floor()
                )
            };
            warnings.push(Warning::new(
                "W_CHORD_ERROR_EXCEEDS_TOLERANCE",
                format!(
                    "in {} of {total} windows the rule's chord error (up to {largest:.6} mm) exceeds the tolerance \
                     {tolerance} mm: they are cut with the tolerance, so their blocks are shorter than feed × block \
                     time; {advice} (E4)",
                    limited.len()
                ),
            ));
        }
    }
    if let Plan::Window {
        estimate: segment::Estimate::ThreePoint,
        ..
    } = job.plan
    {
        let unreliable: Vec<_> = cut
            .windows
            .iter()
            .filter(|w| w.spread > segment::SPREAD_CAP)
            .collect();
        if let Some(worst) = unreliable
            .iter()
            .max_by(|a, b| a.spread.total_cmp(&b.spread))
        {
            warnings.push(Warning::new(
                "W_CURVATURE_ESTIMATE_UNRELIABLE",
                format!(
                    "in {} of {total} windows the curvature grows inside the window (worst at s = {:.3} mm: the \
                     3-point radius is {} the smallest radius there); their radius was held at most {} times \
                     the smallest. Use a shorter window or radius_estimate \"minimum\" (E10)",
                    unreliable.len(),
                    worst.s_start,
                    if worst.spread.is_finite() {
                        format!("{:.2} times", worst.spread)
                    } else {
                        "infinite, not".to_owned()
                    },
                    segment::SPREAD_CAP
                ),
            ));
        }
    }
    let finest = cut
        .windows
        .iter()
        .map(|w| w.chord_error)
        .filter(|&c| c > 0.0)
        .fold(f64::INFINITY, f64::min);
    if finest < 5.0 * LEAST_INCREMENT {
        warnings.push(Warning::new(
            "W_RESOLUTION_LIMITED",
            format!(
                "chord error {finest:.6} mm is below 5 increments of the G-code's {LEAST_INCREMENT} mm: rounding \
                 the points adds up to about half an increment of error (E13)"
            ),
        ));
    }
    warnings
}

/// Warnings about the blocks: short remainders and block-time violations (E8, E9, E12).
fn block_warnings(job: &Job, cut: &Cut, stats: &BlockStats) -> Vec<Warning> {
    let mut warnings = Vec::new();
    if stats.blocks == 1 && stats.short_end_blocks == 1 {
        warnings.push(Warning::new(
            "W_BLOCK_TIME_VIOLATION",
            format!(
                "the whole curve ({:.4} mm) is shorter than one block time at the feed ({:.4} mm): one block (E12)",
                stats.path_length, stats.block_length
            ),
        ));
        return warnings;
    }
    if stats.last_block_length < stats.block_length * (1.0 - 1e-9) {
        let closed = match (cut.vertices.first(), cut.vertices.last()) {
            (Some(first), Some(last)) => (first.point - last.point).norm() <= 1e-9,
            _ => false,
        };
        let corners = stats.short_end_blocks.saturating_sub(1);
        warnings.push(Warning::new(
            "W_SHORT_LAST_BLOCK",
            format!(
                "the last block is {:.4} mm, shorter than one block time at the feed ({:.4} mm){}{} (E8)",
                stats.last_block_length,
                stats.block_length,
                if closed {
                    ": the curve is closed, so on a loop that continues the control starves here"
                } else {
                    ": harmless where the control stops at the path end"
                },
                if corners > 0 {
                    format!("; {corners} more short remainders end at corners")
                } else {
                    String::new()
                }
            ),
        ));
    }
    if stats.short_blocks > 0 {
        warnings.push(Warning::new(
            "W_BLOCK_TIME_VIOLATION",
            format!(
                "{} blocks are shorter than one block time at the feed ({:.4} mm), the shortest {:.6} mm ({:.3} % of \
                 it): the control will slow down there{} (E9)",
                stats.short_blocks,
                stats.block_length,
                stats.min_block_length,
                100.0 * stats.min_block_ratio,
                if job.tolerance.is_some() {
                    "; the tolerance or a curvature change inside windows may cause it"
                } else if matches!(job.shape, shape::Shape::Polyline(_)) {
                    "; a polyline's own edges shorten the chords a little: raise margin (1.02 is plenty for dense \
                     points) or use radius_estimate \"minimum\""
                } else {
                    "; raise margin or use radius_estimate \"minimum\""
                }
            ),
        ));
    }
    warnings
}

/// Header comments for the program (chord.md §6.1).
fn describe(
    job: &Job,
    request: &SegmentRequest,
    chord_error: f64,
    min_chord_error: f64,
    stats: &BlockStats,
) -> Vec<String> {
    let rule = &job.rule;
    let mode = match job.plan {
        Plan::Window { length, estimate } => format!(
            "mode window {length:.3} mm {}",
            match estimate {
                segment::Estimate::ThreePoint => "three point",
                segment::Estimate::Minimum => "minimum radius",
            }
        ),
        Plan::Max { length, .. } => format!("mode curve max over {length:.3} mm windows"),
        Plan::Extremes { .. } => "mode curve extremes".to_owned(),
        Plan::NormalAccel { .. } => "mode curve normal accel".to_owned(),
    };
    let mut lines = vec![
        format!(
            "block time {} ms feed {} margin {} min chord error {}",
            rule.block_time_ms, rule.feed, rule.margin, rule.min_chord_error
        ),
        mode,
        format!("chord error {min_chord_error:.6} to {chord_error:.6} mm"),
        format!(
            "blocks {} shortest {:.4} mm short {} est time {:.3} s",
            stats.blocks, stats.min_block_length, stats.short_blocks, stats.estimated_time_s
        ),
    ];
    if let Some(name) = &request.machine {
        lines.insert(0, format!("machine {name}"));
    }
    lines
}
