//! Deburring as a capability (the seam of engineering.md): `POST /api/v1/deburr`, job operation
//! `deburr`.

use serde::Serialize;

use super::answer::DeburrPoint;
use super::program::Leg;
use super::request::Placement;
use super::{Deburr, DeburrRequest, Edge};
use crate::capability::{
    Capability, Control, Endpoint, OtherTool, OutputOptions, Part, PartSink, PartSource, Purpose, Refs, Resolved, Run,
    Sizing, Split,
};
use crate::error::SolverError;
use crate::gcode::{Reference, ToolCall};
use crate::geometry::Vec3;
use crate::machine::MachineProfile;
use crate::machine::cycle::{CycleTime, Dynamics, Step};
use crate::tool::Tool;
use crate::verify::Verification;
use crate::verify::own::{self, Matter, OwnModel, SampledTube};

/// The deburr capability.
#[derive(Debug, Clone, Copy)]
pub struct DeburrCapability;

/// The deburr answer: the tool used and the solver's result.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct DeburrAnswer {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// With `edge: both` and `inner_tool`: the tool of the inside ridges, as resolved.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inner_tool: Option<Tool>,
    /// The machine the request named, as registered: its block time (and margin, minimum chord
    /// error) spaced the points, its dialect is the G-code default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// With a machine that has `max_accel`: the time the control would take for the program
    /// (feed profile limited by acceleration, and jerk with `max_jerk`; stops at sharp vertices,
    /// rapids at `rapid_feed`, a tool change per tool) and its parts: cutting (the loops), air
    /// (the leads), rapid, tool change.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_time: Option<CycleTime>,
    /// With `holes`, `pattern` or `edge: both`: every loop (one per hole and edge) in the order the
    /// program visits them (the fields beside it are those of the first).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holes: Option<Vec<HoleAnswer>>,
    /// With `holes`, `pattern` or `edge: both`: the order the program visits the loops in and the
    /// travel it saves.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub visiting_order: Option<VisitingOrder>,
    /// The loop of centres, leads, summary and warnings.
    #[serde(flatten)]
    pub result: Deburr,
    /// The program cut on the deburr's own model (docs/spec/verify.md §9): the tube with its
    /// holes as the stock, the tube with the chamfer bands W wide as the part. Absent when the
    /// request turns verification off, for a `bore_block` (its extent is not known), when the
    /// program cannot be written, and for two tools without numbers (the program cannot say
    /// which cuts).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification: Option<Verification>,
}

/// One loop of a several-loop answer: a hole at one edge.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct HoleAnswer {
    /// Where its fields are in the request: `holes[i]`, or `hole` for a pattern's copies and a
    /// single hole.
    pub field: String,
    /// Its place among the request's holes: `i` of `holes[i]`, the copy of a pattern (station by
    /// station, every angle at each), 0 for a single hole.
    pub index: usize,
    /// The request field naming the tool that cuts it: `tool`, or `inner_tool`.
    pub tool_field: &'static str,
    /// The hole points down (θ_P more than 90° from +Z): a vertical tool reaches it only with the
    /// tube turned 180° about its axis, so its loop is given as turned (the program stops with
    /// `M00` for the operator to turn the tube before it).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub turned: bool,
    /// Its penetration angle θ_P, degrees.
    pub penetration_angle_deg: f64,
    /// Its arrangement angle θ_A, degrees.
    pub arrangement_angle_deg: f64,
    /// Its position along the cylinder axis from `workpiece.origin`, mm.
    pub axial_position: f64,
    /// Its loop of centres, leads, summary and warnings; `edge` says which ridge.
    #[serde(flatten)]
    pub result: Deburr,
}

/// The order a several-loop program visits its loops in: loops of one tool together
/// (the tool of `tool` first, then `inner_tool` when it is another), within a tool the holes
/// pointing up before the turned ones (after them for the second tool, so the tube is turned at
/// most twice), each group in a short order (nearest neighbour from its first loop in request
/// order, then 2-opt) over the travel between loops as the program makes it: up to the clearance
/// plane, across, down to the next approach.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct VisitingOrder {
    /// The loops in visiting order.
    pub loops: Vec<VisitStop>,
    /// The travel between loops in this order, mm (programmed tip).
    pub travel: f64,
    /// The travel in request order (hole by hole, outer before inner, grouped by tool), mm.
    pub request_order_travel: f64,
    /// Tool changes inside the program (0, or 1 with an `inner_tool` other than `tool`).
    pub tool_changes: usize,
    /// Stops for the operator to turn the tube (holes pointing down), 0 to 2.
    pub turns: usize,
}

