//! `POST /api/v1/segment` (api.md, Segment; chord.md): a curve cut into G01 blocks whose chord
//! error follows the control's block processing time, as JSON or G-code.

use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::Response;
use kerf_solver::chord::{SegmentCapability, SegmentRequest, SegmentResult};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Ask, OutputQuery};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;

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
        (status = 200, description = "The blocks as JSON, or the program (`?format=gcode`)", content(
            (SegmentResult = "application/json"),
            (String = "text/x-gcode"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown machine or tool number", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible request: `E_INPUT`, `E_DEGENERATE_CURVE`, `E_INFEASIBLE_FEED_FOR_RADIUS` (the message gives the largest feasible feed), `E_TOO_MANY_BLOCKS`, `E_TOO_MANY_POINTS`, `E_NUMERIC_FAILURE`; `E_TIMEOUT` over the synchronous time limit: submit a job", body = Problem, content_type = "application/problem+json")))]
async fn post_segment(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<OutputQuery>,
    AppJson(request): AppJson<SegmentRequest>,
) -> AppResult<Response> {
    super::solve::answer::<SegmentCapability>(&state, request, None, Ask::negotiate(&headers, &query)).await
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_segment))
}
