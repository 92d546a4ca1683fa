//! `POST /api/v1/{name}/stock` (docs/spec/verify.md §9.4): the stock as a capability's own
//! verification cuts the program it writes (verify: the program it is given), as binary glTF
//! coloured by deviation from the capability's part (without one, by what the program cut), up to
//! a line for playback. The same request as the capability's endpoint; the mesh is built on the
//! blocking pool within the answer budget ([`glb_answer`], also a job operation's cut stock's).

use axum::body::Bytes;
use axum::http::{HeaderValue, header};
use axum::response::Response;
use kerf_solver::capability::{self, AnswerBudget, Capability, Control, Purpose, Run};
use kerf_solver::verify::GLB_MEDIA_TYPE;
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};

use crate::capabilities::{self, StockAsk};
use crate::error::{AppError, AppResult};
use crate::http::stream::{held_download, pieces_of};
use crate::state::AppState;

/// A GLB file (for the OpenAPI document): the cut stock as binary glTF.
#[derive(Debug, ToSchema)]
#[schema(value_type = String, format = Binary)]
pub struct GlbFile(pub Vec<u8>);

/// Query parameters of `POST /api/v1/{name}/stock`.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct StockQuery {
    /// Cut the moves on lines up to this one (1-based, of the program the answer writes with the
    /// default output options, its header counted, as the verification's findings count them) and
    /// answer the stock as they left it (playback); default every move.
    #[param(minimum = 0)]
    pub upto_line: Option<usize>,
}

/// Answers the stock of `request`'s own verification (up to `ask.upto_line`) as GLB, in the units
/// the request is written in (as its answer).
///
/// # Errors
/// As [`capabilities::cut_stock`]; `E_TOO_LARGE_ANSWER` at `verification.resolution` for a mesh
/// over the answer budget; 429 when every solver slot is busy.
pub async fn answer<C: Capability>(
    state: &AppState,
    request: C::Request,
    upload: Option<Bytes>,
    upto_line: Option<usize>,
) -> AppResult<Response> {
    let catalog =
        capabilities::catalog(&state.db, capability::all_refs::<C>(&request), capabilities::Catalog::default()).await?;
    let ask = StockAsk { upto_line, resolution: None };
    glb_answer(state, C::NAME, upload, move |run| capabilities::cut_stock::<C>(&request, &catalog, ask, run)).await
}

/// Runs `cut` (a cut stock's GLB) on the blocking pool within the answer budget, with `upload` as
/// the run's file, and answers its bytes as `model/gltf-binary`, timed under `name`.
///
/// # Errors
/// `cut`'s; 429 when every solver slot is busy or the memory budget cannot hold the answer.
pub async fn glb_answer(
    state: &AppState,
    name: &'static str,
    upload: Option<Bytes>,
    cut: impl FnOnce(&Run<'_>) -> Result<Vec<u8>, AppError> + Send + 'static,
) -> AppResult<Response> {
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
            cut(&run)
        })
        .await??;
    let seconds = started.elapsed().as_secs_f64();
    crate::metrics::observe_solver(name, seconds);
    let length = bytes.len();
    let mut response =
        held_download(state.reserve_memory(length)?, pieces_of(Bytes::from(bytes)), length, GLB_MEDIA_TYPE);
    let timing = HeaderValue::from_str(&format!("solve;dur={:.1}", seconds * 1e3))
        .unwrap_or_else(|_| HeaderValue::from_static("solve"));
    response.headers_mut().insert("server-timing", timing);
    response.headers_mut().insert(header::VARY, HeaderValue::from_static("accept"));
    Ok(response)
}
