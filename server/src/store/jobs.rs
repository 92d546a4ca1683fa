//! The job queue: jobs with status, progress, attempts and heartbeat, and
//! their results.
//!
//! In SQLite one process owns the queue: its workers claim the oldest queued job with one atomic
//! UPDATE, and at start every job left `running` is queued again ([`recover`]). In PostgreSQL any
//! number of processes share it, and a job is split into chunks (one per operation, and an
//! operation whose work divides into parts and a finish step: [`split`]) that different workers
//! run at once: a worker claims a chunk in a short transaction with `SELECT … FOR UPDATE SKIP
//! LOCKED` (concurrent claimers skip each other's rows instead of waiting), writes its name and a
//! lease on the chunk, and pushes the lease forward with each heartbeat; a running chunk whose
//! lease expired (its worker died, `kill -9`) is claimed again like a queued one. A part stores its
//! output on its chunk; a whole operation or a finish step stores the operation's result; the last
//! chunk marks the job done.
//! Submissions and cancellations `NOTIFY` the workers (`kerf_jobs`, `kerf_cancel`); every write
//! of a running chunk checks that it is still the writer's and its job still running.

use kerf_solver::ErrorCode;
use kerf_solver::capability::{Part, Split};
use serde::Serialize;
use std::time::Duration;

use utoipa::ToSchema;

use super::on;
use super::packed::{Packed, StoredText};
use crate::db::Db;
use crate::error::{AppError, AppResult, FieldProblem, Problem};
use crate::jobs::file::JobFile;
use crate::jobs::storage::{JobStorage, mib};

/// Attempts a job gets: one retry after a server stop interrupted it.
pub const MAX_ATTEMPTS: i64 = 2;

/// SQLite's current UTC time as stored (a macro, so every statement stays a static string).
macro_rules! now {
    () => {
        "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')"
    };
}

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

/// The channel a submission notifies (payload: the job id).
pub const SUBMITTED_CHANNEL: &str = "kerf_jobs";
/// The channel a cancellation notifies (payload: the job id).
pub const CANCEL_CHANNEL: &str = "kerf_cancel";

/// PostgreSQL advisory lock held while a process checks the quota and adds to the store (so two
/// processes cannot both fit into the last free bytes).
const QUOTA_LOCK: i64 = 0x6b65_7266_0001;
/// PostgreSQL advisory lock of the process pruning old jobs (the others skip their turn).
const PRUNE_LOCK: i64 = 0x6b65_7266_0002;

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
    fn parse(text: &str) -> AppResult<Self> {
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

/// Who claims work: the worker's name, written on the chunk it runs, and how long its lease lasts
/// without a heartbeat (PostgreSQL; SQLite has one process and no leases).
#[derive(Debug, Clone)]
pub struct Claimant {
    /// Unique among the processes sharing the database (host, process id, start time).
    pub worker: String,
    /// How long a claimed chunk stays this worker's without a heartbeat.
    pub lease: Duration,
}

/// What a worker runs: a whole job (SQLite), or one chunk of it (PostgreSQL: chunk `chunk`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Work {
    /// Job id.
    pub id: i64,
    /// The chunk's number within its job (`job_chunks.position`), or `None` for the whole job.
    pub chunk: Option<usize>,
}

impl Work {
    fn position(self) -> i64 {
        self.chunk.map_or(0, |chunk| i64::try_from(chunk).unwrap_or(i64::MAX))
    }
}

/// What a claimed piece of work computes.
#[derive(Debug, Clone, PartialEq)]
pub enum Task {
    /// Every operation of the job, in order (SQLite).
    Job,
    /// Operation `i`, whole: the worker may first split it ([`split`]).
    Operation(usize),
    /// One part of an operation that was split.
    Part {
        /// The operation's index.
        operation: usize,
        /// The part.
        part: Part,
    },
    /// The finish step of an operation that was split: merges its parts' outputs.
    Finish {
        /// The operation's index.
        operation: usize,
    },
}

impl Task {
    /// The operation a chunk belongs to (0 for a whole job: its results start there).
    pub fn operation(&self) -> usize {
        match self {
            Self::Job => 0,
            Self::Operation(operation) | Self::Part { operation, .. } | Self::Finish { operation } => *operation,
        }
    }
}

/// Work a worker claimed.
#[derive(Debug)]
pub struct Claimed {
    /// The job, and the chunk of it.
    pub work: Work,
    /// What the chunk computes.
    pub task: Task,
    /// The resolved job.
    pub job: JobFile,
    /// Which attempt this is (1 for the first).
    pub attempt: i64,
}

/// Sets job `$1`'s progress to the weighted sum of its chunks' (an operation's chunks weigh 1
/// together, so this is the mean over operations of each one's share done).
const JOB_PROGRESS: &str = "UPDATE jobs SET heartbeat_at = now(), progress = (
         SELECT LEAST(1, GREATEST(0, COALESCE(SUM(weight * progress) / NULLIF(SUM(weight), 0), 0)))
         FROM job_chunks WHERE job_id = $1)
     WHERE id = $1 AND status = 'running'";

/// Sets job `id`'s progress from its chunks' ([`JOB_PROGRESS`]) after locking the job's row in a
/// statement of its own. Under READ COMMITTED a statement reads in the snapshot it started with:
/// in one statement two workers' heartbeats could each sum the chunks before the other's commit,
/// and the later write would leave the job behind its chunks (seen once by the cluster test). A
/// transaction that waited for the lock reads the chunks afresh, the other's commit included.
async fn set_job_progress(transaction: &mut sqlx::Transaction<'_, sqlx::Postgres>, id: i64) -> AppResult<()> {
    sqlx::query("SELECT id FROM jobs WHERE id = $1 FOR UPDATE").bind(id).execute(&mut **transaction).await?;
    sqlx::query(JOB_PROGRESS).bind(id).execute(&mut **transaction).await?;
    Ok(())
}

/// Bytes as the stores count them.
fn bytes(count: usize) -> i64 {
    i64::try_from(count).unwrap_or(i64::MAX)
}

/// The 429 `E_JOB_STORE_FULL` of a submission that does not fit.
async fn store_full(db: &Db, needed: i64, quota: i64) -> AppResult<AppError> {
    let (_, used) = usage(db).await?;
    Ok(AppError::JobStoreFull(format!(
        "the job store holds {} of its {} quota, no room for this job ({}); prune finished jobs (kerf jobs \
         prune, or wait for the retention) or raise --job-store-quota-mb",
        mib(used.unsigned_abs()),
        mib(quota.unsigned_abs()),
        mib(needed.unsigned_abs())
    )))
}

