//! The job workers: a bounded pool of tasks that claim jobs from the store, run them on the
//! blocking pool under the shared solver bound, record progress and heartbeat, and store the
//! results; plus cancellation of running jobs and recovery after a stop.
//!
//! The same workers run inside `kerf serve` (SQLite or PostgreSQL) and in `kerf worker`
//! processes (PostgreSQL). With PostgreSQL a listener wakes idle workers on `NOTIFY kerf_jobs`
//! and stops a cancelled job on `NOTIFY kerf_cancel`, whichever process cancelled it; polling
//! every [`IDLE_POLL`] is only the fallback (a lost notification, a lease that expired). A
//! heartbeat that finds the job no longer the worker's (cancelled, or re-claimed after its lease
//! expired) stops it too.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use kerf_solver::ErrorCode;
use sqlx::PgPool;
use sqlx::postgres::PgListener;
use tokio::sync::{Notify, Semaphore};

use super::execute::{JobFailure, execute, execute_finish, execute_operation, execute_part, plan};
use super::file::JobFile;
use crate::db::Db;
use crate::error::{AppError, AppResult, Problem};
use crate::store;
use crate::store::jobs::{
    CANCEL_CHANNEL, Claimant, Claimed, Finished, JobStorage, PartOutput, SUBMITTED_CHANNEL, Task, Work,
};
use crate::store::packed::{Packed, gzip};

/// How often a running job's progress and heartbeat are written.
const HEARTBEAT: Duration = Duration::from_millis(250);
/// How often idle workers look for work without being woken.
pub const IDLE_POLL: Duration = Duration::from_secs(2);
/// How long a claimed job stays a worker's without a heartbeat (PostgreSQL), by default.
pub const DEFAULT_LEASE: Duration = Duration::from_secs(15);

/// Coordination between the HTTP handlers, the listener and the workers of one process.
#[derive(Debug)]
pub struct JobRunner {
    /// Wakes idle workers when a job is submitted.
    pub submitted: Notify,
    cancel_flags: Mutex<HashMap<Work, Arc<AtomicBool>>>,
    claimant: Claimant,
    /// The bounds of the job store: submissions and finished work are checked against them.
    pub storage: JobStorage,
    /// Bytes one operation's answer may take while it is built (`Limits::answer_budget_bytes`).
    pub answer_limit: u64,
}

impl Default for JobRunner {
    fn default() -> Self {
        Self::new(DEFAULT_LEASE, JobStorage::default())
    }
}

/// A name for this process among all that share the database: host, process id and start time.
fn worker_name() -> String {
    let host = std::env::var("HOSTNAME")
        .ok()
        .or_else(|| std::fs::read_to_string("/etc/hostname").ok())
        .map(|h| h.trim().to_owned())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "kerf".to_owned());
    let started = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
    format!("{host}:{}:{}", std::process::id(), started.as_millis())
}

impl JobRunner {
    /// A runner whose claims hold for `lease` without a heartbeat, storing results within
    /// `storage`; its answers are unbounded until [`Self::with_answer_limit`] sets the budget.
    pub fn new(lease: Duration, storage: JobStorage) -> Self {
        Self {
            submitted: Notify::new(),
            cancel_flags: Mutex::default(),
            claimant: Claimant { worker: worker_name(), lease: lease.max(Duration::from_secs(1)) },
            storage,
            answer_limit: u64::MAX,
        }
    }

    /// The same runner, building each operation's answer within `bytes`.
    #[must_use]
    pub fn with_answer_limit(self, bytes: usize) -> Self {
        Self { answer_limit: u64::try_from(bytes).unwrap_or(u64::MAX), ..self }
    }

    /// The name this process's workers write on the jobs they run.
    pub fn worker(&self) -> &str {
        &self.claimant.worker
    }

    /// Tells the workers running job `id` (or chunks of it) in this process, if any, to stop.
    pub fn cancel(&self, id: i64) {
        for (work, flag) in self.flags().iter() {
            if work.id == id {
                flag.store(true, Ordering::Relaxed);
            }
        }
    }

