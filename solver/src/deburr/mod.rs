//! Cross-hole deburring with a ball end mill (spec: docs/spec/deburr.md; patent 000).
//!
//! A through hole meets the outer or inner cylindrical surface of a tube (or the bore of a block)
//! in a closed ridge. For points on that ridge this module computes the ball centre that cuts a
//! chamfer band of width W = √2·Q, chooses the points so the centre polyline stays within the
//! tolerance TA of the ideal centre path, checks the limits of §4, and builds a safe approach and
//! retract for the G-code program.
//!
//! * [`request`]: the request and its validation (§1.4);
//! * `frame`: local frame and its map to the machine (§1.3);
//! * `profile`: hole cross-sections (§2.8);
//! * `centre`: the ball-centre construction (§2.5, §2.7) and the single-section exact one (the
//!   `exact` path's start and the diagnostics);
//! * `envelope`: the `exact` centre path, whose swept envelope meets the true surfaces W apart;
//! * `swept_width`: the chamfer width the emitted moves really cut;
//! * `tolerance`: the target points from TA (§3), or with a block time from the block-time rule
//!   per interval, never coarser than TA (docs/spec/segment.md);
//! * `checks`: validity limits and warnings (§4);
//! * [`mod@program`]: lead moves and G-code (§6.3);
//! * `parts`: a several-loop job's loops split into ranges that several workers solve at once.

mod answer;
mod capability;
mod centre;
mod checks;
mod diagnostics;
mod envelope;
mod frame;
mod job;
mod order;
mod parts;
mod profile;
pub mod program;
pub mod request;
mod swept_width;
mod tolerance;
mod units;

pub use answer::{Deburr, DeburrPoint, DeburrSummary, LeadMotion, LeadMove};
pub use capability::{DeburrAnswer, DeburrCapability, HoleAnswer, VisitStop, VisitingOrder};
pub use diagnostics::{ExactConstruction, PointConstruction, construction_at, ideal_centres};
pub use program::program;
pub use request::{
    CentreDistance, DeburrRequest, Direction, Edge, Hole, HolePattern, HoleShape, MAX_HOLES, Method, PlacedHole,
    Placement, Workpiece,
};

use crate::capability::Control;
use crate::error::ErrorCode;
use crate::validate::Measure;
use centre::{Construction, RidgeCentre};
use envelope::EnvelopePath;
use swept_width::SweptWidths;
use tolerance::{IntervalLimit, Limit, Spacing, Target};

use crate::error::{SolverError, Warning};
use crate::geometry::{Vec3, array3};
use crate::machine::MachineProfile;
use crate::machine::stats::{BlockStats, stats_with_ends};
use crate::tool::Tool;

/// Most points a deburr loop may have; a tolerance needing more is refused (`E_TOO_MANY_POINTS`).
pub const MAX_POINTS: usize = 200_000;

/// Most points at which the true chamfer width of a loop is measured.
const TRUE_WIDTH_SAMPLES: usize = 1024;

/// Relative chamfer-width error of the tangent-line method above which `W_APPROX` is raised (§4).
const APPROX_LIMIT: f64 = 0.05;

/// Smallest band of the swept chamfer width around W that `method: exact` promises, mm: the
/// band is ±max(this, TA), since the straight moves stray from the ideal centre path by up to
/// TA and the swept chamfer with them (`W_WIDTH_OFF`).
pub const WIDTH_TOLERANCE: f64 = 0.005;

/// Solves a deburr request with its resolved tool (a request that names no machine).
///
/// # Errors
/// Every failure of docs/spec/deburr.md §4 with its code, and `E_INPUT` naming the field for bad numbers.
pub fn solve(request: &DeburrRequest, tool: &Tool) -> Result<Deburr, SolverError> {
    solve_with(request, tool, None)
}

