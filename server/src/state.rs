//! Shared state of the running service: the database pool, the configured limits and the bound
//! on concurrent solver work.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError, Weak};
use std::time::Duration;

use tokio::sync::Semaphore;

use crate::answer_cache::AnswerCache;
use crate::auth::Auth;
use crate::db::Db;
use crate::error::{AppError, AppResult};
use crate::jobs::queue::JobRunner;
use crate::store::jobs::JobStorage;

/// Limits that protect the service from large or slow requests.
#[derive(Debug, Clone)]
pub struct Limits {
    /// Largest accepted request body, bytes.
    pub max_body_bytes: usize,
    /// Largest body of the routes that take file uploads (`POST /api/v1/predict` with its STL
    /// stock or a long G-code program), bytes.
    pub max_upload_bytes: usize,
    /// Longest a synchronous solver call may run before the client is told to submit a job.
    pub solver_time_limit: Duration,
    /// How long a request waits for a free solver slot before it gets 429.
    pub solver_queue_wait: Duration,
    /// Longest a client may take to send a request's headers; then the connection is closed.
    pub header_read_timeout: Duration,
    /// Longest a request body may stall between two pieces; then the request ends with 408.
    pub body_idle_timeout: Duration,
    /// Slowest a request body may arrive, bytes per second averaged over `body_rate_window`;
    /// slower, the request ends with 408. 0: no minimum.
    pub min_body_rate: usize,
    /// The window `min_body_rate` is averaged over.
    pub body_rate_window: Duration,
    /// Bytes of solver answers (JSON or G-code) held at once while their clients read them, and of
    /// predict uploads as they arrive; what does not fit gets 429, so slow readers of large
    /// answers or many large uploads cannot exhaust memory. It is also the most one answer (or a
    /// job's operation) may take while it is built: a larger one is refused with
    /// `E_TOO_LARGE_ANSWER`.
    pub answer_budget_bytes: usize,
    /// Bytes of solver answers kept to answer the same question again without solving
    /// ([`crate::answer_cache`]); 0 keeps none.
    pub answer_cache_bytes: usize,
    /// After a stop signal, how long open connections may finish before they are dropped (the
    /// jobs still running are re-queued at the next start, as after a kill).
    pub shutdown_grace: Duration,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_body_bytes: 8 * 1024 * 1024,
            max_upload_bytes: 128 * 1024 * 1024,
            solver_time_limit: Duration::from_secs(30),
            solver_queue_wait: Duration::from_secs(5),
            answer_budget_bytes: 512 * 1024 * 1024,
            answer_cache_bytes: 64 * 1024 * 1024,
            header_read_timeout: Duration::from_secs(10),
            body_idle_timeout: Duration::from_secs(30),
            min_body_rate: 1024,
            body_rate_window: Duration::from_secs(10),
            shutdown_grace: Duration::from_secs(30),
        }
    }
}

/// The store, for handlers that need nothing else (`/metrics`, `/readyz`).
impl axum::extract::FromRef<AppState> for Db {
    fn from_ref(state: &AppState) -> Self {
        state.db.clone()
    }
}

/// Everything a handler needs; cheap to clone.
#[derive(Debug, Clone)]
pub struct AppState {
    /// The store (SQLite or PostgreSQL).
    pub db: Db,
    /// Request limits.
    pub limits: Limits,
    /// Permits for solver work running at once (bounds CPU and memory under a burst); shared
    /// by synchronous requests and job workers.
    pub solver_slots: Arc<Semaphore>,
    /// The job workers' coordination.
    pub jobs: Arc<JobRunner>,
    /// The optional API token.
    pub auth: Auth,
    /// [`Limits::answer_budget_bytes`] in KiB permits.
    pub answer_budget: Arc<Semaphore>,
    /// Answers kept for questions asked again.
    pub answers: Arc<AnswerCache>,
    /// The cancel flags of the solver work running for requests, raised at once on a stop.
    pub solving: Arc<Solving>,
}

/// The cancel flags of the solver work running for synchronous requests, so that a stopping
/// service ends them all within milliseconds instead of waiting for them (the blocking threads
/// they run on would keep the process alive past its shutdown deadline).
#[derive(Debug, Default)]
pub struct Solving {
    stopping: AtomicBool,
    flags: Mutex<Vec<Weak<AtomicBool>>>,
}

