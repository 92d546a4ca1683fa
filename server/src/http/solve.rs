//! What every solver endpoint does after reading its request, through the capability seam:
//! resolve the request's references in the store, solve on the blocking pool under the solver
//! bound (cancelled when the client goes away or the time limit passes: `AppState::solve`), serialise or write the
//! program there too, and answer JSON or G-code. A question asked before is answered from the
//! answer cache ([`crate::answer_cache`]).

use axum::body::Bytes;
use axum::http::{HeaderValue, header};
use axum::response::Response;
use kerf_solver::capability::{self, AnswerBudget, Capability, Control, Purpose, Run};

use super::output::Ask;
use crate::answer_cache::{AnswerCache, CachedAnswer, Question};
use crate::capabilities::{self, Catalog, Delivered};
use crate::error::AppResult;
use crate::http::stream::{held_download, pieces_of};
use crate::state::AppState;

/// Answers `request` of capability `C` as `ask` says; `upload` is a file sent with it.
///
/// # Errors
/// 404 for an unknown tool or machine, 422 for the solver's refusal or a program option that does
/// not apply, 429 when every solver slot is busy, 422 `E_TIMEOUT` over the time limit.
pub async fn answer<C: Capability>(
    state: &AppState,
    request: C::Request,
    upload: Option<Bytes>,
    ask: Ask,
) -> AppResult<Response> {
    let catalog =
        capabilities::catalog(&state.db, capability::all_refs::<C>(&request), capabilities::Catalog::default()).await?;
    // An upload is not part of the question's key, and timings differ from run to run. The
    // question is the request as written; the solver reads it in mm.
    let question = (state.answers.enabled() && upload.is_none() && !ask.timings)
        .then(|| question::<C>(&request, &catalog, &ask))
        .flatten();
    let units = capability::units_of::<C>(&request, &catalog);
    let request = match units.into_mm() {
        None => request,
        Some(scaling) => {
            let mut request = request;
            C::scale_request(&mut request, scaling)?;
            request
        }
    };
    let resolved = capabilities::resolve::<C>(&request, &catalog)?;
    let mut request = request;
    if ask.gcode {
        C::check_output(&request, &ask.output)?;
        C::set_programmed(&mut request, &ask.output);
    }
    // The post the program is written in, for its file name: asked, else the machine's.
    let machine_dialect = capability::all_refs::<C>(&request)
        .iter()
        .find_map(|refs| refs.machine)
        .and_then(|name| catalog.machines.iter().find(|m| m.name.as_deref() == Some(name)))
        .map(|m| m.dialect);
    let disposition =
        super::output::program_disposition(C::NAME, ask.output.dialect.or(machine_dialect).unwrap_or_default());
    if let Some(question) = &question {
        let cached = state.answers.get(question);
        crate::metrics::answer_cache_lookup(cached.is_some());
        if let Some(CachedAnswer { bytes, media_type }) = cached {
            let timing = HeaderValue::from_static("cache;desc=\"answer cache\"");
            return respond(state, bytes, media_type, timing, disposition);
        }
    }
    // The answer is built within the byte budget its client's download is held to.
    let budget = AnswerBudget::new(u64::try_from(state.limits.answer_budget_bytes).unwrap_or(u64::MAX));
    let (delivered, seconds) = state
        .solve(move |cancel| {
            let run = Run {
                control: Control { progress: None, cancel: Some(cancel) },
                upload: upload.as_deref(),
                purpose: if ask.gcode { Purpose::Program } else { Purpose::Json },
                budget: Some(&budget),
            };
            capabilities::solve::<C>(&request, resolved, &run, ask.gcode.then_some(&ask.output), ask.timings, units)
        })
        .await??;
    crate::metrics::observe_solver(C::NAME, seconds);
    let (bytes, media_type) = match delivered {
        Delivered::Program(program) => (Bytes::from(program), "text/x-gcode; charset=utf-8"),
        Delivered::Json(bytes) => (Bytes::from(bytes), "application/json"),
    };
    if let Some(question) = question {
        state.answers.put(question, CachedAnswer { bytes: bytes.clone(), media_type });
    }
    let timing = HeaderValue::from_str(&format!("solve;dur={:.1}", seconds * 1e3))
        .unwrap_or_else(|_| HeaderValue::from_static("solve"));
    respond(state, bytes, media_type, timing, disposition)
}

/// The answer cache's key: the capability, the request, the stored values it resolved to and
/// what the client asked for (format and program options). `None` when something does not
/// serialise (then the request is solved, not cached).
fn question<C: Capability>(request: &C::Request, catalog: &Catalog, ask: &Ask) -> Option<Question> {
    let request = serde_json::to_vec(request).ok()?;
    let found = serde_json::to_vec(&(&catalog.tools, &catalog.machines, &catalog.materials)).ok()?;
    let asked = format!("{ask:?}");
    Some(AnswerCache::question(&[C::NAME.as_bytes(), &request, &found, asked.as_bytes()]))
}

/// The answer's bytes as a response held against the memory budget; a program is an attachment
/// named `disposition`.
fn respond(
    state: &AppState,
    bytes: Bytes,
    media_type: &'static str,
    timing: HeaderValue,
    disposition: HeaderValue,
) -> AppResult<Response> {
    let length = bytes.len();
    let mut response = held_download(state.reserve_memory(length)?, pieces_of(bytes), length, media_type);
    response.headers_mut().insert("server-timing", timing);
    response.headers_mut().insert(header::VARY, HeaderValue::from_static("accept"));
    if media_type.starts_with("text/x-gcode") {
        response.headers_mut().insert(header::CONTENT_DISPOSITION, disposition);
    }
    Ok(response)
}