/// Stores a new queued job (PostgreSQL: with one chunk per operation, which the worker that
/// claims it may split) and wakes the workers;
/// returns its id. A job that would take the store past `quota` bytes is refused (429
/// `E_JOB_STORE_FULL`) and nothing of it is written: the check and the insert are one statement
/// (SQLite) or one transaction under the quota lock (PostgreSQL).
pub async fn insert(db: &Db, job: &JobFile, hash: &str, quota: u64) -> AppResult<i64> {
    let json = serde_json::to_string(job).map_err(|e| AppError::Internal(e.into()))?;
    let operations: Vec<&str> = job.operations.iter().map(|o| o.name()).collect();
    let count = i64::try_from(operations.len()).unwrap_or(i64::MAX);
    let operations = serde_json::to_string(&operations).map_err(|e| AppError::Internal(e.into()))?;
    let (size, quota) = (bytes(json.len()), i64::try_from(quota).unwrap_or(i64::MAX));
    const INSERT: &str = "INSERT INTO jobs (name, status, content_hash, job_json, operations, stored_bytes)
         SELECT $1, 'queued', $2, $3, $4, CAST($5 AS BIGINT)
         WHERE (SELECT COALESCE(SUM(stored_bytes), 0) FROM jobs) + CAST($5 AS BIGINT) <= CAST($6 AS BIGINT)
         RETURNING id";
    match db {
        Db::Sqlite(pool) => {
            let row: Option<(i64,)> = sqlx::query_as(INSERT)
                .bind(&job.name)
                .bind(hash)
                .bind(json)
                .bind(operations)
                .bind(size)
                .bind(quota)
                .fetch_optional(pool)
                .await?;
            match row {
                Some((id,)) => Ok(id),
                None => Err(store_full(db, size, quota).await?),
            }
        }
        Db::Postgres(pool) => {
            // The notification is delivered at commit, when the chunks are there to claim.
            let mut transaction = pool.begin().await?;
            sqlx::query("SELECT pg_advisory_xact_lock($1)").bind(QUOTA_LOCK).execute(&mut *transaction).await?;
            let row: Option<(i64,)> = sqlx::query_as(INSERT)
                .bind(&job.name)
                .bind(hash)
                .bind(json)
                .bind(operations)
                .bind(size)
                .bind(quota)
                .fetch_optional(&mut *transaction)
                .await?;
            let Some((id,)) = row else {
                transaction.rollback().await?;
                return Err(store_full(db, size, quota).await?);
            };
            sqlx::query(
                "INSERT INTO job_chunks (job_id, position, operation, status)
                 SELECT $1, n, n, 'queued' FROM generate_series(0, $2 - 1) AS n",
            )
            .bind(id)
            .bind(count)
            .execute(&mut *transaction)
            .await?;
            wake_workers(&mut transaction, id).await?;
            transaction.commit().await?;
            Ok(id)
        }
    }
}

