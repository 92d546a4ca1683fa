//! Jobs over HTTP (docs/spec/api.md, Jobs): submit a job file (multipart field `file`, or the raw body as
//! JSON or TOML), follow it, fetch its results and G-code (each operation's, or the one program
//! of the whole job, or every output as a zip archive), read back its stored job file, cancel it,
//! list jobs with paging.

use axum::Json;
use axum::extract::{FromRequest, Multipart, Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use kerf_solver::ErrorCode;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use crate::error::{AppError, AppResult, Problem};
use crate::extract::{AppPath, AppQuery, body_bytes, media_type, refuse_declared_over};
use crate::http::output::program_disposition;
use crate::http::stream::{held_download, pieces_of};
use crate::jobs::file::{self, Format, JobFile};
use crate::jobs::program::{self, OperationOutput};
use crate::state::AppState;
use crate::store;
use crate::store::jobs::{JobRecord, JobStatus};
use crate::store::packed::PIECE;

/// The answer to a submission.
#[derive(Debug, Serialize, ToSchema)]
pub struct Submitted {
    /// Job id; follow it at `Location`.
    pub id: i64,
    /// `queued`, or `done` when an identical finished job was reused.
    pub status: JobStatus,
    /// True when the answer is an earlier identical job's.
    pub reused: bool,
}

/// The form of a multipart submission (for the OpenAPI document).
#[derive(Debug, ToSchema)]
pub struct JobForm {
    /// The job file, JSON or TOML (told by its name's extension or media type, else by its text).
    #[schema(value_type = String, format = Binary)]
    pub file: Vec<u8>,
}

/// A job file as TOML text (for the OpenAPI document): the raw body, UTF-8.
#[derive(Debug, ToSchema)]
#[schema(value_type = String, format = Binary)]
pub struct JobFileToml(pub String);

/// A zip archive (for the OpenAPI document).
#[derive(Debug, ToSchema)]
#[schema(value_type = String, format = Binary)]
pub struct ZipArchive(pub Vec<u8>);

/// One operation's result in a finished job.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobResult {
    /// The operation's name.
    pub operation: String,
    /// Its answer, byte for byte as its endpoint answers JSON.
    #[schema(value_type = Object)]
    pub result: Box<serde_json::value::RawValue>,
    /// Whether `GET /api/v1/jobs/{id}/gcode?operation=N` has a program for it.
    pub gcode: bool,
    /// Why no program could be written, if so.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gcode_problem: Option<String>,
}

/// A job with its results once done.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobView {
    /// The job.
    #[serde(flatten)]
    pub job: JobRecord,
    /// Results in operation order (only when `status` is `done`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub results: Option<Vec<JobResult>>,
}

/// A page of jobs, newest first.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobPage {
    /// The jobs.
    pub jobs: Vec<JobRecord>,
    /// Pass as `before` for the next page; absent on the last page.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub next_before: Option<i64>,
}

/// Paging of the job list.
#[derive(Debug, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct PageQuery {
    /// Jobs per page (1–200, default 50).
    pub limit: Option<i64>,
    /// Only jobs with a smaller id (from `next_before`).
    pub before: Option<i64>,
}

/// Which program of a job.
#[derive(Debug, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct ProgramQuery {
    /// Operation index (0-based); needed when the job has several programs.
    pub operation: Option<usize>,
}

/// The `{id}` path parameter.
#[derive(Debug, Deserialize)]
pub(super) struct JobId {
    pub(super) id: i64,
}