/// Solves a deburr request with its resolved tool and machine (the profile its `machine`
/// names). With a block time (the request's or the machine's) the points follow the block-time
/// rule at `feed`, never coarser than `tolerance`, and the summary reports the blocks.
///
/// # Errors
/// As [`solve`] and `E_INPUT` at `block_time_ms` for a bad block time. `machine` is the profile the
/// request's `machine` names, resolved by the caller (`capability::resolve`).
pub fn solve_with(
    request: &DeburrRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
) -> Result<Deburr, SolverError> {
    solve_centred(request, tool, machine, Control::default())
}

/// [`solve_with`] that stops with `E_CANCELLED` once `control`'s cancel flag is set (checked per
/// centre placed).
///
/// # Errors
/// As [`solve_with`], and `E_CANCELLED`.
pub fn solve_controlled(
    request: &DeburrRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    control: Control<'_>,
) -> Result<Deburr, SolverError> {
    solve_centred(request, tool, machine, control)
}

/// Places, checks and describes the centres of one deburr loop, reporting progress by stage
/// (the centres' count is known only once they are placed).
fn solve_centred(
    request: &DeburrRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    control: Control<'_>,
) -> Result<Deburr, SolverError> {
    let job = request.validate(tool, machine)?;
    let mut warnings = checks::ridge(&job)?;
    let construction = Construction::for_job(&job);
    let envelope = (job.method == Method::Exact).then(|| EnvelopePath::solve(&construction, &job.profile));
    control.check()?;
    control.report_fraction(0.2);
    let mut refined = place_centres(&job, &construction, envelope.as_ref(), control)?;
    control.check()?;
    control.report_fraction(0.7);

    let (mut ridges, exact_offset) = ridges_at(&job, &construction, &refined.targets, &refined.centres);
    warnings.extend(point_checks(&job, &refined.targets, &ridges)?);
    let (true_width_min, true_width_max, approx) = true_widths(&construction, &job, &refined.targets, &ridges);
    let swept = swept_width::swept_widths(&construction, &job.profile, &refined.targets, &refined.centres);
    control.check()?;
    match job.method {
        Method::Tangent => warnings.extend(approx.or_else(|| swept_approx(&job, &swept))),
        Method::Exact => warnings.extend(width_off(&job, &swept, envelope.as_ref())),
    }
    checks::far_gouge(&job, &refined.targets, &refined.centres)?;
    let shank_direction = job.frame.local_vector(&Vec3::z());
    let (access_warnings, mut program_blocker) = checks::inner_access(&job, &ridges, &shank_direction);
    warnings.extend(access_warnings);
    warnings.extend(checks::overlap(&job, &construction, &ridges));
    warnings.extend(checks::outer_shank(&job, &ridges));

    if job.direction == Direction::Cw {
        refined.targets.reverse();
        ridges.reverse();
        refined.centres.reverse();
    }
    let (targets, centres) = (&refined.targets, &refined.centres);
    let points = machine_points(&job, targets, &ridges, centres);
    let path_length: f64 = centres.windows(2).map(|pair| (pair[1] - pair[0]).norm()).sum();

    let ends =
        leads_and_time(&job, centres, &ridges, &refined.limits, path_length, &mut program_blocker, &mut warnings);
    let wedge = ridges.iter().map(|r| r.wedge_angle().to_degrees());
    let summary = DeburrSummary {
        count: targets.len() - 1,
        path_length,
        max_deviation: refined.max_deviation,
        tolerance: job.tolerance,
        cut_amount: job.cut_amount,
        width: job.width,
        true_width_min,
        true_width_max,
        swept_width_min: swept.min,
        swept_width_max: swept.max,
        wedge_angle_min_deg: wedge.clone().fold(f64::INFINITY, f64::min),
        wedge_angle_max_deg: wedge.fold(f64::NEG_INFINITY, f64::max),
        max_exact_offset: exact_offset,
        feed: job.feed,
        spindle_rpm: job.spindle_rpm,
        safe_centre_z: ends.safe_centre_z,
        estimated_time_s: ends.estimated_time_s,
        block_time_ms: job.rule.map(|rule| rule.block_time_ms),
        block_length: job.rule.map(|rule| rule.block_length()),
        blocks: ends.blocks.as_ref().map(|stats| stats.blocks),
        min_block_length: ends.blocks.as_ref().map(|stats| stats.min_block_length),
        short_blocks: ends.blocks.as_ref().map(|stats| stats.short_blocks),
    };
    let description = describe(request, &job, &summary);
    Ok(Deburr {
        edge: job.edge,
        method: job.method,
        points,
        lead_in: ends.lead_in,
        lead_out: ends.lead_out,
        summary,
        warnings,
        program_blocker,
        description,
        ball_radius: job.tool.radius,
    })
}

