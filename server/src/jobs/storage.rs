//! Bounds on the job store: the total quota, the per-job cap, retention, and the pruner
//! task that removes finished jobs past their retention (in `kerf serve`, and in `kerf worker` on
//! PostgreSQL: one process at a time prunes, the others skip).

use std::time::Duration;

use crate::db::Db;
use crate::store;

/// One mebibyte.
pub const MIB: u64 = 1024 * 1024;

/// How much job results the store may hold and for how long.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JobStorage {
    /// Bytes all jobs together may take (job files and compressed results); `None`: no quota.
    pub quota_bytes: Option<u64>,
    /// Bytes one job may take (its job file and compressed results).
    pub job_max_bytes: u64,
    /// Finished jobs older than this are pruned; `None`: kept forever.
    pub retention: Option<Duration>,
    /// How often the pruner looks (also once at start).
    pub prune_every: Duration,
}

impl Default for JobStorage {
    fn default() -> Self {
        Self {
            quota_bytes: Some(2048 * MIB),
            job_max_bytes: 256 * MIB,
            retention: Some(Duration::from_secs(30 * 86_400)),
            prune_every: Duration::from_secs(3600),
        }
    }
}

impl JobStorage {
    /// The quota, or no bound.
    pub fn quota(&self) -> u64 {
        self.quota_bytes.unwrap_or(u64::MAX)
    }
}

/// `days` as a retention: `None` for 0 (keep forever).
pub fn days(days: f64) -> Option<Duration> {
    (days.is_finite() && days > 0.0).then(|| Duration::from_secs_f64(days * 86_400.0))
}

/// `bytes` in MiB for messages (one decimal).
pub fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / MIB as f64)
}

/// Starts the pruner: every `storage.prune_every` (and at once) it removes the finished jobs older
/// than the retention. Does nothing when jobs are kept forever.
pub fn start_pruner(db: Db, storage: JobStorage) {
    let Some(retention) = storage.retention else { return };
    tokio::spawn(async move {
        let mut ticker = tokio::time::interval(storage.prune_every.max(Duration::from_millis(10)));
        loop {
            ticker.tick().await;
            match store::jobs::prune(&db, retention).await {
                Ok(Some(pruned)) if !pruned.ids.is_empty() => tracing::info!(
                    jobs = pruned.ids.len(),
                    bytes = pruned.bytes,
                    retention_days = retention.as_secs_f64() / 86_400.0,
                    "pruned finished jobs past their retention"
                ),
                Ok(_) => {}
                Err(error) => tracing::warn!(%error, "pruning old jobs failed; trying again later"),
            }
        }
    });
}