/// A finished job with the same content, if any.
pub async fn find_done(db: &Db, hash: &str) -> AppResult<Option<i64>> {
    let row: Option<(i64,)> = on!(db, query_as,
        both: "SELECT id FROM jobs WHERE content_hash = $1 AND status = 'done' ORDER BY id LIMIT 1",
        [hash], fetch_optional)?;
    Ok(row.map(|(id,)| id))
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

/// Claims the next work for `claimant`. SQLite: the oldest queued job, marked running.
/// PostgreSQL: the first queued chunk of the oldest job still to run (or a running chunk whose
/// lease expired; a finish step only once its operation's parts are all done), marked running
/// with the claimant's name and lease; its job is marked running too. A chunk whose lease
/// expired after its last attempt fails its job with `E_INTERRUPTED`.
pub async fn claim(db: &Db, claimant: &Claimant) -> AppResult<Option<Claimed>> {
    let (work, task, json, attempt) = match db {
        Db::Sqlite(pool) => {
            let row: Option<(i64, String, i64)> = sqlx::query_as(concat!(
                "UPDATE jobs SET status = 'running', attempts = attempts + 1, progress = 0, started_at = ",
                now!(),
                ", heartbeat_at = ",
                now!(),
                " WHERE id = (SELECT id FROM jobs WHERE status = 'queued' ORDER BY id LIMIT 1)
                 RETURNING id, job_json, attempts"
            ))
            .fetch_optional(pool)
            .await?;
            let Some((id, json, attempt)) = row else { return Ok(None) };
            (Work { id, chunk: None }, Task::Job, json, attempt)
        }
        Db::Postgres(pool) => {
            // A chunk of a job cancelled in the meantime is skipped: try the next one.
            let mut found = None;
            for _ in 0..8 {
                match claim_chunk(pool, claimant).await? {
                    Chunk::None => return Ok(None),
                    Chunk::Gone => {}
                    Chunk::Claimed(work, task, json, attempt) => {
                        found = Some((work, task, json, attempt));
                        break;
                    }
                }
            }
            let Some(found) = found else { return Ok(None) };
            found
        }
    };
    match serde_json::from_str(&json) {
        Ok(job) => Ok(Some(Claimed { work, task, job, attempt })),
        Err(error) => {
            let detail = format!("the stored job is unreadable: {error}");
            fail(db, work, claimant, &job_problem(422, "Job failed", ErrorCode::JobFile, &detail)).await?;
            Ok(None)
        }
    }
}

/// The outcome of one claim transaction.
enum Chunk {
    /// Nothing to run.
    None,
    /// A chunk of a job that is no longer to run (cancelled or failed meanwhile).
    Gone,
    /// The chunk, what it computes, its job's JSON and the chunk's attempt.
    Claimed(Work, Task, String, i64),
}

/// A claimed chunk's row: job, position, attempts, kind, operation, units.
type ChunkRow = (i64, i64, i64, String, i64, Option<i64>, Option<i64>, f64);

async fn claim_chunk(pool: &sqlx::PgPool, claimant: &Claimant) -> AppResult<Chunk> {
    let mut transaction = pool.begin().await?;
    sqlx::query(
        "WITH dead AS (
             UPDATE job_chunks SET status = 'failed', lease_expires_at = NULL
             WHERE (job_id, position) IN (
                 SELECT job_id, position FROM job_chunks
                 WHERE status = 'running' AND lease_expires_at < now() AND attempts >= $2
                 FOR UPDATE SKIP LOCKED)
             RETURNING job_id)
         UPDATE jobs SET status = 'failed', finished_at = now(), error = $1
         WHERE id IN (SELECT job_id FROM dead) AND status IN ('queued', 'running')",
    )
    .bind(problem_json(&job_problem(
        503,
        "Job interrupted",
        ErrorCode::Interrupted,
        &format!("its worker stopped (lease expired) on each of its {MAX_ATTEMPTS} attempts; not retried"),
    ))?)
    .bind(MAX_ATTEMPTS)
    .execute(&mut *transaction)
    .await?;
    let chunk: Option<ChunkRow> = sqlx::query_as(
        "WITH next AS (
             SELECT c.job_id, c.position FROM job_chunks c JOIN jobs j ON j.id = c.job_id
             WHERE j.status IN ('queued', 'running')
               AND (c.status = 'queued' OR (c.status = 'running' AND c.lease_expires_at < now()))
               AND (c.kind <> 'finish' OR NOT EXISTS (
                   SELECT 1 FROM job_chunks p
                   WHERE p.job_id = c.job_id AND p.operation = c.operation AND p.kind = 'part' AND p.status <> 'done'))
             ORDER BY c.job_id, c.operation, c.position LIMIT 1
             FOR UPDATE OF c SKIP LOCKED)
         UPDATE job_chunks c SET status = 'running', attempts = c.attempts + 1, progress = 0, worker = $1,
             lease_expires_at = now() + make_interval(secs => $2)
         FROM next WHERE c.job_id = next.job_id AND c.position = next.position
         RETURNING c.job_id, c.position, c.attempts, c.kind, c.operation, c.units_from, c.units_to, c.work",
    )
    .bind(&claimant.worker)
    .bind(claimant.lease.as_secs_f64())
    .fetch_optional(&mut *transaction)
    .await?;
    let Some((id, position, attempt, kind, operation, from, to, work)) = chunk else {
        transaction.commit().await?;
        return Ok(Chunk::None);
    };
    let index = |value: i64| usize::try_from(value).map_err(|e| AppError::Internal(e.into()));
    let operation = index(operation)?;
    let task = match (kind.as_str(), from, to) {
        ("part", Some(from), Some(to)) => {
            Task::Part { operation, part: Part { units: index(from)?..index(to)?, seconds: work } }
        }
        ("finish", _, _) => Task::Finish { operation },
        _ => Task::Operation(operation),
    };
    let job: Option<(String,)> = sqlx::query_as(
        "UPDATE jobs SET status = 'running', started_at = COALESCE(started_at, now()), heartbeat_at = now(),
             attempts = GREATEST(attempts, $2)
         WHERE id = $1 AND status IN ('queued', 'running')
         RETURNING job_json",
    )
    .bind(id)
    .bind(attempt)
    .fetch_optional(&mut *transaction)
    .await?;
    let Some((json,)) = job else {
        // Cancelled between the two statements: leave the chunk to nobody.
        transaction.rollback().await?;
        return Ok(Chunk::Gone);
    };
    // A chunk claimed again starts over: the job's progress loses what it had done.
    set_job_progress(&mut transaction, id).await?;
    transaction.commit().await?;
    Ok(Chunk::Claimed(Work { id, chunk: Some(index(position)?) }, task, json, attempt))
}

/// Splits the operation chunk `work` that `claimant` runs into `split`'s parts (PostgreSQL): the
/// chunk becomes the first part, which the claimant goes on to solve, and the other parts and
/// the operation's finish step are queued (the finish step is claimable once every part is done;
/// [`claim`]); each chunk weighs its share of the estimated work. Returns false when the chunk is
/// no longer the claimant's or its job no longer runs (nothing is written), and always in SQLite,
/// where one process runs the whole job.
pub async fn split(db: &Db, work: Work, claimant: &Claimant, split: &Split) -> AppResult<bool> {
    let Db::Postgres(pool) = db else { return Ok(false) };
    let Some((first, rest)) = split.parts.split_first() else { return Ok(false) };
    let total = split.parts.iter().map(|part| part.seconds).sum::<f64>() + split.finish_seconds;
    let weight = |seconds: f64| {
        if total > 0.0 && total.is_finite() { seconds / total } else { 1.0 / (split.parts.len() + 1) as f64 }
    };
    let unit = |value: usize| i64::try_from(value).unwrap_or(i64::MAX);
    let mut transaction = pool.begin().await?;
    // The job's row first: splitters of one job take turns numbering the new chunks.
    let job: Option<(String,)> = sqlx::query_as("SELECT status FROM jobs WHERE id = $1 FOR UPDATE")
        .bind(work.id)
        .fetch_optional(&mut *transaction)
        .await?;
    if job.is_none_or(|(status,)| status != "running") {
        transaction.rollback().await?;
        return Ok(false);
    }
    let updated = sqlx::query(
        "UPDATE job_chunks SET kind = 'part', units_from = $4, units_to = $5, work = $6, weight = $7
         WHERE job_id = $1 AND position = $2 AND worker = $3 AND status = 'running' AND kind = 'whole'
         RETURNING operation",
    )
    .bind(work.id)
    .bind(work.position())
    .bind(&claimant.worker)
    .bind(unit(first.units.start))
    .bind(unit(first.units.end))
    .bind(first.seconds)
    .bind(weight(first.seconds))
    .fetch_optional(&mut *transaction)
    .await?;
    let Some(row) = updated else {
        transaction.rollback().await?;
        return Ok(false);
    };
    let operation: i64 = sqlx::Row::try_get(&row, 0)?;
    let (next,): (i64,) =
        sqlx::query_as("SELECT COALESCE(MAX(position), -1)::BIGINT + 1 FROM job_chunks WHERE job_id = $1")
            .bind(work.id)
            .fetch_one(&mut *transaction)
            .await?;
    let froms: Vec<i64> = rest.iter().map(|part| unit(part.units.start)).collect();
    let tos: Vec<i64> = rest.iter().map(|part| unit(part.units.end)).collect();
    let seconds: Vec<f64> = rest.iter().map(|part| part.seconds).collect();
    let weights: Vec<f64> = rest.iter().map(|part| weight(part.seconds)).collect();
    sqlx::query(
        "INSERT INTO job_chunks (job_id, position, operation, status, kind, units_from, units_to, work, weight)
         SELECT $1, $2 + k - 1, $3, 'queued', 'part', f, t, w, s
         FROM UNNEST($4::BIGINT[], $5::BIGINT[], $6::DOUBLE PRECISION[], $7::DOUBLE PRECISION[])
             WITH ORDINALITY AS u(f, t, w, s, k)",
    )
    .bind(work.id)
    .bind(next)
    .bind(operation)
    .bind(&froms)
    .bind(&tos)
    .bind(&seconds)
    .bind(&weights)
    .execute(&mut *transaction)
    .await?;
    sqlx::query(
        "INSERT INTO job_chunks (job_id, position, operation, status, kind, work, weight)
         VALUES ($1, $2, $3, 'queued', 'finish', $4, $5)",
    )
    .bind(work.id)
    .bind(next + unit(rest.len()))
    .bind(operation)
    .bind(split.finish_seconds)
    .bind(weight(split.finish_seconds))
    .execute(&mut *transaction)
    .await?;
    set_job_progress(&mut transaction, work.id).await?;
    wake_workers(&mut transaction, work.id).await?;
    transaction.commit().await?;
    Ok(true)
}

