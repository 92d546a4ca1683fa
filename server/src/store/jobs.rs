//! The job queue in SQLite (issue 7): jobs with status, progress, attempts and heartbeat, and
//! their results. Workers claim the oldest queued job with one atomic UPDATE.

use kerf_solver::ErrorCode;
use serde::Serialize;
use sqlx::SqlitePool;
use utoipa::ToSchema;

use crate::capabilities::Stored;
use crate::error::{AppError, AppResult, FieldProblem, Problem};
use crate::jobs::file::JobFile;

/// Attempts a job gets: one retry after a server stop interrupted it.
pub const MAX_ATTEMPTS: i64 = 2;

/// SQLite's current UTC time as stored (a macro, so every statement stays a static string).
macro_rules! now {
    () => {
        "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')"
    };
}

/// The columns of a [`JobRow`].
macro_rules! columns {
    () => {
        "id, name, status, progress, operations, attempts, error, error_field, submitted_at, started_at, finished_at"
    };
}

/// Where a job is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema, sqlx::Type)]
#[serde(rename_all = "snake_case")]
#[sqlx(rename_all = "snake_case")]
pub enum JobStatus {
    /// Waiting for a worker.
    Queued,
    /// A worker runs it.
    Running,
    /// Finished; results stored.
    Done,
    /// An operation was refused, or the job was interrupted too often; see `error`.
    Failed,
    /// Cancelled by `DELETE`.
    Cancelled,
}

/// A job as listed and shown.
#[derive(Debug, Clone, Serialize, ToSchema)]
pub struct JobRecord {
    /// Job id.
    pub id: i64,
    /// Name from the job file.
    pub name: Option<String>,
    /// Status.
    pub status: JobStatus,
    /// Fraction done, 0–1.
    pub progress: f64,
    /// The operations' names, in order.
    pub operations: Vec<String>,
    /// Times it was started (a server stop while running re-queues it once).
    pub attempts: i64,
    /// Why it failed or stopped: the problem object its endpoint would answer for the refused
    /// operation (`code`, `errors[0].path` under `operations[i]`), `E_INTERRUPTED` after
    /// repeated server stops, `E_CANCELLED` when cancelled.
    pub error: Option<Problem>,
    /// UTC timestamps.
    pub submitted_at: String,
    /// When a worker started it.
    pub started_at: Option<String>,
    /// When it finished.
    pub finished_at: Option<String>,
}

/// A row of `jobs` as stored.
#[derive(sqlx::FromRow)]
struct JobRow {
    id: i64,
    name: Option<String>,
    status: JobStatus,
    progress: f64,
    #[sqlx(json)]
    operations: Vec<String>,
    attempts: i64,
    error: Option<String>,
    error_field: Option<String>,
    submitted_at: String,
    started_at: Option<String>,
    finished_at: Option<String>,
}

impl From<JobRow> for JobRecord {
    fn from(row: JobRow) -> Self {
        let error = row.error.map(|text| stored_problem(&text, row.error_field));
        Self {
            id: row.id,
            name: row.name,
            status: row.status,
            progress: row.progress,
            operations: row.operations,
            attempts: row.attempts,
            error,
            submitted_at: row.submitted_at,
            started_at: row.started_at,
            finished_at: row.finished_at,
        }
    }
}

/// A stored error: a problem object, or the prose that jobs stored before problems were.
fn stored_problem(text: &str, field: Option<String>) -> Problem {
    if let Ok(problem) = serde_json::from_str::<Problem>(text) {
        return problem;
    }
    let errors = field.map(|path| vec![FieldProblem { path, message: text.to_owned() }]).unwrap_or_default();
    Problem {
        kind: "about:blank".to_owned(),
        title: "Job failed".to_owned(),
        status: 422,
        detail: text.to_owned(),
        code: ErrorCode::JobFailed,
        errors,
    }
}

/// A problem for a job that stopped for a reason of its own (not an operation's refusal).
fn job_problem(status: u16, title: &str, code: ErrorCode, detail: &str) -> Problem {
    Problem {
        kind: "about:blank".to_owned(),
        title: title.to_owned(),
        status,
        detail: detail.to_owned(),
        code,
        errors: Vec::new(),
    }
}

