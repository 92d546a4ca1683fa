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
        Some(loops.saturating_mul(loop_bound(super::MAX_POINTS, purpose)).saturating_add(ANSWER_BYTES))
    }

    fn solve(request: &DeburrRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<DeburrAnswer, SolverError> {
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
        super::parts::finish(request, context, parts, run)
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
}