/// Wakes idle workers (`LISTEN/NOTIFY`) when `transaction` commits: job `id` has work to claim.
async fn wake_workers(transaction: &mut sqlx::Transaction<'_, sqlx::Postgres>, id: i64) -> AppResult<()> {
    sqlx::query("SELECT pg_notify($1, $2)")
        .bind(SUBMITTED_CHANNEL)
        .bind(id.to_string())
        .execute(&mut **transaction)
        .await?;
    Ok(())
}

/// The outputs of operation `operation`'s parts, in unit order: each gzip-compressed, with the
/// seconds its solve took (PostgreSQL; a finish step reads them).
pub async fn part_outputs(db: &Db, id: i64, operation: usize) -> AppResult<Vec<(Vec<u8>, f64)>> {
    let Db::Postgres(pool) = db else { return Ok(Vec::new()) };
    let rows: Vec<(Option<Vec<u8>>, f64)> = sqlx::query_as(
        "SELECT output_gz, solve_seconds FROM job_chunks WHERE job_id = $1 AND operation = $2 AND kind = 'part'
         ORDER BY units_from",
    )
    .bind(id)
    .bind(i64::try_from(operation).unwrap_or(i64::MAX))
    .fetch_all(pool)
    .await?;
    rows.into_iter()
        .map(|(output, seconds)| {
            output.map(|output| (output, seconds)).ok_or_else(|| {
                AppError::Internal(anyhow::anyhow!("operations[{operation}]: a part's output is missing"))
            })
        })
        .collect()
}

/// Records progress and the heartbeat of running work (PostgreSQL: of the chunk, extending its
/// lease; the job's progress is the weighted sum of its chunks', written in the same transaction
/// so the two always agree). Returns false when the work is no
/// longer the claimant's to run: its job was cancelled or failed, or (PostgreSQL) the chunk was
/// claimed by another worker after this one's lease expired. The worker then stops it.
pub async fn heartbeat(db: &Db, work: Work, claimant: &Claimant, progress: f64) -> AppResult<bool> {
    let progress = progress.clamp(0.0, 1.0);
    match db {
        Db::Sqlite(pool) => {
            let updated = sqlx::query(concat!(
                "UPDATE jobs SET progress = $1, heartbeat_at = ",
                now!(),
                " WHERE id = $2 AND status = 'running'"
            ))
            .bind(progress)
            .bind(work.id)
            .execute(pool)
            .await?;
            Ok(updated.rows_affected() > 0)
        }
        Db::Postgres(pool) => {
            let mut transaction = pool.begin().await?;
            let updated = sqlx::query(
                "UPDATE job_chunks SET progress = $1, lease_expires_at = now() + make_interval(secs => $4)
                 WHERE job_id = $2 AND position = $5 AND worker = $3 AND status = 'running'
                   AND EXISTS (SELECT 1 FROM jobs WHERE id = $2 AND status = 'running')",
            )
            .bind(progress)
            .bind(work.id)
            .bind(&claimant.worker)
            .bind(claimant.lease.as_secs_f64())
            .bind(work.position())
            .execute(&mut *transaction)
            .await?;
            if updated.rows_affected() == 0 {
                transaction.rollback().await?;
                return Ok(false);
            }
            set_job_progress(&mut transaction, work.id).await?;
            transaction.commit().await?;
            Ok(true)
        }
    }
}

/// What became of finished work.
#[derive(Debug, Clone, PartialEq)]
pub enum Finished {
    /// Its results are stored.
    Stored,
    /// Its job was cancelled (or, in PostgreSQL, the chunk is no longer the claimant's) meanwhile.
    Gone,
    /// Its results do not fit (over the per-job cap or the quota): nothing was stored, and the
    /// job is to fail with this problem.
    Refused(Problem),
}

/// Whether `outputs` (operations from `first` on: each one's name and compressed bytes) fit: the
/// job already takes `job_bytes`, the store `total_bytes`. The problem to fail the job with when
/// they do not.
fn check_fit(
    job_bytes: i64,
    total_bytes: i64,
    outputs: &[(&str, i64)],
    first: i64,
    storage: &JobStorage,
) -> Option<Problem> {
    let added: i64 = outputs.iter().map(|(_, size)| size).sum();
    let cap = i64::try_from(storage.job_max_bytes).unwrap_or(i64::MAX);
    let mut running = job_bytes;
    for (offset, (operation, size)) in outputs.iter().enumerate() {
        running = running.saturating_add(*size);
        if running > cap {
            let index = first + bytes(offset);
            let detail = format!(
                "operations[{index}] ({operation}) brings the job's stored results to {} (compressed), over the limit \
                 of {} per job (--job-result-max-mb); split the job or make the operation smaller",
                mib(running.unsigned_abs()),
                mib(storage.job_max_bytes)
            );
            return Some(Problem {
                errors: vec![FieldProblem { path: format!("operations[{index}]"), message: detail.clone() }],
                ..job_problem(422, "Result too large", ErrorCode::ResultTooLarge, &detail)
            });
        }
    }
    let quota = storage.quota();
    (total_bytes.saturating_add(added).unsigned_abs() > quota).then(|| {
        job_problem(
            429,
            "Job store full",
            ErrorCode::JobStoreFull,
            &format!(
                "its results ({} compressed) do not fit: the job store holds {} of its {} quota; prune finished \
                 jobs (kerf jobs prune, or wait for the retention) or raise --job-store-quota-mb, then submit it again",
                mib(added.unsigned_abs()),
                mib(total_bytes.unsigned_abs()),
                mib(quota)
            ),
        )
    })
}

