//! Extractors whose rejections are problem documents: JSON bodies (415 on the wrong content type,
//! 413 over the limit, 400 naming the field on bad shape), query strings, path parameters, and the
//! preconditions of a write (`If-Match`, `If-None-Match`: 412) with the ETags they compare.

use std::time::Duration;

use axum::body::Bytes;
use axum::extract::path::ErrorKind;
use axum::extract::rejection::PathRejection;
use axum::extract::{FromRef, FromRequest, FromRequestParts, Request};
use axum::http::header::{CONTENT_LENGTH, CONTENT_TYPE, ETAG, IF_MATCH, IF_NONE_MATCH};
use axum::http::request::Parts;
use axum::http::{HeaderMap, HeaderName, HeaderValue, StatusCode};
use axum::response::{IntoResponse, Response};
use http_body_util::BodyExt;
use kerf_solver::ErrorCode;
use serde::Serialize;
use serde::de::DeserializeOwned;
use sha2::{Digest, Sha256};
use tokio::sync::OwnedSemaphorePermit;
use tokio::time::Instant;
use utoipa::IntoParams;

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

/// 413 at once when a request declares a body longer than `limit` (`Content-Length`), before
/// anything reads it: a client with `Expect: 100-continue` gets the 413 instead of `100
/// Continue` (hyper sends that only when the body is first read) and never sends the body; one
/// already sending it gets the 413 without the server reading up to the limit first. The answer
/// says `Connection: close` (the unread body cannot be skipped), and the connection is closed
/// after a lingering read ([`crate::serve`]) so the client reads the 413 rather than a reset.
///
/// # Errors
/// 413 when the declared length is over the limit.
pub fn refuse_declared_over(headers: &HeaderMap, limit: usize) -> Result<(), AppError> {
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
            let message = error.into_inner().to_string();
            // A required parameter left out is reported at the root; the message names it.
            let missing = message.strip_prefix("missing field `").and_then(|rest| rest.strip_suffix('`'));
            let field = match (path.as_str(), missing) {
                (".", Some(name)) => name.to_owned(),
                (".", None) => "query".to_owned(),
                _ => path,
            };
            AppError::bad_request(ErrorCode::Query, field.clone(), format!("query parameter {field}: {message}"))
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

/// The strong ETag of a representation (RFC 9110 §8.8.3): a quoted hash of its bytes, so equal
/// bytes give equal tags and any change of a byte gives another.
pub fn strong_etag(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    let hex: String = digest.iter().take(12).map(|b| format!("{b:02x}")).collect();
    format!("\"{hex}\"")
}

/// The ETag of `item`'s JSON answer: the tag of the bytes [`tagged`] sends for it.
///
/// # Errors
/// 500 when `item` cannot be written as JSON.
pub fn etag_of(item: &impl Serialize) -> Result<String, AppError> {
    serde_json::to_vec(item).map(|bytes| strong_etag(&bytes)).map_err(|error| AppError::Internal(error.into()))
}

/// `item` as a JSON answer with `status` and its `ETag`.
///
/// # Errors
/// 500 when `item` cannot be written as JSON.
pub fn tagged(status: StatusCode, item: &impl Serialize) -> Result<Response, AppError> {
    let bytes = serde_json::to_vec(item).map_err(|error| AppError::Internal(error.into()))?;
    let etag = HeaderValue::from_str(&strong_etag(&bytes)).map_err(|error| AppError::Internal(error.into()))?;
    let json = HeaderValue::from_static("application/json");
    Ok((status, [(CONTENT_TYPE, json), (ETAG, etag)], bytes).into_response())
}

/// One entity tag of a precondition header, quotes included (`"abc"`).
#[derive(Debug, Clone, PartialEq, Eq)]
struct EntityTag {
    /// Written `W/"…"`: never matches in `If-Match` (strong comparison, RFC 9110 §8.8.3.2).
    weak: bool,
    quoted: String,
}

/// What `If-Match` or `If-None-Match` names: `*` (any stored item) or a list of entity tags; or
/// neither, which [`Preconditions::check`] refuses.
#[derive(Debug, Clone, PartialEq, Eq)]
enum TagCondition {
    Any,
    Tags(Vec<EntityTag>),
    Unreadable,
}

/// Reads `* / #entity-tag` (RFC 9110 §13.1.1); `None` when the text is neither.
fn parse_condition(text: &str) -> Option<TagCondition> {
    if text.trim() == "*" {
        return Some(TagCondition::Any);
    }
    let mut tags = Vec::new();
    let mut rest = text;
    loop {
        // A list may hold empty elements (RFC 9110 §5.6.1).
        rest = rest.trim_start_matches([' ', '\t', ',']);
        if rest.is_empty() {
            break;
        }
        let (weak, body) = rest.strip_prefix("W/").map_or((false, rest), |body| (true, body));
        let opaque = body.strip_prefix('"')?;
        let end = opaque.find('"')?;
        // etagc: `!`, `#` to `~`, or non-ASCII; no space, no quote, no control.
        if !opaque[..end].bytes().all(|b| b == b'!' || (b'#'..=b'~').contains(&b) || b >= 0x80) {
            return None;
        }
        tags.push(EntityTag { weak, quoted: format!("\"{}\"", &opaque[..end]) });
        rest = opaque[end + 1..].trim_start_matches([' ', '\t']);
        if !rest.is_empty() && !rest.starts_with(',') {
            return None;
        }
    }
    (!tags.is_empty()).then_some(TagCondition::Tags(tags))
}

/// The condition a header states (its lines are one list), `None` when the request has none.
fn condition(headers: &HeaderMap, name: &HeaderName) -> Option<TagCondition> {
    let values: Vec<&HeaderValue> = headers.get_all(name).iter().collect();
    if values.is_empty() {
        return None;
    }
    let text = values.iter().map(|value| value.to_str()).collect::<Result<Vec<_>, _>>().map(|parts| parts.join(","));
    Some(text.ok().as_deref().and_then(parse_condition).unwrap_or(TagCondition::Unreadable))
}

/// The preconditions of a request that writes or deletes a stored item (RFC 9110 §13.1.1–2):
/// `If-Match: <etag>` (or `*`) writes only over the version the client has seen,
/// `If-None-Match: *` only when there is none yet. Without either the write is unconditional.
#[derive(Debug, Clone, Default)]
pub struct Preconditions {
    if_match: Option<TagCondition>,
    if_none_match: Option<TagCondition>,
}

/// The headers [`Preconditions`] reads on a PUT, as the OpenAPI document lists them.
#[derive(Debug, IntoParams)]
#[into_params(parameter_in = Header)]
pub struct ReplaceHeaders {
    /// Replace only if the stored item's ETag is one of these (quoted, as `ETag` gave it), or
    /// `*`: only if the item is stored; else 412 `E_PRECONDITION_FAILED`.
    #[param(rename = "If-Match")]
    pub if_match: Option<String>,
    /// `*`: create only, never replace; else 412 `E_PRECONDITION_FAILED`.
    #[param(rename = "If-None-Match")]
    pub if_none_match: Option<String>,
}

/// The header [`Preconditions`] reads on a DELETE, as the OpenAPI document lists it.
#[derive(Debug, IntoParams)]
#[into_params(parameter_in = Header)]
pub struct DeleteHeaders {
    /// Delete only if the stored item's ETag is one of these (quoted, as `ETag` gave it), or
    /// `*`: only if the item is stored; else 412 `E_PRECONDITION_FAILED`.
    #[param(rename = "If-Match")]
    pub if_match: Option<String>,
}

impl<S: Send + Sync> FromRequestParts<S> for Preconditions {
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Self, Self::Rejection> {
        Ok(Self {
            if_match: condition(&parts.headers, &IF_MATCH),
            if_none_match: condition(&parts.headers, &IF_NONE_MATCH),
        })
    }
}

impl Preconditions {
    /// Whether the write may go ahead on `item` (`tool 7`, `machine "dmu50"`), stored now with
    /// the ETag `current` (`None`: not stored).
    ///
    /// # Errors
    /// 412 naming the header that does not hold, with the current ETag when there is one; also
    /// for a header that is neither `*` nor quoted entity tags: a write is never made on a
    /// condition kerf cannot read.
    pub fn check(&self, item: &str, current: Option<&str>) -> Result<(), AppError> {
        for (condition, header) in [(&self.if_match, "If-Match"), (&self.if_none_match, "If-None-Match")] {
            if condition.as_ref() == Some(&TagCondition::Unreadable) {
                let now =
                    current.map(|current| format!("; the current ETag of {item} is {current}")).unwrap_or_default();
                return Err(AppError::PreconditionFailed {
                    header,
                    detail: format!("{header} must be * or a list of quoted entity tags, as ETag gives them{now}"),
                    etag: current.map(str::to_owned),
                });
            }
        }
        if let Some(condition) = &self.if_match {
            let holds = match (condition, current) {
                (TagCondition::Any, Some(_)) => true,
                (TagCondition::Tags(tags), Some(current)) => tags.iter().any(|tag| !tag.weak && tag.quoted == current),
                (_, None) | (TagCondition::Unreadable, _) => false,
            };
            if !holds {
                let detail = match current {
                    None => format!("If-Match: {item} does not exist (it was deleted or never stored)"),
                    Some(current) => format!("If-Match: {item} has changed; its current ETag is {current}"),
                };
                return Err(AppError::PreconditionFailed {
                    header: "If-Match",
                    detail,
                    etag: current.map(str::to_owned),
                });
            }
        }
        if let (Some(condition), Some(current)) = (&self.if_none_match, current) {
            let matches = match condition {
                TagCondition::Any | TagCondition::Unreadable => true,
                TagCondition::Tags(tags) => tags.iter().any(|tag| tag.quoted == current),
            };
            if matches {
                return Err(AppError::PreconditionFailed {
                    header: "If-None-Match",
                    detail: format!("If-None-Match: {item} already exists; its current ETag is {current}"),
                    etag: Some(current.to_owned()),
                });
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::{EntityTag, TagCondition, parse_condition};

    fn strong(quoted: &str) -> EntityTag {
        EntityTag { weak: false, quoted: quoted.to_owned() }
    }

    #[test]
    fn reads_star_and_tag_lists() {
        assert_eq!(parse_condition(" * "), Some(TagCondition::Any));
        assert_eq!(parse_condition(r#""a1""#), Some(TagCondition::Tags(vec![strong(r#""a1""#)])));
        assert_eq!(
            parse_condition(r#"W/"x", "a,b" ,,"c""#),
            Some(TagCondition::Tags(vec![
                EntityTag { weak: true, quoted: r#""x""#.to_owned() },
                strong(r#""a,b""#),
                strong(r#""c""#)
            ]))
        );
    }

    #[test]
    fn refuses_what_is_not_a_tag_list() {
        for text in ["a1", r#""a1"x"#, r#""a1"#, r#""a b""#, "", " , ", r#""*", *"#, "W/a"] {
            assert_eq!(parse_condition(text), None, "{text:?}");
        }
    }
}
