//! `POST /api/v1/dxf` (docs/spec/dxf.md): a DXF drawing read into the profile that contour takes as
//! its `contour` (the outer boundary) and segment as a `polyline` curve: the outer boundary and
//! its islands in mm, drawn by the page before anything is computed.
//!
//! The body is the file itself, ASCII or binary, of any media type (`application/dxf`,
//! `image/vnd.dxf`, `application/octet-stream`); the options are query parameters. This route
//! has the upload limit (`Limits::max_upload_bytes`) instead of the default body limit.

use axum::Json;
use axum::extract::{DefaultBodyLimit, Request, State};
use kerf_solver::dxf::{self, DrawingUnits, DxfOptions, Profile};
use serde::Deserialize;
use utoipa::IntoParams;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::error::{AppResult, Problem};
use crate::extract::{AppQuery, charged_body_bytes};
use crate::state::AppState;

/// A DXF file as the request body (for the OpenAPI document): its bytes as they are.
#[derive(Debug, utoipa::ToSchema)]
#[schema(value_type = String, format = Binary)]
pub struct DxfFile(pub Vec<u8>);

/// How to read the drawing.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct DxfQuery {
    /// Units of a drawing that does not say them (`$INSUNITS` 0 or missing, as every R12 file):
    /// `mm`, `cm`, `m`, `inch`, `foot` or `micron`. Refused when the drawing says others.
    pub units: Option<DrawingUnits>,
    /// Only the entities of this layer (default all).
    pub layer: Option<String>,
    /// Largest gap between two entity ends joined into one chain, mm (default 0.01).
    pub join_tolerance: Option<f64>,
    /// Largest distance of a chord from its arc, bulge, ellipse or spline, mm (default 0.001).
    pub chord_tolerance: Option<f64>,
}

/// Reads a DXF drawing's profile: the outer boundary (counter-clockwise) and the islands inside
/// it (clockwise), in mm, from LWPOLYLINE/POLYLINE (bulges), LINE/ARC chains, CIRCLE, ELLIPSE and
/// SPLINE entities.
#[utoipa::path(post, path = "/api/v1/dxf", tag = "dxf", operation_id = "read_dxf",
    params(DxfQuery),
    request_body(description = "The DXF file (ASCII or binary, R12 to 2018), sent as it is under any media type; documented as `application/octet-stream`, the raw-bytes type client generators know.", content = DxfFile, content_type = "application/octet-stream"),
    responses(
        (status = 200, description = "The profile", body = Profile),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
        (status = 413, description = "Body over the upload limit", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "`E_INPUT` naming `file` and the entity (an open chain and its gap, a loop crossing itself and where, bad values), `units` (a drawing without units: give them), `layer` (no entities on it)", body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy, or uploads in progress hold the memory budget", body = Problem, content_type = "application/problem+json")))]
async fn post_dxf(
    State(state): State<AppState>,
    AppQuery(query): AppQuery<DxfQuery>,
    request: Request,
) -> AppResult<Json<Profile>> {
    let (body, share) = charged_body_bytes(request, &state, state.limits.max_upload_bytes).await?;
    let options = DxfOptions {
        units: query.units,
        layer: query.layer,
        join_tolerance: query.join_tolerance.unwrap_or(dxf::DEFAULT_JOIN_TOLERANCE),
        chord_tolerance: query.chord_tolerance.unwrap_or(dxf::DEFAULT_CHORD_TOLERANCE),
    };
    let profile = state.solve(move |_| dxf::read(&body, "file", &options)).await??;
    drop(share);
    Ok(Json(profile))
}

/// Routes of this module; the upload limit replaces the default body limit here.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_dxf)).layer(DefaultBodyLimit::disable())
}
