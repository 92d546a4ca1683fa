//! Splitting an operation's chunk into parts and a finish step (PostgreSQL), and reading the
//! parts' outputs back for the finish step.

use crate::store::CommitChecked;
use kerf_solver::capability::Split;

use super::{Claimant, Work, set_job_progress, wake_workers};
use crate::db::Db;
use crate::error::{AppError, AppResult};

/// Splits the operation chunk `work` that `claimant` runs into `split`'s parts (PostgreSQL): the
/// chunk becomes the first part, which the claimant goes on to solve, and the other parts and
/// the operation's finish step are queued (the finish step is claimable once every part is done;
/// [`claim`](super::claim())); each chunk weighs its share of the estimated work. Returns false
/// when the chunk is no longer the claimant's or its job no longer runs (nothing is written), and
/// always in SQLite, where one process runs the whole job.
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
    transaction.commit_checked().await?;
    Ok(true)
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