    fn flags(&self) -> std::sync::MutexGuard<'_, HashMap<Work, Arc<AtomicBool>>> {
        self.cancel_flags.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Hands the jobs this process is running back to the queue (PostgreSQL; on a graceful stop).
    pub async fn release(&self, db: &Db) {
        for flag in self.flags().values() {
            flag.store(true, Ordering::Relaxed);
        }
        match store::jobs::release(db, &self.claimant).await {
            Ok(0) => {}
            Ok(released) => tracing::info!(released, "running jobs handed back to the queue"),
            Err(error) => tracing::warn!(%error, "handing running jobs back failed; their leases will expire"),
        }
    }

    /// Re-queues or fails the jobs a stopped server left running (SQLite), then starts `workers`
    /// workers, and with PostgreSQL the listener that wakes them. `workers` may be 0: an API node
    /// that runs no jobs itself.
    ///
    /// # Errors
    /// When the recovery update fails.
    /// On a full disk (or a database out of reach) the recovery cannot write: the service starts
    /// all the same (reads work, writes answer 507 or 503), and the recovery is tried again until
    /// it succeeds, with the workers started only then (until then no job may be claimed: the
    /// recovery would queue it again under its worker).
    pub async fn start(self: &Arc<Self>, db: &Db, slots: &Arc<Semaphore>, workers: usize) -> anyhow::Result<()> {
        super::pruner::start_pruner(db.clone(), self.storage);
        match recover(db).await {
            Ok(()) => self.start_workers(db, slots, workers),
            Err(error) if error.is_transient() => {
                tracing::warn!(%error, "recovering interrupted jobs failed; the job workers start once it succeeds");
                let (runner, db, slots) = (Arc::clone(self), db.clone(), Arc::clone(slots));
                tokio::spawn(async move {
                    loop {
                        tokio::time::sleep(IDLE_POLL).await;
                        match recover(&db).await {
                            Ok(()) => break,
                            Err(error) if error.is_transient() => {}
                            Err(error) => tracing::error!(%error, "recovering interrupted jobs failed"),
                        }
                    }
                    runner.start_workers(&db, &slots, workers);
                });
            }
            Err(error) => return Err(anyhow::anyhow!("{error}")),
        }
        Ok(())
    }

    fn start_workers(self: &Arc<Self>, db: &Db, slots: &Arc<Semaphore>, workers: usize) {
        if workers == 0 {
            if !db.is_postgres() {
                tracing::warn!("no job workers: submitted jobs wait until a server with workers starts");
            }
            return;
        }
        if let Db::Postgres(pool) = db {
            tokio::spawn(listen(Arc::clone(self), pool.clone()));
        }
        for _ in 0..workers {
            tokio::spawn(work(Arc::clone(self), db.clone(), Arc::clone(slots)));
        }
        tracing::info!(workers, worker = %self.claimant.worker, "job workers started");
    }
}

/// Re-queues or fails the jobs a stopped server left running (SQLite; see
/// [`store::jobs::recover`]).
async fn recover(db: &Db) -> AppResult<()> {
    let (requeued, failed) = store::jobs::recover(db).await?;
    if requeued + failed > 0 {
        tracing::warn!(requeued, failed, "jobs interrupted by the last stop");
    }
    Ok(())
}

/// Wakes idle workers on `kerf_jobs` and stops cancelled jobs on `kerf_cancel`; reconnects
/// after a lost connection (the workers poll meanwhile).
async fn listen(runner: Arc<JobRunner>, pool: PgPool) {
    loop {
        let mut listener = match PgListener::connect_with(&pool).await {
            Ok(listener) => listener,
            Err(error) => {
                tracing::warn!(%error, "LISTEN connection failed; polling until it is back");
                tokio::time::sleep(IDLE_POLL).await;
                continue;
            }
        };
        if let Err(error) = listener.listen_all([SUBMITTED_CHANNEL, CANCEL_CHANNEL]).await {
            tracing::warn!(%error, "LISTEN failed; polling until it works");
            tokio::time::sleep(IDLE_POLL).await;
            continue;
        }
        loop {
            match listener.recv().await {
                Ok(notification) if notification.channel() == CANCEL_CHANNEL => {
                    if let Ok(id) = notification.payload().parse() {
                        runner.cancel(id);
                    }
                }
                Ok(_) => runner.submitted.notify_one(),
                Err(error) => {
                    tracing::warn!(%error, "LISTEN connection lost; reconnecting");
                    // Anything submitted meanwhile is found by the next claim.
                    runner.submitted.notify_waiters();
                    break;
                }
            }
        }
    }
}

