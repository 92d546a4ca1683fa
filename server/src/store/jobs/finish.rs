//! Finishing work: storing an operation's results or a part's output, if they fit the job's cap
//! and the store's quota, and marking the work (and with its last chunk the job) done.

use crate::store::CommitChecked;
use kerf_solver::ErrorCode;

use super::{Claimant, JobStorage, QUOTA_LOCK, Task, Work, bytes, job_problem, mib, set_job_progress, wake_workers};
use crate::db::Db;
use crate::error::{AppError, AppResult, FieldProblem, Problem};
use crate::store::packed::Packed;

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
    let results = Results::new(work, task, outputs);
    match db {
        Db::Sqlite(pool) => finish_sqlite(pool, &results, storage).await,
        Db::Postgres(pool) => finish_postgres(pool, claimant, &results, storage).await,
    }
}

/// The results finished work brings: operations from `first` on, with each one's name and
/// compressed size, and their sum.
struct Results<'a> {
    work: Work,
    first: i64,
    outputs: &'a [Packed],
    sizes: Vec<(&'a str, i64)>,
    added: i64,
}

impl<'a> Results<'a> {
    fn new(work: Work, task: &Task, outputs: &'a [Packed]) -> Self {
        let sizes: Vec<(&str, i64)> =
            outputs.iter().map(|output| (output.operation.as_str(), bytes(output.stored_bytes()))).collect();
        let added = sizes.iter().map(|(_, size)| size).sum();
        Self { work, first: bytes(task.operation()), outputs, sizes, added }
    }
}

/// Inserts `$results`' rows into `job_results` and adds `$delta` to their job's stored bytes, in
/// `$transaction`. The statements are the same in both stores; a macro because their
/// transactions are different types.
macro_rules! insert_results {
    ($transaction:expr, $results:expr, $delta:expr) => {
        for (offset, output) in $results.outputs.iter().enumerate() {
            sqlx::query(
                "INSERT INTO job_results (job_id, position, operation, result_json, result_gz, result_bytes,
                     gcode_gz, gcode_bytes, gcode_problem)
                 VALUES ($1, $2, $3, '', $4, $5, $6, $7, $8)",
            )
            .bind($results.work.id)
            .bind($results.first + i64::try_from(offset).unwrap_or(i64::MAX))
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
            .bind($results.work.id)
            .execute(&mut *$transaction)
            .await?;
    };
}

/// [`finish`] in SQLite: the whole job is done at once.
async fn finish_sqlite(pool: &sqlx::SqlitePool, results: &Results<'_>, storage: &JobStorage) -> AppResult<Finished> {
    // The first statement writes, so the transaction holds the file's write lock from there on:
    // the quota check and the results it admits are one step.
    let mut transaction = pool.begin().await?;
    let job: Option<(i64,)> = sqlx::query_as(concat!(
        "UPDATE jobs SET status = 'done', progress = 1, finished_at = ",
        now!(),
        " WHERE id = $1 AND status = 'running' RETURNING stored_bytes"
    ))
    .bind(results.work.id)
    .fetch_optional(&mut *transaction)
    .await?;
    let Some((job_bytes,)) = job else {
        transaction.rollback().await?;
        return Ok(Finished::Gone);
    };
    let (total,): (i64,) =
        sqlx::query_as("SELECT COALESCE(SUM(stored_bytes), 0) FROM jobs").fetch_one(&mut *transaction).await?;
    if let Some(problem) = check_fit(job_bytes, total, &results.sizes, results.first, storage) {
        transaction.rollback().await?;
        return Ok(Finished::Refused(problem));
    }
    insert_results!(transaction, results, results.added);
    transaction.commit_checked().await?;
    Ok(Finished::Stored)
}

/// [`finish`] in PostgreSQL: one chunk is done, the job with its last one.
async fn finish_postgres(
    pool: &sqlx::PgPool,
    claimant: &Claimant,
    results: &Results<'_>,
    storage: &JobStorage,
) -> AppResult<Finished> {
    let Results { work, first, .. } = *results;
    let mut transaction = pool.begin().await?;
    // The job's row first: finishers of one job's chunks take turns, so the last one sees every
    // other chunk done.
    let Some(job_bytes) = finishing(&mut transaction, work, claimant).await? else {
        transaction.rollback().await?;
        return Ok(Finished::Gone);
    };
    // A finish step's parts are merged into its result: their outputs go.
    let parts = parts_bytes(&mut transaction, work.id, first).await?;
    let total = locked_total(&mut transaction).await?;
    if let Some(problem) = check_fit(job_bytes - parts, total - parts, &results.sizes, first, storage) {
        transaction.rollback().await?;
        return Ok(Finished::Refused(problem));
    }
    insert_results!(transaction, results, results.added - parts);
    sqlx::query("UPDATE job_chunks SET output_gz = NULL WHERE job_id = $1 AND operation = $2 AND kind = 'part'")
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
    transaction.commit_checked().await?;
    Ok(Finished::Stored)
}

/// The bytes the stored outputs of operation `operation`'s parts take (0 for an operation that
/// was not split).
async fn parts_bytes(
    transaction: &mut sqlx::Transaction<'_, sqlx::Postgres>,
    id: i64,
    operation: i64,
) -> AppResult<i64> {
    let (parts,): (i64,) = sqlx::query_as(
        "SELECT COALESCE(SUM(octet_length(output_gz)), 0)::BIGINT FROM job_chunks
         WHERE job_id = $1 AND operation = $2 AND kind = 'part'",
    )
    .bind(id)
    .bind(operation)
    .fetch_one(&mut **transaction)
    .await?;
    Ok(parts)
}

/// The bytes all jobs take, read under the quota lock (PostgreSQL), which `transaction` then
/// holds until it ends: no other process adds to the store between this check and its writes.
async fn locked_total(transaction: &mut sqlx::Transaction<'_, sqlx::Postgres>) -> AppResult<i64> {
    sqlx::query("SELECT pg_advisory_xact_lock($1)").bind(QUOTA_LOCK).execute(&mut **transaction).await?;
    let (total,): (i64,) =
        sqlx::query_as("SELECT COALESCE(SUM(stored_bytes), 0)::BIGINT FROM jobs").fetch_one(&mut **transaction).await?;
    Ok(total)
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
    let total = locked_total(&mut transaction).await?;
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
    transaction.commit_checked().await?;
    Ok(Finished::Stored)
}