/// The way in and out of a loop and what the whole program takes.
struct Ends {
    lead_in: Vec<LeadMove>,
    lead_out: Vec<LeadMove>,
    /// The height the leads start and end at; `None` when no program can be written.
    safe_centre_z: Option<f64>,
    /// The loop and its leads at the feed, or block-limited with a block time, s.
    estimated_time_s: f64,
    /// The loop's blocks, with a block time.
    blocks: Option<BlockStats>,
}

/// The leads (§6.3), `W_NO_PROGRAM` when no program can be written (the first blocker kept),
/// and the time of the loop and its leads, with the block warnings under a block-time rule.
fn leads_and_time(
    job: &Job,
    centres: &[Vec3],
    ridges: &[RidgeCentre],
    limits: &[IntervalLimit],
    path_length: f64,
    program_blocker: &mut Option<SolverError>,
    warnings: &mut Vec<Warning>,
) -> Ends {
    let frame = &job.frame;
    let safe_centre_z = program::safe_centre_z(job, frame);
    let (lead_in, lead_out) = match &safe_centre_z {
        Ok(z) => program::leads(job, frame.point(&centres[0]), frame.vector(&ridges[0].bisector), *z),
        Err(_) => (Vec::new(), Vec::new()),
    };
    if program_blocker.is_none() {
        *program_blocker = safe_centre_z.as_ref().err().cloned();
    }
    if let Some(blocker) = program_blocker {
        warnings.push(Warning::new("W_NO_PROGRAM", format!("no G-code can be written: {}", blocker.message())));
    }
    let lead_feed_length: f64 = lead_feed_length(&lead_in, frame.point(&centres[0]))
        + lead_feed_length(&lead_out, frame.point(&centres[centres.len() - 1]));
    let blocks = job.rule.map(|rule| {
        // The loop continues into the way out: no block of it ends a span.
        let stats = stats_with_ends(centres, rule.feed, rule.block_time_ms, &[]);
        warnings.extend(job.rule_warnings.iter().cloned());
        warnings.extend(block_warnings(job, &stats, limits));
        let lead_time = lead_block_time(&lead_in, frame.point(&centres[0]), &rule)
            + lead_block_time(&lead_out, frame.point(&centres[centres.len() - 1]), &rule);
        (stats, lead_time)
    });
    let estimated_time_s = match &blocks {
        Some((stats, lead_time)) => stats.estimated_time_s + lead_time,
        None => (path_length + lead_feed_length) / job.feed * 60.0,
    };
    Ends {
        lead_in,
        lead_out,
        safe_centre_z: safe_centre_z.ok(),
        estimated_time_s,
        blocks: blocks.map(|(stats, _)| stats),
    }
}

