//! Deburring as a capability (the seam of engineering.md): `POST /api/v1/deburr`, job operation
//! `deburr`.

use serde::Serialize;

use super::{Deburr, DeburrRequest};
use crate::capability::{Capability, OutputOptions, Refs, Resolved, Run};
use crate::error::SolverError;
use crate::machine::MachineProfile;
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
        Refs { tool: Some(&request.tool), machine: request.machine.as_deref(), material: None }
    }

    fn solve(request: &DeburrRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<DeburrAnswer, SolverError> {
        let result = super::solve_controlled(request, &context.tool, context.machine.as_ref(), run.control)?;
        Ok(DeburrAnswer { tool: context.tool, machine: context.machine, result })
    }

    fn program(_request: &DeburrRequest, answer: &DeburrAnswer, output: &OutputOptions) -> Result<String, SolverError> {
        let post = output.post(answer.machine.as_ref(), &answer.tool);
        super::program(&answer.result, &post)
    }

    fn machine(answer: &DeburrAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }
}