/// Stores the results and marks the work done, in one transaction, unless its job was
/// cancelled (or, in PostgreSQL, the chunk is no longer the claimant's) meanwhile, or the results
/// do not fit in `storage` (then nothing is written). In PostgreSQL `task` is a whole operation or
/// a finish step (its result is the operation's; the parts' outputs it merged are dropped), and
/// the job is done with its last chunk.
pub async fn finish(
    db: &Db,
    work: Work,
    task: &Task,
    claimant: &Claimant,
    outputs: &[Packed],
    storage: &JobStorage,
) -> AppResult<Finished> {
    let sizes: Vec<(&str, i64)> =
        outputs.iter().map(|output| (output.operation.as_str(), bytes(output.stored_bytes()))).collect();
    let added: i64 = sizes.iter().map(|(_, size)| size).sum();
    let first = bytes(task.operation());
    macro_rules! results_in {
        ($transaction:expr, $delta:expr) => {
            for (offset, output) in outputs.iter().enumerate() {
                sqlx::query(
                    "INSERT INTO job_results (job_id, position, operation, result_json, result_gz, result_bytes,
                         gcode_gz, gcode_bytes, gcode_problem)
                     VALUES ($1, $2, $3, '', $4, $5, $6, $7, $8)",
                )
                .bind(work.id)
                .bind(first + i64::try_from(offset).unwrap_or(i64::MAX))
                .bind(&output.operation)
                .bind(&output.result_gz)
                .bind(bytes(output.result_bytes))
                .bind(&output.gcode_gz)
                .bind(bytes(output.gcode_bytes))
                .bind(&output.gcode_problem)
                .execute(&mut *$transaction)
                .await?;
            }
            sqlx::query("UPDATE jobs SET stored_bytes = stored_bytes + $1 WHERE id = $2")
                .bind($delta)
                .bind(work.id)
                .execute(&mut *$transaction)
                .await?;
        };
    }
    match db {
        Db::Sqlite(pool) => {
            // The first statement writes, so the transaction holds the file's write lock from
            // there on: the quota check and the results it admits are one step.
            let mut transaction = pool.begin().await?;
            let job: Option<(i64,)> = sqlx::query_as(concat!(
                "UPDATE jobs SET status = 'done', progress = 1, finished_at = ",
                now!(),
                " WHERE id = $1 AND status = 'running' RETURNING stored_bytes"
            ))
            .bind(work.id)
            .fetch_optional(&mut *transaction)
            .await?;
            let Some((job_bytes,)) = job else {
                transaction.rollback().await?;
                return Ok(Finished::Gone);
            };
            let (total,): (i64,) =
                sqlx::query_as("SELECT COALESCE(SUM(stored_bytes), 0) FROM jobs").fetch_one(&mut *transaction).await?;
            if let Some(problem) = check_fit(job_bytes, total, &sizes, first, storage) {
                transaction.rollback().await?;
                return Ok(Finished::Refused(problem));
            }
            results_in!(transaction, added);
            transaction.commit().await?;
        }
        Db::Postgres(pool) => {
            let mut transaction = pool.begin().await?;
            // The job's row first: finishers of one job's chunks take turns, so the last one
            // sees every other chunk done.
            let Some(job_bytes) = finishing(&mut transaction, work, claimant).await? else {
                transaction.rollback().await?;
                return Ok(Finished::Gone);
            };
            // A finish step's parts are merged into its result: their outputs go.
            let (parts,): (i64,) = sqlx::query_as(
                "SELECT COALESCE(SUM(octet_length(output_gz)), 0)::BIGINT FROM job_chunks
                 WHERE job_id = $1 AND operation = $2 AND kind = 'part'",
            )
            .bind(work.id)
            .bind(first)
            .fetch_one(&mut *transaction)
            .await?;
            sqlx::query("SELECT pg_advisory_xact_lock($1)").bind(QUOTA_LOCK).execute(&mut *transaction).await?;
            let (total,): (i64,) = sqlx::query_as("SELECT COALESCE(SUM(stored_bytes), 0)::BIGINT FROM jobs")
                .fetch_one(&mut *transaction)
                .await?;
            if let Some(problem) = check_fit(job_bytes - parts, total - parts, &sizes, first, storage) {
                transaction.rollback().await?;
                return Ok(Finished::Refused(problem));
            }
            results_in!(transaction, added - parts);
            sqlx::query(
                "UPDATE job_chunks SET output_gz = NULL WHERE job_id = $1 AND operation = $2 AND kind = 'part'",
            )
            .bind(work.id)
            .bind(first)
            .execute(&mut *transaction)
            .await?;
            sqlx::query(
                "UPDATE jobs SET status = 'done', progress = 1, finished_at = now()
                 WHERE id = $1 AND NOT EXISTS (SELECT 1 FROM job_chunks WHERE job_id = $1 AND status <> 'done')",
            )
            .bind(work.id)
            .execute(&mut *transaction)
            .await?;
            set_job_progress(&mut transaction, work.id).await?;
            transaction.commit().await?;
        }
    }
    Ok(Finished::Stored)
}

/// Locks the job of running chunk `work` and marks the chunk done, if it is still the claimant's
/// and its job still runs; the job's stored bytes then.
async fn finishing(
    transaction: &mut sqlx::Transaction<'_, sqlx::Postgres>,
    work: Work,
    claimant: &Claimant,
) -> AppResult<Option<i64>> {
    let job: Option<(String, i64)> = sqlx::query_as("SELECT status, stored_bytes FROM jobs WHERE id = $1 FOR UPDATE")
        .bind(work.id)
        .fetch_optional(&mut **transaction)
        .await?;
    let updated = sqlx::query(
        "UPDATE job_chunks SET status = 'done', progress = 1, lease_expires_at = NULL
         WHERE job_id = $1 AND position = $2 AND worker = $3 AND status = 'running'",
    )
    .bind(work.id)
    .bind(work.position())
    .bind(&claimant.worker)
    .execute(&mut **transaction)
    .await?;
    Ok(job.filter(|(status, _)| status == "running" && updated.rows_affected() > 0).map(|(_, stored)| stored))
}

