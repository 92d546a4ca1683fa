//! A finished job operation's cut stock (docs/spec/verify.md §9.4, docs/spec/api.md, Jobs): `GET
//! /api/v1/jobs/{id}/stock` cuts the operation's program on its own model as
//! `POST /api/v1/{name}/stock` does, and `GET /api/v1/jobs/{id}/stock/program` answers the program
//! it cuts, whose lines `upto_line` and the result's findings count. Both resolve the operation
//! against the stored job file (its tools, machines and materials as they were at submission, also
//! the ones given only in the file), so they draw what the job ran.

use axum::extract::State;
use axum::http::{HeaderValue, header};
use axum::response::{IntoResponse, Response};
use kerf_solver::ErrorCode;
use kerf_solver::capability::{Control, Purpose, Run};
use serde::Deserialize;
use utoipa::IntoParams;
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::jobs::{JobId, done_record};
use super::own_stock::{GlbFile, glb_answer};
use crate::capabilities::StockAsk;
use crate::error::{AppError, AppResult, Problem};
use crate::extract::{AppPath, AppQuery};
use crate::jobs::file::JobFile;
use crate::state::AppState;
use crate::store;

/// Which operation's stock, cut how far, at which spacing.
#[derive(Debug, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct JobStockQuery {
    /// Operation index (0-based).
    pub operation: usize,
    /// Cut the moves on lines up to this one (1-based, of `GET /api/v1/jobs/{id}/stock/program`,
    /// as the result's findings count them) and answer the stock as they left it (playback);
    /// default every move.
    #[param(minimum = 0)]
    pub upto_line: Option<usize>,
    /// Dexel spacing (> 0), in the operation's units; default its verification's.
    #[param(exclusive_minimum = 0)]
    pub resolution: Option<f64>,
}

/// Which operation's program.
#[derive(Debug, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct JobOperationQuery {
    /// Operation index (0-based).
    pub operation: usize,
}

/// The stored job file of finished job `id`: 404 for an unknown job, 409 for one not done, 400
/// naming `operation` for an index it does not have.
async fn done_file(state: &AppState, id: i64, operation: usize) -> AppResult<JobFile> {
    done_record(state, id).await?;
    let json = store::outputs::job_file(&state.db, id)
        .await?
        .ok_or_else(|| AppError::not_found(format!("job {id} does not exist")))?;
    let file: JobFile = serde_json::from_str(&json).map_err(|error| AppError::Internal(error.into()))?;
    let count = file.operations.len();
    if operation >= count {
        return Err(AppError::bad_request(
            ErrorCode::Query,
            "operation",
            format!("operation {operation} out of 0..{count}"),
        ));
    }
    Ok(file)
}

/// The stock of a finished job's operation as its program cut it, as binary glTF coloured by
/// deviation from its part (without one, by what the program cut), in the operation's units: what
/// `POST /api/v1/{name}/stock` (verify: `?format=glb`) answers for the operation's request, resolved
/// against the job file. The operation is solved again, within the synchronous time limit.
#[utoipa::path(get, path = "/api/v1/jobs/{id}/stock", tag = "jobs", operation_id = "get_job_operation_stock",
    params(("id" = i64, Path, description = "Job id", minimum = 1), JobStockQuery),
    responses(
        (status = 200, description = "The cut stock", body = GlbFile, content_type = "model/gltf-binary"),
        (status = 400, description = "A bad query (`operation` out of range)", body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 409, description = "Not finished", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "No model to cut (verification turned off; segment, resegment), a bad `resolution` (`E_GRID_MEMORY`), a mesh over the answer budget (`E_TOO_LARGE_ANSWER`), or over the synchronous time limit", body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy, or answers being read hold the memory budget", body = Problem, content_type = "application/problem+json")))]
async fn stock(
    State(state): State<AppState>,
    AppPath(JobId { id }): AppPath<JobId>,
    AppQuery(query): AppQuery<JobStockQuery>,
) -> AppResult<Response> {
    if let Some(resolution) = query.resolution
        && !(resolution.is_finite() && resolution > 0.0)
    {
        return Err(AppError::bad_request(ErrorCode::Query, "resolution", "resolution must be a positive spacing"));
    }
    let file = done_file(&state, id, query.operation).await?;
    let index = query.operation;
    let name = file.operations[index].name();
    let ask = StockAsk { upto_line: query.upto_line, resolution: query.resolution };
    let asked = query.resolution.is_some();
    glb_answer(&state, name, None, move |run| {
        file.operations[index].cut_stock(&file, ask, run).map_err(|error| match error {
            // The spacing the query set is the query's field, not the stored operation's.
            AppError::Unprocessable(error)
                if asked && matches!(error.field(), Some("verification.resolution" | "resolution")) =>
            {
                AppError::Unprocessable(error.at("resolution"))
            }
            error => error.under(&format!("operations[{index}]")),
        })
    })
    .await
    .map_err(|error| over_time(error, "cutting this operation's program again", "ask a coarser `resolution`"))
}

/// A refusal over the synchronous time limit saying what took long and what helps here (`POST
/// /api/v1/jobs`, what the capabilities' endpoints advise, is what the operation already is).
fn over_time(error: AppError, what: &str, help: &str) -> AppError {
    match error {
        AppError::Timeout(_) => {
            AppError::Timeout(format!("{what} takes longer than the synchronous time limit; {help}"))
        }
        error => error,
    }
}

/// The program a finished job's operation cuts for its stock (`GET /api/v1/jobs/{id}/stock`):
/// the operation's answer written with the default output options in the Fanuc dialect, in its
/// units (verify: the program it was given), whose lines the result's findings and `upto_line`
/// count. The job's own program of the operation (`GET /api/v1/jobs/{id}/gcode`) is in the job's
/// post and may number its lines otherwise.
#[utoipa::path(get, path = "/api/v1/jobs/{id}/stock/program", tag = "jobs", operation_id = "get_job_operation_cut_program",
    params(("id" = i64, Path, description = "Job id", minimum = 1), JobOperationQuery),
    responses(
        (status = 200, body = String, content_type = "text/x-gcode"),
        (status = 400, description = "A bad query (`operation` out of range)", body = Problem, content_type = "application/problem+json"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 409, description = "Not finished", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "No program (`E_NO_PROGRAM`), or over the synchronous time limit", body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "All solver slots busy", body = Problem, content_type = "application/problem+json")))]
async fn cut_program(
    State(state): State<AppState>,
    AppPath(JobId { id }): AppPath<JobId>,
    AppQuery(query): AppQuery<JobOperationQuery>,
) -> AppResult<Response> {
    let file = done_file(&state, id, query.operation).await?;
    let index = query.operation;
    let budget =
        kerf_solver::capability::AnswerBudget::new(u64::try_from(state.limits.answer_budget_bytes).unwrap_or(u64::MAX));
    let program = state
        .solve(move |cancel| {
            let run = Run {
                control: Control { progress: None, cancel: Some(cancel) },
                upload: None,
                purpose: Purpose::Program,
                budget: Some(&budget),
            };
            file.operations[index]
                .cut_program(&file, &run)
                .map_err(|error| error.under(&format!("operations[{index}]")))
        })
        .await
        .map_err(|error| {
            over_time(
                error,
                "writing this operation's program again",
                &format!("its program in the job's post is at `GET /api/v1/jobs/{id}/gcode?operation={index}`"),
            )
        })??;
    let mut response = program.into_response();
    response.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("text/x-gcode; charset=utf-8"));
    Ok(response)
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new().routes(routes!(stock)).routes(routes!(cut_program))
}