async fn work(runner: Arc<JobRunner>, db: Db, slots: Arc<Semaphore>) {
    loop {
        match claim(&db, &runner.claimant).await {
            Ok(Some((claimed, job))) => {
                crate::metrics::chunk_claimed();
                run(&runner, &db, &slots, claimed, job).await;
            }
            Ok(None) => {
                let _ = tokio::time::timeout(IDLE_POLL, runner.submitted.notified()).await;
            }
            Err(error) if error.is_transient() => {
                tracing::warn!(%error, "claiming a job failed; trying again");
                tokio::time::sleep(IDLE_POLL).await;
            }
            Err(error) => {
                tracing::error!(%error, "claiming a job failed");
                tokio::time::sleep(IDLE_POLL).await;
            }
        }
    }
}

/// Claims the next work for `claimant` ([`store::jobs::claim`]) with its job file read. A job
/// whose stored file cannot be read is failed with `E_JOB_FILE`, and there is nothing to run.
async fn claim(db: &Db, claimant: &Claimant) -> AppResult<Option<(Claimed, JobFile)>> {
    let Some(mut claimed) = store::jobs::claim(db, claimant).await? else { return Ok(None) };
    // Taken out, so a long run does not hold the file's text besides the file.
    match serde_json::from_str(&std::mem::take(&mut claimed.job_json)) {
        Ok(job) => Ok(Some((claimed, job))),
        Err(error) => {
            let problem = Problem {
                kind: "about:blank".to_owned(),
                title: "Job failed".to_owned(),
                status: 422,
                detail: format!("the stored job is unreadable: {error}"),
                code: ErrorCode::JobFile,
                errors: Vec::new(),
            };
            store::jobs::fail(db, claimed.work, claimant, &problem).await?;
            Ok(None)
        }
    }
}

/// What a chunk computed: an operation's (or a whole job's) results, or a part's output.
enum Output {
    Results(Vec<Packed>),
    Part(PartOutput),
}

