//! `POST /api/v1/predict` (api.md, Error prediction): machining-error prediction and path
//! correction for ball-end-mill finishing, as JSON or as the corrected G-code program.
//!
//! The request is JSON, or `multipart/form-data` with the JSON in part `request` and the stock's
//! STL file (binary or ASCII) in part `stock` when `"stock": {"kind": "mesh"}`. This route has
//! its own body limit (`Limits::max_upload_bytes`, 128 MiB by default) instead of the service's
//! default one.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use axum::body::{Body, Bytes};
use axum::extract::{DefaultBodyLimit, FromRequest, Multipart, Request, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use kerf_solver::SolverError;
use kerf_solver::gcode::{Dialect, Reference, ToolCall};
use kerf_solver::predict::{self, Control, PassStatus, PathInput, Predict, PredictRequest, ProgramOptions, Stock};
use kerf_solver::tool::Tool;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Format, Output, OutputQuery, gcode_response};
use crate::error::{AppError, AppResult, Problem};
use crate::extract::{AppQuery, body_bytes, is_json, media_type, parse_json};
use crate::state::AppState;
use crate::store;

/// How long the prediction took (only with `?timings=true`, and in job results: equal requests
/// otherwise give byte-identical answers). Also sent as the `Server-Timing` header.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct Timings {
    /// Wall time of the prediction and correction, ms.
    pub solve_ms: f64,
    /// Passes predicted (those in `pass_range`, every round).
    pub passes: usize,
    /// Passes predicted per second of wall time.
    pub passes_per_s: f64,
}

/// The prediction answer: the tool used and the solver's result.
#[derive(Debug, Serialize, ToSchema)]
pub struct PredictAnswer {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// Per-pass predictions, summary and warnings.
    #[serde(flatten)]
    pub result: Predict,
    /// Timings, when asked for (`?timings=true`) and in job results.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timings: Option<Timings>,
}

/// Query parameters of `POST /api/v1/predict`: the output negotiation of every path-producing
/// endpoint, plus `timings`.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct PredictQuery {
    /// `json` (default) or `gcode` (the corrected program); `Accept: text/x-gcode` also selects
    /// G-code.
    pub format: Option<Format>,
    /// Dialect of the program written for a `points` path: `fanuc` (default) or `linuxcnc`. A
    /// G-code path is written back in its own format.
    pub dialect: Option<Dialect>,
    /// Programmed point of the corrected program: the request's `reference` by default. A
    /// `points` path is converted; a G-code path keeps its own (another value is refused).
    pub reference: Option<Reference>,
    /// Add `timings` to the JSON answer (default false).
    pub timings: Option<bool>,
}

/// The form of a multipart request (for the OpenAPI document).
#[derive(Debug, ToSchema)]
pub struct PredictForm {
    /// The request, as the JSON body would be, with `"stock": {"kind": "mesh"}`.
    pub request: String,
    /// The stock as an STL file (binary or ASCII), a closed surface.
    #[schema(value_type = String, format = Binary)]
    pub stock: Vec<u8>,
}

/// A request as uploaded: the JSON and, for a mesh stock, the STL bytes.
struct Upload {
    request: PredictRequest,
    mesh: Option<Bytes>,
}

fn multipart_error(part: &str, limit: usize, error: &axum::extract::multipart::MultipartError) -> AppError {
    if error.status() == StatusCode::PAYLOAD_TOO_LARGE {
        AppError::PayloadTooLarge { limit }
    } else {
        AppError::bad_request("E_MULTIPART", part, format!("{part}: {}", error.body_text()))
    }
}