/// One loop of a visiting order: which hole, which edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct VisitStop {
    /// The hole's `index` (its place among the request's holes).
    pub index: usize,
    /// The ridge: `outer` or `inner`.
    pub edge: Edge,
}

impl Capability for DeburrCapability {
    const NAME: &'static str = "deburr";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Deburrs one ridge of a cross hole with a ball end mill, or several holes and both ridges.",
        description: "Returns the closed loop of ball centres in machining order (JSON), or with `Accept: \
            text/x-gcode` / `?format=gcode` a complete program (dialect from `?dialect=`, else the \
            named machine's, else Fanuc). With `block_time_ms` or a `machine` the points follow the \
            block-time rule at `feed` (never coarser than `tolerance`) and the summary reports the \
            blocks. With `holes`, a `pattern` or `edge: both` one program visits every loop (one per \
            hole and edge, listed in `holes`) in a short order (`visiting_order`), changing to \
            `inner_tool` once for the inside ridges and stopping (`M00`) to turn the tube for holes \
            that point down.",
        not_found: "Unknown tool number (`tool`, `inner_tool`) or machine",
        refused: "Impossible geometry (codes in docs/spec/deburr.md §4); `E_TIMEOUT` over the synchronous time \
            limit: submit a job; `E_TOO_LARGE_ANSWER` when the answer would not fit the answer budget",
    };
    type Request = DeburrRequest;
    type Answer = DeburrAnswer;
    type Tool = Tool;

    fn refs(request: &DeburrRequest) -> Refs<'_> {
        Refs { tool: Some(&request.tool), machine: request.machine.as_deref(), material: None }
    }

    fn other_tools(request: &DeburrRequest) -> Vec<OtherTool<'_>> {
        request.inner_tool.iter().map(|tool| OtherTool { field: "inner_tool", tool }).collect()
    }

    /// Every loop at [`MAX_POINTS`](super::MAX_POINTS) points (the solver refuses a loop that
    /// needs more), at `loop_bound` each; a several-loop answer repeats its first loop at the
    /// top.
    fn answer_bound(request: &DeburrRequest, _context: &Resolved<Tool>, purpose: Purpose) -> Option<u64> {
        let loops = if request.is_several() { request.placements().ok()?.len() as u64 + 1 } else { 1 };
        Some(
            loops
                .saturating_mul(loop_bound(super::MAX_POINTS, purpose))
                .saturating_add(ANSWER_BYTES)
                .saturating_add(own::VERIFICATION_BYTES),
        )
    }

    fn solve(request: &DeburrRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<DeburrAnswer, SolverError> {
        let model = own_model(request, &context)?;
        let answer = solve_unverified(request, context, run)?;
        verified(request, model, answer, run)
    }

    fn set_cut_resolution(request: &mut DeburrRequest, resolution: f64) {
        request.verification.get_or_insert_with(Default::default).resolution = Some(resolution);
    }

    /// The tube with its holes less what the program (with its verification's header comments)
    /// cut, up to `upto_line`, against the tube with its chamfer bands.
    fn cut_stock(
        request: &DeburrRequest,
        context: Resolved<Tool>,
        upto_line: Option<usize>,
        units: crate::units::Units,
        run: &Run<'_>,
    ) -> Result<Option<Vec<u8>>, SolverError> {
        let Some((model, grid)) = own_model(request, &context)? else {
            return Ok(None);
        };
        let answer = Self::solve(request, context, run)?;
        let Some((tools, limits)) = own_cut(&answer) else {
            return Ok(None);
        };
        let program = own::program::<DeburrCapability>(request, &answer, run)?;
        own::cut_stock_glb(&model, grid, &program, &tools, limits, own::StockAsk { upto_line, units }, run).map(Some)
    }

    /// A several-loop request's loops in ranges of about `sizing.part_seconds` (`parts`).
    fn split(request: &DeburrRequest, _context: &Resolved<Tool>, sizing: &Sizing) -> Option<Split> {
        super::parts::split(request, sizing)
    }

    /// The loops of `part`.
    fn solve_part(
        request: &DeburrRequest,
        context: Resolved<Tool>,
        part: &Part,
        run: &Run<'_>,
        sink: &mut impl PartSink,
    ) -> Result<(), SolverError> {
        super::parts::solve_part(request, &context, part, run, sink)
    }

    /// Every loop, grouped and ordered as `solve` orders them.
    fn finish(
        request: &DeburrRequest,
        context: Resolved<Tool>,
        parts: &mut impl PartSource,
        run: &Run<'_>,
    ) -> Result<DeburrAnswer, SolverError> {
        let model = own_model(request, &context)?;
        let answer = super::parts::finish(request, context, parts, run)?;
        verified(request, model, answer, run)
    }

    fn program(
        _request: &DeburrRequest,
        answer: &DeburrAnswer,
        output: &OutputOptions,
        control: Control<'_>,
    ) -> Result<String, SolverError> {
        let post = output.post(answer.machine.as_ref(), &answer.tool);
        match &answer.holes {
            Some(holes) => {
                let (legs, tools) = legs(answer, holes);
                super::program::program_for_loops(&legs, &tools, &post, control)
            }
            None => super::program::program_for_holes(&[&answer.result], &post, control),
        }
    }

    fn units(request: &DeburrRequest) -> Option<crate::units::Units> {
        request.units
    }

    fn scale_request(request: &mut DeburrRequest, scaling: crate::units::Scaling) -> Result<(), SolverError> {
        crate::units::Scale::scale(request, scaling);
        Ok(())
    }

    fn scale_answer(answer: &mut DeburrAnswer, scaling: crate::units::Scaling) {
        crate::units::Scale::scale(answer, scaling);
    }

    fn machine(answer: &DeburrAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }
}