/// A part's output, compressed for storage until its finish step.
#[derive(Debug, Clone)]
pub struct PartOutput {
    /// The operation's name.
    pub operation: String,
    /// The output, gzip-compressed CBOR.
    pub gz: Vec<u8>,
    /// Its uncompressed length, bytes.
    pub bytes: usize,
    /// The seconds its solve took.
    pub seconds: f64,
}

/// Stores a part's output on its chunk and marks the chunk done, in one transaction, unless its
/// job was cancelled or the chunk is no longer the claimant's meanwhile, or the output does not fit
/// in `storage` (the job's stored bytes count it until the finish step drops it). Wakes the
/// workers when it was the operation's last part: its finish step is claimable (PostgreSQL).
pub async fn finish_part(
    db: &Db,
    work: Work,
    operation: usize,
    claimant: &Claimant,
    output: &PartOutput,
    storage: &JobStorage,
) -> AppResult<Finished> {
    let Db::Postgres(pool) = db else {
        return Err(AppError::Internal(anyhow::anyhow!("parts are stored in PostgreSQL only")));
    };
    let size = bytes(output.gz.len());
    let operation = bytes(operation);
    let mut transaction = pool.begin().await?;
    let Some(job_bytes) = finishing(&mut transaction, work, claimant).await? else {
        transaction.rollback().await?;
        return Ok(Finished::Gone);
    };
    sqlx::query("SELECT pg_advisory_xact_lock($1)").bind(QUOTA_LOCK).execute(&mut *transaction).await?;
    let (total,): (i64,) =
        sqlx::query_as("SELECT COALESCE(SUM(stored_bytes), 0)::BIGINT FROM jobs").fetch_one(&mut *transaction).await?;
    if let Some(problem) = check_fit(job_bytes, total, &[(output.operation.as_str(), size)], operation, storage) {
        transaction.rollback().await?;
        return Ok(Finished::Refused(problem));
    }
    sqlx::query(
        "UPDATE job_chunks SET output_gz = $3, output_bytes = $4, solve_seconds = $5
         WHERE job_id = $1 AND position = $2",
    )
    .bind(work.id)
    .bind(work.position())
    .bind(&output.gz)
    .bind(bytes(output.bytes))
    .bind(output.seconds)
    .execute(&mut *transaction)
    .await?;
    sqlx::query("UPDATE jobs SET stored_bytes = stored_bytes + $1 WHERE id = $2")
        .bind(size)
        .bind(work.id)
        .execute(&mut *transaction)
        .await?;
    set_job_progress(&mut transaction, work.id).await?;
    let (left,): (i64,) = sqlx::query_as(
        "SELECT COUNT(*) FROM job_chunks WHERE job_id = $1 AND operation = $2 AND kind = 'part' AND status <> 'done'",
    )
    .bind(work.id)
    .bind(operation)
    .fetch_one(&mut *transaction)
    .await?;
    if left == 0 {
        wake_workers(&mut transaction, work.id).await?;
    }
    transaction.commit().await?;
    Ok(Finished::Stored)
}

/// Marks running work's job failed with the problem (PostgreSQL: only while the chunk is the
/// claimant's; the job's other chunks stop at their next heartbeat), and drops what its chunks
/// stored in the same transaction: nobody sees the job failed with their outputs still there.
pub async fn fail(db: &Db, work: Work, claimant: &Claimant, problem: &Problem) -> AppResult<()> {
    let json = problem_json(problem)?;
    let field = problem.errors.first().map(|error| error.path.clone());
    match db {
        Db::Sqlite(pool) => {
            // IMMEDIATE: the write lock from the start (see `cancel`).
            let mut transaction = pool.begin_with("BEGIN IMMEDIATE").await?;
            sqlx::query(concat!(
                "UPDATE jobs SET status = 'failed', error = $1, error_field = $2, finished_at = ",
                now!(),
                " WHERE id = $3 AND status = 'running'"
            ))
            .bind(json)
            .bind(field)
            .bind(work.id)
            .execute(&mut *transaction)
            .await?;
            drop_partial_results_sqlite(&mut transaction, work.id).await?;
            transaction.commit().await?;
        }
        Db::Postgres(pool) => {
            let mut transaction = pool.begin().await?;
            sqlx::query(
                "WITH chunk AS (
                     UPDATE job_chunks SET status = 'failed', lease_expires_at = NULL
                     WHERE job_id = $3 AND position = $5 AND worker = $4 AND status = 'running'
                     RETURNING job_id)
                 UPDATE jobs SET status = 'failed', error = $1, error_field = $2, finished_at = now()
                 WHERE id IN (SELECT job_id FROM chunk) AND status = 'running'",
            )
            .bind(json)
            .bind(field)
            .bind(work.id)
            .bind(&claimant.worker)
            .bind(work.position())
            .execute(&mut *transaction)
            .await?;
            drop_partial_results_postgres(&mut transaction, work.id).await?;
            transaction.commit().await?;
        }
    }
    Ok(())
}

/// Removes what the chunks of a job that failed or was cancelled stored (PostgreSQL: other
/// chunks may have finished first), so a job that will never be done takes no more than its job
/// file. No-op for a job still to run or done. Run in the transaction that ends the job.
async fn drop_partial_results_sqlite(connection: &mut sqlx::SqliteConnection, id: i64) -> AppResult<()> {
    sqlx::query(DROP_RESULTS).bind(id).execute(&mut *connection).await?;
    sqlx::query(
        "UPDATE jobs SET stored_bytes = length(CAST(job_json AS BLOB))
         WHERE id = $1 AND status IN ('failed', 'cancelled')",
    )
    .bind(id)
    .execute(&mut *connection)
    .await?;
    Ok(())
}

