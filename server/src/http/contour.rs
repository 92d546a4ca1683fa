//! `POST /api/v1/contour` (api.md, Contour): layered contour milling with corner loops and
//! inside-corner relief, as JSON or G-code; and `POST /api/v1/contour/loops`: corner loops added
//! to a closed tool-centre path made elsewhere (corners.md §3.4, claims 8–10), as JSON.

use axum::Json;
use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::{IntoResponse, Response};
use kerf_solver::chord::MachineProfile;
use kerf_solver::corners::detect::{self, DetectMode, MaterialSide, PathLoopAnswer, PathLoopRequest};
use kerf_solver::corners::{self, ContourAnswer, ContourRequest, CornerLoop};
use kerf_solver::gcode::{Dialect, Post, Reference, ToolCall};
use kerf_solver::tool::{Tool, ToolRef};
use kerf_solver::{SolverError, Warning};
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Output, OutputQuery, gcode_response};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;
use crate::store;

/// Most moves in a JSON answer (about 35 MB of JSON). A G-code program and a job may hold up to
/// the solver's own limit, [`corners::request::MAX_MOVES`].
pub const MAX_JSON_MOVES: usize = 500_000;

/// The contour answer: the tool used and the solver's result.
#[derive(Debug, Serialize, ToSchema)]
pub struct ContourResult {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// The machine the request named, as registered: its block time (and margin, minimum chord
    /// error) chorded the arcs, its dialect is the G-code default.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// Layers with their moves, corners, passes, summary and warnings.
    #[serde(flatten)]
    pub result: ContourAnswer,
}

/// Layered contour milling: the tool-centre path of every layer with corner loops at protruding
/// corners and optional relief at inside corners.
///
/// Returns the layers' moves, the corners with their actions and the material left or cut
/// (JSON, at most 500 000 moves), or with `Accept: text/x-gcode` / `?format=gcode` a complete
/// program (up to the solver's limit of 6 000 000 moves; dialect from `?dialect=`, else the
/// named machine's, else Fanuc). With `block_time_ms` or a `machine` the arcs are chorded by the
/// block-time rule and the summary reports the blocks.
#[utoipa::path(post, path = "/api/v1/contour", tag = "contour",
    params(OutputQuery),
    request_body = ContourRequest,
    responses(
        (status = 200, description = "The path as JSON", body = ContourResult),
        (status = 200, description = "The program (`?format=gcode`)", body = String, content_type = "text/x-gcode"),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number or machine", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible contour or over a limit (codes in corners.md §5; `E_TOO_MANY_MOVES` for answers over the move limit); `E_TIMEOUT` over the synchronous time limit: submit a job", body = Problem, content_type = "application/problem+json")))]
async fn post_contour(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<OutputQuery>,
    AppJson(request): AppJson<ContourRequest>,
) -> AppResult<Response> {
    let output = Output::negotiate(&headers, &query);
    let tool = store::tools::resolve(&state.db, &request.tool).await?;
    let machine = store::machines::resolve(&state.db, request.machine.as_deref()).await?;
    if output.gcode {
        let answer = state.solve(move || run(&request, tool, machine, corners::request::MAX_MOVES)).await??;
        let dialect = super::machines::dialect(output.dialect, answer.machine.as_ref());
        return Ok(gcode_response(program(&answer, dialect, output.reference)?));
    }
    let answer = state.solve(move || run(&request, tool, machine, MAX_JSON_MOVES)).await?.map_err(json_limit_advice)?;
    Ok(Json(answer).into_response())
}

/// A JSON answer over [`MAX_JSON_MOVES`] gets the advice to ask for G-code or submit a job.
fn json_limit_advice(error: SolverError) -> SolverError {
    if error.code() != "E_TOO_MANY_MOVES" {
        return error;
    }
    let advice = format!(
        "{} (a JSON answer holds at most {MAX_JSON_MOVES} moves; ask for G-code with Accept: text/x-gcode or \
         ?format=gcode, or submit a job (POST /api/v1/jobs), which allow up to {} moves)",
        error.message(),
        corners::request::MAX_MOVES
    );
    let field = error.field().map(str::to_owned);
    let advised = SolverError::new(error.code(), advice);
    match field {
        Some(field) => advised.at(field),
        None => advised,
    }
}

/// Solves a contour request with its resolved tool and machine, refusing answers over
/// `max_moves` moves (used by the route and by jobs).
pub fn run(
    request: &ContourRequest,
    tool: Tool,
    machine: Option<MachineProfile>,
    max_moves: usize,
) -> Result<ContourResult, SolverError> {
    let result = corners::solve_with(request, &tool, machine.as_ref(), max_moves)?;
    Ok(ContourResult { tool, machine, result })
}

