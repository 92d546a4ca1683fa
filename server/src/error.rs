//! `AppError`: every failure the HTTP layer can answer, rendered as RFC 9457
//! `application/problem+json` (docs/spec/api.md, Errors). 5xx causes are logged, never sent to the client.

use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use kerf_solver::ErrorCode;
use kerf_solver::SolverError;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// One field-level complaint inside a problem document.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
pub struct FieldProblem {
    /// Dotted JSON path of the field (`hole.radius`, `tool`, `contour[3]`), or the query/path
    /// parameter name.
    pub path: String,
    /// What is wrong with it.
    pub message: String,
}

/// An RFC 9457 problem document, as every error answer carries.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
pub struct Problem {
    /// Always `about:blank`: the status code and `code` say what happened.
    #[serde(rename = "type")]
    pub kind: String,
    /// Short, human-readable summary of the status.
    pub title: String,
    /// HTTP status code.
    pub status: u16,
    /// Human-readable explanation specific to this request.
    pub detail: String,
    /// Stable machine-readable code (e.g. `E_HOLE_TOO_LARGE`, `E_JSON`, `E_NOT_FOUND`).
    pub code: ErrorCode,
    /// The fields at fault.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<FieldProblem>,
}

/// Everything a handler can fail with.
#[derive(Debug, thiserror::Error)]
pub enum AppError {
    /// 400: the body or a parameter is not of the right shape.
    #[error("{detail}")]
    BadRequest { code: ErrorCode, detail: String, field: Option<String> },
    /// 401: a state-changing request without the right bearer token.
    #[error("{0}")]
    Unauthorized(String),
    /// 404: no such resource; `field` names the request field that referred to it, if any.
    #[error("{detail}")]
    NotFound { detail: String, field: Option<String> },
    /// 405: the path exists, the method does not.
    #[error("method not allowed")]
    MethodNotAllowed,
    /// 409: the request conflicts with stored state.
    #[error("{0}")]
    Conflict(String),
    /// 412: `If-Match` or `If-None-Match` (`header`) does not hold for the stored item; `etag` is
    /// the item's current ETag when it exists, sent back so a client can show what is stored.
    #[error("{detail}")]
    PreconditionFailed { header: &'static str, detail: String, etag: Option<String> },
    /// 413: the body is over the limit.
    #[error("request body is larger than the limit of {limit} bytes")]
    PayloadTooLarge { limit: usize },
    /// 408 `E_BODY`: the body arrives slower than the minimum receive rate.
    #[error("{0}")]
    BodyTooSlow(String),
    /// 415: wrong content type.
    #[error("{0}")]
    UnsupportedMediaType(String),
    /// 422: well-formed but impossible; from the solver or a validation rule.
    #[error(transparent)]
    Unprocessable(#[from] SolverError),
    /// 429: the service is saturated; try again.
    #[error("{0}")]
    TooManyRequests(String),
    /// 429 `E_JOB_STORE_FULL`: the job store is at its quota; finished jobs must be pruned (or
    /// the quota raised) before another job fits. No `Retry-After`: waiting alone does not help
    /// until the retention prunes.
    #[error("{0}")]
    JobStoreFull(String),
    /// 422 `E_TIMEOUT`: the synchronous time limit was hit; submit a job instead. Not a 5xx:
    /// the request is well-formed but too long for a synchronous answer (docs/spec/api.md: a 5xx is a bug).
    #[error("{0}")]
    Timeout(String),
    /// 507 `E_STORAGE_FULL`: the database's disk is full; nothing of the request was written.
    /// Reads still work; writes succeed again once space is freed.
    #[error("{0}")]
    StorageFull(String),
    /// 503 `E_UNAVAILABLE`: the database cannot be reached (down, restarting, every connection
    /// busy past the pool's acquire timeout); nothing of the request was written. Answered with
    /// `Retry-After`.
    #[error("{0}")]
    Unavailable(String),
    /// 500: a bug or an infrastructure failure. The cause is logged, not sent.
    #[error(transparent)]
    Internal(#[from] anyhow::Error),
}

impl AppError {
    /// A 400 naming `field`.
    pub fn bad_request(code: ErrorCode, field: impl Into<String>, detail: impl Into<String>) -> Self {
        Self::BadRequest { code, detail: detail.into(), field: Some(field.into()) }
    }

    /// A 404 for a resource addressed by the path.
    pub fn not_found(detail: impl Into<String>) -> Self {
        Self::NotFound { detail: detail.into(), field: None }
    }

    /// A 404 for a resource a request field refers to (an unknown tool number, machine, ...).
    pub fn unknown(field: impl Into<String>, detail: impl Into<String>) -> Self {
        Self::NotFound { detail: detail.into(), field: Some(field.into()) }
    }

    /// The same error with its field path under `prefix` (`operations[2]` + `hole.radius` →
    /// `operations[2].hole.radius`); an error without a field points at `prefix` itself.
    #[must_use]
    pub fn under(self, prefix: &str) -> Self {
        let join = |field: Option<String>| Some(field.map_or_else(|| prefix.to_owned(), |f| format!("{prefix}.{f}")));
        match self {
            Self::BadRequest { code, detail, field } => Self::BadRequest { code, detail, field: join(field) },
            Self::NotFound { detail, field } => Self::NotFound { detail, field: join(field) },
            Self::Unprocessable(error) => {
                let field = join(error.field().map(str::to_owned)).unwrap_or_default();
                Self::Unprocessable(error.at(field))
            }
            other => other,
        }
    }

    fn status_title(&self) -> (StatusCode, &'static str) {
        match self {
            Self::BadRequest { .. } => (StatusCode::BAD_REQUEST, "Bad request"),
            Self::Unauthorized(_) => (StatusCode::UNAUTHORIZED, "Unauthorized"),
            Self::NotFound { .. } => (StatusCode::NOT_FOUND, "Not found"),
            Self::MethodNotAllowed => (StatusCode::METHOD_NOT_ALLOWED, "Method not allowed"),
            Self::Conflict(_) => (StatusCode::CONFLICT, "Conflict"),
            Self::PreconditionFailed { .. } => (StatusCode::PRECONDITION_FAILED, "Precondition failed"),
            Self::PayloadTooLarge { .. } => (StatusCode::PAYLOAD_TOO_LARGE, "Payload too large"),
            Self::BodyTooSlow(_) => (StatusCode::REQUEST_TIMEOUT, "Request timeout"),
            Self::UnsupportedMediaType(_) => (StatusCode::UNSUPPORTED_MEDIA_TYPE, "Unsupported media type"),
            Self::Unprocessable(_) => (StatusCode::UNPROCESSABLE_ENTITY, "Unprocessable request"),
            Self::TooManyRequests(_) => (StatusCode::TOO_MANY_REQUESTS, "Too many requests"),
            Self::JobStoreFull(_) => (StatusCode::TOO_MANY_REQUESTS, "Job store full"),
            Self::Timeout(_) => (StatusCode::UNPROCESSABLE_ENTITY, "Over the synchronous time limit"),
            Self::StorageFull(_) => (StatusCode::INSUFFICIENT_STORAGE, "Storage full"),
            Self::Unavailable(_) => (StatusCode::SERVICE_UNAVAILABLE, "Database unavailable"),
            Self::Internal(_) => (StatusCode::INTERNAL_SERVER_ERROR, "Internal error"),
        }
    }

    /// The problem document for this error.
    pub fn problem(&self) -> Problem {
        let (status, title) = self.status_title();
        let (code, detail, field): (ErrorCode, String, Option<String>) = match self {
            Self::BadRequest { code, detail, field } => (*code, detail.clone(), field.clone()),
            Self::NotFound { detail, field } => (ErrorCode::NotFound, detail.clone(), field.clone()),
            Self::Unprocessable(error) => (error.code(), error.message().to_owned(), error.field().map(str::to_owned)),
            Self::PreconditionFailed { header, detail, .. } => {
                (ErrorCode::PreconditionFailed, detail.clone(), Some((*header).to_owned()))
            }
            Self::Internal(_) => (ErrorCode::Internal, "internal error; it has been logged".to_owned(), None),
            other => {
                let code = match other {
                    Self::Unauthorized(_) => ErrorCode::Unauthorized,
                    Self::MethodNotAllowed => ErrorCode::Method,
                    Self::Conflict(_) => ErrorCode::Conflict,
                    Self::PayloadTooLarge { .. } => ErrorCode::TooLarge,
                    Self::BodyTooSlow(_) => ErrorCode::Body,
                    Self::UnsupportedMediaType(_) => ErrorCode::ContentType,
                    Self::TooManyRequests(_) => ErrorCode::Busy,
                    Self::JobStoreFull(_) => ErrorCode::JobStoreFull,
                    Self::StorageFull(_) => ErrorCode::StorageFull,
                    Self::Unavailable(_) => ErrorCode::Unavailable,
                    _ => ErrorCode::Timeout,
                };
                (code, other.to_string(), None)
            }
        };
        let errors = field.map(|path| vec![FieldProblem { path, message: detail.clone() }]).unwrap_or_default();
        Problem {
            kind: "about:blank".to_owned(),
            title: title.to_owned(),
            status: status.as_u16(),
            detail,
            code,
            errors,
        }
    }
}

impl IntoResponse for AppError {
    fn into_response(self) -> Response {
        if let Self::Internal(cause) = &self {
            tracing::error!(error = ?cause, "internal error");
        }
        let problem = self.problem();
        let status = StatusCode::from_u16(problem.status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
        let body = serde_json::to_vec(&problem).unwrap_or_default();
        let mut response = (status, body).into_response();
        response.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("application/problem+json"));
        if matches!(self, Self::Unauthorized(_)) {
            response.headers_mut().insert(header::WWW_AUTHENTICATE, HeaderValue::from_static("Bearer"));
        }
        if let Self::PreconditionFailed { etag: Some(etag), .. } = &self
            && let Ok(value) = HeaderValue::from_str(etag)
        {
            response.headers_mut().insert(header::ETAG, value);
        }
        if matches!(self, Self::TooManyRequests(_)) {
            // Slots and the answer budget free up within seconds.
            response.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from_static("2"));
        }
        if matches!(self, Self::Unavailable(_)) {
            // A database restart or a failover takes seconds.
            response.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from_static(RETRY_AFTER_UNAVAILABLE));
        }
        response
    }
}

/// Seconds a client is told to wait (`Retry-After`) while the database cannot be reached.
pub const RETRY_AFTER_UNAVAILABLE: &str = "5";

/// Whether `error` says the database's disk is full: SQLite's `SQLITE_FULL` (13) or no room for
/// its shared-memory index (`SQLITE_IOERR_SHMSIZE`, 4874), PostgreSQL's `disk_full` (53100).
pub fn disk_full(error: &sqlx::Error) -> bool {
    let sqlx::Error::Database(error) = error else { return false };
    matches!(error.code().as_deref(), Some("13" | "4874" | "53100"))
}

/// Whether `error` says the database cannot be reached now, but may be again: no connection
/// within the pool's acquire timeout, a connection lost or refused, PostgreSQL shutting down or
/// starting (class 57P, `cannot_connect_now`), a connection exception (class 08), or SQLite's
/// write lock held past the busy timeout (`SQLITE_BUSY`, 5).
fn unavailable(error: &sqlx::Error) -> bool {
    match error {
        sqlx::Error::PoolTimedOut | sqlx::Error::PoolClosed | sqlx::Error::Io(_) | sqlx::Error::WorkerCrashed => true,
        sqlx::Error::Database(error) => error
            .code()
            .is_some_and(|code| code.starts_with("57P") || code.starts_with("08") || code == "5" || code == "53300"),
        _ => false,
    }
}

impl From<sqlx::Error> for AppError {
    /// The cause is logged, not sent (it may name hosts and files).
    fn from(error: sqlx::Error) -> Self {
        if disk_full(&error) {
            tracing::warn!(%error, "the database's disk is full");
            return Self::StorageFull(
                "the database's disk is full; nothing of this request was stored (reads still work; writes work again \
                 once space is freed)"
                    .to_owned(),
            );
        }
        if unavailable(&error) {
            tracing::warn!(%error, "the database cannot be reached");
            return Self::Unavailable(
                "the database cannot be reached now; nothing of this request was stored, try again shortly".to_owned(),
            );
        }
        Self::Internal(error.into())
    }
}

impl AppError {
    /// Whether this failure may pass by itself (a full disk freed, a database back): work whose
    /// result could not be stored keeps it and tries again.
    pub fn is_transient(&self) -> bool {
        matches!(self, Self::StorageFull(_) | Self::Unavailable(_))
    }
}

/// Result of a handler.
pub type AppResult<T> = Result<T, AppError>;