/// The target points and their centres (§3): bisection by TA (or the block-time rule), the
/// dense refinement, and for `method: exact` more points where the swept chamfer leaves its band.
/// The centres come from the `exact` path when there is one, else from the tangent method.
fn place_centres(
    job: &Job,
    construction: &Construction,
    envelope: Option<&EnvelopePath>,
    control: Control<'_>,
) -> Result<tolerance::Refined, SolverError> {
    let profile = &job.profile;
    let centre_at = |segment: usize, s: f64| -> Result<Vec3, SolverError> {
        control.check()?;
        match envelope {
            Some(path) => Ok(path.centre(construction, profile, segment, s)),
            None => Ok(construction.tangent_centre(&profile.segments[segment].point(profile.radius, s))),
        }
    };
    let spacing = Spacing::new(job.tolerance, job.rule, request::MIN_TOLERANCE);
    let mut bisected = tolerance::targets(profile, &spacing, MAX_POINTS, centre_at)?;
    control.report_fraction(0.4);
    // The loop ends where it starts: the closing target (end of the last segment) is the start
    // point, which evaluates differently only by rounding (sin 2π ≠ 0).
    let last = bisected.centres.len() - 1;
    bisected.centres[last] = bisected.centres[0];
    let mut refined = tolerance::refine(&bisected, &spacing, MAX_POINTS, centre_at)?;
    if envelope.is_some() {
        let band = WIDTH_TOLERANCE.max(job.tolerance);
        swept_width::refine_for_width(construction, profile, &mut refined, band, MAX_POINTS, centre_at)?;
    }
    Ok(refined)
}

/// The ridge construction at each target, its centre replaced by the placed one for `method:
/// exact` (with CL measured to it), and the largest distance of an exact centre from the
/// tangent-line one. The last ridge is the first: the loop closes.
fn ridges_at(
    job: &Job,
    construction: &Construction,
    targets: &[Target],
    centres: &[Vec3],
) -> (Vec<RidgeCentre>, Option<f64>) {
    let profile = &job.profile;
    let mut ridges: Vec<RidgeCentre> = Vec::with_capacity(targets.len());
    let mut exact_offset: Option<f64> = None;
    for (target, centre) in targets.iter().zip(centres) {
        let point = profile.segments[target.segment].point(profile.radius, target.parameter);
        let mut ridge = construction.tangent(&point);
        if job.method == Method::Exact {
            exact_offset = Some(exact_offset.unwrap_or(0.0).max((centre - ridge.centre).norm()));
            // CL of the exact centre: its distance from P, signed as for the patent (positive when
            // C is on the air side).
            let from_target = ridge.target - centre;
            ridge.centre_offset = from_target.norm().copysign(from_target.dot(&ridge.bisector));
            ridge.centre = *centre;
        }
        ridges.push(ridge);
    }
    let last = ridges.len() - 1;
    ridges[last] = ridges[0];
    (ridges, exact_offset)
}

/// The answer's points in machine coordinates: target, centre and tip, with the construction's
/// figures at each.
fn machine_points(job: &Job, targets: &[Target], ridges: &[RidgeCentre], centres: &[Vec3]) -> Vec<DeburrPoint> {
    let (frame, profile) = (&job.frame, &job.profile);
    let down = job.tool.radius * Vec3::z();
    targets
        .iter()
        .zip(ridges)
        .zip(centres)
        .map(|((target, ridge), centre)| {
            let machine_centre = frame.point(centre);
            let point = profile.segments[target.segment].point(profile.radius, target.parameter);
            DeburrPoint {
                target: array3(&frame.point(&ridge.target)),
                centre: array3(&machine_centre),
                tip: array3(&(machine_centre - down)),
                wedge_angle_deg: ridge.wedge_angle().to_degrees(),
                segment: profile.segments[target.segment].name,
                parameter: target.parameter,
                phi_deg: point.phi.map(f64::to_degrees),
                centre_offset: ridge.centre_offset,
            }
        })
        .collect()
}

/// Block-limited time of the feed moves of a lead, starting from `start`: Σ max(L/F, T_b), s.
fn lead_block_time(moves: &[LeadMove], start: Vec3, rule: &crate::machine::BlockRule) -> f64 {
    let mut from = start;
    let mut time = 0.0;
    for step in moves {
        let to = crate::geometry::vec3(step.centre);
        if step.motion == LeadMotion::Feed {
            time += ((to - from).norm() / rule.feed * 60.0).max(rule.block_time_ms / 1000.0);
        }
        from = to;
    }
    time
}