/// Reads the uploaded job file's text and its format.
async fn upload(state: &AppState, request: Request) -> AppResult<(String, Format)> {
    let limit = state.limits.max_body_bytes;
    refuse_declared_over(request.headers(), limit)?;
    let media = media_type(request.headers());
    let (bytes, name, media) = match media.as_deref() {
        Some("multipart/form-data") => {
            // Received whole first, so a form is held to the size limit and the minimum receive
            // rate like every other body; the form is then read from memory.
            let (parts, body) = request.into_parts();
            let mut received = Request::new(body);
            *received.headers_mut() = parts.headers.clone();
            let bytes = body_bytes(received, state, limit).await?;
            let request = Request::from_parts(parts, axum::body::Body::from(bytes));
            let mut multipart = Multipart::from_request(request, state)
                .await
                .map_err(|rejection| AppError::bad_request(ErrorCode::Multipart, "file", rejection.body_text()))?;
            let mut found = None;
            loop {
                let field = match multipart.next_field().await {
                    Ok(Some(field)) => field,
                    Ok(None) => break,
                    Err(error) if error.status() == StatusCode::PAYLOAD_TOO_LARGE => {
                        return Err(AppError::PayloadTooLarge { limit });
                    }
                    Err(error) => return Err(AppError::bad_request(ErrorCode::Multipart, "file", error.body_text())),
                };
                if field.name() != Some("file") {
                    continue;
                }
                let name = field.file_name().map(str::to_owned);
                let media = field.content_type().map(str::to_owned);
                let bytes = field.bytes().await.map_err(|error| {
                    if error.status() == StatusCode::PAYLOAD_TOO_LARGE {
                        AppError::PayloadTooLarge { limit }
                    } else {
                        AppError::bad_request(ErrorCode::Multipart, "file", error.body_text())
                    }
                })?;
                found = Some((bytes, name, media));
                break;
            }
            found.ok_or_else(|| {
                AppError::bad_request(ErrorCode::Multipart, "file", "the form has no field named file")
            })?
        }
        Some("application/json" | "application/toml" | "text/toml" | "application/x-toml" | "text/x-toml") => {
            (body_bytes(request, state, limit).await?, None, media)
        }
        _ => {
            return Err(AppError::UnsupportedMediaType(
                "send the job file as multipart/form-data (field file), application/json or application/toml"
                    .to_owned(),
            ));
        }
    };
    let text = String::from_utf8(bytes.to_vec())
        .map_err(|_| AppError::bad_request(ErrorCode::JobFile, "file", "the job file is not UTF-8 text"))?;
    let format = Format::detect(name.as_deref(), media.as_deref(), &text);
    Ok((text, format))
}

fn located(id: i64, status: StatusCode, body: &Submitted) -> Response {
    let mut response = (status, Json(body)).into_response();
    if let Ok(location) = HeaderValue::from_str(&format!("/api/v1/jobs/{id}")) {
        response.headers_mut().insert(header::LOCATION, location);
    }
    response
}

/// Submits a job file. 202 with the queued job; 200 when an identical finished job is reused.
#[utoipa::path(post, path = "/api/v1/jobs", tag = "jobs", operation_id = "submit_job",
    request_body(description = "The job file: JSON, TOML (`application/toml`), or a form with it in field `file`.",
        content(
            (JobFile = "application/json"),
            (JobFileToml = "application/toml"),
            (JobForm = "multipart/form-data"))),
    responses(
        (status = 202, description = "Queued", body = Submitted, headers(("Location" = String))),
        (status = 200, description = "An identical finished job", body = Submitted, headers(("Location" = String))),
        (status = 400, description = "Not a job file; line and field in the problem", body = Problem, content_type = "application/problem+json"),
        (status = 404, description = "Unknown tool number", body = Problem, content_type = "application/problem+json"),
        (status = 413, body = Problem, content_type = "application/problem+json"),
        (status = 415, body = Problem, content_type = "application/problem+json"),
        (status = 422, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "`E_JOB_STORE_FULL`: the job store is at its quota (prune finished jobs or raise the quota); nothing was stored", body = Problem, content_type = "application/problem+json")))]
async fn submit(State(state): State<AppState>, request: Request) -> AppResult<Response> {
    let (text, format) = upload(&state, request).await?;
    // Parsed on a blocking thread: a large job file is CPU work the async threads must not do.
    let job = tokio::task::spawn_blocking(move || file::parse(&text, format))
        .await
        .map_err(|error| AppError::Internal(anyhow::anyhow!("parsing the job file failed: {error}")))??
        .resolve(Some(&state.db))
        .await?;
    let hash = job.content_hash();
    if let Some(id) = store::jobs::find_done(&state.db, &hash).await? {
        return Ok(located(id, StatusCode::OK, &Submitted { id, status: JobStatus::Done, reused: true }));
    }
    let id = store::jobs::insert(&state.db, &job, &hash, state.jobs.storage.quota()).await?;
    state.jobs.submitted.notify_one();
    Ok(located(id, StatusCode::ACCEPTED, &Submitted { id, status: JobStatus::Queued, reused: false }))
}

