//! `POST /api/v1/engagement` (api.md, Engagement): tool–workpiece contact along one path or
//! several candidate paths, chip thickness per flute count, time and the recommended flute
//! counts, as JSON; or the G-code of one path with the chip-thinning feed plan's F words.

use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::Response;
use kerf_solver::capability::OutputOptions;
use kerf_solver::engagement::{EngagementCapability, EngagementRequest, EngagementResponse};
use kerf_solver::gcode::{Dialect, Reference};
use serde::Deserialize;
use utoipa::IntoParams;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Ask, Format, wants_gcode};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;

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
    /// G-code only: which entry of `paths` to program (0-based; default the request's
    /// `candidate`, else 0); a request with `path` has only candidate 0.
    pub candidate: Option<usize>,
    /// Arc segments of the path: `g2g3` (G02/G03 with I/J, end points those of the chords) or
    /// `chords` (G01 within 0.001 mm, or by the block-time rule); default the machine's `arcs`,
    /// else `chords`.
    pub arcs: Option<kerf_solver::gcode::Arcs>,
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
        (status = 200, description = "The engagement analysis as JSON, or the program of one path (`?format=gcode`)", content(
            (EngagementResponse = "application/json"),
            (String = "text/x-gcode"))),
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
    let ask = Ask {
        gcode: wants_gcode(&headers, query.format),
        output: OutputOptions {
            dialect: query.dialect,
            reference: query.reference,
            candidate: query.candidate,
            arcs: query.arcs,
        },
        timings: false,
    };
    super::solve::answer::<EngagementCapability>(&state, request, None, ask).await
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_engagement))
}