/// [`drop_partial_results_sqlite`] for PostgreSQL, where the chunks keep their outputs too.
async fn drop_partial_results_postgres(connection: &mut sqlx::PgConnection, id: i64) -> AppResult<()> {
    sqlx::query(DROP_RESULTS).bind(id).execute(&mut *connection).await?;
    sqlx::query(
        "UPDATE jobs SET stored_bytes = octet_length(job_json) WHERE id = $1 AND status IN ('failed', 'cancelled')",
    )
    .bind(id)
    .execute(&mut *connection)
    .await?;
    sqlx::query(
        "UPDATE job_chunks SET output_gz = NULL WHERE job_id = $1 AND output_gz IS NOT NULL
         AND EXISTS (SELECT 1 FROM jobs WHERE id = $1 AND status IN ('failed', 'cancelled'))",
    )
    .bind(id)
    .execute(&mut *connection)
    .await?;
    Ok(())
}

/// The results of a job that failed or was cancelled (the same in both stores).
const DROP_RESULTS: &str = "DELETE FROM job_results WHERE job_id = $1
    AND EXISTS (SELECT 1 FROM jobs WHERE id = $1 AND status IN ('failed', 'cancelled'))";

/// Cancels a queued or running job. `Ok(None)` if there is no such job; otherwise the status
/// the job had, and whether this call cancelled it. In PostgreSQL the workers are notified, so
/// the one running it stops at once (its heartbeat would find out within a second anyway).
/// What the job's chunks stored is dropped in the same transaction.
pub async fn cancel(db: &Db, id: i64) -> AppResult<Option<(JobStatus, bool)>> {
    let error = problem_json(&job_problem(409, "Cancelled", ErrorCode::Cancelled, "cancelled by request"))?;
    macro_rules! cancel_in {
        ($begin:expr, $select:expr, $update:expr, $notify:expr, $drop:ident) => {{
            let mut transaction = $begin.await?;
            let row: Option<(String,)> = sqlx::query_as($select).bind(id).fetch_optional(&mut *transaction).await?;
            let Some((status,)) = row else { return Ok(None) };
            let status = JobStatus::parse(&status)?;
            let cancellable = matches!(status, JobStatus::Queued | JobStatus::Running);
            if cancellable {
                sqlx::query($update).bind(error).bind(id).execute(&mut *transaction).await?;
                if let Some(notify) = $notify {
                    sqlx::query(notify).bind(CANCEL_CHANNEL).bind(id.to_string()).execute(&mut *transaction).await?;
                }
                $drop(&mut transaction, id).await?;
            }
            transaction.commit().await?;
            Ok(Some((status, cancellable)))
        }};
    }
    match db {
        // IMMEDIATE: the write lock from the start. A deferred transaction that reads and then
        // writes fails at once with SQLITE_BUSY when a worker wrote in between (the busy timeout
        // does not apply to a stale read snapshot): a 500 under load.
        Db::Sqlite(pool) => cancel_in!(
            pool.begin_with("BEGIN IMMEDIATE"),
            "SELECT status FROM jobs WHERE id = $1",
            concat!("UPDATE jobs SET status = 'cancelled', finished_at = ", now!(), ", error = $1 WHERE id = $2"),
            None::<&'static str>,
            drop_partial_results_sqlite
        ),
        Db::Postgres(pool) => cancel_in!(
            pool.begin(),
            "SELECT status FROM jobs WHERE id = $1 FOR UPDATE",
            "UPDATE jobs SET status = 'cancelled', finished_at = now(), error = $1 WHERE id = $2",
            Some("SELECT pg_notify($1, $2)"),
            drop_partial_results_postgres
        ),
    }
}

/// One operation's stored result.
#[derive(Debug)]
pub struct ResultRow {
    /// The operation's name.
    pub operation: String,
    /// Its result JSON.
    pub result: StoredText,
    /// Whether a program exists.
    pub gcode: bool,
    /// Why no program could be written, if so.
    pub gcode_problem: Option<String>,
}

/// A finished job's results, in operation order.
pub async fn results(db: &Db, id: i64) -> AppResult<Vec<ResultRow>> {
    type Row = (String, Option<String>, Option<Vec<u8>>, i64, bool, Option<String>);
    let rows: Vec<Row> = on!(db, query_as,
        both: "SELECT operation, result_json, result_gz, result_bytes, gcode IS NOT NULL OR gcode_gz IS NOT NULL,
                   gcode_problem
               FROM job_results WHERE job_id = $1 ORDER BY position",
        [id], fetch_all)?;
    Ok(rows
        .into_iter()
        .map(|(operation, json, compressed, length, gcode, gcode_problem)| ResultRow {
            operation,
            result: StoredText::from_columns(json, compressed, length).unwrap_or(StoredText::Plain(String::new())),
            gcode,
            gcode_problem,
        })
        .collect())
}

/// The bytes a finished job's results take uncompressed (what showing them holds in memory).
pub async fn results_length(db: &Db, id: i64) -> AppResult<i64> {
    let (length,): (i64,) = on!(db, query_as,
        sqlite: "SELECT COALESCE(SUM(result_bytes), 0) FROM job_results WHERE job_id = $1",
        postgres: "SELECT COALESCE(SUM(result_bytes), 0)::BIGINT FROM job_results WHERE job_id = $1",
        [id], fetch_one)?;
    Ok(length)
}

/// For each operation of a finished job, in order: whether it has a program, and why not.
pub async fn programs(db: &Db, id: i64) -> AppResult<Vec<(bool, Option<String>)>> {
    Ok(on!(db, query_as,
        both: "SELECT gcode IS NOT NULL OR gcode_gz IS NOT NULL, gcode_problem FROM job_results WHERE job_id = $1
               ORDER BY position",
        [id], fetch_all)?)
}

/// The program of operation `position` of a finished job, if it has one.
pub async fn program(db: &Db, id: i64, position: usize) -> AppResult<Option<StoredText>> {
    let row: Option<(Option<String>, Option<Vec<u8>>, i64)> = on!(db, query_as,
        both: "SELECT gcode, gcode_gz, gcode_bytes FROM job_results WHERE job_id = $1 AND position = $2",
        [id, bytes(position)], fetch_optional)?;
    Ok(row.and_then(|(text, compressed, length)| StoredText::from_columns(text, compressed, length)))
}

