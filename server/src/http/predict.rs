//! `POST /api/v1/predict` (docs/spec/api.md, Error prediction): machining-error prediction and path
//! correction for ball-end-mill finishing, as JSON; `POST /api/v1/predict/program` answers the
//! corrected G-code program, `POST /api/v1/predict/stock` the stock as its verification cuts it.
//!
//! The request is JSON, or `multipart/form-data` with the JSON in part `request` and the stock's
//! STL file (binary or ASCII) in part `stock` when `"stock": {"kind": "mesh"}`. This route has
//! its own body limit (`Limits::max_upload_bytes`, 128 MiB by default) instead of the service's
//! default one.

use axum::body::Bytes;
use axum::extract::{DefaultBodyLimit, Request, State};
use axum::http::{HeaderMap, header};
use axum::response::Response;
use kerf_solver::capability::{Capability, OutputOptions};
use kerf_solver::gcode::{Dialect, Reference};
use kerf_solver::predict::{PredictAnswer, PredictCapability, PredictRequest};
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Ask, Format, wants_gcode};
use super::own_stock::GlbFile;
use super::own_stock::{self, StockQuery};
use super::upload;
use crate::error::{AppResult, Problem};
use crate::extract::{AppQuery, charged_body_bytes, is_json, media_type};
use crate::state::AppState;

/// Query parameters of `POST /api/v1/predict`: the output negotiation of every path-producing
/// endpoint, plus `timings` (the document lists [`PredictJsonQuery`]).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PredictQuery {
    /// `json` (default) or `gcode` (the corrected program); `Accept: text/x-gcode` also selects
    /// G-code.
    pub format: Option<Format>,
    /// Dialect (the post) of the program written for a `points` path: `fanuc` (default), `haas`,
    /// `linuxcnc`, `sinumerik`, `heidenhain`, `heidenhain_iso` or `grbl`. A G-code path is
    /// written back in its own format.
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

/// The query of the predict endpoint's JSON answer, as documented.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct PredictJsonQuery {
    /// Add `timings` to the JSON answer (default false).
    pub timings: Option<bool>,
}

/// The query of `POST /api/v1/predict/program`: how the corrected program is written.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct PredictProgramQuery {
    /// Dialect (the post) of the program written for a `points` path: `fanuc` (default), `haas`,
    /// `linuxcnc`, `sinumerik`, `heidenhain`, `heidenhain_iso` or `grbl`. A G-code path is
    /// written back in its own format.
    pub dialect: Option<Dialect>,
    /// Programmed point of the corrected program: the request's `reference` by default. A
    /// `points` path is converted; a G-code path keeps its own (another value is refused).
    pub reference: Option<Reference>,
}