impl Solving {
    /// Keeps `flag` to raise on a stop; raises it at once when the service is stopping already.
    fn register(&self, flag: &Arc<AtomicBool>) {
        let mut flags = self.flags.lock().unwrap_or_else(PoisonError::into_inner);
        flags.retain(|kept| kept.strong_count() > 0);
        flags.push(Arc::downgrade(flag));
        drop(flags);
        if self.stopping.load(Ordering::SeqCst) {
            flag.store(true, Ordering::Relaxed);
        }
    }

    /// Raises the cancel flag of all solver work running for requests, and of any started later.
    pub fn stop(&self) {
        self.stopping.store(true, Ordering::SeqCst);
        let flags = self.flags.lock().unwrap_or_else(PoisonError::into_inner);
        for flag in flags.iter().filter_map(Weak::upgrade) {
            flag.store(true, Ordering::Relaxed);
        }
    }
}

impl AppState {
    /// State over `db` with `limits`, allowing `solver_slots` solver calls at once, guarded by
    /// `auth`, with job leases of `lease` (PostgreSQL) and the job store bounded by `storage`.
    pub fn new(db: Db, limits: Limits, solver_slots: usize, auth: Auth, lease: Duration, storage: JobStorage) -> Self {
        Self {
            answer_budget: Arc::new(Semaphore::new(
                limits.answer_budget_bytes.div_ceil(1024).clamp(1, Semaphore::MAX_PERMITS),
            )),
            answers: Arc::new(AnswerCache::new(limits.answer_cache_bytes)),
            jobs: Arc::new(JobRunner::new(lease, storage).with_answer_limit(limits.answer_budget_bytes)),
            db,
            limits,
            solver_slots: Arc::new(Semaphore::new(solver_slots.max(1))),
            auth,
            solving: Arc::new(Solving::default()),
        }
    }

    /// Runs pure solver work on the blocking pool, never on an async worker thread, under the
    /// concurrency bound and the synchronous time limit. `work` gets a cancel flag that is set
    /// when the limit passes, the client goes away (this future is dropped) or the service stops
    /// ([`Solving::stop`]); the solvers and program writers check it per unit of work, so the
    /// slot is free again within milliseconds.
    pub async fn solve<T, F>(&self, work: F) -> AppResult<T>
    where
        F: FnOnce(&AtomicBool) -> T + Send + 'static,
        T: Send + 'static,
    {
        let permit =
            tokio::time::timeout(self.limits.solver_queue_wait, Arc::clone(&self.solver_slots).acquire_owned())
                .await
                .map_err(|_| AppError::TooManyRequests("all solver slots are busy; retry shortly".to_owned()))?
                .map_err(|error| AppError::Internal(error.into()))?;
        let cancel = Arc::new(AtomicBool::new(false));
        self.solving.register(&cancel);
        let _stop = CancelOnDrop(Arc::clone(&cancel));
        let task = tokio::task::spawn_blocking(move || {
            let _permit = permit;
            work(&cancel)
        });
        match tokio::time::timeout(self.limits.solver_time_limit, task).await {
            Ok(Ok(value)) => Ok(value),
            Ok(Err(join_error)) => Err(AppError::Internal(anyhow::anyhow!("solver task failed: {join_error}"))),
            Err(_) => Err(AppError::Timeout(format!(
                "the computation takes longer than the synchronous limit of {} s; submit it as a job (POST /api/v1/jobs)",
                self.limits.solver_time_limit.as_secs_f64()
            ))),
        }
    }
}

/// Sets the cancel flag when dropped: on the time limit, when the client goes away, and after a
/// normal end (when it no longer matters).
struct CancelOnDrop(Arc<AtomicBool>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        self.0.store(true, Ordering::Relaxed);
    }
}

impl AppState {
    /// A share of the memory budget ([`Limits::answer_budget_bytes`]) for `bytes` held in memory
    /// on behalf of one request (an answer being read, an upload being received), released when
    /// the permit drops. Something larger than the whole budget takes all of it, alone.
    ///
    /// # Errors
    /// 429 when the budget is held by other requests.
    pub fn reserve_memory(&self, bytes: usize) -> AppResult<tokio::sync::OwnedSemaphorePermit> {
        let budget_kib = self.limits.answer_budget_bytes.div_ceil(1024).clamp(1, Semaphore::MAX_PERMITS);
        let kib = u32::try_from(bytes.div_ceil(1024).clamp(1, budget_kib)).unwrap_or(u32::MAX);
        Arc::clone(&self.answer_budget).try_acquire_many_owned(kib).map_err(|_| {
            AppError::TooManyRequests(
                "large answers and uploads in progress hold the memory budget; retry shortly or submit a job"
                    .to_owned(),
            )
        })
    }
}
