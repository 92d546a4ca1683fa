//! `POST /api/v1/{name}/stock` (docs/spec/verify.md §9.4): the stock as a capability's own
//! verification cuts the program it writes, as binary glTF coloured by deviation from the
//! capability's part (without one, by what the program cut), up to a line for playback. The same request as the capability's endpoint;
//! the mesh is built on the blocking pool within the answer budget, as verify's (`verify_mesh`).

use axum::body::Bytes;
use axum::http::{HeaderValue, header};
use axum::response::Response;
use kerf_solver::SolverError;
use kerf_solver::capability::{self, AnswerBudget, Capability, Control, Purpose, Run};
use kerf_solver::verify::GLB_MEDIA_TYPE;
use serde::Deserialize;
use utoipa::IntoParams;

use crate::capabilities;
use crate::error::{AppError, AppResult};
use crate::http::stream::{held_download, pieces_of};
use crate::state::AppState;

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

/// Answers the stock of `request`'s own verification (up to `upto_line`) as GLB, in the units the
/// request is written in (as its answer).
///
/// # Errors
/// As the capability's endpoint: 404 for an unknown tool or machine, 422 for its refusals; 422
/// `E_INPUT` at `verification` when the request has no model to cut (verification turned off,
/// or a capability or request without one); `E_TOO_LARGE_ANSWER` at `verification.resolution`
/// for a mesh over the answer budget; 429 when every solver slot is busy.
pub async fn answer<C: Capability>(
    state: &AppState,
    request: C::Request,
    upload: Option<Bytes>,
    upto_line: Option<usize>,
) -> AppResult<Response> {
    let catalog =
        capabilities::catalog(&state.db, capability::all_refs::<C>(&request), capabilities::Catalog::default()).await?;
    let (request, units) = capabilities::in_mm::<C>(&request, &catalog)?;
    let request = request.into_owned();
    let resolved = capabilities::resolve::<C>(&request, &catalog)?;
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
            C::cut_stock(&request, resolved, upto_line, units, &run)
        })
        .await?
        .map_err(AppError::from)?
        .ok_or_else(|| {
            AppError::from(SolverError::input(
                "verification",
                format!(
                    "this {} request has no model to cut its program on: its verification is turned off, or it has \
                     none (docs/spec/verify.md §9.2)",
                    C::NAME
                ),
            ))
        })?;
    let seconds = started.elapsed().as_secs_f64();
    crate::metrics::observe_solver(C::NAME, seconds);
    let length = bytes.len();
    let mut response =
        held_download(state.reserve_memory(length)?, pieces_of(Bytes::from(bytes)), length, GLB_MEDIA_TYPE);
    let timing = HeaderValue::from_str(&format!("solve;dur={:.1}", seconds * 1e3))
        .unwrap_or_else(|_| HeaderValue::from_static("solve"));
    response.headers_mut().insert("server-timing", timing);
    response.headers_mut().insert(header::VARY, HeaderValue::from_static("accept"));
    Ok(response)
}