async fn run(
    runner: &JobRunner,
    db: &Db,
    slots: &Arc<Semaphore>,
    Claimed { work, task, attempt, .. }: Claimed,
    job: JobFile,
) {
    let claimant = &runner.claimant;
    let id = work.id;
    tracing::info!(id, chunk = ?work.chunk, ?task, attempt, worker = %claimant.worker, "claimed");
    let cancelled = Arc::new(AtomicBool::new(false));
    runner.flags().insert(work, Arc::clone(&cancelled));
    let progress = Arc::new(AtomicU64::new(0));
    let beat = Beat { db, work, claimant, progress: &progress, cancelled: &cancelled };
    let Ok(permit) = Arc::clone(slots).acquire_owned().await else { return };
    let job = Arc::new(job);
    let Some(task) = divide(&beat, &job, task).await else {
        runner.flags().remove(&work);
        return;
    };
    let parts = match &task {
        Task::Finish { operation } => match store::jobs::part_outputs(db, id, *operation).await {
            Ok(parts) => parts,
            Err(error) => {
                tracing::error!(id, %error, "reading the parts' outputs failed");
                runner.flags().remove(&work);
                if let Err(error) = store::jobs::fail(db, work, claimant, &error.problem()).await {
                    tracing::error!(id, %error, "storing the job outcome failed");
                }
                return;
            }
        },
        _ => Vec::new(),
    };
    let (task_progress, task_cancelled, computed) = (Arc::clone(&progress), Arc::clone(&cancelled), task.clone());
    let answer_limit = runner.answer_limit;
    let computing = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        let report = |fraction: f64| task_progress.store(fraction.to_bits(), Ordering::Relaxed);
        let packed = |outputs: Vec<crate::capabilities::Stored>| {
            // Compressed here, on the blocking thread and in the solver slot, not on the async
            // threads.
            Output::Results(
                outputs
                    .iter()
                    .map(|stored| {
                        Packed::new(
                            &stored.operation,
                            stored.result.get(),
                            stored.gcode.as_deref(),
                            stored.gcode_problem.as_deref(),
                        )
                    })
                    .collect(),
            )
        };
        Ok::<_, JobFailure>(match computed {
            Task::Job => packed(execute(&job, &report, &task_cancelled, answer_limit)?),
            Task::Operation(index) => {
                packed(vec![execute_operation(&job, index, &report, &task_cancelled, answer_limit)?])
            }
            Task::Part { operation, part } => {
                let output = execute_part(&job, operation, &part, &report, &task_cancelled, answer_limit)?;
                Output::Part(PartOutput {
                    operation: job.operations[operation].name().to_owned(),
                    gz: gzip(&output.bytes),
                    bytes: output.bytes.len(),
                    seconds: output.seconds,
                })
            }
            Task::Finish { operation } => {
                let seconds = parts.iter().map(|(_, seconds)| seconds).sum();
                let parts = parts.into_iter().map(|(output, _)| output).collect();
                packed(vec![execute_finish(&job, operation, parts, seconds, &report, &task_cancelled, answer_limit)?])
            }
        })
    });
    let outcome = beat.during(computing).await;
    runner.flags().remove(&work);
    let fail = |problem: Problem| async move {
        kept(db, work, claimant, "failure", || store::jobs::fail(db, work, claimant, &problem)).await
    };
    let stored = match outcome {
        Ok(Ok(output)) => match finish(db, work, &task, claimant, &output, &runner.storage).await {
            Ok(Finished::Refused(problem)) => {
                tracing::warn!(id, code = %problem.code.as_str(), "{}", problem.detail);
                fail(problem).await
            }
            other => other.map(drop),
        },
        Ok(Err(JobFailure::Cancelled)) => Ok(()),
        Ok(Err(JobFailure::Refused(problem))) => fail(*problem).await,
        Err(join_error) => {
            tracing::error!(id, %join_error, "job task failed");
            let internal = AppError::Internal(anyhow::anyhow!("the job's task failed"));
            fail(internal.problem()).await
        }
    };
    if let Err(error) = stored {
        tracing::error!(id, %error, "storing the job outcome failed");
    }
}

/// How often an outcome that could not be stored is tried again.
const STORE_RETRY: Duration = Duration::from_millis(500);

/// Runs `store`, a write of finished work's outcome, until it holds. A failure that may pass by
/// itself (the database out of reach, a full disk: [`AppError::is_transient`]) is tried again
/// every [`STORE_RETRY`], the outcome kept in memory meanwhile: in PostgreSQL for as long as the
/// chunk's lease (after it another worker may have claimed the chunk again, and a late write
/// finds it no longer ours), in SQLite until it holds (no other process can take the job; a
/// stop queues it again at the next start). Any other failure is tried once more (two
/// finishers of one job's chunks can meet in a deadlock that PostgreSQL breaks by failing one).
async fn kept<T, Store, Stored>(db: &Db, work: Work, claimant: &Claimant, what: &str, store: Store) -> AppResult<T>
where
    Store: Fn() -> Stored,
    Stored: std::future::Future<Output = AppResult<T>>,
{
    let deadline = db.is_postgres().then(|| std::time::Instant::now() + claimant.lease);
    let mut tried_again = false;
    let mut kept_since: Option<std::time::Instant> = None;
    loop {
        match store().await {
            Ok(stored) => {
                if let Some(since) = kept_since {
                    let waited = since.elapsed().as_secs_f64();
                    tracing::info!(id = work.id, waited, "the kept {what} is stored");
                }
                return Ok(stored);
            }
            Err(error)
                if error.is_transient() && deadline.is_none_or(|deadline| std::time::Instant::now() < deadline) =>
            {
                if kept_since.is_none() {
                    tracing::warn!(id = work.id, %error, "storing the {what} failed; kept, trying again");
                    kept_since = Some(std::time::Instant::now());
                }
                tokio::time::sleep(STORE_RETRY).await;
            }
            Err(error) if !error.is_transient() && !tried_again => {
                tracing::warn!(id = work.id, %error, "storing the {what} failed; once more");
                tried_again = true;
            }
            Err(error) => return Err(error),
        }
    }
}