/// Reads the body under the upload limit: JSON, or the multipart form.
async fn upload(state: &AppState, request: Request) -> AppResult<Upload> {
    let limit = state.limits.max_upload_bytes;
    let declared =
        request.headers().get(header::CONTENT_LENGTH).and_then(|v| v.to_str().ok()).and_then(|v| v.parse::<u64>().ok());
    if declared.is_some_and(|length| length > limit as u64) {
        return Err(AppError::PayloadTooLarge { limit });
    }
    // The route's default limit is off (see `router`); this one applies instead.
    let request = request.map(|body| Body::new(http_body_util::Limited::new(body, limit)));
    if is_json(request.headers()) {
        let bytes = body_bytes(request, state, limit).await?;
        return Ok(Upload { request: parse_json(&bytes)?, mesh: None });
    }
    if media_type(request.headers()).as_deref() != Some("multipart/form-data") {
        return Err(AppError::UnsupportedMediaType(
            "send the request as application/json, or as multipart/form-data with the JSON in part `request` \
             and the STL file in part `stock`"
                .to_owned(),
        ));
    }
    let mut multipart = Multipart::from_request(request, state)
        .await
        .map_err(|rejection| AppError::bad_request("E_MULTIPART", "body", rejection.body_text()))?;
    let (mut json, mut mesh): (Option<Bytes>, Option<Bytes>) = (None, None);
    loop {
        let field = match multipart.next_field().await {
            Ok(Some(field)) => field,
            Ok(None) => break,
            Err(error) => return Err(multipart_error("body", limit, &error)),
        };
        let name = field.name().unwrap_or_default().to_owned();
        let slot = match name.as_str() {
            "request" => &mut json,
            "stock" => &mut mesh,
            _ => {
                return Err(AppError::bad_request(
                    "E_MULTIPART",
                    if name.is_empty() { "body".to_owned() } else { name.clone() },
                    format!("unexpected form part `{name}`: send `request` (the JSON) and `stock` (the STL file)"),
                ));
            }
        };
        if slot.is_some() {
            return Err(AppError::bad_request(
                "E_MULTIPART",
                name.clone(),
                format!("form part `{name}` is given twice"),
            ));
        }
        *slot = Some(field.bytes().await.map_err(|error| multipart_error(&name, limit, &error))?);
    }
    let json = json.ok_or_else(|| {
        AppError::bad_request("E_MULTIPART", "request", "the form has no part `request` with the JSON request")
    })?;
    Ok(Upload { request: parse_json(&json)?, mesh })
}

/// Sets the cancel flag when dropped: a request that hits the time limit, or whose client goes
/// away, stops its prediction instead of leaving it running on the blocking pool.
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

/// What the blocking part of a request produced.
enum Answer {
    Json(Vec<u8>, f64),
    Gcode(String, f64),
}

fn server_timing(response: &mut Response, solve_ms: f64) {
    if let Ok(value) = HeaderValue::from_str(&format!("solve;dur={solve_ms:.1}")) {
        response.headers_mut().insert("server-timing", value);
    }
}

