//! Optional bearer token: when `KERF_API_TOKEN` is set, every request that changes
//! state or solves needs `Authorization: Bearer <token>` (a job operation's cut stock is read
//! with GET but solves the operation again); with `--private` reads of the API need it too.
//! The health check, the page's files and the API documentation stay open: they hold no data.

use axum::extract::{Request, State};
use axum::http::{Method, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use crate::error::AppError;

/// Who may call the API.
#[derive(Debug, Clone, Default)]
pub struct Auth {
    /// The token; `None` leaves the API open.
    pub token: Option<String>,
    /// Reads need the token too.
    pub private: bool,
}

impl Auth {
    fn needs_token(&self, method: &Method, path: &str) -> bool {
        if self.token.is_none() {
            return false;
        }
        let reading = matches!(*method, Method::GET | Method::HEAD | Method::OPTIONS);
        let data = path.starts_with("/api/") && path != "/api/v1/openapi.json";
        let solving =
            path.starts_with("/api/v1/jobs/") && (path.ends_with("/stock") || path.ends_with("/stock/program"));
        if reading && !solving { self.private && data } else { true }
    }

    fn accepts(&self, request: &Request) -> bool {
        let Some(expected) = &self.token else { return true };
        let given = request
            .headers()
            .get(header::AUTHORIZATION)
            .and_then(|value| value.to_str().ok())
            .and_then(|value| value.strip_prefix("Bearer "))
            .unwrap_or_default();
        // Compare every byte, so the time taken does not tell how much of a guess was right.
        given.len() == expected.len() && given.bytes().zip(expected.bytes()).fold(0, |diff, (a, b)| diff | (a ^ b)) == 0
    }
}

/// Middleware: refuses requests that need the token and lack it with 401. It takes only the
/// [`Auth`] (not the whole application state), so this module needs nothing above it.
pub async fn require_token(State(auth): State<Auth>, request: Request, next: Next) -> Response {
    if auth.needs_token(request.method(), request.uri().path()) && !auth.accepts(&request) {
        return AppError::Unauthorized(
            "this request needs the API token: send Authorization: Bearer <token>".to_owned(),
        )
        .into_response();
    }
    next.run(request).await
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn which_requests_need_the_token() {
        let open = Auth::default();
        assert!(!open.needs_token(&Method::PUT, "/api/v1/tools/1"));
        let token = Auth { token: Some("s3cret".to_owned()), private: false };
        assert!(token.needs_token(&Method::PUT, "/api/v1/tools/1"));
        assert!(token.needs_token(&Method::POST, "/api/v1/deburr"));
        assert!(!token.needs_token(&Method::GET, "/api/v1/tools"));
        assert!(!token.needs_token(&Method::GET, "/api/v1/jobs/3/gcode"));
        assert!(token.needs_token(&Method::GET, "/api/v1/jobs/3/stock"));
        assert!(token.needs_token(&Method::GET, "/api/v1/jobs/3/stock/program"));
        let private = Auth { private: true, ..token };
        assert!(private.needs_token(&Method::GET, "/api/v1/tools"));
        assert!(!private.needs_token(&Method::GET, "/healthz"));
        assert!(!private.needs_token(&Method::GET, "/"));
        assert!(!private.needs_token(&Method::GET, "/api/v1/openapi.json"));
    }
}