/// Jobs, newest first, a page at a time.
#[utoipa::path(get, path = "/api/v1/jobs", tag = "jobs", operation_id = "list_jobs", params(PageQuery),
    responses((status = 200, body = JobPage), (status = 400, body = Problem, content_type = "application/problem+json")))]
async fn list(State(state): State<AppState>, AppQuery(query): AppQuery<PageQuery>) -> AppResult<Json<JobPage>> {
    let limit = query.limit.unwrap_or(50);
    if !(1..=200).contains(&limit) {
        return Err(AppError::bad_request(ErrorCode::Query, "limit", "limit must be 1 to 200"));
    }
    let jobs = store::jobs::list(&state.db, limit + 1, query.before).await?;
    let more = jobs.len() > usize::try_from(limit).unwrap_or(usize::MAX);
    let jobs: Vec<JobRecord> = jobs.into_iter().take(usize::try_from(limit).unwrap_or(0)).collect();
    let next_before = if more { jobs.last().map(|job| job.id) } else { None };
    Ok(Json(JobPage { jobs, next_before }))
}

async fn record(state: &AppState, id: i64) -> AppResult<JobRecord> {
    store::jobs::get(&state.db, id).await?.ok_or_else(|| AppError::not_found(format!("job {id} does not exist")))
}

/// The record of a finished job: 404 for an unknown one, 409 for one not done.
pub(super) async fn done_record(state: &AppState, id: i64) -> AppResult<JobRecord> {
    let job = record(state, id).await?;
    if job.status != JobStatus::Done {
        return Err(AppError::Conflict(format!("job {id} is {:?}, not done", job.status).to_lowercase()));
    }
    Ok(job)
}

/// A job: status, progress and, when done, its results.
///
/// The results of a done job are held in memory twice (decompressed, then the answer) while the
/// client reads them: that share of the memory budget is taken before they are read from the
/// store (429 when other answers hold it).
#[utoipa::path(get, path = "/api/v1/jobs/{id}", tag = "jobs", operation_id = "get_job",
    params(("id" = i64, Path, description = "Job id", minimum = 1)),
    responses(
        (status = 200, body = JobView),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "Large answers being read hold the memory budget; retry", body = Problem, content_type = "application/problem+json")))]
async fn show(State(state): State<AppState>, AppPath(JobId { id }): AppPath<JobId>) -> AppResult<Response> {
    let job = record(&state, id).await?;
    if job.status != JobStatus::Done {
        return Ok(Json(JobView { job, results: None }).into_response());
    }
    let length = usize::try_from(store::jobs::results_length(&state.db, id).await?).unwrap_or(usize::MAX);
    let permit = state.reserve_memory(length.saturating_mul(2))?;
    let rows = store::jobs::results(&state.db, id).await?;
    let body = tokio::task::spawn_blocking(move || {
        let mut results = Vec::with_capacity(rows.len());
        for row in rows {
            let result = serde_json::value::RawValue::from_string(row.result.into_string()?)
                .map_err(|e| AppError::Internal(e.into()))?;
            results.push(JobResult {
                operation: row.operation,
                result,
                gcode: row.gcode,
                gcode_problem: row.gcode_problem,
            });
        }
        serde_json::to_vec(&JobView { job, results: Some(results) }).map_err(|e| AppError::Internal(e.into()))
    })
    .await
    .map_err(|e| AppError::Internal(e.into()))??;
    let length = body.len();
    Ok(held_download(permit, pieces_of(body.into()), length, "application/json"))
}

/// The job file as the service stores it, for any job (queued, running, done, failed or
/// cancelled): JSON, with every operation's `operation` and request in submission order and the
/// tools, machines and materials its operations name as they were resolved at submission (a TOML
/// file is stored as this JSON). Submitting it again runs the same job; for a done job the
/// submission is answered with that job (`reused`).
#[utoipa::path(get, path = "/api/v1/jobs/{id}/file", tag = "jobs", operation_id = "get_job_file",
    params(("id" = i64, Path, description = "Job id", minimum = 1)),
    responses(
        (status = 200, description = "The stored job file, byte for byte", body = JobFile, content_type = "application/json"),
        (status = 404, description = "Unknown or removed job", body = Problem, content_type = "application/problem+json")))]