/// The answer before verification: one loop, or every loop arranged.
fn solve_unverified(
    request: &DeburrRequest,
    context: Resolved<Tool>,
    run: &Run<'_>,
) -> Result<DeburrAnswer, SolverError> {
    if !request.is_several() {
        let result = super::solve_controlled(request, &context.tool, context.machine.as_ref(), run.control)?;
        run.charge_unit(1, 1, ANSWER_BYTES, || loop_bytes(&result, run.purpose))?;
        let cycle_time = context
            .machine
            .as_ref()
            .and_then(MachineProfile::dynamics)
            .map(|d| cycle_time(&[Leg { deburr: &result, tool: 0, turned: false }], &d));
        return Ok(DeburrAnswer {
            tool: context.tool,
            inner_tool: None,
            machine: context.machine,
            cycle_time,
            holes: None,
            visiting_order: None,
            result,
            verification: None,
        });
    }
    let inner_tool = inner_tool(request, &context);
    let placements = request.placements()?;
    let count = placements.len();
    let mut loops = Vec::with_capacity(count);
    for placement in placements {
        run.control.check()?;
        let result = solve_loop(&placement, &context, inner_tool.as_ref(), run)?;
        charge_loop(run, &result, loops.len(), count)?;
        loops.push(hole_answer(placement, result));
    }
    Ok(arrange(context, inner_tool, loops))
}

