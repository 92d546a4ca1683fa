//! Extractors whose rejections are problem documents: JSON bodies (415 on the wrong content type,
//! 413 over the limit, 400 naming the field on bad shape), query strings and path parameters.

use std::time::Duration;

use axum::body::Bytes;
use axum::extract::path::ErrorKind;
use axum::extract::rejection::PathRejection;
use axum::extract::{FromRef, FromRequest, FromRequestParts, Request};
use axum::http::HeaderMap;
use axum::http::header::{CONTENT_LENGTH, CONTENT_TYPE};
use axum::http::request::Parts;
use http_body_util::BodyExt;
use kerf_solver::ErrorCode;
use serde::de::DeserializeOwned;
use tokio::sync::OwnedSemaphorePermit;
use tokio::time::Instant;

use crate::error::AppError;
use crate::state::AppState;

/// A JSON body parsed into `T` (`application/json` only).
#[derive(Debug, Clone)]
pub struct AppJson<T>(pub T);

impl<T, S> FromRequest<S> for AppJson<T>
where
    T: DeserializeOwned,
    S: Send + Sync,
    AppState: FromRef<S>,
{
    type Rejection = AppError;

    async fn from_request(request: Request, state: &S) -> Result<Self, Self::Rejection> {
        if !is_json(request.headers()) {
            return Err(AppError::UnsupportedMediaType(
                "the body must be JSON: send Content-Type: application/json".to_owned(),
            ));
        }
        let state = AppState::from_ref(state);
        let bytes = body_bytes(request, &state, state.limits.max_body_bytes).await?;
        parse_json(&bytes).map(Self)
    }
}

/// True when the request says its body is JSON (`application/json` or `application/*+json`).
pub fn is_json(headers: &HeaderMap) -> bool {
    media_type(headers).is_some_and(|essence| {
        essence == "application/json" || (essence.starts_with("application/") && essence.ends_with("+json"))
    })
}

/// The request's media type without parameters, lower case (`text/plain; charset=utf-8` → `text/plain`).
pub fn media_type(headers: &HeaderMap) -> Option<String> {
    let value = headers.get(CONTENT_TYPE)?.to_str().ok()?;
    let essence = value.split(';').next().unwrap_or_default().trim().to_ascii_lowercase();
    (!essence.is_empty()).then_some(essence)
}

/// 413 at once when a request with `Expect: 100-continue` declares a body longer than `limit`
/// (`Content-Length`), before anything reads it: the client gets the 413 instead of `100
/// Continue` (hyper sends that only when the body is first read) and never sends the body.
///
/// Only then: a client that is already sending its body gets its 413 from reading up to the
/// limit, as before. Answering it without reading would close the connection on unread bytes,
/// and the reset that follows can destroy the 413 before the client reads it.
///
/// # Errors
/// 413 when the declared length is over the limit.
pub fn refuse_declared_over(headers: &HeaderMap, limit: usize) -> Result<(), AppError> {
    let waits_to_send = headers
        .get(axum::http::header::EXPECT)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|v| v.trim().eq_ignore_ascii_case("100-continue"));
    if !waits_to_send {
        return Ok(());
    }
    let declared = headers.get(CONTENT_LENGTH).and_then(|v| v.to_str().ok()).and_then(|v| v.trim().parse::<u64>().ok());
    match declared {
        Some(length) if length > u64::try_from(limit).unwrap_or(u64::MAX) => Err(AppError::PayloadTooLarge { limit }),
        _ => Ok(()),
    }
}

/// Reads the whole body, at most `limit` bytes: 413 over it (at once when the declared length is
/// over the limit: [`refuse_declared_over`]), 408 when it arrives slower than the minimum receive
/// rate ([`Limits::min_body_rate`](crate::state::Limits::min_body_rate)).
///
/// # Errors
/// 413 over the limit, 408 too slow, 400 `E_BODY` when the body cannot be read.
pub async fn body_bytes(request: Request, state: &AppState, limit: usize) -> Result<Bytes, AppError> {
    receive(request, state, limit, false).await.map(|(bytes, _)| bytes)
}

/// [`body_bytes`] charged to the memory budget ([`AppState::reserve_memory`]) as it arrives:
/// by the bytes received, not the length declared, so a slow upload holds only what it sent.
/// The permit holds the body's share until dropped.
///
/// # Errors
/// As [`body_bytes`]; 429 when the budget is held by others.
pub async fn charged_body_bytes(
    request: Request,
    state: &AppState,
    limit: usize,
) -> Result<(Bytes, Option<OwnedSemaphorePermit>), AppError> {
    receive(request, state, limit, true).await
}

async fn receive(
    request: Request,
    state: &AppState,
    limit: usize,
    charged: bool,
) -> Result<(Bytes, Option<OwnedSemaphorePermit>), AppError> {
    refuse_declared_over(request.headers(), limit)?;
    let mut body = request.into_body();
    let mut received: Vec<u8> = Vec::new();
    let mut share: Option<OwnedSemaphorePermit> = None;
    let mut rate = ReceiveRate::new(state.limits.min_body_rate, state.limits.body_rate_window);
    loop {
        let next = match rate.deadline() {
            Some(deadline) => match tokio::time::timeout_at(deadline, body.frame()).await {
                Ok(next) => next,
                Err(_) => {
                    rate.check(Instant::now())?;
                    continue;
                }
            },
            None => body.frame().await,
        };
        let Some(frame) = next else { break };
        let frame = frame.map_err(|error| {
            AppError::bad_request(ErrorCode::Body, "body", format!("could not read the body: {error}"))
        })?;
        let Ok(data) = frame.into_data() else { continue };
        if received.len().saturating_add(data.len()) > limit {
            return Err(AppError::PayloadTooLarge { limit });
        }
        received.extend_from_slice(&data);
        rate.add(data.len());
        if charged {
            share = Some(charge(state, share, received.len())?);
        }
        rate.check(Instant::now())?;
    }
    Ok((Bytes::from(received), share))
}