async fn job_file(State(state): State<AppState>, AppPath(JobId { id }): AppPath<JobId>) -> AppResult<Response> {
    let json = store::outputs::job_file(&state.db, id)
        .await?
        .ok_or_else(|| AppError::not_found(format!("job {id} does not exist")))?;
    let mut response = json.into_response();
    response.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("application/json"));
    if let Ok(disposition) = HeaderValue::from_str(&format!("inline; filename=\"kerf-job-{id}.json\"")) {
        response.headers_mut().insert(header::CONTENT_DISPOSITION, disposition);
    }
    Ok(response)
}

/// A finished job's G-code program (one per operation), a download named by its post
/// (`kerf-job-{id}-{operation}.nc`, `.mpf`, `.h`, `.i`).
///
/// It is decompressed as the client reads it, never whole in memory; the compressed program holds
/// its share of the memory budget until sent (429 when other answers hold it).
#[utoipa::path(get, path = "/api/v1/jobs/{id}/gcode", tag = "jobs", operation_id = "get_job_operation_program",
    params(("id" = i64, Path, description = "Job id", minimum = 1), ProgramQuery),
    responses(
        (status = 200, body = String, content_type = "text/x-gcode", headers(("Content-Disposition" = String,
            description = "attachment named `kerf-job-{id}-{operation}` with the post's extension (`.nc`, `.mpf`, `.h`, `.i`)"))),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 409, description = "Not finished", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "No program for that operation, or several to choose from", body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "Large answers being read hold the memory budget; retry", body = Problem, content_type = "application/problem+json")))]
async fn gcode(
    State(state): State<AppState>,
    AppPath(JobId { id }): AppPath<JobId>,
    AppQuery(query): AppQuery<ProgramQuery>,
) -> AppResult<Response> {
    done_record(&state, id).await?;
    let programs = store::jobs::programs(&state.db, id).await?;
    let index = match (query.operation, programs.len()) {
        (Some(index), count) if index < count => index,
        (Some(index), count) => {
            return Err(AppError::bad_request(
                ErrorCode::Query,
                "operation",
                format!("operation {index} out of 0..{count}"),
            ));
        }
        (None, 1) => 0,
        (None, count) => {
            return Err(kerf_solver::SolverError::input(
                "operation",
                format!("job {id} has {count} operations: choose one with ?operation=0..{}", count - 1),
            )
            .into());
        }
    };
    let (has_program, problem) = &programs[index];
    let program = if *has_program { store::jobs::program(&state.db, id, index).await? } else { None };
    let Some(program) = program else {
        return Err(kerf_solver::SolverError::new(
            ErrorCode::NoProgram,
            format!("operation {index} has no program: {}", problem.as_deref().unwrap_or("it writes no path")),
        )
        .at("operation")
        .into());
    };
    let file = store::outputs::job_file(&state.db, id)
        .await?
        .and_then(|json| serde_json::from_str::<JobFile>(&json).ok())
        .ok_or_else(|| AppError::not_found(format!("job {id} does not exist")))?;
    let disposition = program_disposition(&format!("job-{id}-{index}"), program::operation_dialect(&file, index));
    let permit = state.reserve_memory(program.held() + PIECE)?;
    let length = program.length();
    let mut response = held_download(permit, program.pieces(), length, "text/x-gcode; charset=utf-8");
    response.headers_mut().insert(header::CONTENT_DISPOSITION, disposition);
    Ok(response)
}

/// A finished job's stored file and every operation's stored outputs: 404 for an unknown job,
/// 409 for one not done, 429 while the memory budget cannot hold them and what is built of them
/// (the program or the archive, about as large again), which the permit reserves.
async fn finished(
    state: &AppState,
    id: i64,
) -> AppResult<(JobFile, Vec<store::outputs::OperationRow>, tokio::sync::OwnedSemaphorePermit)> {
    done_record(state, id).await?;
    let permit = state.reserve_memory(store::outputs::length(&state.db, id).await?.saturating_mul(2))?;
    let json = store::outputs::job_file(&state.db, id)
        .await?
        .ok_or_else(|| AppError::not_found(format!("job {id} does not exist")))?;
    let file: JobFile = serde_json::from_str(&json).map_err(|error| AppError::Internal(error.into()))?;
    Ok((file, store::outputs::outputs(&state.db, id).await?, permit))
}