/// The deburr's own model and its grid (docs/spec/verify.md §9.2), built before any work so a
/// resolution over the memory limit is refused up front: the tube (its bore and outer radius)
/// along the holes' stations with every hole as the stock, less every loop's chamfer band as
/// the part. A point of the tube is in a hole where the hole's profile holds it (on the side of
/// the axis the hole is drilled from); it is in the chamfer band of a ridge where its distances
/// d_s from the ridge's cylinder and d_h from the hole wall satisfy d_s + d_h < W·cos(β/2),
/// β the wedge angle between the two faces there: the flat chamfer whose edges lie W apart.
/// `None`: no verification (turned off, a `bore_block`, or two tools the program cannot tell
/// apart).
fn own_model(
    request: &DeburrRequest,
    context: &Resolved<Tool>,
) -> Result<Option<(SampledTube, own::Grid)>, SolverError> {
    let options = request.verification.unwrap_or_default();
    if !options.enabled {
        return Ok(None);
    }
    let inner = inner_tool(request, context);
    let two_tools = inner.as_ref().is_some_and(|inner| *inner != context.tool);
    if two_tools && (context.tool.number.is_none() || inner.as_ref().is_some_and(|inner| inner.number.is_none())) {
        return Ok(None);
    }
    // Refusals of the request itself are left to the solve, which names them.
    let jobs: Vec<super::job::Job> = if request.is_several() {
        let Ok(placements) = request.placements() else { return Ok(None) };
        let mut jobs = Vec::with_capacity(placements.len());
        for placement in placements {
            let tool = match &inner {
                Some(inner) if placement.tool_field == "inner_tool" => inner,
                _ => &context.tool,
            };
            let Ok(job) = placement.request.validate(tool, context.machine.as_ref()) else { return Ok(None) };
            jobs.push(job);
        }
        jobs
    } else {
        let Ok(job) = request.validate(&context.tool, context.machine.as_ref()) else { return Ok(None) };
        vec![job]
    };
    let Some((bore, outer)) = jobs.first().and_then(|job| job.tube_radii) else {
        return Ok(None);
    };
    let ball = jobs.iter().map(|job| job.tool.radius).fold(0.0, f64::max);
    let axis = jobs[0].frame.vector(&Vec3::y());
    let base = jobs[0].frame.origin;
    let (mut first, mut last) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut windows = Vec::with_capacity(jobs.len());
    let mut thinnest = f64::INFINITY;
    for job in &jobs {
        let profile = &job.profile;
        let reach = job.width + ball + 1.0;
        let half_x = profile.half_across + profile.radius + reach;
        let half_y = profile.half_along + profile.radius + reach;
        let station = (job.frame.origin - base).dot(&axis);
        first = first.min(station - half_y - 2.0 * ball);
        last = last.max(station + half_y + 2.0 * ball);
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for corner in 0..8 {
            let x = profile.centre_x + if corner & 1 == 0 { -half_x } else { half_x };
            let y = if corner & 2 == 0 { -half_y } else { half_y };
            let z = if corner & 4 == 0 { 0.0 } else { outer + reach };
            let point = job.frame.point(&Vec3::new(x, y, z));
            lo = [lo[0].min(point.x), lo[1].min(point.y), lo[2].min(point.z)];
            hi = [hi[0].max(point.x), hi[1].max(point.y), hi[2].max(point.z)];
        }
        windows.push((lo, hi));
        thinnest = thinnest.min(job.width);
    }
    let holes = jobs.len();
    let width = jobs[0].width;
    let classify = move |point: &Vec3| -> Matter {
        let mut matter = Matter::Part;
        for job in &jobs {
            let local = job.frame.rotation.transpose() * (point - job.frame.origin);
            if local.z <= 0.0 {
                continue;
            }
            let (wall, (gx, _)) = job.profile.signed_distance(local.x, local.y);
            if wall < 0.0 {
                return Matter::Air;
            }
            let rho = local.x.hypot(local.z);
            // Distance from the ridge's cylinder into the material, and cos β from the faces'
            // outward normals (the hole wall's is −∇d_h, the cylinder's ±radial).
            let (surface, cos_beta) = match job.edge {
                Edge::Inner => (rho - bore, -gx * local.x / rho),
                Edge::Outer | Edge::Both => (outer - rho, gx * local.x / rho),
            };
            let half_beta = 0.5 * cos_beta.clamp(-1.0, 1.0).acos();
            if surface + wall < job.width * half_beta.cos() {
                matter = Matter::Cut;
            }
        }
        matter
    };
    let model = SampledTube {
        start: base + first * axis,
        end: base + last * axis,
        outer,
        inner: bore,
        windows,
        classify: Box::new(classify),
        step: thinnest / 8.0,
        description: format!(
            "stock: the tube (bore radius {bore} mm, outer radius {outer} mm) with its {holes} hole(s); part: the same with the chamfer band of every loop cut away, its edges W = {width:.4} mm apart"
        ),
    };
    let ball_tool = Tool { radius: ball, ..context.tool.clone() };
    let grid = own::grid(model.footprint(), &ball_tool, &options)?;
    Ok(Some((model, grid)))
}

/// `answer` with its program cut on the deburr's own `model`: its `verification`, the warnings
/// and the program's header comments of what that found. A ball cuts an arc where the part's
/// chamfer is flat: the arc lies deeper than the chord by the sagitta D − √(D² − W²/4), which
/// the depth along z may double on the chamfer's slopes (up to 60°); the width may be off by
/// the method's tolerance max(0.005, `tolerance`). Both are allowed besides the default
/// tolerance.
fn verified(
    request: &DeburrRequest,
    model: Option<(SampledTube, own::Grid)>,
    mut answer: DeburrAnswer,
    run: &Run<'_>,
) -> Result<DeburrAnswer, SolverError> {
    let Some((model, grid)) = model else {
        return Ok(answer);
    };
    let Some((tools, limits)) = own_cut(&answer) else {
        return Ok(answer);
    };
    let program = own::program::<DeburrCapability>(request, &answer, run)?;
    let mut verification = own::verify_tools(&model, grid, &program, &tools, limits, run)?;
    let mut description = Vec::new();
    own::report(&mut verification, &mut answer.result.warnings, &mut description);
    answer.result.description.extend(description.iter().cloned());
    if let Some(first) = answer.holes.as_mut().and_then(|holes| holes.first_mut()) {
        first.result.description.extend(description);
    }
    answer.verification = Some(verification);
    Ok(answer)
}

/// The tools a program calls, each with the `T` number it calls it by (one without a number cuts
/// every move).
type CalledTools<'a> = Vec<(Option<u32>, &'a Tool)>;

