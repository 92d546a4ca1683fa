//! Jobs as listed and shown: their status, progress and error, read back from the `jobs` rows.

use kerf_solver::ErrorCode;
use serde::Serialize;
use utoipa::ToSchema;

use crate::db::Db;
use crate::error::{AppError, AppResult, FieldProblem, Problem};
use crate::store::on;

/// The columns of a [`JobRow`] in SQLite.
macro_rules! columns {
    () => {
        "id, name, status, progress, operations, attempts, error, error_field, submitted_at, started_at, finished_at"
    };
}

/// A PostgreSQL timestamp column as SQLite stores them (`2026-01-02T03:04:05.678Z`).
macro_rules! pg_time {
    ($column:literal) => {
        concat!("to_char(", $column, " AT TIME ZONE 'UTC', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"') AS ", $column)
    };
}

/// The columns of a [`JobRow`] in PostgreSQL.
macro_rules! pg_columns {
    () => {
        concat!(
            "id, name, status, progress, operations, attempts, error, error_field, ",
            pg_time!("submitted_at"),
            ", ",
            pg_time!("started_at"),
            ", ",
            pg_time!("finished_at")
        )
    };
}

/// Where a job is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
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

impl JobStatus {
    /// The status stored as `text` (the `status` column's CHECK allows no other).
    pub(super) fn parse(text: &str) -> AppResult<Self> {
        Ok(match text {
            "queued" => Self::Queued,
            "running" => Self::Running,
            "done" => Self::Done,
            "failed" => Self::Failed,
            "cancelled" => Self::Cancelled,
            other => return Err(AppError::Internal(anyhow::anyhow!("unknown stored job status {other:?}"))),
        })
    }
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
    status: String,
    progress: f64,
    /// JSON array of names.
    operations: String,
    attempts: i64,
    error: Option<String>,
    error_field: Option<String>,
    submitted_at: String,
    started_at: Option<String>,
    finished_at: Option<String>,
}

impl TryFrom<JobRow> for JobRecord {
    type Error = AppError;

    fn try_from(row: JobRow) -> AppResult<Self> {
        let error = row.error.map(|text| stored_problem(&text, row.error_field));
        let operations = serde_json::from_str(&row.operations)
            .map_err(|error| AppError::Internal(anyhow::anyhow!("stored operations are unreadable: {error}")))?;
        Ok(Self {
            id: row.id,
            name: row.name,
            status: JobStatus::parse(&row.status)?,
            progress: row.progress,
            operations,
            attempts: row.attempts,
            error,
            submitted_at: row.submitted_at,
            started_at: row.started_at,
            finished_at: row.finished_at,
        })
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

/// One job.
pub async fn get(db: &Db, id: i64) -> AppResult<Option<JobRecord>> {
    let row: Option<JobRow> = on!(db, query_as,
        sqlite: concat!("SELECT ", columns!(), " FROM jobs WHERE id = $1"),
        postgres: concat!("SELECT ", pg_columns!(), " FROM jobs WHERE id = $1"),
        [id], fetch_optional)?;
    row.map(JobRecord::try_from).transpose()
}

/// Up to `limit` jobs with ids below `before`, newest first.
pub async fn list(db: &Db, limit: i64, before: Option<i64>) -> AppResult<Vec<JobRecord>> {
    let rows: Vec<JobRow> = on!(db, query_as,
        sqlite: concat!("SELECT ", columns!(), " FROM jobs WHERE id < $1 ORDER BY id DESC LIMIT $2"),
        postgres: concat!("SELECT ", pg_columns!(), " FROM jobs WHERE id < $1 ORDER BY id DESC LIMIT $2"),
        [before.unwrap_or(i64::MAX), limit], fetch_all)?;
    rows.into_iter().map(JobRecord::try_from).collect()
}
