//! What every solver endpoint does after reading its request, through the capability seam:
//! resolve the request's references in the store, solve on the blocking pool under the solver
//! bound (cancelled when the client goes away or the time limit passes), serialise or write the
//! program there too, and answer JSON or G-code.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use axum::body::Bytes;
use axum::http::{HeaderValue, header};
use axum::response::{IntoResponse, Response};
use kerf_solver::capability::{Capability, Control, Purpose, Run};

use super::output::{Ask, gcode_response};
use crate::capabilities::{self, Delivered};
use crate::error::AppResult;
use crate::state::AppState;
use crate::store;

/// Sets the cancel flag when dropped: a request that hits the time limit, or whose client goes
/// away, stops its computation (where the capability checks the flag) instead of leaving it
/// running on the blocking pool.
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

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
    let catalog = store::catalog(&state.db, [C::refs(&request)], capabilities::Catalog::default()).await?;
    let resolved = capabilities::resolve::<C>(&request, &catalog)?;
    if ask.gcode {
        C::check_output(&request, &ask.output)?;
    }
    let cancel = Arc::new(AtomicBool::new(false));
    let _stop = CancelOnDrop(Arc::clone(&cancel));
    let (delivered, seconds) = state
        .solve(move || {
            let run = Run {
                control: Control { progress: None, cancel: Some(&cancel) },
                upload: upload.as_deref(),
                purpose: if ask.gcode { Purpose::Program } else { Purpose::Json },
            };
            capabilities::solve::<C>(&request, resolved, &run, ask.gcode.then_some(&ask.output), ask.timings)
        })
        .await??;
    crate::metrics::observe_solver(C::NAME, seconds);
    let mut response = match delivered {
        Delivered::Program(program) => gcode_response(program),
        Delivered::Json(bytes) => {
            let mut response = bytes.into_response();
            response.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("application/json"));
            response
        }
    };
    if let Ok(value) = HeaderValue::from_str(&format!("solve;dur={:.1}", seconds * 1e3)) {
        response.headers_mut().insert("server-timing", value);
    }
    response.headers_mut().insert(header::VARY, HeaderValue::from_static("accept"));
    Ok(response)
}