/// The tools `answer`'s program calls and the limits of its verification; `None` when a loop has
/// no program.
fn own_cut(answer: &DeburrAnswer) -> Option<(CalledTools<'_>, own::Limits)> {
    let loops: Vec<&Deburr> = match &answer.holes {
        Some(holes) => holes.iter().map(|hole| &hole.result).collect(),
        None => vec![&answer.result],
    };
    if loops.iter().any(|deburr| deburr.program_blocker.is_some()) {
        return None;
    }
    let (mut slack, mut allowance) = (0.0_f64, 0.0_f64);
    for deburr in &loops {
        let (ball, width) = (deburr.ball_radius, deburr.summary.width);
        let sagitta = ball - (ball * ball - 0.25 * width * width).max(0.0).sqrt();
        let off = deburr.summary.tolerance.max(0.005);
        slack = slack.max(2.0 * (sagitta + off));
        allowance = allowance.max(2.0 * off);
    }
    let limits = own::Limits {
        tolerance: own::OWN_TOLERANCE + slack,
        allowance: crate::verify::DEFAULT_ALLOWANCE + allowance,
        wall_tolerance: 0.0,
    };
    let inner = answer.inner_tool.as_ref().filter(|inner| **inner != answer.tool);
    let mut tools = vec![(inner.map(|_| answer.tool.number).unwrap_or(None), &answer.tool)];
    if let Some(inner) = inner {
        tools.push((inner.number, inner));
    }
    Some((tools, limits))
}

/// Most bytes one answer point takes as JSON: its 13 numbers at their longest (24 characters,
/// `-2.2250738585072014e-308`), its longest segment name, its keys and separators (checked by
/// `point_json_is_within_its_bound`).
const POINT_JSON_BYTES: u64 = 448;

/// Most bytes one answer point takes in a program: one `G01`/`G02` line with five coordinates
/// of up to `-1000000.0000` (the coordinate range) and a feed word.
const POINT_PROGRAM_BYTES: u64 = 128;

/// Most bytes of one loop besides its points: edge, method, leads, summary, warnings, and its
/// place among the holes (checked against the reference case by
/// `loop_bound_holds_the_reference_case`).
const LOOP_BYTES: u64 = 64 * 1024;

/// Most bytes of an answer besides its loops: tools, machine, cycle time, visiting order.
const ANSWER_BYTES: u64 = 256 * 1024;

/// Most bytes a loop of `points` points takes for `purpose`: the points in memory, plus their
/// JSON, their program, or for a job both.
fn loop_bound(points: usize, purpose: Purpose) -> u64 {
    let per_point = POINT_BYTES
        + match purpose {
            Purpose::Json => POINT_JSON_BYTES,
            Purpose::Program => POINT_PROGRAM_BYTES,
            Purpose::Job => POINT_JSON_BYTES + POINT_PROGRAM_BYTES,
        };
    (points as u64).saturating_mul(per_point).saturating_add(LOOP_BYTES)
}

/// Bytes of one point in memory.
const POINT_BYTES: u64 = std::mem::size_of::<DeburrPoint>() as u64;

/// The bytes the solved loop `result` takes for `purpose`: its points in memory, plus its JSON
/// as written (counted, not kept), its program at [`POINT_PROGRAM_BYTES`] a point, or for a job
/// both.
fn loop_bytes(result: &Deburr, purpose: Purpose) -> u64 {
    let points = result.points.len() as u64;
    let json = || crate::capability::json_bytes(result) + PLACE_BYTES;
    let program = || points.saturating_mul(POINT_PROGRAM_BYTES).saturating_add(PLACE_BYTES);
    points.saturating_mul(POINT_BYTES)
        + match purpose {
            Purpose::Json => json(),
            Purpose::Program => program(),
            Purpose::Job => json() + program(),
        }
}

/// Most bytes of a loop's place among the holes (its field, index, tool field, angles, axial
/// position) as JSON, and of the moves between two loops in a program.
const PLACE_BYTES: u64 = 1024;

/// Charges loop `index` of `count` to the run's budget as it is built; the first loop twice (a
/// several-loop answer repeats it at the top).
pub(super) fn charge_loop(run: &Run<'_>, result: &Deburr, index: usize, count: usize) -> Result<(), SolverError> {
    let copies = if index == 0 { 2 } else { 1 };
    run.charge_unit(index + 1, count, ANSWER_BYTES, || copies * loop_bytes(result, run.purpose))
}

/// The tool of the inside ridges: `inner_tool` as resolved, when the request gives one.
pub(super) fn inner_tool(request: &DeburrRequest, context: &Resolved<Tool>) -> Option<Tool> {
    request.inner_tool.as_ref().and(context.other_tools.first().cloned())
}

