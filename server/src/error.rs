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
            Self::PayloadTooLarge { .. } => (StatusCode::PAYLOAD_TOO_LARGE, "Payload too large"),
            Self::BodyTooSlow(_) => (StatusCode::REQUEST_TIMEOUT, "Request timeout"),
            Self::UnsupportedMediaType(_) => (StatusCode::UNSUPPORTED_MEDIA_TYPE, "Unsupported media type"),
            Self::Unprocessable(_) => (StatusCode::UNPROCESSABLE_ENTITY, "Unprocessable request"),
            Self::TooManyRequests(_) => (StatusCode::TOO_MANY_REQUESTS, "Too many requests"),
            Self::JobStoreFull(_) => (StatusCode::TOO_MANY_REQUESTS, "Job store full"),
            Self::Timeout(_) => (StatusCode::UNPROCESSABLE_ENTITY, "Over the synchronous time limit"),
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
        if matches!(self, Self::TooManyRequests(_)) {
            // Slots and the answer budget free up within seconds.
            response.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from_static("2"));
        }
        response
    }
}

impl From<sqlx::Error> for AppError {
    fn from(error: sqlx::Error) -> Self {
        Self::Internal(error.into())
    }
}

/// Result of a handler.
pub type AppResult<T> = Result<T, AppError>;