fn operation_outputs(rows: &[store::outputs::OperationRow]) -> Vec<OperationOutput<'_>> {
    rows.iter()
        .map(|(operation, result, gcode, gcode_problem)| OperationOutput {
            operation,
            result,
            gcode: gcode.as_deref(),
            gcode_problem: gcode_problem.as_deref(),
        })
        .collect()
}

/// A finished job's one program (a download named by its post: `kerf-job-{id}.nc`, `.mpf`, `.i`):
/// every operation in order with its tool change, spindle and coolant, one program number (`[output] program_number`, else `2000 + (id − 1) mod 6000`), a
/// header listing operations, tools and estimated times. Operations without a program are named
/// in the header as not included.
#[utoipa::path(get, path = "/api/v1/jobs/{id}/program", tag = "jobs", operation_id = "get_job_program",
    params(("id" = i64, Path, description = "Job id", minimum = 1)),
    responses(
        (status = 200, body = String, content_type = "text/x-gcode", headers(("Content-Disposition" = String,
            description = "attachment named `kerf-job-{id}` with the post's extension (`.nc`, `.mpf`, `.h`, `.i`)"))),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 409, description = "Not finished", body = Problem, content_type = "application/problem+json"),
        (status = 422, description = "No operation has a program (`E_NO_PROGRAM`)", body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "Large answers being read hold the memory budget; retry", body = Problem, content_type = "application/problem+json")))]
async fn job_program(State(state): State<AppState>, AppPath(JobId { id }): AppPath<JobId>) -> AppResult<Response> {
    let (file, rows, permit) = finished(&state, id).await?;
    let number = program::program_number(&file, Some(id));
    let text = program::job_program(&file, number, &operation_outputs(&rows))?;
    drop(rows);
    let length = text.len();
    let mut response = held_download(permit, pieces_of(text.into()), length, "text/x-gcode; charset=utf-8");
    let disposition = program_disposition(&format!("job-{id}"), program::dialect(&file));
    response.headers_mut().insert(header::CONTENT_DISPOSITION, disposition);
    Ok(response)
}

/// Every output of a finished job as a zip archive (deflated, ZIP64 where an entry or the archive
/// passes 4 GiB): `job.json`, each operation's answer `NN-operation.json` and program
/// `NN-operation.nc`, and the job's one program `program.nc` (the files `kerf run -o DIR` writes).
/// The archive is sent as it is compressed, entry by entry, so its length is not known up front.
#[utoipa::path(get, path = "/api/v1/jobs/{id}/outputs.zip", tag = "jobs", operation_id = "get_job_outputs",
    params(("id" = i64, Path, description = "Job id", minimum = 1)),
    responses(
        (status = 200, description = "The archive", body = ZipArchive, content_type = "application/zip"),
        (status = 404, body = Problem, content_type = "application/problem+json"),
        (status = 409, description = "Not finished", body = Problem, content_type = "application/problem+json"),
        (status = 429, description = "Large answers being read hold the memory budget; retry", body = Problem, content_type = "application/problem+json")))]
async fn outputs_zip(State(state): State<AppState>, AppPath(JobId { id }): AppPath<JobId>) -> AppResult<Response> {
    let (file, rows, permit) = finished(&state, id).await?;
    // A few pieces in flight between the compressing thread and the connection.
    let (sender, receiver) = tokio::sync::mpsc::channel::<std::io::Result<axum::body::Bytes>>(4);
    tokio::task::spawn_blocking(move || {
        let number = program::program_number(&file, Some(id));
        let files = program::files(&file, number, &operation_outputs(&rows));
        drop(rows);
        let mut sink = PieceSender { sender, piece: Vec::with_capacity(PIECE) };
        match write_zip(files, &mut sink).and_then(|()| sink.send_piece()) {
            Ok(()) => {}
            // The client went away: nothing to tell.
            Err(error) if error.kind() == std::io::ErrorKind::BrokenPipe => {}
            Err(error) => {
                // End the body with the error, so the connection is cut rather than the archive
                // ending short as if whole.
                tracing::warn!(job = id, %error, "outputs.zip not sent whole");
                let _ = sink.sender.blocking_send(Err(error));
            }
        }
    });
    // The permit goes back once the last piece is out of our hands or the client went away.
    let pieces = futures_util::stream::unfold((receiver, permit), |(mut receiver, permit)| async move {
        receiver.recv().await.map(|piece| (piece, (receiver, permit)))
    });
    let mut response = axum::body::Body::from_stream(pieces).into_response();
    response.headers_mut().insert(header::CONTENT_TYPE, HeaderValue::from_static("application/zip"));
    if let Ok(disposition) = HeaderValue::from_str(&format!("attachment; filename=\"kerf-job-{id}.zip\"")) {
        response.headers_mut().insert(header::CONTENT_DISPOSITION, disposition);
    }
    Ok(response)
}