/// Warnings about blocks shorter than feed × block time, with why they are: the
/// tolerance forbids longer chords, the radius is too small for the feed, or a piece of the
/// profile is shorter than one block.
fn block_warnings(job: &Job, stats: &BlockStats, limits: &[IntervalLimit]) -> Vec<Warning> {
    let Some(rule) = job.rule else { return Vec::new() };
    let mut warnings = Vec::new();
    let smallest = |why: Limit| limits.iter().filter(|l| l.why == why).map(|l| l.radius).fold(f64::INFINITY, f64::min);
    let reach = crate::machine::BlockRule { margin: rule.margin * tolerance::BISECTION_REACH, ..rule };
    let by_tolerance = smallest(Limit::Tolerance);
    if by_tolerance.is_finite() && stats.short_blocks > 0 {
        warnings.push(Warning::new(
            "W_CHORD_ERROR_EXCEEDS_TOLERANCE",
            format!(
                "the tolerance {} mm is finer than the block-time rule needs at {} mm/min on the centre path (radius \
                 down to {:.3} mm): it forbids blocks of one block time there. At most {:.0} mm/min would meet both",
                job.tolerance,
                rule.feed,
                by_tolerance,
                reach.feed_for_tolerance(by_tolerance, job.tolerance).floor()
            ),
        ));
    }
    let tight = smallest(Limit::Tight).min(smallest(Limit::Infeasible));
    if tight.is_finite() && stats.short_blocks > 0 {
        warnings.push(Warning::new(
            "W_FEED_TOO_HIGH_FOR_RADIUS",
            format!(
                "the centre path turns on a radius of {tight:.3} mm, too tight for blocks of {:.4} mm at {} mm/min: \
                 at most {:.0} mm/min keeps them one block time long there",
                rule.block_length(),
                rule.feed,
                reach.feed_limit(tight).floor()
            ),
        ));
    }
    if stats.short_blocks > 0 {
        warnings.push(Warning::new(
            "W_BLOCK_TIME_VIOLATION",
            format!(
                "{} of {} blocks are shorter than one block time at the feed ({:.4} mm), the shortest {:.6} mm \
                 ({:.1} % of it): the control slows down there{}",
                stats.short_blocks,
                stats.blocks,
                stats.block_length,
                stats.min_block_length,
                stats.min_block_ratio * 100.0,
                if warnings.is_empty() {
                    "; the profile has pieces shorter than one block (short straight sides or small arcs)"
                } else {
                    ""
                }
            ),
        ));
    }
    warnings
}

/// Length of the feed moves of a lead, starting from `start`.
fn lead_feed_length(moves: &[LeadMove], start: Vec3) -> f64 {
    let mut from = start;
    let mut length = 0.0;
    for step in moves {
        let to = crate::geometry::vec3(step.centre);
        if step.motion == LeadMotion::Feed {
            length += (to - from).norm();
        }
        from = to;
    }
    length
}

/// Per-point limits: E_BALL_MISSES_EDGE, W_CENTRE_IN_MATERIAL, W_SHARP_EDGE (§4).
fn point_checks(job: &Job, targets: &[Target], ridges: &[RidgeCentre]) -> Result<Vec<Warning>, SolverError> {
    let ball = job.tool.radius;
    let mut in_material = 0;
    let mut deepest = 0.0_f64;
    let mut sharp = 0;
    let mut sharpest = 90.0_f64;
    for (target, ridge) in targets.iter().zip(ridges) {
        let name = job.profile.segments[target.segment].name;
        if ridge.centre_offset <= -ball {
            return Err(SolverError::new(
                ErrorCode::BallMissesEdge,
                format!(
                    "at {name} s = {:.4} the wedge is so sharp (β = {:.2}°) that the ball would not reach the edge: \
                     reduce Q or use a larger ball",
                    target.parameter,
                    ridge.wedge_angle().to_degrees()
                ),
            )
            .at("cut_amount"));
        }
        if ridge.centre_offset < 0.0 {
            in_material += 1;
            deepest = deepest.min(ridge.centre_offset);
        }
        let wedge = ridge.wedge_angle().to_degrees();
        if !(30.0..=170.0).contains(&wedge) {
            sharp += 1;
            if (wedge - 90.0).abs() > (sharpest - 90.0).abs() {
                sharpest = wedge;
            }
        }
    }
    let mut warnings = Vec::new();
    if in_material > 0 {
        warnings.push(Warning::new(
            "W_CENTRE_IN_MATERIAL",
            format!(
                "at {in_material} points the ball centre lies inside the wedge (CL down to {deepest:.4} mm): the profile \
                 is a deep cove, cut depth up to {:.4} mm",
                ball - deepest
            ),
        ));
    }
    if sharp > 0 {
        warnings.push(Warning::new(
            "W_SHARP_EDGE",
            format!("at {sharp} points the wedge angle is outside 30°–170° (down to {sharpest:.2}°): W loses its meaning there"),
        ));
    }
    Ok(warnings)
}

