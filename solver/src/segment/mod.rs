//! Chord error from the controller's block processing time (spec: docs/spec/segment.md; patent 001,
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
//! * `shape`, `nurbs`, `cubic`, `arclength`, `radius`: the curves (circle, arc, ellipse, polyline, NURBS) by arc
//!   length, chord deviation, radius of curvature, corners; `polynomial`: real roots of low-degree
//!   polynomials (the exact radius turns of plain cubic spans);
//! * `cut`: greedy chords, the window procedure with carry-over and progress rule, the
//!   single-value run (§2.9); `search`: the fast chord search (§2.9a; `polyline` for polylines), `reference`: the §2.9
//!   numerics it is tested against ([`solve_reference`]); `guarantee`: mode `guarantee` (§2.9a);
//! * [`stats`]: block figures of any polyline ([`block_stats`]); `report`: warnings (§4); `wire`:
//!   the answer's JSON, written as serde writes it but faster;
//! * [`machine`]: controller profiles; [`mod@program`]: G-code.
//!
//! # Calling it
//!
//! * `POST /api/v1/segment`: parse a [`SegmentRequest`], resolve its `machine` name to a
//!   [`MachineProfile`] (404 if unknown), call [`solve`]`(&request, machine.as_ref())` and answer
//!   the [`SegmentSolution`] as JSON, or [`fn@program`]`(&answer, &`[`Post`]`)` for G-code (the dialect
//!   from the query, else the machine's; the tool call from the request's optional `tool`, which the
//!   solver itself ignores). Errors: `E_INPUT`, `E_DEGENERATE_CURVE`,
//!   `E_INFEASIBLE_FEED_FOR_RADIUS`, `E_TOO_MANY_BLOCKS`, `E_TOO_MANY_POINTS`,
//!   `E_NUMERIC_FAILURE`: all 422.
//! * Machines: store a validated ([`MachineProfile::validate`]) profile as JSON under a name
//!   checked by [`validate_machine_name`].
//! * Another path solver (deburr does, contour) with `machine`, `feed`, `block_time_ms` and a
//!   `tolerance`: [`BlockRule::resolve`] gives the rule; [`BlockRule::tolerance_for`]`(r, tol)`
//!   the chord tolerance at a local radius (never coarser than `tol`), or for the whole path
//!   `tolerance_for(r_min, tol)` (embodiment 4); [`block_stats`] reports any polyline's blocks,
//!   shortest block, short blocks and block-limited time. To cut its own curve by the rule,
//!   sample it densely (≤ 1/10 of [`BlockRule::target_chord`] apart), send the samples as a
//!   [`Curve::Polyline`] (or an arc as [`Curve::Arc`]) through [`SegmentRequest::guarantee`]
//!   (mode `guarantee`, docs/spec/segment.md §2.9a: no block but a final remainder shorter than margin ×
//!   feed × block time) and [`solve`], and map each answer point back by its `s` (arc length
//!   along the samples).
//!
//! [`rule`]: crate::machine::rule
//! [`stats`]: crate::machine::stats
//! [`machine`]: crate::machine
//! [`block_stats`]: crate::machine::block_stats
//! [`BlockRule::resolve`]: crate::machine::BlockRule::resolve
//! [`BlockRule::target_chord`]: crate::machine::BlockRule::target_chord
//! [`BlockRule::tolerance_for`]: crate::machine::BlockRule::tolerance_for
//! [`validate_machine_name`]: crate::machine::validate_machine_name
//! [`Post`]: crate::gcode::Post
//!
//! # Choices where the spec is open (docs/spec/segment.md §8)
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
mod capability;
mod cubic;
mod cut;
mod guarantee;
mod job;
mod numeric;
mod nurbs;
mod polyline;
mod polynomial;
pub mod program;
mod radius;
mod reference;
mod report;
pub mod request;
pub mod resegment;
mod search;
mod shape;
mod units;
mod wire;

pub use answer::{CommandPoint, Comparison, SegmentSolution, SegmentWindow, WindowStatus};
pub use capability::{SegmentAnswer, SegmentCapability};
pub use nurbs::{MAX_CONTROL_POINTS, MAX_DEGREE};
pub(crate) use program::cycle_time;
pub use program::program;
pub use request::{Curve, CurveRule, Direction, RadiusEstimate, SegmentRequest};
pub use resegment::{ResegmentAnswer, ResegmentCapability, ResegmentRequest};

use crate::capability::Control;
use crate::error::ErrorCode;
use crate::machine::{ChordStatus, MachineProfile};
use crate::validate::Measure;
use cut::{Cut, CutError, Cutter, InfeasibleAt, Numerics, Status};
use job::{Job, Plan};

use crate::error::SolverError;

/// Most blocks one cut may have (`E_TOO_MANY_BLOCKS`).
pub const MAX_BLOCKS: usize = 1_000_000;