/// `share` grown to cover `bytes` received, in whole KiB (the budget's unit), never past the
/// whole budget (an upload larger than it takes all of it, alone).
fn charge(
    state: &AppState,
    share: Option<OwnedSemaphorePermit>,
    bytes: usize,
) -> Result<OwnedSemaphorePermit, AppError> {
    let held = share.as_ref().map_or(0, |permit| permit.num_permits() * 1024);
    let budget = state.limits.answer_budget_bytes.max(1);
    let wanted = bytes.min(budget);
    match share {
        Some(permit) if wanted <= held => Ok(permit),
        Some(mut permit) => {
            permit.merge(state.reserve_memory(wanted - held)?);
            Ok(permit)
        }
        None => state.reserve_memory(wanted),
    }
}

/// The minimum receive rate: the bytes of each window of `window` since the body began must
/// reach `bytes_per_second × window`.
struct ReceiveRate {
    bytes_per_second: usize,
    window: Duration,
    started: Instant,
    in_window: usize,
}

impl ReceiveRate {
    fn new(bytes_per_second: usize, window: Duration) -> Self {
        Self { bytes_per_second, window, started: Instant::now(), in_window: 0 }
    }

    /// When the current window ends; `None` without a minimum.
    fn deadline(&self) -> Option<Instant> {
        (self.bytes_per_second > 0 && !self.window.is_zero()).then(|| self.started + self.window)
    }

    fn add(&mut self, bytes: usize) {
        self.in_window = self.in_window.saturating_add(bytes);
    }

    /// At or past the end of a window: 408 when it fell short, else the next window begins.
    fn check(&mut self, now: Instant) -> Result<(), AppError> {
        let Some(deadline) = self.deadline() else { return Ok(()) };
        if now < deadline {
            return Ok(());
        }
        let seconds = self.window.as_secs_f64();
        if (self.in_window as f64) < self.bytes_per_second as f64 * seconds {
            return Err(AppError::BodyTooSlow(format!(
                "the body arrived at {:.0} bytes/s over {seconds} s, slower than the minimum of {} bytes/s \
                 (--min-body-rate); send it faster",
                self.in_window as f64 / seconds,
                self.bytes_per_second
            )));
        }
        self.started = now;
        self.in_window = 0;
        Ok(())
    }
}

/// Parses JSON into `T`; a failure names the JSON path of the offending field.
pub fn parse_json<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, AppError> {
    // Every request body is an object; serde would otherwise read an array as the fields in order.
    if bytes.iter().find(|b| !b.is_ascii_whitespace()) != Some(&b'{') {
        return Err(AppError::bad_request(ErrorCode::Json, "body", "the body must be a JSON object"));
    }
    let mut deserializer = serde_json::Deserializer::from_slice(bytes);
    let value = serde_path_to_error::deserialize(&mut deserializer).map_err(|error| {
        let path = error.path().to_string();
        let inner = error.into_inner();
        // serde_path_to_error says "." for the root and "?" where it could not track the path.
        let field = if path == "." || path == "?" { "body".to_owned() } else { path };
        AppError::bad_request(
            ErrorCode::Json,
            field.clone(),
            format!("{field}: {}", clean_serde_message(&inner.to_string())),
        )
    })?;
    deserializer.end().map_err(|error| {
        AppError::bad_request(ErrorCode::Json, "body", format!("trailing characters after the JSON value: {error}"))
    })?;
    Ok(value)
}

/// serde_json appends " at line 0 column 0" to errors raised inside nested deserializers.
fn clean_serde_message(message: &str) -> String {
    message.strip_suffix(" at line 0 column 0").unwrap_or(message).to_owned()
}

/// Query parameters parsed into `T`; a failure names the parameter.
#[derive(Debug, Clone)]
pub struct AppQuery<T>(pub T);

impl<T, S> FromRequestParts<S> for AppQuery<T>
where
    T: DeserializeOwned,
    S: Send + Sync,
{
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Self, Self::Rejection> {
        let query = parts.uri.query().unwrap_or_default();
        let deserializer = serde_urlencoded::Deserializer::new(form_urlencoded::parse(query.as_bytes()));
        serde_path_to_error::deserialize(deserializer).map(Self).map_err(|error| {
            let path = error.path().to_string();
            let field = if path == "." { "query".to_owned() } else { path };
            AppError::bad_request(
                ErrorCode::Query,
                field.clone(),
                format!("query parameter {field}: {}", error.into_inner()),
            )
        })
    }
}

/// Path parameters parsed into `T`; a failure is a 400 naming the parameter.
#[derive(Debug, Clone)]
pub struct AppPath<T>(pub T);

impl<T, S> FromRequestParts<S> for AppPath<T>
where
    T: DeserializeOwned + Send,
    S: Send + Sync,
{
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, state: &S) -> Result<Self, Self::Rejection> {
        axum::extract::Path::<T>::from_request_parts(parts, state).await.map(|path| Self(path.0)).map_err(
            |rejection: PathRejection| {
                let key = match &rejection {
                    PathRejection::FailedToDeserializePathParams(error) => match error.kind() {
                        ErrorKind::ParseErrorAtKey { key, .. }
                        | ErrorKind::InvalidUtf8InPathParam { key }
                        | ErrorKind::DeserializeError { key, .. } => Some(key.clone()),
                        _ => None,
                    },
                    _ => None,
                };
                AppError::bad_request(ErrorCode::Path, key.unwrap_or_else(|| "path".to_owned()), rejection.body_text())
            },
        )
    }
}
