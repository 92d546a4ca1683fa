//! `POST /api/v1/contour` (api.md, Contour): layered contour milling with corner loops and
//! inside-corner relief, as JSON or G-code; and `POST /api/v1/contour/loops`: corner loops added
//! to a closed tool-centre path made elsewhere (corners.md §3.4, claims 8–10), as JSON.

use axum::Json;
use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::Response;
use kerf_solver::capability::Control;
use kerf_solver::corners::{ContourCapability, ContourRequest, ContourResult, LoopsRequest, LoopsResult};
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Ask, OutputQuery};
use crate::capabilities::{self, Catalog};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;
use crate::store;

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
        (status = 200, description = "The path as JSON, or the program (`?format=gcode`)", content(
            (ContourResult = "application/json"),
            (String = "text/x-gcode"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number or machine", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible contour or over a limit (codes in corners.md §5; `E_TOO_MANY_MOVES` for answers over the move limit); `E_TIMEOUT` over the synchronous time limit: submit a job", body = Problem, content_type = "application/problem+json")))]
async fn post_contour(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<OutputQuery>,
    AppJson(request): AppJson<ContourRequest>,
) -> AppResult<Response> {
    super::solve::answer::<ContourCapability>(&state, request, None, Ask::negotiate(&headers, &query)).await
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
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Bad numbers, a degenerate path, or over a limit; `E_TIMEOUT` over the synchronous time limit", body = Problem, content_type = "application/problem+json")))]
async fn post_loops(
    State(state): State<AppState>,
    AppQuery(_query): AppQuery<LoopsQuery>,
    AppJson(request): AppJson<LoopsRequest>,
) -> AppResult<Json<LoopsResult>> {
    let catalog = store::catalog(&state.db, [request.refs()], Catalog::default()).await?;
    let tool = capabilities::resolve_refs::<kerf_solver::tool::Tool>(request.refs(), &catalog)?.tool;
    let answer =
        state.solve(move |cancel| request.solve(tool, Control { progress: None, cancel: Some(cancel) })).await??;
    Ok(Json(answer))
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_contour)).routes(routes!(post_loops))
}