/// Solves a segment request. `machine` is the profile the request names (resolved by the
/// server; `None` when it names none): its values are the defaults the request overrides.
///
/// # Errors
/// `E_INPUT` (bad or missing numbers, bad knots or weights, unsafe margins), `E_DEGENERATE_CURVE`
/// (no length), `E_INFEASIBLE_FEED_FOR_RADIUS` (E3: the message gives the largest feasible
/// feed), `E_TOO_MANY_BLOCKS` (over [`MAX_BLOCKS`]), `E_TOO_MANY_POINTS` (arc-length table over
/// its limit), `E_NUMERIC_FAILURE` (E14).
pub fn solve(request: &SegmentRequest, machine: Option<&MachineProfile>) -> Result<SegmentSolution, SolverError> {
    solve_by(request, machine, Numerics::Fast, Control::default(), None)
}

/// [`solve`] that stops with `E_CANCELLED` once `control`'s cancel flag is set (checked per block).
///
/// # Errors
/// As [`solve`], and `E_CANCELLED`.
pub fn solve_controlled(
    request: &SegmentRequest,
    machine: Option<&MachineProfile>,
    control: Control<'_>,
) -> Result<SegmentSolution, SolverError> {
    solve_by(request, machine, Numerics::Fast, control, None)
}

/// As [`solve_controlled`] under `run`: its control, and its answer budget charged for the
/// command points a block at a time as they are cut (in memory and at most as delivered for
/// `run.purpose`), so a curve whose answer would not fit is refused after a block past the
/// budget instead of after the whole cut.
///
/// # Errors
/// As [`solve_controlled`]; `E_TOO_LARGE_ANSWER` over the budget.
pub fn solve_run(
    request: &SegmentRequest,
    machine: Option<&MachineProfile>,
    run: &crate::capability::Run<'_>,
) -> Result<SegmentSolution, SolverError> {
    let charge = run.budget.map(|budget| cut::PointCharge { budget, point_bytes: answer::point_bound(run.purpose) });
    match request.curve.from_upload(run.upload)? {
        Some(curve) => {
            let request = SegmentRequest { curve, ..request.clone() };
            solve_by(&request, machine, Numerics::Fast, run.control, charge)
        }
        None => solve_by(request, machine, Numerics::Fast, run.control, charge),
    }
}

/// [`solve`] by the reference numerics of docs/spec/segment.md §2.9 (about 400 curve evaluations per
/// block): the oracle the fast search is tested against (§2.9a), not for production.
///
/// # Errors
/// As [`solve`].
#[doc(hidden)]
pub fn solve_reference(
    request: &SegmentRequest,
    machine: Option<&MachineProfile>,
) -> Result<SegmentSolution, SolverError> {
    solve_by(request, machine, Numerics::Reference, Control::default(), None)
}

fn solve_by(
    request: &SegmentRequest,
    machine: Option<&MachineProfile>,
    numerics: Numerics,
    control: Control<'_>,
    charge: Option<cut::PointCharge<'_>>,
) -> Result<SegmentSolution, SolverError> {
    let job = request.validate(machine)?;
    let rule = &job.rule;
    let limit_field = if job.tolerance.is_some() { "tolerance" } else { "min_chord_error" };
    let mut cutter = Cutter::new(&job.shape, &job.spans, MAX_BLOCKS, limit_field, numerics, control);
    cutter.charge = charge;
    let cut = match job.plan {
        Plan::Window { length, estimate } => {
            cutter.windows(rule, job.tolerance, length, estimate).map_err(|error| cut_error(&job, error))?
        }
        Plan::Guarantee => cutter.guarantee(rule, job.tolerance).map_err(|error| cut_error(&job, error))?,
        Plan::Max { length, estimate } => {
            let radii = cutter.tiled_radii(length, estimate, rule.target_chord())?;
            let mut worst: Option<(f64, f64, ChordStatus)> = None;
            for (s, radius) in radii {
                let (chord_error, status) = rule
                    .chord_error(radius)
                    .map_err(|infeasible| infeasible_error(&job, InfeasibleAt { s, infeasible }))?;
                if worst.is_none_or(|(largest, _, _)| chord_error > largest) {
                    worst = Some((chord_error, radius, status));
                }
            }
            let (chord_error, radius, status) =
                worst.unwrap_or((rule.min_chord_error, f64::INFINITY, ChordStatus::Surface));
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
                if min_radius.is_some() { error.at("min_radius") } else { error }
            })?;
            single_value(&job, &cutter, chord_error, radius, status)?
        }
    };
    answer(&job, request, &cutter, &cut)
}

