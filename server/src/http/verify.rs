//! `POST /api/v1/verify` (docs/spec/verify.md): cuts a G-code program out of the stock with the
//! tools it calls and answers what it found, through the capability seam (`solve::answer`): JSON,
//! or the cut stock as binary glTF (`own_stock`), asked for with `?format=glb` or an `Accept` that
//! ranks `model/gltf-binary` above `application/json` (docs/spec/verify.md §8 Mesh).
//!
//! The request is JSON, or `multipart/form-data` with the JSON in part `request` and the STL files
//! of a `"kind": "mesh"` part or stock in parts `part` and `stock`. This route has the upload body
//! limit (`Limits::max_upload_bytes`) instead of the service's default one.

use axum::body::Bytes;
use axum::extract::{DefaultBodyLimit, Request, State};
use axum::http::{HeaderMap, header};
use axum::response::Response;
use kerf_solver::SolverError;
use kerf_solver::capability::Capability;
use kerf_solver::verify::{GLB_MEDIA_TYPE, Meshes, Solid, VerifyAnswer, VerifyCapability, VerifyRequest};
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::output::{Ask, accept_prefers};
use super::own_stock::{self, GlbFile};
use super::upload;
use crate::error::{AppResult, Problem};
use crate::extract::{AppQuery, charged_body_bytes, is_json, media_type};
use crate::state::AppState;

/// The form of a multipart request (for the OpenAPI document).
#[derive(Debug, ToSchema)]
pub struct VerifyForm {
    /// The request, as the JSON body would be, with `"kind": "mesh"` for each solid sent as a file.
    pub request: String,
    /// The part as an STL file (binary or ASCII): a closed surface, normals outward.
    #[schema(value_type = Option<String>, format = Binary)]
    pub part: Option<Vec<u8>>,
    /// The stock as an STL file, likewise.
    #[schema(value_type = Option<String>, format = Binary)]
    pub stock: Option<Vec<u8>>,
}

/// The answer formats of the verify endpoint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum VerifyFormat {
    /// The findings as JSON (default).
    Json,
    /// The cut stock as binary glTF (`model/gltf-binary`), the JSON answer in its `extras.verify`.
    Glb,
}

/// Whether the client asks for the mesh: `format` if given, else the `Accept` header.
fn wants_glb(headers: &HeaderMap, format: Option<VerifyFormat>) -> bool {
    match format {
        Some(format) => format == VerifyFormat::Glb,
        None => accept_prefers(headers, GLB_MEDIA_TYPE),
    }
}

/// The form's file parts.
const FILES: [&str; 2] = ["part", "stock"];

/// The one upload the capability takes for the form's files (`part`, `stock`), each checked
/// against the kind of its solid.
fn meshes(request: &VerifyRequest, part: Option<Bytes>, stock: Option<Bytes>) -> AppResult<Option<Bytes>> {
    let solids = [(request.part.as_ref(), &part, "part"), (Some(&request.stock), &stock, "stock")];
    for (solid, file, name) in solids {
        if file.is_some() && !solid.is_some_and(Solid::is_mesh) {
            return Err(SolverError::input(
                format!("{name}.kind"),
                format!("an STL file was uploaded in form part `{name}` but {name}.kind is not \"mesh\""),
            )
            .into());
        }
    }
    Ok(match (part, stock) {
        (Some(part), Some(stock)) => Some(Meshes::pack(&part, &stock).into()),
        (part, stock) => part.or(stock),
    })
}

/// Query parameters of `POST /api/v1/verify`: the findings as JSON, or the cut stock as binary
/// glTF (verify writes no program).
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct VerifyQuery {
    /// `json` (default) or `glb` (the cut stock as binary glTF, `model/gltf-binary`, with the
    /// JSON answer in its `extras.verify`); without it, an `Accept` that ranks
    /// `model/gltf-binary` above `application/json` selects the mesh.
    pub format: Option<VerifyFormat>,
    /// Mesh only: cut the moves on lines up to this one (1-based) and answer the stock as they
    /// left it (playback); default every move.
    #[param(minimum = 0)]
    pub upto_line: Option<usize>,
}

/// The verify capability's endpoint, documented with the capability's own texts.
#[utoipa::path(post, path = "/api/v1/verify", tag = "verify",
    operation_id = "verify",
    summary = <VerifyCapability as Capability>::ENDPOINT.summary,
    description = <VerifyCapability as Capability>::ENDPOINT.description,
    params(VerifyQuery),
    request_body(description = "The request as JSON, or a form with it in part `request` and STL files in parts `part` and `stock`.",
        content(
            (VerifyRequest = "application/json"),
            (VerifyForm = "multipart/form-data"))),
    responses(
        (status = 200, description = "The findings, volumes and removal per block (JSON), or the cut stock as binary glTF coloured by deviation from the part",
            content((VerifyAnswer = "application/json"), (GlbFile = "model/gltf-binary"))),
        (status = 400, body = Problem, content_type = "application/problem+json"),
        (status = 404, description = <VerifyCapability as Capability>::ENDPOINT.not_found, body = Problem, content_type = "application/problem+json"),
        (status = 408, description = "The body arrived slower than the minimum receive rate", body = Problem, content_type = "application/problem+json"),
        (status = 413, description = "Body over the upload limit", body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy, or uploads and answers in progress hold the memory budget", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = <VerifyCapability as Capability>::ENDPOINT.refused, body = Problem, content_type = "application/problem+json")))]
async fn post_verify(
    State(state): State<AppState>,
    AppQuery(query): AppQuery<VerifyQuery>,
    request: Request,
) -> AppResult<Response> {
    let glb = wants_glb(request.headers(), query.format);
    if !glb && query.upto_line.is_some() {
        return Err(SolverError::input("upto_line", "upto_line cuts the mesh: ask for format=glb").into());
    }
    let json = is_json(request.headers());
    if !json && media_type(request.headers()).as_deref() != Some("multipart/form-data") {
        return Err(upload::unsupported(&FILES));
    }
    let content_type = request.headers().get(header::CONTENT_TYPE).cloned();
    // As predict: the upload holds its share of the memory budget while it arrives and is read
    // in a solver slot.
    let (body, upload_share) = charged_body_bytes(request, &state, state.limits.max_upload_bytes).await?;
    let upload::Upload { request, files } =
        state.solve(move |_| upload::read::<VerifyRequest>(json, content_type, body, &FILES)).await??;
    drop(upload_share);
    let [part, stock]: [Option<Bytes>; 2] = files.try_into().unwrap_or_default();
    let meshes = meshes(&request, part, stock)?;
    if glb {
        return own_stock::answer::<VerifyCapability>(&state, request, meshes, query.upto_line).await;
    }
    super::solve::answer::<VerifyCapability>(&state, request, meshes, Ask::default()).await
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(post_verify)).layer(DefaultBodyLimit::disable())
}
