//! Deburring as a capability (the seam of engineering.md): `POST /api/v1/deburr`, job operation
//! `deburr`.

use serde::Serialize;

use super::{Deburr, DeburrRequest};
use crate::capability::{Capability, OutputOptions, Refs, Resolved, Run};
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
    /// The loop of centres, leads, summary and warnings.
    #[serde(flatten)]
    pub result: Deburr,
}

impl Capability for DeburrCapability {
    const NAME: &'static str = "deburr";
    type Request = DeburrRequest;
    type Answer = DeburrAnswer;
    type Tool = Tool;

    fn refs(request: &DeburrRequest) -> Refs<'_> {
        Refs { tool: Some(&request.tool), machine: request.machine.as_deref() }
    }

    fn solve(request: &DeburrRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<DeburrAnswer, SolverError> {
        let result = super::solve_controlled(request, &context.tool, context.machine.as_ref(), run.control)?;
        let cycle_time = context.machine.as_ref().and_then(MachineProfile::dynamics).map(|d| cycle_time(&result, &d));
        Ok(DeburrAnswer { tool: context.tool, machine: context.machine, cycle_time, result })
    }

    fn program(_request: &DeburrRequest, answer: &DeburrAnswer, output: &OutputOptions) -> Result<String, SolverError> {
        let post = output.post(answer.machine.as_ref(), &answer.tool);
        super::program(&answer.result, &post)
    }

    fn machine(answer: &DeburrAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }
}

/// The cycle time of the deburring program: the leads' feed moves in the air, the loop cutting
/// at the deburring feed (the program's moves down run in air at that feed too), one tool change.
fn cycle_time(result: &Deburr, dynamics: &Dynamics) -> CycleTime {
    use super::LeadMotion;
    let feed = result.summary.feed;
    let lead = |step: &super::LeadMove| {
        let to = Vec3::from(step.centre);
        match step.motion {
            LeadMotion::Rapid => Step::Rapid(to),
            LeadMotion::Feed => Step::Feed { to, feed, air: true },
        }
    };
    let mut steps: Vec<Step> = result.lead_in.iter().map(lead).collect();
    steps.extend(result.points.iter().skip(1).map(|p| Step::Feed { to: Vec3::from(p.centre), feed, air: false }));
    steps.extend(result.lead_out.iter().map(lead));
    let start = result.lead_in.first().map_or_else(Vec3::zeros, |step| Vec3::from(step.centre));
    crate::machine::cycle::cycle_time(start, &steps, dynamics, 1)
}