/// The cut of a whole-curve chord error, as one window.
fn single_value(
    job: &Job,
    cutter: &Cutter<'_>,
    rule_chord_error: f64,
    radius: f64,
    surface: ChordStatus,
) -> Result<Cut, SolverError> {
    let (chord_error, status) = cut::classify(rule_chord_error, surface, radius, job.tolerance);
    let mut cut = cutter.constant(chord_error, radius)?;
    let length = job.shape.length();
    cut.windows.push(cut::WindowRecord {
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
    let (radius, s) =
        if curve_radius < at.infeasible.radius { (curve_radius, curve_s) } else { (at.infeasible.radius, at.s) };
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
        ErrorCode::InfeasibleFeedForRadius,
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
    if value >= 1e-3 { format!("{value:.4}") } else { format!("{value:.3e}") }
}

fn status_of(status: Status) -> WindowStatus {
    match status {
        Status::Surface => WindowStatus::Ok,
        Status::Straight => WindowStatus::Straight,
        Status::ClampedToMin => WindowStatus::ClampedToMinChordError,
        Status::LimitedByTolerance => WindowStatus::LimitedByTolerance,
    }
}

fn finite_or_none(value: f64) -> Option<f64> {
    value.is_finite().then_some(value)
}

/// Largest deviation of the curve from the chords of a cut.
fn max_deviation(cutter: &Cutter<'_>, cut: &Cut) -> f64 {
    cut.vertices
        .windows(2)
        .zip(&cut.deviations)
        .map(|(pair, measured)| measured.unwrap_or_else(|| cutter.deviation(pair[0].u, pair[1].u)))
        .fold(0.0, f64::max)
}

fn answer(job: &Job, request: &SegmentRequest, cutter: &Cutter<'_>, cut: &Cut) -> Result<SegmentSolution, SolverError> {
    let rule = &job.rule;
    // Read from the cut's vertices as they are: a copy of 100 000 positions is megabytes of
    // fresh pages for the allocator to fault in.
    let stats = crate::machine::stats::stats_along(
        &cut.vertices,
        |vertex| &vertex.point,
        rule.feed,
        rule.block_time_ms,
        &cut.span_ends,
    );
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
    if let Some(charge) = cutter.charge {
        charge.budget.charge(windows.len() as u64 * answer::WINDOW_BYTES, 1, 1)?;
    }
    let chord_error = cut.windows.iter().map(|w| w.chord_error).fold(0.0, f64::max);
    let min_window_chord_error = cut.windows.iter().map(|w| w.chord_error).fold(f64::INFINITY, f64::min);
    let min_radius = cut.windows.iter().map(|w| w.radius).fold(f64::INFINITY, f64::min);
    let tolerance_feed = job.tolerance.map(|tolerance| {
        cut.windows.iter().map(|w| rule.feed_for_tolerance(w.radius, tolerance)).fold(f64::INFINITY, f64::min)
    });

    let mut warnings = job.warnings.clone();
    warnings.extend(report::sparse_polyline(job));
    warnings.extend(report::window_warnings(job, cut));
    warnings.extend(report::block_warnings(job, cut, &stats));

    let comparison = match job.compare_tolerance {
        Some(tolerance) => {
            let mut fixed_cutter =
                Cutter::new(&job.shape, &job.spans, MAX_BLOCKS, "compare_tolerance", cutter.numerics, cutter.control);
            // The comparison's cut is held beside the answer's while it is measured.
            fixed_cutter.charge =
                cutter.charge.map(|charge| cut::PointCharge { point_bytes: answer::POINT_MEMORY_BYTES, ..charge });
            let fixed = fixed_cutter.constant(tolerance, min_radius)?;
            Some(Comparison {
                tolerance,
                max_deviation: max_deviation(&fixed_cutter, &fixed),
                stats: crate::machine::stats::stats_along(
                    &fixed.vertices,
                    |vertex| &vertex.point,
                    rule.feed,
                    rule.block_time_ms,
                    &fixed.span_ends,
                ),
            })
        }
        None => None,
    };

    let highest = cut.vertices.iter().map(|v| v.point.z).fold(f64::NEG_INFINITY, f64::max);
    let safe_z = match job.safe_z {
        Some(z) if z < highest => {
            return Err(SolverError::input(
                "safe_z",
                format!(
                    "safe_z {} is below the curve's highest point z = {}",
                    Measure::Length.quote(z),
                    Measure::Length.quote(highest)
                ),
            ));
        }
        Some(z) => z,
        None => highest + request::DEFAULT_CLEARANCE,
    };
    let description = report::describe(job, request, chord_error, min_window_chord_error, &stats);
    Ok(SegmentSolution {
        chord_error,
        min_window_chord_error: if min_window_chord_error.is_finite() { min_window_chord_error } else { 0.0 },
        windows,
        points: cut.vertices.iter().map(|v| CommandPoint::new(&v.point, job.dimension)).collect(),
        s: cut.vertices.iter().map(|v| v.s).collect(),
        max_deviation: max_deviation(cutter, cut),
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
        circle: match &job.shape {
            shape::Shape::Arc(arc) => Some(arc.clone()),
            _ => None,
        },
    })
}
