//! The pruner task that removes finished jobs past their retention (in `kerf serve`, and in `kerf
//! worker` on PostgreSQL: one process at a time prunes, the others skip).

use std::time::Duration;

use crate::db::Db;
use crate::store;
use crate::store::jobs::JobStorage;

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