/// Keeps a stored JSON result (a job's) within [`MAX_JSON_MOVES`]: from the first layer that
/// would pass the limit on, layers keep their `z` but lose their moves, and a
/// `W_MOVES_NOT_STORED` warning says so (the G-code program, written before, has every move).
pub fn limit_stored_moves(answer: &mut ContourResult) {
    let total = answer.result.summary.moves;
    if total <= MAX_JSON_MOVES {
        return;
    }
    let mut kept = 0;
    let mut first_dropped = None;
    for (index, layer) in answer.result.layers.iter_mut().enumerate() {
        if first_dropped.is_some() || kept + layer.moves.len() > MAX_JSON_MOVES {
            first_dropped.get_or_insert(index);
            layer.moves = Vec::new();
        } else {
            kept += layer.moves.len();
        }
    }
    if let Some(first) = first_dropped {
        let layers = answer.result.layers.len();
        answer.result.warnings.push(Warning::new(
            "W_MOVES_NOT_STORED",
            format!(
                "the answer has {total} moves, more than the {MAX_JSON_MOVES} a stored JSON result holds: layers {first} to \
                 {} are listed without their moves; the G-code program has every move",
                layers - 1
            ),
        ));
    }
}

/// The G-code program of a solved contour request.
pub fn program(answer: &ContourResult, dialect: Dialect, reference: Reference) -> Result<String, SolverError> {
    let post = Post { dialect, reference, tool: ToolCall::for_tool(&answer.tool) };
    corners::program(&answer.result, &post)
}

/// `POST /api/v1/contour/loops`: a closed tool-centre path made elsewhere, whose corners get
/// loops (corners.md §3.4, claims 8–10).
#[derive(Debug, Clone, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct LoopsRequest {
    /// A registered tool number or an inline tool; its `radius` sizes the loops.
    pub tool: ToolRef,
    /// The closed path `[[x, y], ...]` of the tool centre in travel order (the last point need
    /// not repeat the first; at most 200 000 points).
    pub path: Vec<[f64; 2]>,
    /// `left` (default) or `right` of travel: where the material lies.
    #[serde(default)]
    pub material_side: MaterialSide,
    /// `turn_angle` (default), `patent_curvature` (claim 8) or `patent_delta_l` (claim 9).
    #[serde(default)]
    pub detect: DetectMode,
    /// Threshold of the mode: ψ_min in degrees for `turn_angle` (default 10), κ_th in 1/mm for
    /// `patent_curvature` (default 1/tool radius), λ_th for `patent_delta_l` (default sin 5°).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<f64>,
    /// Loop style and sizing, as for contours.
    #[serde(default)]
    pub corner_loop: CornerLoop,
    /// Chord tolerance of loop arcs, mm (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
}

/// The only answer format of the loops endpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JsonOnly {
    /// The JSON answer.
    Json,
}

/// Query parameters of the loops endpoint: `?format=gcode` is refused (the path has no heights
/// or feeds for a program).
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct LoopsQuery {
    /// `json`, the only format.
    pub format: Option<JsonOnly>,
}

/// The looped path: the tool used and the solver's result.
#[derive(Debug, Serialize, ToSchema)]
pub struct LoopsResult {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// Detection measures per point, the looped path and the claim-10 check.
    #[serde(flatten)]
    pub result: PathLoopAnswer,
}

/// Corner loops on an existing tool path: finds the protruding corners of a closed tool-centre
/// path (turn angle, or the patent's curvature or radial-difference rules) and loops round them.
///
/// JSON only: the path has no heights or feeds, so its moves go into the client's own program.
/// At most 500 000 moves.
#[utoipa::path(post, path = "/api/v1/contour/loops", tag = "contour",
    params(LoopsQuery),
    request_body = LoopsRequest,
    responses(
        (status = 200, description = "The looped path", body = LoopsResult),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad numbers, a degenerate path, or over a limit; `E_TIMEOUT` over the synchronous time limit", body = Problem, content_type = "application/problem+json")))]
async fn post_loops(
    State(state): State<AppState>,
    AppQuery(_query): AppQuery<LoopsQuery>,
    AppJson(request): AppJson<LoopsRequest>,
) -> AppResult<Json<LoopsResult>> {
    let tool = store::tools::resolve(&state.db, &request.tool).await?;
    let answer = state.solve(move || run_loops(&request, tool)).await??;
    Ok(Json(answer))
}

/// Adds loops to the request's path with its resolved tool.
pub fn run_loops(request: &LoopsRequest, tool: Tool) -> Result<LoopsResult, SolverError> {
    tool.validate("tool.")?;
    let path_request = PathLoopRequest {
        path: request.path.clone(),
        material_side: request.material_side,
        detect: request.detect,
        threshold: request.threshold,
        tool_radius: tool.radius,
        corner_loop: request.corner_loop.clone(),
        tolerance: request.tolerance,
    };
    let result = detect::loop_path_within(&path_request, MAX_JSON_MOVES)?;
    Ok(LoopsResult { tool, result })
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_contour)).routes(routes!(post_loops))
}