fn problem_json(problem: &Problem) -> AppResult<String> {
    serde_json::to_string(problem).map_err(|e| AppError::Internal(e.into()))
}

/// Stores a new queued job; returns its id.
pub async fn insert(db: &SqlitePool, job: &JobFile, hash: &str) -> AppResult<i64> {
    let json = serde_json::to_string(job).map_err(|e| AppError::Internal(e.into()))?;
    let operations: Vec<&str> = job.operations.iter().map(|o| o.name()).collect();
    let operations = serde_json::to_string(&operations).map_err(|e| AppError::Internal(e.into()))?;
    let (id,): (i64,) = sqlx::query_as(
        "INSERT INTO jobs (name, status, content_hash, job_json, operations) VALUES (?, 'queued', ?, ?, ?) RETURNING id",
    )
    .bind(&job.name)
    .bind(hash)
    .bind(json)
    .bind(operations)
    .fetch_one(db)
    .await?;
    Ok(id)
}

/// A finished job with the same content, if any.
pub async fn find_done(db: &SqlitePool, hash: &str) -> AppResult<Option<i64>> {
    let row: Option<(i64,)> =
        sqlx::query_as("SELECT id FROM jobs WHERE content_hash = ? AND status = 'done' ORDER BY id LIMIT 1")
            .bind(hash)
            .fetch_optional(db)
            .await?;
    Ok(row.map(|(id,)| id))
}

/// One job.
pub async fn get(db: &SqlitePool, id: i64) -> AppResult<Option<JobRecord>> {
    let row: Option<JobRow> =
        sqlx::query_as(concat!("SELECT ", columns!(), " FROM jobs WHERE id = ?")).bind(id).fetch_optional(db).await?;
    Ok(row.map(JobRecord::from))
}

/// Up to `limit` jobs with ids below `before`, newest first.
pub async fn list(db: &SqlitePool, limit: i64, before: Option<i64>) -> AppResult<Vec<JobRecord>> {
    let rows: Vec<JobRow> =
        sqlx::query_as(concat!("SELECT ", columns!(), " FROM jobs WHERE id < ? ORDER BY id DESC LIMIT ?"))
            .bind(before.unwrap_or(i64::MAX))
            .bind(limit)
            .fetch_all(db)
            .await?;
    Ok(rows.into_iter().map(JobRecord::from).collect())
}

/// Claims the oldest queued job for a worker: marks it running and returns it.
pub async fn claim(db: &SqlitePool) -> AppResult<Option<(i64, JobFile)>> {
    let row: Option<(i64, String)> = sqlx::query_as(concat!(
        "UPDATE jobs SET status = 'running', attempts = attempts + 1, progress = 0, started_at = ",
        now!(),
        ",
                heartbeat_at = ",
        now!(),
        "
         WHERE id = (SELECT id FROM jobs WHERE status = 'queued' ORDER BY id LIMIT 1)
         RETURNING id, job_json"
    ))
    .fetch_optional(db)
    .await?;
    let Some((id, json)) = row else { return Ok(None) };
    match serde_json::from_str(&json) {
        Ok(job) => Ok(Some((id, job))),
        Err(error) => {
            let detail = format!("the stored job is unreadable: {error}");
            fail(db, id, &job_problem(422, "Job failed", ErrorCode::JobFile, &detail)).await?;
            Ok(None)
        }
    }
}

/// Records progress and the heartbeat of a running job.
pub async fn heartbeat(db: &SqlitePool, id: i64, progress: f64) -> AppResult<()> {
    sqlx::query(concat!(
        "UPDATE jobs SET progress = ?, heartbeat_at = ",
        now!(),
        " WHERE id = ? AND status = 'running'"
    ))
    .bind(progress.clamp(0.0, 1.0))
    .bind(id)
    .execute(db)
    .await?;
    Ok(())
}

