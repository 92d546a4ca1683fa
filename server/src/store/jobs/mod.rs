//! The job queue: jobs with status, progress, attempts and heartbeat, and
//! their results.
//!
//! In SQLite one process owns the queue: its workers claim the oldest queued job with one atomic
//! UPDATE, and at start every job left `running` is queued again ([`recover()`]). In PostgreSQL any
//! number of processes share it, and a job is split into chunks (one per operation, and an
//! operation whose work divides into parts and a finish step: [`split()`]) that different workers
//! run at once: a worker claims a chunk in a short transaction with `SELECT … FOR UPDATE SKIP
//! LOCKED` (concurrent claimers skip each other's rows instead of waiting), writes its name and a
//! lease on the chunk, and pushes the lease forward with each heartbeat; a running chunk whose
//! lease expired (its worker died, `kill -9`) is claimed again like a queued one. A part stores its
//! output on its chunk; a whole operation or a finish step stores the operation's result; the last
//! chunk marks the job done.
//! Submissions and cancellations `NOTIFY` the workers (`kerf_jobs`, `kerf_cancel`); every write
//! of a running chunk checks that it is still the writer's and its job still running.
//!
//! One module per step of a job's life (submit, claim, split, heartbeat, finish, fail), plus
//! reading jobs and results back, pruning, and the store's bounds. They are private and their
//! items re-exported here, so each has the one path `store::jobs::…` whichever file holds it.

use kerf_solver::ErrorCode;
use kerf_solver::capability::Part;
use std::time::Duration;

use crate::error::{AppError, AppResult, Problem};

/// SQLite's current UTC time as stored (a macro, so every statement stays a static string).
/// Defined before the `mod` lines below: a `macro_rules!` macro is visible only after it.
macro_rules! now {
    () => {
        "strftime('%Y-%m-%dT%H:%M:%fZ', 'now')"
    };
}

/// Attempts a job gets: one retry after a server stop interrupted it.
pub const MAX_ATTEMPTS: i64 = 2;

/// The channel a submission notifies (payload: the job id).
pub const SUBMITTED_CHANNEL: &str = "kerf_jobs";

/// The channel a cancellation notifies (payload: the job id).
pub const CANCEL_CHANNEL: &str = "kerf_cancel";

/// PostgreSQL advisory lock held while a process checks the quota and adds to the store (so two
/// processes cannot both fit into the last free bytes).
const QUOTA_LOCK: i64 = 0x6b65_7266_0001;

/// PostgreSQL advisory lock of the process pruning old jobs (the others skip their turn).
const PRUNE_LOCK: i64 = 0x6b65_7266_0002;

mod claim;
mod fail;
mod finish;
mod heartbeat;
mod prune;
mod records;
mod results;
mod split;
mod storage;
mod submit;

pub use claim::{Claimed, claim, recover, release};
pub use fail::{cancel, fail, remove};
pub use finish::{Finished, PartOutput, finish, finish_part};
pub use heartbeat::heartbeat;
pub use prune::{Pruned, convert_to_incremental_vacuum, incremental_vacuum, prune};
pub use records::{JobRecord, JobStatus, get, list};
pub use results::{ResultRow, program, programs, results, results_length};
pub use split::{part_outputs, split};
pub use storage::{JobStorage, MIB, days, mib, usage};
pub use submit::{Submission, find_done, insert};

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

/// Wakes idle workers (`LISTEN/NOTIFY`) when `transaction` commits: job `id` has work to claim.
async fn wake_workers(transaction: &mut sqlx::Transaction<'_, sqlx::Postgres>, id: i64) -> AppResult<()> {
    sqlx::query("SELECT pg_notify($1, $2)")
        .bind(SUBMITTED_CHANNEL)
        .bind(id.to_string())
        .execute(&mut **transaction)
        .await?;
    Ok(())
}

/// Bytes as the stores count them.
fn bytes(count: usize) -> i64 {
    i64::try_from(count).unwrap_or(i64::MAX)
}
