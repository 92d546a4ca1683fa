//! Metrics and readiness: `GET /metrics` in the Prometheus/OpenMetrics text format,
//! written by the `prometheus-client` crate, and `GET /readyz`, ready only while the database
//! answers. The API serves both on its own port; a `kerf worker` on `--metrics-bind`.
//!
//! | metric | kind | labels |
//! |---|---|---|
//! | `kerf_http_requests_total` | counter | `route` (the matched route template), `status` |
//! | `kerf_http_request_duration_seconds` | histogram | `route` |
//! | `kerf_solver_seconds` | histogram | `capability` (synchronous requests and job operations) |
//! | `kerf_jobs` | gauge, read from the database at each scrape | `state` |
//! | `kerf_job_store_bytes` | gauge, read at each scrape: what the stored jobs take (job files, compressed results), the quota's measure | |
//! | `kerf_job_chunks_claimed_total` | counter (chunks, or whole SQLite jobs, this process claimed) | |
//! | `kerf_answer_cache_lookups_total` | counter (solver requests looked up in the answer cache) | `result` (`hit`, `miss`) |

use std::sync::LazyLock;
use std::time::{Duration, Instant};

use axum::Router;
use axum::extract::{FromRef, MatchedPath, Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use kerf_solver::ErrorCode;
use prometheus_client::encoding::EncodeLabelSet;
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::family::{Family, MetricConstructor};
use prometheus_client::metrics::gauge::Gauge;
use prometheus_client::metrics::histogram::{Histogram, exponential_buckets};
use prometheus_client::registry::Registry;

use crate::db::Db;
use crate::error::Problem;
use crate::store;

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct RequestLabels {
    route: String,
    status: u16,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct RouteLabels {
    route: String,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct CapabilityLabels {
    capability: String,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct LookupLabels {
    result: &'static str,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct StateLabels {
    state: &'static str,
}

/// Histogram buckets from `start` seconds, ×2.5 each, `count` of them.
#[derive(Clone, Copy)]
struct Buckets {
    start: f64,
    count: u16,
}

impl MetricConstructor<Histogram> for Buckets {
    fn new_metric(&self) -> Histogram {
        Histogram::new(exponential_buckets(self.start, 2.5, self.count))
    }
}

/// The process's metrics (one registry per process, shared by every service it runs).
struct Metrics {
    registry: Registry,
    requests: Family<RequestLabels, Counter>,
    request_seconds: Family<RouteLabels, Histogram, Buckets>,
    solver_seconds: Family<CapabilityLabels, Histogram, Buckets>,
    jobs: Family<StateLabels, Gauge>,
    store_bytes: Gauge,
    chunks_claimed: Counter,
    cache_lookups: Family<LookupLabels, Counter>,
}

static METRICS: LazyLock<Metrics> = LazyLock::new(|| {
    let mut registry = Registry::default();
    let requests = Family::<RequestLabels, Counter>::default();
    registry.register("kerf_http_requests", "HTTP requests answered, by route and status", requests.clone());
    // 1 ms to about 4 min.
    let request_seconds = Family::new_with_constructor(Buckets { start: 0.001, count: 14 });
    registry.register("kerf_http_request_duration_seconds", "HTTP request duration", request_seconds.clone());
    // 1 ms to about 2.5 h: job operations run long.
    let solver_seconds = Family::new_with_constructor(Buckets { start: 0.001, count: 17 });
    registry.register("kerf_solver_seconds", "Time one solver call took, by capability", solver_seconds.clone());
    let jobs = Family::<StateLabels, Gauge>::default();
    registry.register("kerf_jobs", "Jobs in the database, by state", jobs.clone());
    let store_bytes = Gauge::default();
    registry.register(
        "kerf_job_store_bytes",
        "Bytes the stored jobs take (job files and compressed results; what the quota bounds)",
        store_bytes.clone(),
    );
    let chunks_claimed = Counter::default();
    registry.register("kerf_job_chunks_claimed", "Job chunks this process claimed", chunks_claimed.clone());
    let cache_lookups = Family::<LookupLabels, Counter>::default();
    registry.register(
        "kerf_answer_cache_lookups",
        "Solver requests looked up in the answer cache, by result",
        cache_lookups.clone(),
    );
    Metrics { registry, requests, request_seconds, solver_seconds, jobs, store_bytes, chunks_claimed, cache_lookups }
});

/// Records one solver call of `capability` that took `seconds`.
pub fn observe_solver(capability: &str, seconds: f64) {
    METRICS.solver_seconds.get_or_create(&CapabilityLabels { capability: capability.to_owned() }).observe(seconds);
}

/// Counts one answer-cache lookup, a hit or a miss.
pub fn answer_cache_lookup(hit: bool) {
    METRICS.cache_lookups.get_or_create(&LookupLabels { result: if hit { "hit" } else { "miss" } }).inc();
}

/// Counts one claimed job chunk.
pub fn chunk_claimed() {
    METRICS.chunks_claimed.inc();
}

/// Middleware: counts and times every request by its route template (`/api/v1/tools/{number}`,
/// not the number itself, so the label set stays small).
pub async fn track(request: Request, next: Next) -> Response {
    let route = request
        .extensions()
        .get::<MatchedPath>()
        .map_or_else(|| "unmatched".to_owned(), |path| path.as_str().to_owned());
    let started = Instant::now();
    let response = next.run(request).await;
    let seconds = started.elapsed().as_secs_f64();
    METRICS.request_seconds.get_or_create(&RouteLabels { route: route.clone() }).observe(seconds);
    METRICS.requests.get_or_create(&RequestLabels { route, status: response.status().as_u16() }).inc();
    response
}

const STATES: [&str; 5] = ["queued", "running", "done", "failed", "cancelled"];

/// `GET /metrics`: every metric in the OpenMetrics text format (which Prometheus reads).
pub async fn metrics(State(db): State<Db>) -> Response {
    // The gauge is the process's, the counts are this database's: one scrape at a time, so two
    // services in one process (the tests) each answer their own.
    static SCRAPE: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());
    let _scrape = SCRAPE.lock().await;
    match tokio::time::timeout(Duration::from_secs(2), store::job_counts(&db)).await {
        Ok(Ok(counts)) => {
            for state in STATES {
                let count = counts.iter().find(|(s, _)| s == state).map_or(0, |(_, n)| *n);
                METRICS.jobs.get_or_create(&StateLabels { state }).set(count);
            }
        }
        // The other metrics are still worth a scrape; the gauge keeps its last values.
        Ok(Err(error)) => tracing::warn!(%error, "counting jobs for /metrics failed"),
        Err(_) => tracing::warn!("counting jobs for /metrics timed out"),
    }
    match tokio::time::timeout(Duration::from_secs(2), store::jobs::usage(&db)).await {
        Ok(Ok((_, bytes))) => {
            METRICS.store_bytes.set(bytes);
        }
        Ok(Err(error)) => tracing::warn!(%error, "measuring the job store for /metrics failed"),
        Err(_) => tracing::warn!("measuring the job store for /metrics timed out"),
    }
    let mut text = String::new();
    if let Err(error) = prometheus_client::encoding::text::encode(&mut text, &METRICS.registry) {
        tracing::error!(%error, "encoding metrics failed");
        return StatusCode::INTERNAL_SERVER_ERROR.into_response();
    }
    let mut response = text.into_response();
    response.headers_mut().insert(
        header::CONTENT_TYPE,
        HeaderValue::from_static("application/openmetrics-text; version=1.0.0; charset=utf-8"),
    );
    response
}

/// `GET /readyz`: 200 when the database answers within 2 s, else 503 (a load balancer or
/// Kubernetes then sends no traffic to this process).
pub async fn readyz(State(db): State<Db>) -> Response {
    let failure = match tokio::time::timeout(Duration::from_secs(2), db.ping()).await {
        Ok(Ok(())) => {
            return axum::Json(serde_json::json!({"status": "ready", "database": db.kind()})).into_response();
        }
        Ok(Err(error)) => format!("the database does not answer: {error}"),
        Err(_) => "the database did not answer within 2 s".to_owned(),
    };
    let problem = Problem {
        kind: "about:blank".to_owned(),
        title: "Not ready".to_owned(),
        status: 503,
        detail: failure,
        code: ErrorCode::Unavailable,
        errors: Vec::new(),
    };
    let mut response = (StatusCode::SERVICE_UNAVAILABLE, axum::Json(problem)).into_response();
    response.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("application/problem+json"));
    response.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from_static(crate::error::RETRY_AFTER_UNAVAILABLE));
    response
}

/// `/metrics` and `/readyz` for a router whose state holds the database.
pub fn routes<S>() -> Router<S>
where
    S: Clone + Send + Sync + 'static,
    Db: FromRef<S>,
{
    Router::new().route("/metrics", get(metrics)).route("/readyz", get(readyz))
}

/// The whole HTTP service of a `kerf worker` on `--metrics-bind`: `/metrics`, `/readyz` and
/// `/healthz` (the process is up).
pub fn worker_router(db: Db) -> Router {
    routes::<Db>().route("/healthz", get(|| async { "ok" })).layer(axum::middleware::from_fn(track)).with_state(db)
}
