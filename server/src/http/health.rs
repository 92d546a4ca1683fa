//! `GET /healthz`: 200 when the database answers.

use axum::Json;
use axum::extract::State;
use serde::Serialize;
use utoipa::ToSchema;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::error::{AppResult, Problem};
use crate::state::AppState;

/// Health answer.
#[derive(Debug, Serialize, ToSchema)]
pub struct Health {
    /// Always `ok`.
    pub status: &'static str,
    /// kerf version.
    pub version: &'static str,
}

/// The service is up and its database is reachable (503 `E_UNAVAILABLE` with `Retry-After`
/// within the pool's acquire timeout when it is not).
#[utoipa::path(get, path = "/healthz", tag = "service", operation_id = "get_health",
    responses((status = 200, body = Health), (status = 500, body = Problem, content_type = "application/problem+json")))]
async fn healthz(State(state): State<AppState>) -> AppResult<Json<Health>> {
    state.db.ping().await?;
    Ok(Json(Health { status: "ok", version: env!("CARGO_PKG_VERSION") }))
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(healthz))
}
