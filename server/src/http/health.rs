//! `GET /healthz`, the liveness probe: 200 while the process answers HTTP, whatever the database
//! does (`/readyz` says whether it can serve: [`crate::metrics::readyz`]).

use axum::Json;
use serde::Serialize;
use utoipa::ToSchema;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::state::AppState;

/// Health answer.
#[derive(Debug, Serialize, ToSchema)]
pub struct Health {
    /// Always `ok`.
    pub status: &'static str,
    /// kerf version.
    pub version: &'static str,
}

/// Liveness: the process is up and answers HTTP.
///
/// It does not touch the database, so an outage of the database does not get every API process
/// restarted; `GET /readyz` (503 with
/// `Retry-After` while the database does not answer) is the readiness probe.
#[utoipa::path(get, path = "/healthz", tag = "service", operation_id = "get_health", responses((status = 200, body = Health)))]
async fn healthz() -> Json<Health> {
    Json(Health { status: "ok", version: env!("CARGO_PKG_VERSION") })
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(healthz))
}
