//! Bounds on the job store (the total quota, the per-job cap, retention) and what it holds now.

use std::time::Duration;

use crate::db::Db;
use crate::error::AppResult;
use crate::store::on;

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

/// Jobs stored and the bytes they take (job files and compressed results).
pub async fn usage(db: &Db) -> AppResult<(i64, i64)> {
    Ok(on!(db, query_as,
        sqlite: "SELECT COUNT(*), COALESCE(SUM(stored_bytes), 0) FROM jobs",
        postgres: "SELECT COUNT(*), COALESCE(SUM(stored_bytes), 0)::BIGINT FROM jobs",
        [], fetch_one)?)
}
