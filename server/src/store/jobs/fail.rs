//! Ending a job without results: failed by its worker or cancelled by request, with what its
//! chunks stored dropped in the same transaction.

use crate::store::CommitChecked;
use kerf_solver::ErrorCode;

use super::{CANCEL_CHANNEL, Claimant, JobStatus, Work, job_problem, problem_json};
use crate::db::Db;
use crate::error::{AppResult, Problem};
use crate::store::on;

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
            transaction.commit_checked().await?;
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
            transaction.commit_checked().await?;
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
            transaction.commit_checked().await?;
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

/// Removes an ended job (done, failed or cancelled) with its results and outputs (they go with
/// it: `ON DELETE CASCADE`); false when there is no such job or it has not ended (a queued or
/// running job is cancelled first, never removed under its worker).
pub async fn remove(db: &Db, id: i64) -> AppResult<bool> {
    let removed = on!(db, query,
        both: "DELETE FROM jobs WHERE id = $1 AND status IN ('done', 'failed', 'cancelled')",
        [id], execute)?;
    Ok(removed > 0)
}
