//! The cut stock of `POST /api/v1/verify` as binary glTF (docs/spec/verify.md §8 Mesh), asked for
//! with `?format=glb` or an `Accept` that ranks `model/gltf-binary` above `application/json`:
//! the tools resolved as for the JSON answer, the cut and the mesh built on the blocking pool
//! within the answer budget.

use axum::body::Bytes;
use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::Response;
use kerf_solver::capability::{AnswerBudget, Control, Purpose, Run};
use kerf_solver::verify::{Found, GLB_MEDIA_TYPE, VerifyCapability, VerifyRequest, cut_stock_glb};
use serde::Deserialize;
use utoipa::ToSchema;

use super::output::accept_prefers;
use crate::capabilities;
use crate::error::{AppError, AppResult};
use crate::http::stream::{held_download, pieces_of};
use crate::state::AppState;

/// The answer formats of the verify endpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum VerifyFormat {
    /// The findings as JSON (default).
    Json,
    /// The cut stock as binary glTF (`model/gltf-binary`), the JSON answer in its `extras.verify`.
    Glb,
}

/// A GLB file (for the OpenAPI document): the cut stock as binary glTF.
#[derive(Debug, ToSchema)]
#[schema(value_type = String, format = Binary)]
pub struct GlbFile(pub Vec<u8>);

/// Whether the client asks for the mesh: `format` if given, else the `Accept` header.
pub fn wants_glb(headers: &HeaderMap, format: Option<VerifyFormat>) -> bool {
    match format {
        Some(format) => format == VerifyFormat::Glb,
        None => accept_prefers(headers, GLB_MEDIA_TYPE),
    }
}

/// Answers the stock as `request`'s program (up to `upto_line`) left it, as GLB.
///
/// # Errors
/// As the JSON answer: 404 for an unknown tool, 422 for the solver's refusal (a mesh over the
/// answer budget is refused at `resolution`), 429 when every solver slot is busy.
pub async fn answer(
    state: &AppState,
    request: VerifyRequest,
    upload: Option<Bytes>,
    upto_line: Option<usize>,
) -> AppResult<Response> {
    let refs = kerf_solver::capability::all_refs::<VerifyCapability>(&request);
    let catalog = capabilities::catalog(&state.db, refs, capabilities::Catalog::default()).await?;
    // Read in mm as the JSON answer's request is; the mesh and its answer in the request's units.
    let (request, units) = capabilities::in_mm::<VerifyCapability>(&request, &catalog)?;
    let request = request.into_owned();
    let resolved = capabilities::resolve::<VerifyCapability>(&request, &catalog)?;
    let budget = AnswerBudget::new(u64::try_from(state.limits.answer_budget_bytes).unwrap_or(u64::MAX));
    let started = std::time::Instant::now();
    let bytes = state
        .solve(move |cancel| {
            let run = Run {
                control: Control { progress: None, cancel: Some(cancel) },
                upload: upload.as_deref(),
                purpose: Purpose::Json,
                budget: Some(&budget),
            };
            let found = Found { material: resolved.material.as_ref(), machine: resolved.machine.as_ref() };
            cut_stock_glb(&request, resolved.other_tools, found, upto_line, units, &run)
                .map_err(|error| capabilities::refusal_in(error, units))
        })
        .await?
        .map_err(AppError::from)?;
    let seconds = started.elapsed().as_secs_f64();
    crate::metrics::observe_solver("verify", seconds);
    let length = bytes.len();
    let mut response =
        held_download(state.reserve_memory(length)?, pieces_of(Bytes::from(bytes)), length, GLB_MEDIA_TYPE);
    let timing = HeaderValue::from_str(&format!("solve;dur={:.1}", seconds * 1e3))
        .unwrap_or_else(|_| HeaderValue::from_static("solve"));
    response.headers_mut().insert("server-timing", timing);
    response.headers_mut().insert(header::VARY, HeaderValue::from_static("accept"));
    Ok(response)
}
