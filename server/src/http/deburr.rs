//! `POST /api/v1/deburr` (api.md, Deburr): cross-hole deburring, as JSON or G-code.

use axum::Json;
use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::{IntoResponse, Response};
use kerf_solver::SolverError;
use kerf_solver::chord::MachineProfile;
use kerf_solver::deburr::{self, Deburr, DeburrRequest};
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

/// The deburr answer: the tool used and the solver's result.
#[derive(Debug, Serialize, ToSchema)]
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

/// Deburrs one ridge of a cross hole with a ball end mill.
///
/// Returns the closed loop of ball centres in machining order (JSON), or with
/// `Accept: text/x-gcode` / `?format=gcode` a complete program (dialect from `?dialect=`, else
/// the named machine's, else Fanuc). With `block_time_ms` or a `machine` the points follow the
/// block-time rule at `feed` (never coarser than `tolerance`) and the summary reports the blocks.
#[utoipa::path(post, path = "/api/v1/deburr", tag = "deburr",
    params(OutputQuery),
    request_body = DeburrRequest,
    responses(
        (status = 200, description = "The path as JSON", body = DeburrAnswer),
        (status = 200, description = "The program (`?format=gcode`)", body = String, content_type = "text/x-gcode"),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number or machine", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible geometry (codes in deburr.md §4); `E_TIMEOUT` over the synchronous time limit: submit a job", body = Problem, content_type = "application/problem+json")))]
async fn post_deburr(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<OutputQuery>,
    AppJson(request): AppJson<DeburrRequest>,
) -> AppResult<Response> {
    let output = Output::negotiate(&headers, &query);
    let tool = store::tools::resolve(&state.db, &request.tool).await?;
    let machine = store::machines::resolve(&state.db, request.machine.as_deref()).await?;
    let answer = state.solve(move || run(&request, tool, machine)).await??;
    if output.gcode {
        let dialect = super::machines::dialect(output.dialect, answer.machine.as_ref());
        return Ok(gcode_response(program(&answer, dialect, output.reference)?));
    }
    Ok(Json(answer).into_response())
}

/// Solves a deburr request with its resolved tool and machine (used by the route and by jobs).
pub fn run(request: &DeburrRequest, tool: Tool, machine: Option<MachineProfile>) -> Result<DeburrAnswer, SolverError> {
    let result = deburr::solve_with(request, &tool, machine.as_ref())?;
    Ok(DeburrAnswer { tool, machine, result })
}

/// The G-code program of a solved deburr request.
pub fn program(answer: &DeburrAnswer, dialect: Dialect, reference: Reference) -> Result<String, SolverError> {
    let post = Post { dialect, reference, tool: ToolCall::for_tool(&answer.tool) };
    deburr::program(&answer.result, &post)
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_deburr))
}