/// Jobs stored and the bytes they take (job files and compressed results).
pub async fn usage(db: &Db) -> AppResult<(i64, i64)> {
    Ok(on!(db, query_as,
        sqlite: "SELECT COUNT(*), COALESCE(SUM(stored_bytes), 0) FROM jobs",
        postgres: "SELECT COUNT(*), COALESCE(SUM(stored_bytes), 0)::BIGINT FROM jobs",
        [], fetch_one)?)
}

/// Finished jobs removed by [`prune`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Pruned {
    /// Their ids, ascending.
    pub ids: Vec<i64>,
    /// The bytes they took.
    pub bytes: i64,
}

/// Removes the finished jobs (done, failed, cancelled) that finished more than `older_than` ago,
/// with their results; queued and running jobs are never touched. SQLite then gives the freed
/// pages back to the file system (incremental vacuum, where the file has it) and truncates the
/// write-ahead log. `None` in PostgreSQL when another process is pruning right now.
pub async fn prune(db: &Db, older_than: Duration) -> AppResult<Option<Pruned>> {
    let mut rows: Vec<(i64, i64)> = match db {
        Db::Sqlite(pool) => {
            let rows = sqlx::query_as(
                "DELETE FROM jobs WHERE status IN ('done', 'failed', 'cancelled')
                     AND finished_at < strftime('%Y-%m-%dT%H:%M:%fZ', 'now', $1)
                 RETURNING id, stored_bytes",
            )
            .bind(format!("-{:.3} seconds", older_than.as_secs_f64()))
            .fetch_all(pool)
            .await?;
            if !rows.is_empty() {
                sqlx::query("PRAGMA incremental_vacuum").execute(pool).await?;
                sqlx::query("PRAGMA wal_checkpoint(TRUNCATE)").execute(pool).await?;
            }
            rows
        }
        Db::Postgres(pool) => {
            let mut transaction = pool.begin().await?;
            let (ours,): (bool,) = sqlx::query_as("SELECT pg_try_advisory_xact_lock($1)")
                .bind(PRUNE_LOCK)
                .fetch_one(&mut *transaction)
                .await?;
            if !ours {
                return Ok(None);
            }
            let rows = sqlx::query_as(
                "DELETE FROM jobs WHERE status IN ('done', 'failed', 'cancelled')
                     AND finished_at < now() - make_interval(secs => $1)
                 RETURNING id, stored_bytes",
            )
            .bind(older_than.as_secs_f64())
            .fetch_all(&mut *transaction)
            .await?;
            transaction.commit().await?;
            rows
        }
    };
    rows.sort_unstable();
    Ok(Some(Pruned {
        bytes: rows.iter().map(|(_, bytes)| bytes).sum(),
        ids: rows.into_iter().map(|(id, _)| id).collect(),
    }))
}

/// How an SQLite file gives freed space back: `true` when it has incremental vacuum (files
/// created since migration 0004), `false` for older files (freed pages are reused, the file does
/// not shrink until [`convert_to_incremental_vacuum`]). Always `true` in PostgreSQL.
pub async fn incremental_vacuum(db: &Db) -> AppResult<bool> {
    let Db::Sqlite(pool) = db else { return Ok(true) };
    let (mode,): (i64,) = sqlx::query_as("PRAGMA auto_vacuum").fetch_one(pool).await?;
    Ok(mode == 2)
}

/// Rewrites an SQLite file with incremental vacuum (one full `VACUUM`: it needs the file's size
/// again in free disk space and no other process using the file), giving all free pages back.
/// Nothing to do in PostgreSQL.
pub async fn convert_to_incremental_vacuum(db: &Db) -> AppResult<()> {
    let Db::Sqlite(pool) = db else { return Ok(()) };
    // The mode and the VACUUM that applies it must run on one connection.
    let mut connection = pool.acquire().await?;
    sqlx::query("PRAGMA auto_vacuum = INCREMENTAL").execute(&mut *connection).await?;
    sqlx::query("VACUUM").execute(&mut *connection).await?;
    sqlx::query("PRAGMA wal_checkpoint(TRUNCATE)").execute(&mut *connection).await?;
    Ok(())
}

/// At start-up of an SQLite service no job can be running: each one a stopped server left
/// `running` is queued again, or failed with the reason once it has used its attempts. Returns
/// (re-queued, failed). In PostgreSQL other processes may be running jobs right now: nothing is
/// touched, expired leases are claimed again instead ([`claim`]).
pub async fn recover(db: &Db) -> AppResult<(u64, u64)> {
    let Db::Sqlite(pool) = db else { return Ok((0, 0)) };
    let failed = sqlx::query(concat!(
        "UPDATE jobs SET status = 'failed', finished_at = ",
        now!(),
        ", error = $1
         WHERE status = 'running' AND attempts >= $2"
    ))
    .bind(problem_json(&job_problem(
        503,
        "Job interrupted",
        ErrorCode::Interrupted,
        &format!("interrupted by a server stop on each of its {MAX_ATTEMPTS} attempts; not retried"),
    ))?)
    .bind(MAX_ATTEMPTS)
    .execute(pool)
    .await?
    .rows_affected();
    let requeued = sqlx::query("UPDATE jobs SET status = 'queued', progress = 0 WHERE status = 'running'")
        .execute(pool)
        .await?
        .rows_affected();
    Ok((requeued, failed))
}

/// Hands the chunks `claimant` is running back to the queue (PostgreSQL, on a graceful stop of
/// its process), so another worker takes them at once instead of after the lease; the attempt
/// does not count. Returns how many. SQLite's [`recover`] does this at the next start.
pub async fn release(db: &Db, claimant: &Claimant) -> AppResult<u64> {
    let Db::Postgres(pool) = db else { return Ok(0) };
    let mut transaction = pool.begin().await?;
    let jobs: Vec<(i64,)> = sqlx::query_as(
        "UPDATE job_chunks SET status = 'queued', progress = 0, worker = NULL, lease_expires_at = NULL,
             attempts = GREATEST(attempts - 1, 0)
         WHERE status = 'running' AND worker = $1
         RETURNING job_id",
    )
    .bind(&claimant.worker)
    .fetch_all(&mut *transaction)
    .await?;
    let released = jobs.len() as u64;
    for (id,) in jobs {
        set_job_progress(&mut transaction, id).await?;
    }
    if released > 0 {
        sqlx::query("SELECT pg_notify($1, '')").bind(SUBMITTED_CHANNEL).execute(&mut *transaction).await?;
    }
    transaction.commit().await?;
    Ok(released)
}
