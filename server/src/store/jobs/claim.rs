//! Claiming work: the next queued job (SQLite) or chunk (PostgreSQL) for a worker, and handing
//! back what a stopped server or worker held.

use crate::store::CommitChecked;
use kerf_solver::ErrorCode;
use kerf_solver::capability::Part;

use super::{Claimant, MAX_ATTEMPTS, SUBMITTED_CHANNEL, Task, Work, job_problem, problem_json, set_job_progress};
use crate::db::Db;
use crate::error::{AppError, AppResult};

/// Work a worker claimed.
#[derive(Debug)]
pub struct Claimed {
    /// The job, and the chunk of it.
    pub work: Work,
    /// What the chunk computes.
    pub task: Task,
    /// The resolved job's file, as stored (JSON); the worker reads it, and fails the job when it
    /// cannot (the store does not know the job file's type).
    pub job_json: String,
    /// Which attempt this is (1 for the first).
    pub attempt: i64,
}

/// Claims the next work for `claimant`. SQLite: the oldest queued job, marked running.
/// PostgreSQL: the first queued chunk of the oldest job still to run (or a running chunk whose
/// lease expired; a finish step only once its operation's parts are all done), marked running
/// with the claimant's name and lease; its job is marked running too. A chunk whose lease
/// expired after its last attempt fails its job with `E_INTERRUPTED`.
pub async fn claim(db: &Db, claimant: &Claimant) -> AppResult<Option<Claimed>> {
    let (work, task, json, attempt) = match db {
        Db::Sqlite(pool) => {
            // Driven to its end (`fetch_all`): the claim holds only once its implicit commit did.
            let rows: Vec<(i64, String, i64)> = sqlx::query_as(concat!(
                "UPDATE jobs SET status = 'running', attempts = attempts + 1, progress = 0, started_at = ",
                now!(),
                ", heartbeat_at = ",
                now!(),
                " WHERE id = (SELECT id FROM jobs WHERE status = 'queued' ORDER BY id LIMIT 1)
                 RETURNING id, job_json, attempts"
            ))
            .fetch_all(pool)
            .await?;
            let Some((id, json, attempt)) = rows.into_iter().next() else { return Ok(None) };
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
    Ok(Some(Claimed { work, task, job_json: json, attempt }))
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
        &format!(
            "no word from its worker within the lease (the worker stopped, or could not reach the database) on each \
             of its {MAX_ATTEMPTS} attempts; not retried"
        ),
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
        transaction.commit_checked().await?;
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
    transaction.commit_checked().await?;
    Ok(Chunk::Claimed(Work { id, chunk: Some(index(position)?) }, task, json, attempt))
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
    transaction.commit_checked().await?;
    Ok(released)
}
