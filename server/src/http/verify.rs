//! `POST /api/v1/verify` (docs/spec/verify.md): cuts a G-code program out of the stock with the
//! tools it calls and answers what it found, through the capability seam (`solve::answer`). It is
//! routed here rather than from the capability registry, which would also give it a job operation
//! and a tab on the page; its answer is JSON only.

use axum::extract::State;
use axum::response::Response;
use kerf_solver::capability::Capability;
use kerf_solver::verify::{VerifyAnswer, VerifyCapability, VerifyRequest};
use serde::Deserialize;
use utoipa::IntoParams;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::contour::JsonOnly;
use super::output::Ask;
use crate::error::{AppResult, Problem};
use crate::extract::{AppJson, AppQuery};
use crate::state::AppState;

/// Query parameters of `POST /api/v1/verify`: the answer is JSON only (verify writes no program).
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct VerifyQuery {
    /// `json`, the only format.
    pub format: Option<JsonOnly>,
}

/// The verify capability's endpoint, documented with the capability's own texts.
#[utoipa::path(post, path = "/api/v1/verify", tag = "verify",
    operation_id = "verify",
    summary = <VerifyCapability as Capability>::ENDPOINT.summary,
    description = <VerifyCapability as Capability>::ENDPOINT.description,
    params(VerifyQuery),
    request_body = VerifyRequest,
    responses(
        (status = 200, description = "The findings, volumes and removal per block", body = VerifyAnswer),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = <VerifyCapability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
        (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = <VerifyCapability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
async fn post_verify(
    State(state): State<AppState>,
    AppQuery(_query): AppQuery<VerifyQuery>,
    AppJson(request): AppJson<VerifyRequest>,
) -> AppResult<Response> {
    super::solve::answer::<VerifyCapability>(&state, request, None, Ask::default()).await
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_verify))
}