/// The predict capability's endpoint, with its upload (documented with the capability's
/// [`Endpoint`](kerf_solver::capability::Endpoint) texts like the generated ones): the JSON
/// answer; `?format=gcode` or an `Accept` preferring `text/x-gcode` still answer the program here (undocumented: `POST /api/v1/predict/program` is the documented way).
#[utoipa::path(post, path = "/api/v1/predict", tag = "predict", operation_id = "predict",
    summary = <PredictCapability as Capability>::ENDPOINT.summary,
    description = <PredictCapability as Capability>::ENDPOINT.description,
    params(PredictJsonQuery),
    request_body(description = "The request as JSON, or a form with it in part `request` and the STL stock in part `stock`.",
        content(
            (PredictRequest = "application/json"),
            (PredictForm = "multipart/form-data"))),
    responses(
        (status = 200, description = "The prediction", body = PredictAnswer, content_type = "application/json"),
        (status = 400, description = "Not the right shape (JSON or form)", body = Problem, content_type = "application/problem+json"),
        (status = 404, description = <PredictCapability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
        (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
        (status = 413, description = "Body over the upload limit", body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = <PredictCapability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy, or uploads and answers in progress hold the memory budget", body = Problem, content_type = "application/problem+json")))]
async fn post_predict(
    State(state): State<AppState>,
    headers: HeaderMap,
    AppQuery(query): AppQuery<PredictQuery>,
    request: Request,
) -> AppResult<Response> {
    let ask = Ask {
        gcode: wants_gcode(&headers, query.format),
        output: OutputOptions { dialect: query.dialect, reference: query.reference, ..OutputOptions::default() },
        timings: query.timings.unwrap_or(false),
    };
    predict(&state, request, ask).await
}

/// The corrected program of the same request.
#[utoipa::path(post, path = "/api/v1/predict/program", tag = "predict", operation_id = "predict_program",
    summary = "The same request's corrected path as a G-code program",
    description = <PredictCapability as Capability>::ENDPOINT.description,
    params(PredictProgramQuery),
    request_body(description = "The request as JSON, or a form with it in part `request` and the STL stock in part `stock`.",
        content(
            (PredictRequest = "application/json"),
            (PredictForm = "multipart/form-data"))),
    responses(
        (status = 200, description = "The corrected program", body = String, content_type = "text/x-gcode"),
        (status = 400, description = "Not the right shape (JSON or form)", body = Problem, content_type = "application/problem+json"),
        (status = 404, description = <PredictCapability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
        (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
        (status = 413, description = "Body over the upload limit", body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = <PredictCapability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy, or uploads and answers in progress hold the memory budget", body = Problem, content_type = "application/problem+json")))]
async fn post_predict_program(
    State(state): State<AppState>,
    AppQuery(query): AppQuery<PredictProgramQuery>,
    request: Request,
) -> AppResult<Response> {
    let ask = Ask {
        gcode: true,
        output: OutputOptions { dialect: query.dialect, reference: query.reference, ..OutputOptions::default() },
        timings: false,
    };
    predict(&state, request, ask).await
}

/// The stock as the request's verification cuts the corrected program, as binary glTF.
#[utoipa::path(post, path = "/api/v1/predict/stock", tag = "predict", operation_id = "predict_stock",
    summary = "The stock as the request's own verification cuts its corrected program, as binary glTF",
    description = "The corrected program (the one the answer writes with the default output options, Fanuc) cut on the given stock (the model of the answer's `verification`, docs/spec/verify.md §9), as binary glTF (`model/gltf-binary`) coloured by what the program cut (the request gives no part: `extras.colouring` is `cut`), with that cut's `verification` in its `extras.verification`; `upto_line` cuts only the moves up to a line (playback). In the request's units, as its answer (positions, `_DEVIATION` and `extras.verification`; `extras.units` names them). A request with verification off is refused naming `verification`.",
    params(StockQuery),
    request_body(description = "The request as JSON, or a form with it in part `request` and the STL stock in part `stock`.",
        content(
            (PredictRequest = "application/json"),
            (PredictForm = "multipart/form-data"))),
    responses(
        (status = 200, description = "The cut stock", body = GlbFile, content_type = "model/gltf-binary"),
        (status = 400, description = "Not the right shape (JSON or form)", body = Problem, content_type = "application/problem+json"),
        (status = 404, description = <PredictCapability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
        (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
        (status = 413, description = "Body over the upload limit", body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, description = <PredictCapability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy, or uploads and answers in progress hold the memory budget", body = Problem, content_type = "application/problem+json")))]
async fn post_predict_stock(
    State(state): State<AppState>,
    AppQuery(query): AppQuery<StockQuery>,
    request: Request,
) -> AppResult<Response> {
    let (request, mesh) = read(&state, request).await?;
    own_stock::answer::<PredictCapability>(&state, request, mesh, query.upto_line).await
}

/// Reads the JSON or form `request` and answers it as `ask` says.
async fn predict(state: &AppState, request: Request, ask: Ask) -> AppResult<Response> {
    let (request, mesh) = read(state, request).await?;
    super::solve::answer::<PredictCapability>(state, request, mesh, ask).await
}

/// Reads the JSON or form `request`: the request and the STL file of its stock, if sent.
async fn read(state: &AppState, request: Request) -> AppResult<(PredictRequest, Option<Bytes>)> {
    let json = is_json(request.headers());
    if !json && media_type(request.headers()).as_deref() != Some("multipart/form-data") {
        return Err(upload::unsupported(&["stock"]));
    }
    let content_type = request.headers().get(header::CONTENT_TYPE).cloned();
    // While it arrives, possibly slowly, the upload holds its share of the memory budget: the
    // bytes received so far. It is read on a blocking thread in a solver slot, off the async
    // threads; once read, the solver slots bound it.
    let (body, upload_share) = charged_body_bytes(request, state, state.limits.max_upload_bytes).await?;
    let upload::Upload { request, mut files } =
        state.solve(move |_| upload::read::<PredictRequest>(json, content_type, body, &["stock"])).await??;
    drop(upload_share);
    Ok((request, files.pop().flatten()))
}

/// Routes of this module; the upload limit replaces the default body limit here.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new()
        .routes(routes!(post_predict))
        .routes(routes!(post_predict_program))
        .routes(routes!(post_predict_stock))
        .layer(DefaultBodyLimit::disable())
}
