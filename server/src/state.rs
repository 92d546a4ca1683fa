//! Shared state of the running service: the database pool, the configured limits and the bound
//! on concurrent solver work.

use std::sync::Arc;
use std::time::Duration;

use tokio::sync::Semaphore;

use crate::auth::Auth;
use crate::db::Db;
use crate::error::{AppError, AppResult};
use crate::jobs::queue::JobRunner;

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
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_body_bytes: 8 * 1024 * 1024,
            max_upload_bytes: 128 * 1024 * 1024,
            solver_time_limit: Duration::from_secs(30),
            solver_queue_wait: Duration::from_secs(5),
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
}

impl AppState {
    /// State over `db` with `limits`, allowing `solver_slots` solver calls at once, guarded by
    /// `auth`, with job leases of `lease` (PostgreSQL).
    pub fn new(db: Db, limits: Limits, solver_slots: usize, auth: Auth, lease: Duration) -> Self {
        Self {
            db,
            limits,
            solver_slots: Arc::new(Semaphore::new(solver_slots.max(1))),
            jobs: Arc::new(JobRunner::new(lease)),
            auth,
        }
    }

    /// Runs pure solver work on the blocking pool, never on an async worker thread, under the
    /// concurrency bound and the synchronous time limit.
    pub async fn solve<T, F>(&self, work: F) -> AppResult<T>
    where
        F: FnOnce() -> T + Send + 'static,
        T: Send + 'static,
    {
        let permit =
            tokio::time::timeout(self.limits.solver_queue_wait, Arc::clone(&self.solver_slots).acquire_owned())
                .await
                .map_err(|_| AppError::TooManyRequests("all solver slots are busy; retry shortly".to_owned()))?
                .map_err(|error| AppError::Internal(error.into()))?;
        let task = tokio::task::spawn_blocking(move || {
            let _permit = permit;
            work()
        });
        match tokio::time::timeout(self.limits.solver_time_limit, task).await {
            Ok(Ok(value)) => Ok(value),
            Ok(Err(join_error)) => Err(AppError::Internal(anyhow::anyhow!("solver task failed: {join_error}"))),
            Err(_) => Err(AppError::Timeout(format!(
                "the computation takes longer than the synchronous limit of {} s; submit it as a job (POST /api/v1/jobs)",
                self.limits.solver_time_limit.as_secs()
            ))),
        }
    }
}