/// Predicts the machining error of a ball-end-mill finishing path and corrects the path.
///
/// Returns one record per pass (error along the surface normal, contact angle, generation point,
/// normal, flags, corrected end point), a summary with the worst passes and warnings (JSON), or
/// with `Accept: text/x-gcode` / `?format=gcode` the corrected program. The body is JSON, or a
/// form with the JSON in part `request` and the STL stock in part `stock`. Long paths exceed the
/// synchronous time limit (422 `E_TIMEOUT`): submit them as a job (`operation = "predict"`).
#[utoipa::path(post, path = "/api/v1/predict", tag = "predict",
    params(PredictQuery),
    request_body(description = "The request as JSON, or a form with it in part `request` and the STL stock in part `stock`.",
        content(
            (PredictRequest = "application/json"),
            (PredictForm = "multipart/form-data"))),
    responses(
        (status = 200, description = "The prediction as JSON", body = PredictAnswer),
        (status = 200, description = "The corrected program (`?format=gcode`)", body = String, content_type = "text/x-gcode"),
        (status = 400, description = "Not the right shape (JSON or form)", body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number", body = Problem, content_type = "application/problem+json"),
        (status = 413, description = "Body over the upload limit", body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "Impossible or over a limit: tool kind, no shape-error table, G-code errors with the line, open mesh, resolution over the memory limit; `E_TIMEOUT` over the synchronous time limit: submit a job", body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json")))]
async fn post_predict(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<PredictQuery>,
    request: Request,
) -> AppResult<Response> {
    let output = Output::negotiate(
        &headers,
        &OutputQuery { format: query.format, dialect: query.dialect, reference: query.reference },
    );
    let Upload { request, mesh } = upload(&state, request).await?;
    if output.gcode {
        check_reference(&request, query.reference)?;
    }
    match (&request.stock, &mesh) {
        (Stock::Mesh {}, None) => {
            return Err(SolverError::input(
                "stock",
                "a mesh stock needs its STL file: send multipart/form-data with the JSON in part `request` \
                 and the STL file in part `stock`",
            )
            .into());
        }
        (stock, Some(_)) if !matches!(stock, Stock::Mesh {}) => {
            return Err(
                SolverError::input("stock.kind", "an STL file was uploaded but stock.kind is not \"mesh\"").into()
            );
        }
        _ => {}
    }
    let tool = store::tools::resolve(&state.db, &request.tool).await?;
    let cancel = Arc::new(AtomicBool::new(false));
    let _stop = CancelOnDrop(Arc::clone(&cancel));
    let with_timings = query.timings.unwrap_or(false);
    let answer = state
        .solve(move || -> Result<Answer, AppError> {
            let control = Control { progress: None, cancel: Some(&cancel) };
            let mut answer = run(&request, tool, mesh.as_deref(), &control)?;
            let solve_ms = answer.timings.as_ref().map_or(0.0, |t| t.solve_ms);
            if output.gcode {
                let dialect = output.dialect.unwrap_or_default();
                return Ok(Answer::Gcode(program(&request, &answer, dialect, query.reference)?, solve_ms));
            }
            if !with_timings {
                answer.timings = None;
            }
            let bytes = serde_json::to_vec(&answer).map_err(|e| AppError::Internal(e.into()))?;
            Ok(Answer::Json(bytes, solve_ms))
        })
        .await??;
    let mut response = match answer {
        Answer::Gcode(program, solve_ms) => {
            let mut response = gcode_response(program);
            server_timing(&mut response, solve_ms);
            response
        }
        Answer::Json(bytes, solve_ms) => {
            let mut response = bytes.into_response();
            response.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("application/json"));
            server_timing(&mut response, solve_ms);
            response
        }
    };
    response.headers_mut().insert(header::VARY, HeaderValue::from_static("accept"));
    Ok(response)
}

/// A G-code path is written back with its own programmed point: another one is refused.
fn check_reference(request: &PredictRequest, reference: Option<Reference>) -> Result<(), SolverError> {
    match (&request.path, reference) {
        (PathInput::Gcode { .. }, Some(asked)) if asked != request.reference => Err(SolverError::input(
            "reference",
            format!(
                "a G-code path is written back with its own programmed point (the request's reference, {}); \
                 leave ?reference out or ask for {}",
                request.reference.as_str(),
                request.reference.as_str()
            ),
        )),
        _ => Ok(()),
    }
}

/// Predicts and corrects a request with its resolved tool and, for a mesh stock, the STL bytes
/// (used by the route and by jobs). `control` carries the progress callback and cancel flag.
///
/// # Errors
/// The solver's refusals; `E_CANCELLED` when `control.cancel` was set.
pub fn run(
    request: &PredictRequest,
    tool: Tool,
    mesh: Option<&[u8]>,
    control: &Control<'_>,
) -> Result<PredictAnswer, SolverError> {
    let started = Instant::now();
    let result = predict::solve_with(request, &tool, mesh, control)?;
    let seconds = started.elapsed().as_secs_f64();
    let rounds = result.summary.rounds.len().max(1);
    let passes = result.passes.iter().filter(|p| p.status != PassStatus::NotPredicted).count() * rounds;
    let timings = Timings {
        solve_ms: (seconds * 1e4).round() / 10.0,
        passes,
        passes_per_s: if seconds > 0.0 { (passes as f64 / seconds).round() } else { 0.0 },
    };
    Ok(PredictAnswer { tool, result, timings: Some(timings) })
}

/// The corrected program of a solved request. A G-code path is the input program with only the
/// coordinates of moved end points changed (same lines, comments and modal words; `dialect` does
/// not apply); a `points` path becomes a complete program in `dialect`, written for `reference`
/// (the request's when `None`).
///
/// # Errors
/// `E_INPUT` at `reference` when a G-code path is asked for another programmed point.
pub fn program(
    request: &PredictRequest,
    answer: &PredictAnswer,
    dialect: Dialect,
    reference: Option<Reference>,
) -> Result<String, SolverError> {
    check_reference(request, reference)?;
    let options = ProgramOptions { dialect, tool: ToolCall::for_tool(&answer.tool) };
    match (&request.path, reference) {
        (PathInput::Points { points }, Some(asked)) if asked != request.reference => {
            // Tip = centre − R·z: move the points to the other programmed point.
            let shift = if asked == Reference::Centre { answer.tool.radius } else { -answer.tool.radius };
            let mut converted = request.clone();
            converted.reference = asked;
            converted.path = PathInput::Points { points: points.iter().map(|p| [p[0], p[1], p[2] + shift]).collect() };
            predict::corrected_program(&converted, &answer.result, &options)
        }
        _ => predict::corrected_program(request, &answer.result, &options),
    }
}

/// The program a job writes: a `points` path in the job's dialect and programmed point, a G-code
/// path as its own program with corrected coordinates.
///
/// # Errors
/// As [`program`].
pub fn job_program(
    request: &PredictRequest,
    answer: &PredictAnswer,
    dialect: Dialect,
    reference: Reference,
) -> Result<String, SolverError> {
    let reference = matches!(request.path, PathInput::Points { .. }).then_some(reference);
    program(request, answer, dialect, reference)
}

/// Routes of this module; the upload limit replaces the default body limit here.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_predict)).layer(DefaultBodyLimit::disable())
}