/// The heartbeat of one claimed chunk.
struct Beat<'a> {
    db: &'a Db,
    work: Work,
    claimant: &'a Claimant,
    progress: &'a AtomicU64,
    cancelled: &'a AtomicBool,
}

impl Beat<'_> {
    /// Awaits `task`, writing the chunk's progress and heartbeat every [`HEARTBEAT`] meanwhile; a
    /// heartbeat that finds the chunk no longer ours (cancelled, or claimed again after our lease
    /// expired) sets the cancel flag, which stops the computation.
    async fn during<T>(&self, mut task: tokio::task::JoinHandle<T>) -> Result<T, tokio::task::JoinError> {
        let mut ticker = tokio::time::interval(HEARTBEAT);
        loop {
            tokio::select! {
                outcome = &mut task => return outcome,
                _ = ticker.tick() => {
                    let fraction = f64::from_bits(self.progress.load(Ordering::Relaxed));
                    match store::jobs::heartbeat(self.db, self.work, self.claimant, fraction).await {
                        Ok(true) => {}
                        // Cancelled, or no longer ours: stop computing.
                        Ok(false) => self.cancelled.store(true, Ordering::Relaxed),
                        Err(error) => tracing::warn!(id = self.work.id, %error, "recording progress failed"),
                    }
                }
            }
        }
    }
}

/// A whole operation's chunk (PostgreSQL) whose work divides is split first ([`plan`],
/// [`store::jobs::split`]): the chunk becomes the first part, which this worker then solves,
/// while other workers claim the other parts. Other tasks run as claimed. `None` when the chunk
/// is no longer ours.
async fn divide(beat: &Beat<'_>, job: &Arc<JobFile>, task: Task) -> Option<Task> {
    let Task::Operation(index) = task else { return Some(task) };
    if !beat.db.is_postgres() {
        return Some(task);
    }
    let planned = {
        let job = Arc::clone(job);
        beat.during(tokio::task::spawn_blocking(move || plan(&job, index))).await
    };
    let split = match planned {
        Ok(Some(split)) if !beat.cancelled.load(Ordering::Relaxed) => split,
        Ok(_) => return Some(task),
        Err(error) => {
            tracing::error!(id = beat.work.id, %error, "splitting the operation failed; solving it whole");
            return Some(task);
        }
    };
    match store::jobs::split(beat.db, beat.work, beat.claimant, &split).await {
        Ok(true) => {
            tracing::info!(id = beat.work.id, operation = index, parts = split.parts.len(), "split");
            let part = split.parts.into_iter().next()?;
            Some(Task::Part { operation: index, part })
        }
        Ok(false) => None,
        Err(error) => {
            tracing::warn!(id = beat.work.id, %error, "storing the split failed; solving the operation whole");
            Some(task)
        }
    }
}

/// Stores finished work ([`kept`]: kept and tried again while the store cannot take it). Work
/// that cannot be stored in the end is not lost: its chunk's lease expires and another worker
/// runs it again.
async fn finish(
    db: &Db,
    work: Work,
    task: &Task,
    claimant: &Claimant,
    output: &Output,
    storage: &JobStorage,
) -> AppResult<Finished> {
    kept(db, work, claimant, "result", || async {
        match output {
            Output::Part(part) => store::jobs::finish_part(db, work, task.operation(), claimant, part, storage).await,
            Output::Results(outputs) => store::jobs::finish(db, work, task, claimant, outputs, storage).await,
        }
    })
    .await
}