use job::Job;

/// Range of the chamfer width really cut by one ball section in VP at the emitted centres, and
/// W_APPROX if the worst is more than 5 % off W (§2.9, §4).
fn true_widths(
    construction: &Construction,
    job: &Job,
    targets: &[Target],
    ridges: &[RidgeCentre],
) -> (f64, f64, Option<Warning>) {
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut worst: Option<(f64, usize)> = None;
    // The true width changes smoothly along the ridge: measuring it at up to
    // TRUE_WIDTH_SAMPLES points spread evenly over a dense loop gives the same range.
    let stride = ridges.len().div_ceil(TRUE_WIDTH_SAMPLES).max(1);
    for (index, ridge) in ridges.iter().enumerate().step_by(stride) {
        let Some(width) = construction.true_width(&job.profile, ridge) else {
            continue;
        };
        low = low.min(width);
        high = high.max(width);
        let error = (width / job.width - 1.0).abs();
        if error > APPROX_LIMIT && worst.is_none_or(|(e, _)| error > e) {
            worst = Some((error, index));
        }
    }
    if !low.is_finite() {
        (low, high) = (job.width, job.width);
    }
    let warning = worst.map(|(error, index)| {
        let target = targets[index];
        Warning::new(
            "W_APPROX",
            format!(
                "the tangent-line approximation cuts a chamfer {:.1} % off W at {} s = {:.4}; use method \"exact\"",
                error * 100.0,
                job.profile.segments[target.segment].name,
                target.parameter
            ),
        )
    });
    (low, high, warning)
}

/// Where on the ridge a measurement was taken, for messages: segment, s and φ on arcs.
fn place(job: &Job, segment: usize, parameter: f64) -> String {
    let piece = &job.profile.segments[segment];
    let phi = piece.point(job.profile.radius, parameter).phi;
    match phi {
        Some(phi) => format!("{} s = {parameter:.4} (φ = {:.2}°)", piece.name, phi.to_degrees()),
        None => format!("{} s = {parameter:.4}", piece.name),
    }
}

/// W_APPROX for the tangent method when the swept chamfer (not one section) is more than 5 % off W.
fn swept_approx(job: &Job, swept: &SweptWidths) -> Option<Warning> {
    let (segment, parameter, width) = swept.worst?;
    let error = (width / job.width - 1.0).abs();
    (error > APPROX_LIMIT).then(|| {
        Warning::new(
            "W_APPROX",
            format!(
                "the tangent-line centres sweep a chamfer {:.1} % off W at {}; use method \"exact\"",
                error * 100.0,
                place(job, segment, parameter)
            ),
        )
    })
}

