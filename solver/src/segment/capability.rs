//! Segmentation as a capability (docs/spec/segment.md, docs/spec/api.md Segment; the seam of
//! engineering.md): `POST /api/v1/segment`, job operation `segment`.

use crate::validate::Measure;
use serde::Serialize;

use super::{SegmentRequest, SegmentSolution};
use crate::capability::{Capability, Control, Endpoint, OutputOptions, Refs, Resolved, Run};
use crate::error::SolverError;
use crate::gcode::{Post, Reference, ToolCall};
use crate::machine::MachineProfile;
use crate::tool::Tool;

/// The segment capability.
#[derive(Debug, Clone, Copy)]
pub struct SegmentCapability;

/// The segment answer: the machine and tool used, and the solver's result.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct SegmentAnswer {
    /// The machine the request named, as registered: its values are the defaults the request
    /// overrode or used (the values used are `feed`, `block_time_ms`, `margin`, `min_chord_error`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// The tool the program calls, as resolved from the table or given inline.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tool: Option<Tool>,
    /// Windows, command points, block figures, the comparison and warnings.
    #[serde(flatten)]
    pub result: SegmentSolution,
    /// With a machine that has `max_accel`: the time the control would take for the program
    /// (the plunge at the plunge feed, the blocks with a trapezoidal feed profile and the block
    /// time, the retract at `rapid_feed`, one tool change when a tool is named) and its parts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_time: Option<crate::machine::cycle::CycleTime>,
}

impl Capability for SegmentCapability {
    const NAME: &'static str = "segment";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Cuts a curve into G01 blocks by the block-time rule.",
        description: "Returns the command points with the chord error per window and the block figures (JSON), \
            or with `Accept: text/x-gcode` / `?format=gcode` a complete program of G01 blocks with \
            the F word (dialect from `?dialect=`, else the named machine's, else Fanuc; `reference` \
            does not apply: the curve is the programmed point).",
        not_found: "Unknown machine or tool number",
        refused: "Impossible request: `E_INPUT`, `E_DEGENERATE_CURVE`, `E_INFEASIBLE_FEED_FOR_RADIUS` (the \
            message gives the largest feasible feed), `E_TOO_MANY_BLOCKS`, `E_TOO_MANY_POINTS`, \
            `E_NUMERIC_FAILURE`; `E_TIMEOUT` over the synchronous time limit: submit a job; `E_TOO_LARGE_ANSWER` when the answer would not fit the answer budget",
    };
    type Request = SegmentRequest;
    type Answer = SegmentAnswer;
    type Tool = Option<Tool>;

    fn refs(request: &SegmentRequest) -> Refs<'_> {
        Refs { tool: request.tool.as_ref(), machine: request.machine.as_deref(), material: None }
    }

    fn solve(
        request: &SegmentRequest,
        context: Resolved<Option<Tool>>,
        run: &Run<'_>,
    ) -> Result<SegmentAnswer, SolverError> {
        if let Some(tool) = &context.tool {
            tool.validate("tool.")?;
        }
        if let Some(feed) = request.plunge_feed {
            crate::validate::positive("plunge_feed", feed, Measure::Feed)?;
        }
        let result = super::solve_run(request, context.machine.as_ref(), run)?;
        let cycle_time = context.machine.as_ref().and_then(|machine| {
            let plunge =
                request.plunge_feed.or(context.tool.as_ref().and_then(|t| t.plunge_feed)).or(machine.plunge_feed);
            super::cycle_time(&result, machine, plunge, context.tool.is_some())
        });
        Ok(SegmentAnswer { machine: context.machine, tool: context.tool, result, cycle_time })
    }

    /// The curve is the programmed point: `reference` does not apply.
    fn program(
        request: &SegmentRequest,
        answer: &SegmentAnswer,
        output: &OutputOptions,
        control: Control<'_>,
    ) -> Result<String, SolverError> {
        let tool = match &answer.tool {
            Some(tool) => ToolCall::for_tool(tool),
            None => ToolCall::Manual("none named in the request".to_owned()),
        };
        let post = Post {
            dialect: output.dialect_for(answer.machine.as_ref()),
            reference: Reference::Tip,
            tool,
            arcs: output.arcs_for(answer.machine.as_ref()),
            plunge_feed: request
                .plunge_feed
                .or(answer.tool.as_ref().and_then(|tool| tool.plunge_feed))
                .or(answer.machine.as_ref().and_then(|m| m.plunge_feed)),
            units: output.units.unwrap_or_default(),
        };
        super::program::program_controlled(&answer.result, &post, control)
    }

    fn units(request: &SegmentRequest) -> Option<crate::units::Units> {
        request.units
    }

    fn scale_request(request: &mut SegmentRequest, scaling: crate::units::Scaling) -> Result<(), SolverError> {
        crate::units::Scale::scale(request, scaling);
        // Its lengths are now mm, but its program is written in the units it came in, and the
        // program's least increment (E13) is 0.0001 of those.
        request.units = Some(scaling.units());
        Ok(())
    }

    fn scale_answer(answer: &mut SegmentAnswer, scaling: crate::units::Scaling) {
        crate::units::Scale::scale(answer, scaling);
    }

    fn machine(answer: &SegmentAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }

    /// Serde's text, the command points written by hand (`wire`).
    fn to_json(answer: SegmentAnswer) -> serde_json::Result<Vec<u8>> {
        super::wire::to_json(answer)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::capability::{AnswerBudget, Purpose};
    use crate::error::ErrorCode;

    #[test]
    fn points_over_the_budget_are_refused_a_block_past_it() {
        // Some 270 000 command points: refused while they are cut, not after.
        let request: SegmentRequest = serde_json::from_value(serde_json::json!({
            "curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [50, 20], "start_deg": 0, "end_deg": 270},
            "feed": 10, "block_time_ms": 4
        }))
        .unwrap();
        let budget = AnswerBudget::new(1 << 20);
        let run = Run { budget: Some(&budget), ..Run::default() };
        let context = Resolved { tool: None, machine: None, material: None, other_tools: Vec::new() };
        let error = SegmentCapability::solve(&request, context, &run).unwrap_err();
        assert_eq!(error.code(), ErrorCode::TooLargeAnswer, "{error}");
        let block = super::super::cut::CHARGED_POINTS as u64 * super::super::answer::point_bound(Purpose::Json);
        assert!(budget.used() <= budget.limit() + block, "{} charged", budget.used());
    }
}
