//! `POST /api/v1/segment` (api.md, Segment; chord.md): a curve cut into G01 blocks whose chord
//! error follows the control's block processing time, as JSON or G-code.

use axum::Json;
use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::{IntoResponse, Response};
use kerf_solver::SolverError;
use kerf_solver::chord::{self, MachineProfile, SegmentAnswer, SegmentRequest};
use kerf_solver::gcode::{Dialect, Post, Reference, ToolCall};
use kerf_solver::tool::Tool;
use serde::Serialize;
use utoipa::ToSchema;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Output, OutputQuery, gcode_response};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;
use crate::store;

/// The segment answer: the machine and tool used, and the solver's result.
#[derive(Debug, Serialize, ToSchema)]
pub struct SegmentResult {
    /// The machine the request named, as registered: its values are the defaults the request
    /// overrode or used (the values used are `feed`, `block_time_ms`, `margin`, `min_chord_error`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// The tool the program calls, as resolved from the table or given inline.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tool: Option<Tool>,
    /// Windows, command points, block figures, the comparison and warnings.
    #[serde(flatten)]
    pub result: SegmentAnswer,
}

/// Cuts a curve into G01 blocks by the block-time rule.
///
/// Returns the command points with the chord error per window and the block figures (JSON), or
/// with `Accept: text/x-gcode` / `?format=gcode` a complete program of G01 blocks with the F word
/// (dialect from `?dialect=`, else the named machine's, else Fanuc; `reference` does not apply:
/// the curve is the programmed point).
#[utoipa::path(post, path = "/api/v1/segment", tag = "segment",
    params(OutputQuery),
    request_body = SegmentRequest,
    responses(
        (status = 200, description = "The blocks as JSON", body = SegmentResult),
        (status = 200, description = "The program (`?format=gcode`)", body = String, content_type = "text/x-gcode"),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown machine or tool number", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible request: `E_INPUT`, `E_DEGENERATE_CURVE`, `E_INFEASIBLE_FEED_FOR_RADIUS` (the message gives the largest feasible feed), `E_TOO_MANY_BLOCKS`, `E_TOO_MANY_POINTS`, `E_NUMERIC_FAILURE`; `E_TIMEOUT` over the synchronous time limit: submit a job", body = Problem, content_type = "application/problem+json")))]
async fn post_segment(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<OutputQuery>,
    AppJson(request): AppJson<SegmentRequest>,
) -> AppResult<Response> {
    let output = Output::negotiate(&headers, &query);
    let machine = store::machines::resolve(&state.db, request.machine.as_deref()).await?;
    let tool = match &request.tool {
        Some(tool) => Some(store::tools::resolve(&state.db, tool).await?),
        None => None,
    };
    let answer = state.solve(move || run(&request, machine, tool)).await??;
    if output.gcode {
        let dialect = super::machines::dialect(output.dialect, answer.machine.as_ref());
        return Ok(gcode_response(program(&answer, dialect)?));
    }
    Ok(Json(answer).into_response())
}

/// Solves a segment request with its resolved machine and tool (used by the route and by jobs).
pub fn run(
    request: &SegmentRequest,
    machine: Option<MachineProfile>,
    tool: Option<Tool>,
) -> Result<SegmentResult, SolverError> {
    if let Some(tool) = &tool {
        tool.validate("tool.")?;
    }
    let result = chord::solve(request, machine.as_ref())?;
    Ok(SegmentResult { machine, tool, result })
}

/// The G-code program of a solved segment request.
pub fn program(answer: &SegmentResult, dialect: Dialect) -> Result<String, SolverError> {
    let tool = match &answer.tool {
        Some(tool) => ToolCall::for_tool(tool),
        None => ToolCall::Manual("none named in the request".to_owned()),
    };
    chord::program(&answer.result, &Post { dialect, reference: Reference::Tip, tool })
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_segment))
}
