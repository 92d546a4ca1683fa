//! Assembles the service: routes, OpenAPI document and docs, the page, problem+json for every
//! rejection (unknown path, wrong method, panics), body limit and request tracing.

use std::any::Any;
use std::time::Duration;

use axum::Router;
use axum::body::Body;
use axum::extract::DefaultBodyLimit;
use axum::http::Response;
use axum::response::IntoResponse;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::timeout::RequestBodyTimeoutLayer;
use tower_http::trace::TraceLayer;
use utoipa::OpenApi;
use utoipa_axum::router::OpenApiRouter;
use utoipa_swagger_ui::SwaggerUi;

use crate::auth::{Auth, require_token};
use crate::db::Database;
use crate::error::AppError;
use crate::openapi::ApiDoc;
use crate::state::{AppState, Limits};
use crate::store::jobs::JobStorage;
use crate::{db, http, metrics, web};

/// How to run the service.
#[derive(Debug, Clone)]
pub struct Config {
    /// The store: an SQLite file (created with the schema if missing) or a PostgreSQL URL.
    pub database: Database,
    /// Request limits.
    pub limits: Limits,
    /// Solver calls allowed at once (synchronous requests and jobs together).
    pub solver_slots: usize,
    /// Job workers in this process (0: an API node that runs no jobs).
    pub job_workers: usize,
    /// How long a claimed job stays a worker's without a heartbeat (PostgreSQL).
    pub job_lease: Duration,
    /// The optional API token.
    pub auth: Auth,
    /// The job store's quota, per-job cap and retention.
    pub job_storage: JobStorage,
}

/// The OpenAPI document and the API routes.
pub fn api() -> (Router<AppState>, utoipa::openapi::OpenApi) {
    let (routes, document) = OpenApiRouter::with_openapi(ApiDoc::openapi())
        .merge(http::health::router())
        .merge(http::tools::router())
        .merge(http::endpoints::router())
        .merge(http::contour::router())
        .merge(http::dxf::router())
        .merge(http::jobs::router())
        .merge(http::machines::router())
        .merge(http::materials::router())
        .split_for_parts();
    let mut document = document;
    crate::openapi::describe_responses(&mut document);
    crate::openapi::describe_security(&mut document);
    crate::openapi::describe_storage(&mut document);
    (routes, document)
}

/// The whole service over `state`.
pub fn router(state: AppState) -> Router {
    let max_body = state.limits.max_body_bytes;
    let (api_routes, document) = api();
    // The docs' own handler answers an unknown file with an empty 404: make it a problem.
    let docs = Router::from(SwaggerUi::new("/docs").url("/api/v1/openapi.json", document))
        .layer(axum::middleware::map_response(empty_not_found_as_problem));
    api_routes
        .merge(docs)
        .merge(web::router())
        .merge(metrics::routes())
        .fallback(|| async { AppError::not_found("no such resource") })
        .method_not_allowed_fallback(|| async { AppError::MethodNotAllowed })
        .layer(axum::middleware::from_fn_with_state(state.auth.clone(), require_token))
        .layer(DefaultBodyLimit::max(max_body))
        .layer(RequestBodyTimeoutLayer::new(state.limits.body_idle_timeout))
        .layer(axum::middleware::from_fn(metrics::track))
        .layer(TraceLayer::new_for_http())
        .layer(CatchPanicLayer::custom(panic_response))
        .with_state(state)
}

async fn empty_not_found_as_problem(response: Response<Body>) -> Response<Body> {
    if response.status() == axum::http::StatusCode::NOT_FOUND
        && !response.headers().contains_key(axum::http::header::CONTENT_TYPE)
    {
        return AppError::not_found("no such page of the API docs").into_response();
    }
    response
}

fn panic_response(cause: Box<dyn Any + Send + 'static>) -> Response<Body> {
    let message = cause
        .downcast_ref::<String>()
        .map(String::as_str)
        .or_else(|| cause.downcast_ref::<&str>().copied())
        .unwrap_or("unknown panic");
    AppError::Internal(anyhow::anyhow!("handler panicked: {message}")).into_response()
}

/// Opens the database, recovers interrupted jobs, starts the job workers and builds the service.
///
/// # Errors
/// When the database cannot be opened or migrated.
pub async fn build(config: &Config) -> anyhow::Result<(Router, AppState)> {
    let pool = db::open(&config.database).await?;
    let state = AppState::new(
        pool,
        config.limits.clone(),
        config.solver_slots,
        config.auth.clone(),
        config.job_lease,
        config.job_storage,
    );
    if !crate::store::jobs::incremental_vacuum(&state.db).await? {
        tracing::warn!(
            database = %config.database,
            "this SQLite file was made before incremental vacuum: the space of pruned jobs is reused but the file \
             does not shrink; stop the service and run `kerf jobs prune` once to convert it"
        );
    }
    state.jobs.start(&state.db, &state.solver_slots, config.job_workers).await?;
    Ok((router(state.clone()), state))
}