/// Writes the zip archive of `files` (name, contents) to `sink` one entry at a time, each deflated
/// and dropped once written; every entry dated 1980-01-01 00:00 so that a job's archive is the
/// same bytes whenever it is made.
fn write_zip(files: Vec<(String, Vec<u8>)>, sink: impl std::io::Write) -> std::io::Result<()> {
    use std::io::Write as _;
    let mut archive = zip::ZipWriter::new_stream(sink);
    for (name, data) in files {
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Deflated)
            .last_modified_time(zip::DateTime::default())
            .large_file(u32::try_from(data.len()).is_err());
        archive.start_file(name, options)?;
        archive.write_all(&data)?;
    }
    archive.finish()?;
    Ok(())
}

/// A writer that hands what it is given to a response body in pieces of [`PIECE`] bytes, waiting
/// while the body holds as many as its channel does (the client reads slower than we compress).
struct PieceSender {
    sender: tokio::sync::mpsc::Sender<std::io::Result<axum::body::Bytes>>,
    piece: Vec<u8>,
}

impl PieceSender {
    /// Sends the piece gathered so far, if any.
    fn send_piece(&mut self) -> std::io::Result<()> {
        if self.piece.is_empty() {
            return Ok(());
        }
        let piece = std::mem::replace(&mut self.piece, Vec::with_capacity(PIECE));
        self.sender
            .blocking_send(Ok(piece.into()))
            .map_err(|_| std::io::Error::new(std::io::ErrorKind::BrokenPipe, "the client went away"))
    }
}

impl std::io::Write for PieceSender {
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<usize> {
        let taken = bytes.len().min(PIECE - self.piece.len());
        self.piece.extend_from_slice(&bytes[..taken]);
        if self.piece.len() == PIECE {
            self.send_piece()?;
        }
        Ok(taken)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Cancels a queued or running job (200 with the job, now `cancelled`); removes an ended one
/// (done, failed or cancelled) with its results and outputs (204; the job is 404 afterwards).
#[utoipa::path(delete, path = "/api/v1/jobs/{id}", tag = "jobs", operation_id = "cancel_job",
    params(("id" = i64, Path, description = "Job id", minimum = 1)),
    responses(
        (status = 200, description = "Cancelled: the job was queued or running", body = JobView),
        (status = 204, description = "Removed with its results and outputs: the job had ended (done, failed or cancelled)"),
        (status = 404, body = Problem, content_type = "application/problem+json")))]
async fn cancel(State(state): State<AppState>, AppPath(JobId { id }): AppPath<JobId>) -> AppResult<Response> {
    let gone = || AppError::not_found(format!("job {id} does not exist"));
    match store::jobs::cancel(&state.db, id).await? {
        None => Err(gone()),
        Some((_, false)) => {
            if store::jobs::remove(&state.db, id).await? {
                Ok(StatusCode::NO_CONTENT.into_response())
            } else {
                // Removed by another request in between.
                Err(gone())
            }
        }
        Some((_, true)) => {
            state.jobs.cancel(id);
            Ok(Json(JobView { job: record(&state, id).await?, results: None }).into_response())
        }
    }
}

/// Routes of this module.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::new()
        .routes(routes!(submit, list))
        .routes(routes!(show, cancel))
        .routes(routes!(gcode))
        .routes(routes!(job_file))
        .routes(routes!(job_program))
        .routes(routes!(outputs_zip))
}
