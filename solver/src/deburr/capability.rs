//! Deburring as a capability (the seam of engineering.md): `POST /api/v1/deburr`, job operation
//! `deburr`.

use serde::Serialize;

use super::{Deburr, DeburrRequest};
use crate::capability::{Capability, Endpoint, OutputOptions, Refs, Resolved, Run};
use crate::error::SolverError;
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
    /// The machine the request named, as registered: its block time (and margin, minimum chord
    /// error) spaced the points, its dialect is the G-code default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// With a machine that has `max_accel`: the time the control would take for the program
    /// (trapezoidal feed profile, stops at sharp vertices, rapids at `rapid_feed`, one tool
    /// change) and its parts: cutting (the loop), air (the leads), rapid, tool change (issue 15).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_time: Option<CycleTime>,
    /// With `holes` or `pattern`: every hole in the order the program visits them (the fields
    /// beside it are those of the first).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub holes: Option<Vec<HoleAnswer>>,
    /// The loop of centres, leads, summary and warnings.
    #[serde(flatten)]
    pub result: Deburr,
}

/// One hole of a several-hole answer.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct HoleAnswer {
    /// Where its fields are in the request: `holes[i]`, or `hole` for a pattern's copies.
    pub field: String,
    /// Its penetration angle θ_P, degrees.
    pub penetration_angle_deg: f64,
    /// Its arrangement angle θ_A, degrees.
    pub arrangement_angle_deg: f64,
    /// Its position along the cylinder axis from `workpiece.origin`, mm.
    pub axial_position: f64,
    /// Its loop of centres, leads, summary and warnings.
    #[serde(flatten)]
    pub result: Deburr,
}

impl Capability for DeburrCapability {
    const NAME: &'static str = "deburr";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Deburrs one ridge of a cross hole with a ball end mill.",
        description: "Returns the closed loop of ball centres in machining order (JSON), or with `Accept: \
            text/x-gcode` / `?format=gcode` a complete program (dialect from `?dialect=`, else the \
            named machine's, else Fanuc). With `block_time_ms` or a `machine` the points follow the \
            block-time rule at `feed` (never coarser than `tolerance`) and the summary reports the \
            blocks.",
        not_found: "Unknown tool number or machine",
        refused: "Impossible geometry (codes in deburr.md §4); `E_TIMEOUT` over the synchronous time \
            limit: submit a job",
    };
    type Request = DeburrRequest;
    type Answer = DeburrAnswer;
    type Tool = Tool;

    fn refs(request: &DeburrRequest) -> Refs<'_> {
        Refs { tool: Some(&request.tool), machine: request.machine.as_deref(), material: None }
    }

    fn solve(request: &DeburrRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<DeburrAnswer, SolverError> {
        if !request.is_several() {
            let result = super::solve_controlled(request, &context.tool, context.machine.as_ref(), run.control)?;
            let cycle_time =
                context.machine.as_ref().and_then(MachineProfile::dynamics).map(|d| cycle_time(&[&result], &d));
            return Ok(DeburrAnswer { tool: context.tool, machine: context.machine, cycle_time, holes: None, result });
        }
        let mut holes = Vec::new();
        for placement in request.placements()? {
            run.control.check()?;
            let result =
                super::solve_controlled(&placement.request, &context.tool, context.machine.as_ref(), run.control)
                    .map_err(|error| match error.field() {
                        // A hole's own field: named where the request has it.
                        Some(field) if placement.field != "hole" && field.starts_with("hole.") => {
                            let inner = field.trim_start_matches("hole.").to_owned();
                            error.at(format!("{}.{inner}", placement.field))
                        }
                        _ => error,
                    })?;
            holes.push(HoleAnswer {
                field: placement.field,
                penetration_angle_deg: placement.penetration_angle_deg,
                arrangement_angle_deg: placement.arrangement_angle_deg,
                axial_position: placement.axial_position,
                result,
            });
        }
        let results: Vec<&Deburr> = holes.iter().map(|hole| &hole.result).collect();
        let cycle_time = context.machine.as_ref().and_then(MachineProfile::dynamics).map(|d| cycle_time(&results, &d));
        let result = holes[0].result.clone();
        Ok(DeburrAnswer { tool: context.tool, machine: context.machine, cycle_time, holes: Some(holes), result })
    }

    fn program(_request: &DeburrRequest, answer: &DeburrAnswer, output: &OutputOptions) -> Result<String, SolverError> {
        let post = output.post(answer.machine.as_ref(), &answer.tool);
        match &answer.holes {
            Some(holes) => {
                let results: Vec<&Deburr> = holes.iter().map(|hole| &hole.result).collect();
                super::program::program_for_holes(&results, &post)
            }
            None => super::program(&answer.result, &post),
        }
    }

    fn machine(answer: &DeburrAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }
}

/// The cycle time of the deburring program: the leads' feed moves in the air, each loop cutting
/// at the deburring feed (the program's moves down run in air at that feed too), one tool change.
/// Between holes the path goes straight from one way out to the next approach (the program lifts
/// to the highest clearance plane first: the same length when the planes agree).
fn cycle_time(holes: &[&Deburr], dynamics: &Dynamics) -> CycleTime {
    use super::LeadMotion;
    let mut steps = Vec::new();
    for hole in holes {
        let feed = hole.summary.feed;
        let lead = |step: &super::LeadMove| {
            let to = Vec3::from(step.centre);
            match step.motion {
                LeadMotion::Rapid => Step::Rapid(to),
                LeadMotion::Feed => Step::Feed { to, feed, air: true },
            }
        };
        steps.extend(hole.lead_in.iter().map(lead));
        steps.extend(hole.points.iter().skip(1).map(|p| Step::Feed { to: Vec3::from(p.centre), feed, air: false }));
        steps.extend(hole.lead_out.iter().map(lead));
    }
    let start =
        holes.first().and_then(|hole| hole.lead_in.first()).map_or_else(Vec3::zeros, |step| Vec3::from(step.centre));
    crate::machine::cycle::cycle_time(start, &steps, dynamics, 1)
}
