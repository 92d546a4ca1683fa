//! The body of an endpoint that takes files (predict, verify): the JSON request, or a
//! `multipart/form-data` form with the JSON in part `request` and each file in the part named for
//! it. The body is received whole first (charged to the memory budget as it arrives).

use axum::body::{Body, Bytes};
use axum::extract::{FromRequest, Multipart, Request};
use axum::http::{HeaderValue, header};
use kerf_solver::ErrorCode;
use serde::de::DeserializeOwned;

use crate::error::{AppError, AppResult};
use crate::extract::parse_json;

/// A body as uploaded: the request read from its JSON, and each named file given (in the order
/// of the names asked for).
pub(crate) struct Upload<T> {
    pub request: T,
    pub files: Vec<Option<Bytes>>,
}

fn multipart_error(part: &str, error: &axum::extract::multipart::MultipartError) -> AppError {
    AppError::bad_request(ErrorCode::Multipart, part, format!("{part}: {}", error.body_text()))
}

/// The refusal of a body that is neither JSON nor a form, naming the form's file parts.
pub(crate) fn unsupported(files: &[&str]) -> AppError {
    AppError::UnsupportedMediaType(format!(
        "send the request as application/json, or as multipart/form-data with the JSON in part `request` and the STL \
         file in part {}",
        listed(files)
    ))
}

/// `files` as prose: "`stock`", "`part` or `stock`".
fn listed(files: &[&str]) -> String {
    let names: Vec<String> = files.iter().map(|name| format!("`{name}`")).collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.concat(),
    }
}

/// Reads a body received whole: the JSON, or the multipart form with `content_type` whose file
/// parts are named `files`. CPU work on a large upload: call it on a blocking thread.
pub(crate) fn read<T: DeserializeOwned>(
    json: bool,
    content_type: Option<HeaderValue>,
    body: Bytes,
    files: &[&str],
) -> AppResult<Upload<T>> {
    if json {
        return Ok(Upload { request: parse_json(&body)?, files: vec![None; files.len()] });
    }
    let mut form = Request::new(Body::from(body));
    if let Some(content_type) = content_type {
        form.headers_mut().insert(header::CONTENT_TYPE, content_type);
    }
    // The body is all in memory: the form's parts are split without waiting for anything.
    tokio::runtime::Handle::current().block_on(read_form(form, files, "STL"))
}

/// The parts of the multipart form `form`: `request` (the JSON) and the files named `files`, each
/// a file of `kind` (`STL`, `DXF`) as the refusal of an unexpected part says.
pub(crate) async fn read_form<T: DeserializeOwned>(form: Request, files: &[&str], kind: &str) -> AppResult<Upload<T>> {
    let mut multipart = Multipart::from_request(form, &())
        .await
        .map_err(|rejection| AppError::bad_request(ErrorCode::Multipart, "body", rejection.body_text()))?;
    let mut json: Option<Bytes> = None;
    let mut given: Vec<Option<Bytes>> = vec![None; files.len()];
    loop {
        let field = match multipart.next_field().await {
            Ok(Some(field)) => field,
            Ok(None) => break,
            Err(error) => return Err(multipart_error("body", &error)),
        };
        let name = field.name().unwrap_or_default().to_owned();
        let slot = if name == "request" {
            &mut json
        } else if let Some(index) = files.iter().position(|file| *file == name) {
            &mut given[index]
        } else {
            return Err(AppError::bad_request(
                ErrorCode::Multipart,
                if name.is_empty() { "body".to_owned() } else { name.clone() },
                format!(
                    "unexpected form part `{name}`: send `request` (the JSON) and {} (the {kind} file)",
                    listed(files).replace(" or ", " and ")
                ),
            ));
        };
        if slot.is_some() {
            return Err(AppError::bad_request(
                ErrorCode::Multipart,
                name.clone(),
                format!("form part `{name}` is given twice"),
            ));
        }
        *slot = Some(field.bytes().await.map_err(|error| multipart_error(&name, &error))?);
    }
    let json = json.ok_or_else(|| {
        AppError::bad_request(ErrorCode::Multipart, "request", "the form has no part `request` with the JSON request")
    })?;
    Ok(Upload { request: parse_json(&json)?, files: given })
}
