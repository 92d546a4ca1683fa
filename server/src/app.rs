//! Assembles the service: routes, OpenAPI document and docs, the page, problem+json for every
//! rejection (unknown path, wrong method, panics), body limit, and the conventions every answer
//! follows (docs/spec/api.md, Conventions): CORS for the configured origins, gzip above 1 KiB,
//! `X-Request-Id` with one log line per request, `Connection: close` on 413.

use std::any::Any;
use std::hash::BuildHasher;
use std::sync::LazyLock;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use axum::Router;
use axum::body::Body;
use axum::extract::{DefaultBodyLimit, MatchedPath, Request};
use axum::http::{Extensions, HeaderMap, HeaderName, HeaderValue, Method, Response, StatusCode, Version, header};
use axum::middleware::Next;
use axum::response::IntoResponse;
use tower_http::catch_panic::CatchPanicLayer;
use tower_http::compression::predicate::{NotForContentType, Predicate, SizeAbove};
use tower_http::compression::{CompressionLayer, DefaultPredicate};
use tower_http::cors::{AllowOrigin, CorsLayer};
use tower_http::timeout::RequestBodyTimeoutLayer;
use tracing::Instrument;
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
    /// Origins whose pages may call the API from a browser (CORS): `scheme://host[:port]`, or
    /// `*` for any; none by default.
    pub cors_origins: Vec<String>,
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
        .merge(http::job_stock::router())
        .merge(http::machines::router())
        .merge(http::materials::router())
        .split_for_parts();
    let mut document = document;
    crate::openapi::describe_responses(&mut document);
    crate::openapi::describe_security(&mut document);
    crate::openapi::describe_storage(&mut document);
    crate::openapi::shape_for_generators(&mut document);
    (routes, document)
}

/// The whole service over `state`, with no CORS origin.
pub fn router(state: AppState) -> Router {
    router_for(state, &[])
}

/// The whole service over `state`, whose API pages of `cors_origins` may call.
pub fn router_for(state: AppState, cors_origins: &[String]) -> Router {
    let max_body = state.limits.max_body_bytes;
    let (api_routes, document) = api();
    // The docs' own handler answers an unknown file with an empty 404: make it a problem.
    let docs = Router::from(SwaggerUi::new("/docs").url("/api/v1/openapi.json", document))
        .layer(axum::middleware::map_response(empty_not_found_as_problem));
    let mut routes = api_routes
        .merge(docs)
        .merge(web::router())
        .merge(metrics::routes())
        .fallback(|| async { AppError::not_found("no such resource") })
        .method_not_allowed_fallback(|| async { AppError::MethodNotAllowed })
        .layer(axum::middleware::from_fn_with_state(state.auth.clone(), require_token))
        .layer(DefaultBodyLimit::max(max_body))
        .layer(RequestBodyTimeoutLayer::new(state.limits.body_idle_timeout))
        .layer(axum::middleware::from_fn(metrics::track));
    // Outside the token check: a browser's preflight carries no token.
    if let Some(cors) = cors(cors_origins) {
        routes = routes.layer(cors);
    }
    routes
        .layer(compression())
        .layer(CatchPanicLayer::custom(panic_response))
        .layer(axum::middleware::from_fn(observe))
        .with_state(state)
}

/// Answers smaller than this are sent as they are: gzip's header and the work outweigh the gain.
pub const COMPRESS_ABOVE_BYTES: u64 = 1024;

/// gzip for answers of [`COMPRESS_ABOVE_BYTES`] or more (streamed ones too, whose size is not
/// known) when `Accept-Encoding` allows it; not for zip archives, which are compressed already,
/// nor for an answer with a strong `ETag` (a stored tool, machine or material): the tag names the
/// bytes sent, and a gzipped body under the same strong tag would be another representation
/// with the tag a client sends back in `If-Match`.
fn compression() -> CompressionLayer<impl Predicate> {
    let without_entity_tag =
        |_: StatusCode, _: Version, headers: &HeaderMap, _: &Extensions| !headers.contains_key(header::ETAG);
    CompressionLayer::new().compress_when(
        DefaultPredicate::new()
            .and(SizeAbove::new(COMPRESS_ABOVE_BYTES))
            .and(NotForContentType::const_new("application/zip"))
            .and(without_entity_tag),
    )
}