/// One loop of a several-loop request: its hole at its edge with its tool, errors named where
/// the request has the fields.
pub(super) fn solve_loop(
    placement: &Placement,
    context: &Resolved<Tool>,
    inner_tool: Option<&Tool>,
    run: &Run<'_>,
) -> Result<Deburr, SolverError> {
    let tool = match inner_tool {
        Some(inner) if placement.tool_field == "inner_tool" => inner,
        _ => &context.tool,
    };
    super::solve_controlled(&placement.request, tool, context.machine.as_ref(), run.control).map_err(|error| {
        match error.field() {
            // A hole's own field: named where the request has it.
            Some(field) if placement.field != "hole" && field.starts_with("hole.") => {
                let inner = field.trim_start_matches("hole.").to_owned();
                error.at(format!("{}.{inner}", placement.field))
            }
            // The inside ridge's tool: named as the request names it.
            Some(field) if placement.tool_field == "inner_tool" && field.starts_with("tool") => {
                let rest = field.trim_start_matches("tool").to_owned();
                error.at(format!("inner_tool{rest}"))
            }
            _ => error,
        }
    })
}

/// A loop of a several-loop answer: its placement and its result.
pub(super) fn hole_answer(placement: Placement, result: Deburr) -> HoleAnswer {
    HoleAnswer {
        field: placement.field,
        index: placement.index,
        tool_field: placement.tool_field,
        turned: placement.turned,
        penetration_angle_deg: placement.penetration_angle_deg,
        arrangement_angle_deg: placement.arrangement_angle_deg,
        axial_position: placement.axial_position,
        result,
    }
}

/// The answer of a several-loop request from its loops in request order: the loops grouped by
/// tool and turn, each group in a short visiting order (`order`), the program's cycle time.
pub(super) fn arrange(context: Resolved<Tool>, inner_tool: Option<Tool>, loops: Vec<HoleAnswer>) -> DeburrAnswer {
    let another = inner_tool.as_ref().filter(|inner| **inner != context.tool).cloned();
    let tool = |hole: &HoleAnswer| usize::from(another.is_some() && hole.tool_field == "inner_tool");
    // The groups in program order: the first tool up then turned, the second turned then up.
    let rank = |hole: &HoleAnswer| 2 * tool(hole) + usize::from(hole.turned != (tool(hole) == 1));
    // Request order, grouped (stable: each group keeps its request order).
    let request_order: Vec<usize> = {
        let mut indices: Vec<usize> = (0..loops.len()).collect();
        indices.sort_by_key(|&i| rank(&loops[i]));
        indices
    };
    let results: Vec<&Deburr> = loops.iter().map(|hole| &hole.result).collect();
    let safe_z = super::program::safe_z(&results, Reference::Tip).ok();
    let cost = |from: &Deburr, to: &Deburr| safe_z.map_or(0.0, |z| super::program::travel(from, to, z, Reference::Tip));
    let mut order = Vec::with_capacity(loops.len());
    for group in 0..4 {
        let indices: Vec<usize> = request_order.iter().copied().filter(|&i| rank(&loops[i]) == group).collect();
        let matrix: Vec<Vec<f64>> = indices
            .iter()
            .map(|&a| indices.iter().map(|&b| cost(&loops[a].result, &loops[b].result)).collect())
            .collect();
        order.extend(super::order::short_order(&matrix).into_iter().map(|at| indices[at]));
    }
    let travel_of = |sequence: &[usize]| -> f64 {
        sequence.windows(2).map(|pair| cost(&loops[pair[0]].result, &loops[pair[1]].result)).sum()
    };
    let changes = |pick: &dyn Fn(&HoleAnswer) -> usize| {
        order.windows(2).filter(|pair| pick(&loops[pair[0]]) != pick(&loops[pair[1]])).count()
    };
    let visiting_order = VisitingOrder {
        loops: order.iter().map(|&i| VisitStop { index: loops[i].index, edge: loops[i].result.edge }).collect(),
        travel: travel_of(&order),
        request_order_travel: travel_of(&request_order),
        tool_changes: changes(&tool),
        turns: changes(&|hole: &HoleAnswer| usize::from(hole.turned))
            + usize::from(order.first().is_some_and(|&i| loops[i].turned)),
    };
    let mut slots: Vec<Option<HoleAnswer>> = loops.into_iter().map(Some).collect();
    let holes: Vec<HoleAnswer> = order.iter().filter_map(|&i| slots[i].take()).collect();
    let legs: Vec<Leg<'_>> =
        holes.iter().map(|hole| Leg { deburr: &hole.result, tool: tool(hole), turned: hole.turned }).collect();
    let cycle_time = context.machine.as_ref().and_then(MachineProfile::dynamics).map(|d| cycle_time(&legs, &d));
    let result = holes[0].result.clone();
    DeburrAnswer {
        tool: context.tool,
        inner_tool,
        machine: context.machine,
        cycle_time,
        holes: Some(holes),
        visiting_order: Some(visiting_order),
        result,
        verification: None,
    }
}

