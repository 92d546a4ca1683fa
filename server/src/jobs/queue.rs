//! The job workers: a bounded pool of tasks that claim queued jobs from SQLite, run them on the
//! blocking pool under the shared solver bound, record progress and heartbeat, and store the
//! results; plus cancellation of running jobs and recovery after a stop.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

use sqlx::SqlitePool;
use tokio::sync::{Notify, Semaphore};

use super::execute::{JobFailure, execute};
use crate::error::AppError;
use crate::store;

/// How often a running job's progress and heartbeat are written.
const HEARTBEAT: Duration = Duration::from_millis(250);
/// How often idle workers look for work without being woken.
const IDLE_POLL: Duration = Duration::from_secs(2);

/// Coordination between the HTTP handlers and the workers.
#[derive(Debug, Default)]
pub struct JobRunner {
    /// Wakes idle workers when a job is submitted.
    pub submitted: Notify,
    cancel_flags: Mutex<HashMap<i64, Arc<AtomicBool>>>,
    /// Set at shutdown: workers claim nothing more.
    stopping: AtomicBool,
}

impl JobRunner {
    /// Tells the worker running job `id`, if any, to stop.
    pub fn cancel(&self, id: i64) {
        if let Some(flag) = self.flags().get(&id) {
            flag.store(true, Ordering::Relaxed);
        }
    }

    /// Tells every running job to stop, at shutdown: a stopped job keeps its `running` record,
    /// which the next start re-queues (as after a kill).
    pub fn stop_all(&self) {
        self.stopping.store(true, Ordering::Relaxed);
        for flag in self.flags().values() {
            flag.store(true, Ordering::Relaxed);
        }
    }

    fn flags(&self) -> std::sync::MutexGuard<'_, HashMap<i64, Arc<AtomicBool>>> {
        self.cancel_flags.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Re-queues or fails the jobs a stopped server left running, then starts `workers` workers.
    ///
    /// # Errors
    /// When the recovery update fails.
    pub async fn start(
        self: &Arc<Self>,
        db: &SqlitePool,
        slots: &Arc<Semaphore>,
        workers: usize,
    ) -> anyhow::Result<()> {
        let (requeued, failed) = store::jobs::recover(db).await.map_err(|e| anyhow::anyhow!("{e}"))?;
        if requeued + failed > 0 {
            tracing::warn!(requeued, failed, "jobs interrupted by the last stop");
        }
        for _ in 0..workers.max(1) {
            tokio::spawn(work(Arc::clone(self), db.clone(), Arc::clone(slots)));
        }
        Ok(())
    }
}

async fn work(runner: Arc<JobRunner>, db: SqlitePool, slots: Arc<Semaphore>) {
    while !runner.stopping.load(Ordering::Relaxed) {
        match store::jobs::claim(&db).await {
            Ok(Some((id, job))) => run(&runner, &db, &slots, id, job).await,
            Ok(None) => {
                let _ = tokio::time::timeout(IDLE_POLL, runner.submitted.notified()).await;
            }
            Err(error) => {
                tracing::error!(%error, "claiming a job failed");
                tokio::time::sleep(IDLE_POLL).await;
            }
        }
    }
}

async fn run(runner: &JobRunner, db: &SqlitePool, slots: &Arc<Semaphore>, id: i64, job: super::file::JobFile) {
    let cancelled = Arc::new(AtomicBool::new(false));
    runner.flags().insert(id, Arc::clone(&cancelled));
    let progress = Arc::new(AtomicU64::new(0));
    let Ok(permit) = Arc::clone(slots).acquire_owned().await else { return };
    let (task_progress, task_cancelled) = (Arc::clone(&progress), Arc::clone(&cancelled));
    let mut task = tokio::task::spawn_blocking(move || {
        let _permit = permit;
        execute(&job, &|fraction| task_progress.store(fraction.to_bits(), Ordering::Relaxed), &task_cancelled)
    });
    let mut ticker = tokio::time::interval(HEARTBEAT);
    let outcome = loop {
        tokio::select! {
            outcome = &mut task => break outcome,
            _ = ticker.tick() => {
                let fraction = f64::from_bits(progress.load(Ordering::Relaxed));
                if let Err(error) = store::jobs::heartbeat(db, id, fraction).await {
                    tracing::warn!(id, %error, "recording progress failed");
                }
            }
        }
    };
    runner.flags().remove(&id);
    let stored = match outcome {
        Ok(Ok(outputs)) => store::jobs::finish(db, id, &outputs).await.map(|_| ()),
        Ok(Err(JobFailure::Cancelled)) => Ok(()),
        Ok(Err(JobFailure::Refused(problem))) => store::jobs::fail(db, id, &problem).await,
        Err(join_error) => {
            tracing::error!(id, %join_error, "job task failed");
            let internal = AppError::Internal(anyhow::anyhow!("the job's task failed"));
            store::jobs::fail(db, id, &internal.problem()).await
        }
    };
    if let Err(error) = stored {
        tracing::error!(id, %error, "storing the job outcome failed");
    }
}