/// Stores the results and marks the job done, in one transaction, unless it was cancelled
/// meanwhile. Returns whether it was stored.
pub async fn finish(db: &SqlitePool, id: i64, outputs: &[Stored]) -> AppResult<bool> {
    let mut transaction = db.begin().await?;
    let updated = sqlx::query(concat!(
        "UPDATE jobs SET status = 'done', progress = 1, finished_at = ",
        now!(),
        " WHERE id = ? AND status = 'running'"
    ))
    .bind(id)
    .execute(&mut *transaction)
    .await?;
    if updated.rows_affected() == 0 {
        transaction.rollback().await?;
        return Ok(false);
    }
    for (position, output) in outputs.iter().enumerate() {
        let result = output.result.get();
        sqlx::query(
            "INSERT INTO job_results (job_id, position, operation, result_json, gcode, gcode_problem)
             VALUES (?, ?, ?, ?, ?, ?)",
        )
        .bind(id)
        .bind(i64::try_from(position).unwrap_or(i64::MAX))
        .bind(&output.operation)
        .bind(result)
        .bind(&output.gcode)
        .bind(&output.gcode_problem)
        .execute(&mut *transaction)
        .await?;
    }
    transaction.commit().await?;
    Ok(true)
}

/// Marks a running job failed with the problem.
pub async fn fail(db: &SqlitePool, id: i64, problem: &Problem) -> AppResult<()> {
    let json = problem_json(problem)?;
    let field = problem.errors.first().map(|error| error.path.clone());
    sqlx::query(concat!(
        "UPDATE jobs SET status = 'failed', error = ?, error_field = ?, finished_at = ",
        now!(),
        "
         WHERE id = ? AND status = 'running'"
    ))
    .bind(json)
    .bind(field)
    .bind(id)
    .execute(db)
    .await?;
    Ok(())
}

/// Cancels a queued or running job. `Ok(None)` if there is no such job; otherwise the status
/// the job had, and whether this call cancelled it.
pub async fn cancel(db: &SqlitePool, id: i64) -> AppResult<Option<(JobStatus, bool)>> {
    let mut transaction = db.begin().await?;
    let row: Option<(JobStatus,)> =
        sqlx::query_as("SELECT status FROM jobs WHERE id = ?").bind(id).fetch_optional(&mut *transaction).await?;
    let Some((status,)) = row else { return Ok(None) };
    let cancellable = matches!(status, JobStatus::Queued | JobStatus::Running);
    if cancellable {
        sqlx::query(concat!(
            "UPDATE jobs SET status = 'cancelled', finished_at = ",
            now!(),
            ", error = ? WHERE id = ?"
        ))
        .bind(problem_json(&job_problem(409, "Cancelled", ErrorCode::Cancelled, "cancelled by request"))?)
        .bind(id)
        .execute(&mut *transaction)
        .await?;
    }
    transaction.commit().await?;
    Ok(Some((status, cancellable)))
}

/// A finished job's results, in operation order: operation, result JSON, whether a program
/// exists and why not.
pub async fn results(db: &SqlitePool, id: i64) -> AppResult<Vec<(String, String, bool, Option<String>)>> {
    Ok(sqlx::query_as(
        "SELECT operation, result_json, gcode IS NOT NULL, gcode_problem FROM job_results WHERE job_id = ?
         ORDER BY position",
    )
    .bind(id)
    .fetch_all(db)
    .await?)
}

/// The programs of a finished job, in operation order (`None` where none could be written).
pub async fn programs(db: &SqlitePool, id: i64) -> AppResult<Vec<(Option<String>, Option<String>)>> {
    Ok(sqlx::query_as("SELECT gcode, gcode_problem FROM job_results WHERE job_id = ? ORDER BY position")
        .bind(id)
        .fetch_all(db)
        .await?)
}

/// At start-up no job can be running: each one a stopped server left `running` is queued again,
/// or failed with the reason once it has used its attempts. Returns (re-queued, failed).
pub async fn recover(db: &SqlitePool) -> AppResult<(u64, u64)> {
    let failed = sqlx::query(concat!(
        "UPDATE jobs SET status = 'failed', finished_at = ",
        now!(),
        ", error = ?
         WHERE status = 'running' AND attempts >= ?"
    ))
    .bind(problem_json(&job_problem(
        503,
        "Job interrupted",
        ErrorCode::Interrupted,
        &format!("interrupted by a server stop on each of its {MAX_ATTEMPTS} attempts; not retried"),
    ))?)
    .bind(MAX_ATTEMPTS)
    .execute(db)
    .await?
    .rows_affected();
    let requeued = sqlx::query("UPDATE jobs SET status = 'queued', progress = 0 WHERE status = 'running'")
        .execute(db)
        .await?
        .rows_affected();
    Ok((requeued, failed))
}