/// W_WIDTH_OFF: the exact method's swept chamfer leaves W ± max(0.005 mm, TA) (the
/// moves stray from the ideal centre path by up to TA), with the worst place, and why when the
/// coupled solve found no placement that gives W there.
fn width_off(job: &Job, swept: &SweptWidths, envelope: Option<&EnvelopePath>) -> Option<Warning> {
    let (segment, parameter, width) = swept.worst?;
    let band = WIDTH_TOLERANCE.max(job.tolerance);
    if (width - job.width).abs() <= band {
        return None;
    }
    let why = match envelope {
        Some(path) if path.approximate_edges > 0 => format!(
            "; at {} of the ridge's nodes the true surfaces, cut by the normal plane, have no band edges W apart \
             (the ridge turns too tightly for this W), so the tangent-line edges were aimed at there",
            path.approximate_edges
        ),
        Some(path) if path.shortfall > 0.1 * band => format!(
            "; the ridge turns too tightly for the ball near {}: a ball reaching the band edges there would cut \
             past them nearby, so the balls bridge the bend, staying up to {:.4} mm short of the band edges, and the \
             chamfer is narrower there: the closest to W without cutting wider than W anywhere",
            place(job, path.shortfall_at.0, path.shortfall_at.1),
            path.shortfall
        ),
        Some(path) if path.residual > 0.1 * band => format!(
            "; no ball placement gives W there: the swept envelope stays {:.4} mm off the band edges near {} \
             (the ball is too small or the ridge turns too tightly), this is the closest found",
            path.residual,
            place(job, path.residual_at.0, path.residual_at.1)
        ),
        _ => String::new(),
    };
    Some(Warning::new(
        "W_WIDTH_OFF",
        format!(
            "the swept chamfer is {width:.4} mm wide at {} where W = {:.4} mm ({:+.4} mm, beyond ±{band} mm){why}",
            place(job, segment, parameter),
            job.width,
            width - job.width
        ),
    ))
}

/// Header lines naming the job parameters for the G-code program.
fn describe(request: &DeburrRequest, job: &Job, summary: &DeburrSummary) -> Vec<String> {
    let edge = match job.edge {
        Edge::Outer => "outer",
        Edge::Inner => "inner",
        Edge::Both => "both",
    };
    let part = match &request.workpiece {
        Workpiece::Tube { arrangement_angle_deg, .. } => {
            let (inner, outer) = job.tube_radii.unwrap_or_default();
            format!(
                "tube RN {} RT {} arrangement {arrangement_angle_deg} deg",
                Measure::Length.quote(inner),
                Measure::Length.quote(outer)
            )
        }
        Workpiece::BoreBlock { bore_radius, arrangement_angle_deg, .. } => {
            format!("bore block R {} arrangement {arrangement_angle_deg} deg", Measure::Length.quote(*bore_radius))
        }
    };
    let Some(hole) = &request.hole else { return Vec::new() };
    let shape = match hole.shape {
        HoleShape::Round => "round",
        HoleShape::Slot => "slot",
        HoleShape::RoundedRect => "rounded rect",
    };
    let extent = match hole.centre_distance {
        Some(CentreDistance::Along(length)) => format!(" centres {}", Measure::Length.quote(length)),
        Some(CentreDistance::AcrossAlong([across, along])) => {
            format!(" centres {} x {}", Measure::Length.quote(across), Measure::Length.quote(along))
        }
        None => String::new(),
    };
    vec![
        format!("deburr {edge} edge, {part}"),
        format!(
            "{shape} hole R {}{extent} eccentricity {} penetration {} deg",
            Measure::Length.quote(hole.size("hole").map_or(f64::NAN, |size| size.radius())),
            Measure::Length.quote(job.profile.centre_x),
            hole.penetration_angle_deg
        ),
        format!(
            "ball R {} Q {:.4} mm W {:.4} mm TA {} method {:?}, {} points",
            Measure::Length.quote(job.tool.radius),
            job.cut_amount,
            job.width,
            Measure::Length.quote(job.tolerance),
            job.method,
            summary.count
        ),
        format!("feed {} spindle {} rpm", Measure::Feed.quote(job.feed), job.spindle_rpm),
    ]
    .into_iter()
    .chain(job.rule.map(|rule| {
        format!(
            "block time {} ms margin {}: {} blocks, shortest {:.4} mm, {} shorter than {:.4} mm",
            rule.block_time_ms,
            rule.margin,
            summary.blocks.unwrap_or(0),
            summary.min_block_length.unwrap_or(0.0),
            summary.short_blocks.unwrap_or(0),
            rule.block_length()
        )
    }))
    .collect()
}