/// The request id header: the client's when usable ([`usable_request_id`]), else one made here.
pub static REQUEST_ID: HeaderName = HeaderName::from_static("x-request-id");

/// CORS for `origins` (`*`: any), `None` for none: the methods and request headers the API
/// reads, and the answer headers a page needs (the entity tag for `If-Match`, the request id,
/// `Retry-After` of 429/503, the `Location` of a submitted job).
fn cors(origins: &[String]) -> Option<CorsLayer> {
    if origins.is_empty() {
        return None;
    }
    let allowed = if origins.iter().any(|origin| origin == "*") {
        AllowOrigin::any()
    } else {
        AllowOrigin::list(origins.iter().filter_map(|origin| HeaderValue::from_str(origin).ok()))
    };
    Some(
        CorsLayer::new()
            .allow_origin(allowed)
            .allow_methods([Method::GET, Method::HEAD, Method::POST, Method::PUT, Method::DELETE])
            .allow_headers([
                header::ACCEPT,
                header::AUTHORIZATION,
                header::CONTENT_TYPE,
                header::IF_MATCH,
                header::IF_NONE_MATCH,
                REQUEST_ID.clone(),
            ])
            .expose_headers([
                header::ETAG,
                REQUEST_ID.clone(),
                header::RETRY_AFTER,
                header::LOCATION,
                header::CONTENT_DISPOSITION,
            ])
            .max_age(Duration::from_secs(600)),
    )
}

/// Longest request id taken from a client.
pub const REQUEST_ID_MAX_LEN: usize = 128;

/// Whether a client's `X-Request-Id` is kept: 1 to [`REQUEST_ID_MAX_LEN`] visible ASCII
/// characters (no spaces or control characters, which would garble a log line).
pub fn usable_request_id(value: &HeaderValue) -> bool {
    let bytes = value.as_bytes();
    (1..=REQUEST_ID_MAX_LEN).contains(&bytes.len()) && bytes.iter().all(|b| b.is_ascii_graphic())
}

/// A new request id: 32 hex digits, from a per-process random key and a counter (unique within
/// the process, unlikely to repeat across processes).
fn new_request_id() -> HeaderValue {
    static KEY: LazyLock<std::collections::hash_map::RandomState> =
        LazyLock::new(std::collections::hash_map::RandomState::new);
    static COUNT: AtomicU64 = AtomicU64::new(0);
    let count = COUNT.fetch_add(1, Ordering::Relaxed);
    let id = format!("{:016x}{:016x}", KEY.hash_one((count, 0_u8)), KEY.hash_one((count, 1_u8)));
    HeaderValue::from_str(&id).unwrap_or_else(|_| HeaderValue::from_static("0"))
}

/// Middleware around everything else: gives the request its id ([`REQUEST_ID`]), runs it in a
/// `request` span carrying method, matched route and id (so every line logged for it names
/// them), writes one `info` line when the answer's head is ready (status, milliseconds), and sets
/// the id on the answer. A 413 also says `Connection: close`: its body was not read, so the
/// connection cannot carry another request.
async fn observe(mut request: Request, next: Next) -> Response<Body> {
    let id = request
        .headers()
        .get(&REQUEST_ID)
        .filter(|value| usable_request_id(value))
        .cloned()
        .unwrap_or_else(new_request_id);
    request.headers_mut().insert(REQUEST_ID.clone(), id.clone());
    let route = request.extensions().get::<MatchedPath>().map_or("unmatched", MatchedPath::as_str).to_owned();
    let span = tracing::info_span!(
        "request",
        method = %request.method(),
        route = %route,
        request_id = %id.to_str().unwrap_or_default(),
    );
    let started = Instant::now();
    let mut response = next.run(request).instrument(span.clone()).await;
    let status = response.status();
    span.in_scope(|| {
        tracing::info!(status = status.as_u16(), duration_ms = started.elapsed().as_secs_f64() * 1000.0, "answered");
    });
    if status == StatusCode::PAYLOAD_TOO_LARGE {
        response.headers_mut().insert(header::CONNECTION, HeaderValue::from_static("close"));
    }
    response.headers_mut().insert(REQUEST_ID.clone(), id);
    response
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
    Ok((router_for(state.clone(), &config.cors_origins), state))
}