/// The loops of a several-loop answer as the program visits them, and the tool call of each
/// tool: `tool`, then `inner_tool` when it is another tool.
fn legs<'a>(answer: &'a DeburrAnswer, holes: &'a [HoleAnswer]) -> (Vec<Leg<'a>>, Vec<ToolCall>) {
    let another = answer.inner_tool.as_ref().filter(|inner| **inner != answer.tool);
    let legs = holes
        .iter()
        .map(|hole| Leg {
            deburr: &hole.result,
            tool: usize::from(another.is_some() && hole.tool_field == "inner_tool"),
            turned: hole.turned,
        })
        .collect();
    let tools = std::iter::once(&answer.tool).chain(another).map(ToolCall::for_tool).collect();
    (legs, tools)
}

/// The cycle time of the deburring program: the moves the program makes (each loop's approach,
/// loop and way out, the travel between loops over the clearance plane), the loops cutting at
/// the deburring feed and every other move in the air (the program's moves down run in air at
/// that feed too), one tool change per tool (the operator's turns of the tube are not timed).
fn cycle_time(legs: &[Leg<'_>], dynamics: &Dynamics) -> CycleTime {
    use crate::path::Motion;
    let visit = super::program::visit(legs, Reference::Tip);
    let steps: Vec<Step> = visit
        .path
        .moves
        .iter()
        .zip(&visit.air)
        .map(|(step, air)| match step.motion {
            Motion::Rapid => Step::Rapid(step.to),
            Motion::Linear { feed } | Motion::Arc { feed, .. } => Step::Feed { to: step.to, feed, air: *air },
        })
        .collect();
    let start = visit.path.moves.first().map_or_else(Vec3::zeros, |step| step.to);
    let mut tools: Vec<usize> = legs.iter().map(|leg| leg.tool).collect();
    tools.dedup();
    crate::machine::cycle::cycle_time(start, &steps, dynamics, tools.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_json_is_within_its_bound() {
        // The longest number serde writes (ryu) and the longest segment name.
        let longest = -2.225_073_858_507_201_4e-308;
        let point = DeburrPoint {
            target: [longest; 3],
            centre: [longest; 3],
            tip: [longest; 3],
            wedge_angle_deg: longest,
            segment: "line_y+x",
            parameter: longest,
            phi_deg: Some(longest),
            centre_offset: longest,
        };
        let json = serde_json::to_vec(&point).unwrap();
        assert_eq!(serde_json::to_string(&longest).unwrap().len(), 24);
        // With the comma that separates it from the next point.
        assert!((json.len() as u64) < POINT_JSON_BYTES, "{} bytes: {}", json.len(), String::from_utf8_lossy(&json));
    }

    #[test]
    fn loop_bound_holds_the_reference_case() {
        // Reference case 1 at both edges of two holes: four loops and the first again at the top.
        let request: DeburrRequest = serde_json::from_value(serde_json::json!({
            "tool": {"kind": "ball", "radius": 3},
            "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
            "holes": [{"shape": "round", "radius": 10}, {"shape": "round", "radius": 6, "axial_position": 40}],
            "edge": "both", "cut_amount": 0.5
        }))
        .unwrap();
        let crate::tool::ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        let context = Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() };
        let answer = DeburrCapability::solve(&request, context.clone(), &Run::default()).unwrap();
        let holes = answer.holes.as_ref().unwrap();
        let json = serde_json::to_vec(&answer).unwrap().len() as u64;
        let program = crate::capability::program::<DeburrCapability>(
            &request,
            &answer,
            &OutputOptions::default(),
            Control::default(),
        )
        .unwrap()
        .len() as u64;
        let points: u64 = holes.iter().map(|hole| hole.result.points.len() as u64).sum();
        let memory = (points + answer.result.points.len() as u64) * POINT_BYTES;
        for (purpose, built) in [
            (Purpose::Json, memory + json),
            (Purpose::Program, memory + program),
            (Purpose::Job, memory + json + program),
        ] {
            let bound = DeburrCapability::answer_bound(&request, &context, purpose).unwrap();
            assert!(built <= bound, "{purpose:?}: {built} over the bound {bound}");
            // What the loops are charged (the first twice) covers what is built.
            let charged: u64 = holes.iter().map(|hole| loop_bytes(&hole.result, purpose)).sum::<u64>()
                + loop_bytes(&holes[0].result, purpose)
                + ANSWER_BYTES;
            assert!(built <= charged, "{purpose:?}: {built} over the charge {charged}");
            for hole in holes {
                let (bytes, bound) = (loop_bytes(&hole.result, purpose), loop_bound(hole.result.points.len(), purpose));
                assert!(bytes <= bound, "{purpose:?}: a loop of {bytes} bytes over its bound {bound}");
            }
        }
    }

    /// Reference case 1 of docs/spec/deburr.md: a Ø20 hole in a tube of radii 40 and 50, ball R3,
    /// Q 0.5.
    fn reference() -> DeburrRequest {
        serde_json::from_value(serde_json::json!({
            "tool": {"kind": "ball", "radius": 3},
            "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
            "hole": {"shape": "round", "radius": 10},
            "edge": "outer", "cut_amount": 0.5
        }))
        .unwrap()
    }

    fn context(request: &DeburrRequest) -> Resolved<Tool> {
        let crate::tool::ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() }
    }

    fn fanuc(request: &DeburrRequest, answer: &DeburrAnswer) -> String {
        let output = OutputOptions { dialect: Some(crate::gcode::Dialect::Fanuc), ..OutputOptions::default() };
        crate::capability::program::<DeburrCapability>(request, answer, &output, Control::default()).unwrap()
    }

    /// The inside ridge with a lollipop cutter (a Ø3 neck): a plain ball's flutes above the ball
    /// cut into the hole wall on the way out to the bore (found as gouges at the lines of the
    /// move out and the loop).
    #[test]
    fn the_reference_chamfer_cuts_clean_on_its_own_model() {
        for edge in ["outer", "inner", "both"] {
            let mut request = reference();
            request.edge = serde_json::from_value(serde_json::json!(edge)).unwrap();
            request.tool =
                serde_json::from_value(serde_json::json!({"kind": "ball", "radius": 3, "neck_radius": 1.5})).unwrap();
            let answer = DeburrCapability::solve(&request, context(&request), &Run::default()).unwrap();
            let verification = answer.verification.as_ref().expect("verified");
            assert!(verification.ok, "{edge}: {:#?}", verification.findings);
            // The band: W long in section, about Q² / 2 in area, around the ridge (2π·10 long).
            let band = verification.stock_volume_mm3 - verification.part_volume_mm3;
            let removed = verification.removed_volume_mm3;
            assert!(band > 0.0 && removed >= band, "{edge}: band {band}, removed {removed}");
            assert!(!fanuc(&request, &answer).contains("WARNING"));
        }
        let mut plain = reference();
        plain.edge = Edge::Inner;
        let answer = DeburrCapability::solve(&plain, context(&plain), &Run::default()).unwrap();
        let verification = answer.verification.as_ref().unwrap();
        assert!(verification.findings.iter().any(|f| f.kind == crate::verify::FindingKind::Gouge));
        assert!(answer.result.warnings.iter().any(|warning| warning.code == "W_VERIFY_GOUGE"));
    }

    /// The loop's centres 0.3 mm lower than solved: the ball cuts past the chamfer into the
    /// part, warned and written in the program's header at the lines of the program.
    #[test]
    fn a_loop_run_too_deep_gouges() {
        let request = reference();
        let context = context(&request);
        let model = own_model(&request, &context).unwrap();
        let mut answer = solve_unverified(&request, context, &Run::default()).unwrap();
        for point in &mut answer.result.points {
            point.centre[2] -= 0.3;
        }
        let unverified = fanuc(&request, &answer);
        let answer = verified(&request, model, answer, &Run::default()).unwrap();
        let verification = answer.verification.as_ref().unwrap();
        let gouge = verification.findings.iter().find(|f| f.kind == crate::verify::FindingKind::Gouge);
        let gouge = gouge.unwrap_or_else(|| panic!("{:#?}", verification.findings));
        assert!(answer.result.warnings.iter().any(|warning| warning.code == "W_VERIFY_GOUGE"));
        let program = fanuc(&request, &answer);
        let line = gouge.line.unwrap();
        assert!(program.contains(&format!("(WARNING GOUGE AT LINE {line}: ")), "{program}");
        let (lines, before): (Vec<&str>, Vec<&str>) = (program.lines().collect(), unverified.lines().collect());
        let added = lines.len() - before.len();
        assert_eq!(lines[line - 1], before[line - 1 - added]);
        assert!(lines[line - 1].starts_with("G01"), "{}", lines[line - 1]);
    }
}
