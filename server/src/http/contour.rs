//! `POST /api/v1/contour/loops` (docs/spec/api.md, Contour): corner loops added to a closed tool-centre path
//! made elsewhere (docs/spec/contour.md §3.4, claims 8–10), as JSON. `POST /api/v1/contour` is the contour
//! capability's endpoint, generated in `endpoints`.

use axum::Json;
use axum::extract::State;
use kerf_solver::capability::Control;
use kerf_solver::contour::{LoopsAnswer, LoopsRequest};
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::capabilities::{self, Catalog};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;

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
#[utoipa::path(post, path = "/api/v1/contour/loops", tag = "contour", operation_id = "contour_loops",
    params(LoopsQuery),
    request_body = LoopsRequest,
    responses(
        (status = 200, description = "The looped path", body = LoopsAnswer),
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
) -> AppResult<Json<LoopsAnswer>> {
    let catalog = capabilities::catalog(&state.db, [request.refs()], Catalog::default()).await?;
    let tool = capabilities::resolve_refs::<kerf_solver::tool::Tool>(request.refs(), &catalog)?.tool;
    let answer =
        state.solve(move |cancel| request.solve(tool, Control { progress: None, cancel: Some(cancel) })).await??;
    Ok(Json(answer))
}

/// Routes of this module (`POST /api/v1/contour` itself is generated in `endpoints`).
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_loops))
}
