//! `POST /api/v1/engagement` (api.md, Engagement): tool–workpiece contact along one path or
//! several candidate paths, chip thickness per flute count, time and the recommended flute
//! counts, as JSON; or the G-code of one path with the chip-thinning feed plan's F words.

use axum::Json;
use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::{IntoResponse, Response};
use kerf_solver::SolverError;
use kerf_solver::chord::MachineProfile;
use kerf_solver::engagement::{self, EngagementAnswer, EngagementRequest, Stock};
use kerf_solver::gcode::{Dialect, Post, Reference, ToolCall};
use kerf_solver::tool::Tool;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Format, Output, OutputQuery, gcode_response};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;
use crate::store;

/// The engagement answer: the tool used, the stock and limits it was judged against (so the
/// answer can be plotted on its own, as the page does for job results), and the solver's result
/// (one path's fields at the top level for a request with `path`, `candidates` for a request
/// with `paths`).
#[derive(Debug, Serialize, ToSchema)]
pub struct EngagementResponse {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// The machine the request named, as registered: its `max_feed` caps the feed plan unless
    /// `feed_plan.max_feed` is given, its dialect is the G-code default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// The stock, as given.
    pub stock: Stock,
    /// T1 as given, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thickness_limit: Option<f64>,
    /// T2 as given, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_limit_s: Option<f64>,
    /// Samples, flute counts and recommendation (or `candidates`, one such result per path).
    #[serde(flatten)]
    pub result: EngagementAnswer,
}

/// Query parameters of `POST /api/v1/engagement`.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct EngagementQuery {
    /// `json` (default) or `gcode`; `Accept: text/x-gcode` also selects G-code.
    pub format: Option<Format>,
    /// G-code dialect: `fanuc` or `linuxcnc` (default: the named machine's, else `fanuc`).
    pub dialect: Option<Dialect>,
    /// Programmed point: `tip` (default; length offset to the tool tip) or `centre` (the centre
    /// of the tool's end rounding: the ball centre, the bull-nose corner centre, the tip for a
    /// flat end mill).
    pub reference: Option<Reference>,
    /// G-code only: which entry of `paths` to program (0-based, default 0); a request with
    /// `path` has only candidate 0.
    pub candidate: Option<usize>,
}

/// Analyses the tool–workpiece engagement along a tool path and recommends flute counts.
///
/// Moves the tool's cutting circle along the path over the stock and returns, per sample, the
/// engaged arcs (tool angle: 90° ahead, 0° right, 180° left of travel), the radial depth and the
/// summed chip thickness of every candidate flute count; per flute count the representative
/// thicknesses, the machining time and whether it meets `thickness_limit` and `time_limit_s`.
/// `paths` compares several candidate paths side by side. With `Accept: text/x-gcode` or
/// `?format=gcode` (and `axial_depth`) it returns the program of one path (`?candidate=`) at the
/// feeds of `feed_plan` (chip-thinning compensation) or at the nominal feed. A `machine`
/// supplies `feed_plan.max_feed` and the dialect.
#[utoipa::path(post, path = "/api/v1/engagement", tag = "engagement",
    params(EngagementQuery),
    request_body = EngagementRequest,
    responses(
        (status = 200, description = "The engagement analysis as JSON", body = EngagementResponse),
        (status = 200, description = "The program of one path (`?format=gcode`)", body = String, content_type = "text/x-gcode"),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number or machine", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible or over a limit: `E_INPUT`, `E_PATH`, `E_STOCK`, `E_TOO_LARGE`, \
            `E_TOO_MANY_SAMPLES`, `E_GRID_MEMORY`, `E_WORK_LIMIT` (engagement.md §9); `E_TIMEOUT` over the synchronous \
            time limit: submit a job",
            body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json")))]
async fn post_engagement(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<EngagementQuery>,
    AppJson(request): AppJson<EngagementRequest>,
) -> AppResult<Response> {
    let output = Output::negotiate(
        &headers,
        &OutputQuery { format: query.format, dialect: query.dialect, reference: query.reference },
    );
    let tool = store::tools::resolve(&state.db, &request.tool).await?;
    let machine = store::machines::resolve(&state.db, request.machine.as_deref()).await?;
    let answer = state.solve(move || run(&request, tool, machine)).await??;
    if output.gcode {
        let candidate = query.candidate.unwrap_or(0);
        let dialect = super::machines::dialect(output.dialect, answer.machine.as_ref());
        return Ok(gcode_response(program(&answer, candidate, dialect, output.reference)?));
    }
    Ok(Json(answer).into_response())
}

/// Solves an engagement request with its resolved tool and machine (used by the route and by
/// jobs).
pub fn run(
    request: &EngagementRequest,
    tool: Tool,
    machine: Option<MachineProfile>,
) -> Result<EngagementResponse, SolverError> {
    let result = engagement::solve_with(request, &tool, machine.as_ref())?;
    Ok(EngagementResponse {
        tool,
        machine,
        stock: request.stock.clone(),
        thickness_limit: request.thickness_limit,
        time_limit_s: request.time_limit_s,
        result,
    })
}

/// The G-code program of candidate `candidate` of a solved engagement request.
pub fn program(
    answer: &EngagementResponse,
    candidate: usize,
    dialect: Dialect,
    reference: Reference,
) -> Result<String, SolverError> {
    let post = Post { dialect, reference, tool: ToolCall::for_tool(&answer.tool) };
    engagement::program(&answer.result, candidate, &post)
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_engagement))
}
