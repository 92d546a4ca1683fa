//! Submitting a job: storing it queued (within the quota), or finding a finished one with the
//! same content to answer instead.

use crate::store::CommitChecked;
use serde::Serialize;

use super::{QUOTA_LOCK, bytes, mib, usage, wake_workers};
use crate::db::Db;
use crate::error::{AppError, AppResult};
use crate::store::on;

/// What the store keeps of a submitted job besides its file (stored as JSON): the name shown in
/// lists and the operations' names. A trait so the store need not know the job file's type,
/// which lives above it (the `jobs` module's `JobFile`).
pub trait Submission: Serialize {
    /// The job's name, if it has one.
    fn job_name(&self) -> Option<&str>;
    /// The operations' names, in order.
    fn operation_names(&self) -> Vec<&str>;
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
pub async fn insert(db: &Db, job: &impl Submission, hash: &str, quota: u64) -> AppResult<i64> {
    let json = serde_json::to_string(job).map_err(|e| AppError::Internal(e.into()))?;
    let operations = job.operation_names();
    let count = i64::try_from(operations.len()).unwrap_or(i64::MAX);
    let operations = serde_json::to_string(&operations).map_err(|e| AppError::Internal(e.into()))?;
    let (size, quota) = (bytes(json.len()), i64::try_from(quota).unwrap_or(i64::MAX));
    const INSERT: &str = "INSERT INTO jobs (name, status, content_hash, job_json, operations, stored_bytes)
         SELECT $1, 'queued', $2, $3, $4, CAST($5 AS BIGINT)
         WHERE (SELECT COALESCE(SUM(stored_bytes), 0) FROM jobs) + CAST($5 AS BIGINT) <= CAST($6 AS BIGINT)
         RETURNING id";
    match db {
        Db::Sqlite(pool) => {
            // Driven to its end (`fetch_all`): the implicit commit, which a full disk fails,
            // happens there, and only then is the job stored.
            let rows: Vec<(i64,)> = sqlx::query_as(INSERT)
                .bind(job.job_name())
                .bind(hash)
                .bind(json)
                .bind(operations)
                .bind(size)
                .bind(quota)
                .fetch_all(pool)
                .await?;
            match rows.into_iter().next() {
                Some((id,)) => Ok(id),
                None => Err(store_full(db, size, quota).await?),
            }
        }
        Db::Postgres(pool) => {
            // The notification is delivered at commit, when the chunks are there to claim.
            let mut transaction = pool.begin().await?;
            sqlx::query("SELECT pg_advisory_xact_lock($1)").bind(QUOTA_LOCK).execute(&mut *transaction).await?;
            let row: Option<(i64,)> = sqlx::query_as(INSERT)
                .bind(job.job_name())
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
            transaction.commit_checked().await?;
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
