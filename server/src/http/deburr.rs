//! `POST /api/v1/deburr` (api.md, Deburr): cross-hole deburring, as JSON or G-code.

use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::Response;
use kerf_solver::deburr::{DeburrAnswer, DeburrCapability, DeburrRequest};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Ask, OutputQuery};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;

/// Deburrs one ridge of a cross hole with a ball end mill, or several holes and both ridges.
///
/// Returns the closed loop of ball centres in machining order (JSON), or with
/// `Accept: text/x-gcode` / `?format=gcode` a complete program (dialect from `?dialect=`, else
/// the named machine's, else Fanuc). With `block_time_ms` or a `machine` the points follow the
/// block-time rule at `feed` (never coarser than `tolerance`) and the summary reports the blocks.
/// With `holes`, a `pattern` or `edge: both` one program visits every loop (one per hole and
/// edge, listed in `holes`) in a short order (`visiting_order`), changing to `inner_tool` once for
/// the inside ridges and stopping (`M00`) to turn the tube for holes that point down.
#[utoipa::path(post, path = "/api/v1/deburr", tag = "deburr",
    params(OutputQuery),
    request_body = DeburrRequest,
    responses(
        (status = 200, description = "The path as JSON, or the program (`?format=gcode`)", content(
            (DeburrAnswer = "application/json"),
            (String = "text/x-gcode"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number (`tool`, `inner_tool`) or machine", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible geometry (codes in deburr.md §4); `E_TIMEOUT` over the synchronous time limit: submit a job", body = Problem, content_type = "application/problem+json")))]
async fn post_deburr(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<OutputQuery>,
    AppJson(request): AppJson<DeburrRequest>,
) -> AppResult<Response> {
    super::solve::answer::<DeburrCapability>(&state, request, None, Ask::negotiate(&headers, &query)).await
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_deburr))
}
