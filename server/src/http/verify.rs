//! `POST /api/v1/verify` (docs/spec/verify.md): cuts a G-code program out of the stock with the
//! tools it calls and answers what it found, through the capability seam (`solve::answer`). It is
//! routed here rather than from the capability registry, which would also give it a job operation
//! and a tab on the page. It answers JSON, or the cut stock as binary glTF (`verify_mesh`).

use axum::extract::State;
use axum::http::HeaderMap;
use axum::response::Response;
use kerf_solver::capability::Capability;
use kerf_solver::verify::{VerifyAnswer, VerifyCapability, VerifyRequest};
use serde::Deserialize;
use utoipa::IntoParams;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::Ask;
use super::verify_mesh::{self, VerifyFormat};
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;

/// Query parameters of `POST /api/v1/verify`: the findings as JSON, or the cut stock as binary
/// glTF (verify writes no program).
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct VerifyQuery {
    /// `json` (default) or `glb` (the cut stock as binary glTF, `model/gltf-binary`, with the
    /// JSON answer in its `extras.verify`); without it, an `Accept` that ranks
    /// `model/gltf-binary` above `application/json` selects the mesh.
    pub format: Option<VerifyFormat>,
    /// Mesh only: cut the moves on lines up to this one (1-based) and answer the stock as they
    /// left it (playback); default every move.
    #[param(minimum = 0)]
    pub upto_line: Option<usize>,
}

/// The verify capability's endpoint, documented with the capability's own texts.
#[utoipa::path(post, path = "/api/v1/verify", tag = "verify",
    operation_id = "verify",
    summary = <VerifyCapability as Capability>::ENDPOINT.summary,
    description = <VerifyCapability as Capability>::ENDPOINT.description,
    params(VerifyQuery),
    request_body = VerifyRequest,
    responses(
        (status = 200, description = "The findings, volumes and removal per block (JSON), or the cut stock as binary glTF coloured by deviation from the part",
            content((VerifyAnswer = "application/json"), (verify_mesh::GlbFile = "model/gltf-binary"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = <VerifyCapability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
        (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = <VerifyCapability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
async fn post_verify(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<VerifyQuery>,
    AppJson(request): AppJson<VerifyRequest>,
) -> AppResult<Response> {
    if verify_mesh::wants_glb(&headers, query.format) {
        return verify_mesh::answer(&state, request, query.upto_line).await;
    }
    if query.upto_line.is_some() {
        return Err(kerf_solver::SolverError::input("upto_line", "upto_line cuts the mesh: ask for format=glb").into());
    }
    super::solve::answer::<VerifyCapability>(&state, request, None, Ask::default()).await
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_verify))
}
