//! Pruning finished jobs past their retention, and giving the space back (SQLite's vacuum).

use crate::store::CommitChecked;
use std::time::Duration;

use super::PRUNE_LOCK;
use crate::db::Db;
use crate::error::AppResult;

/// Finished jobs removed by [`prune`].
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Pruned {
    /// Their ids, ascending.
    pub ids: Vec<i64>,
    /// The bytes they took.
    pub bytes: i64,
}

/// Removes the finished jobs (done, failed, cancelled) that finished more than `older_than` ago,
/// with their results; queued and running jobs are never touched. SQLite then gives the freed
/// pages back to the file system (incremental vacuum, where the file has it) and truncates the
/// write-ahead log. `None` in PostgreSQL when another process is pruning right now.
pub async fn prune(db: &Db, older_than: Duration) -> AppResult<Option<Pruned>> {
    let mut rows: Vec<(i64, i64)> = match db {
        Db::Sqlite(pool) => {
            let rows = sqlx::query_as(
                "DELETE FROM jobs WHERE status IN ('done', 'failed', 'cancelled')
                     AND finished_at < strftime('%Y-%m-%dT%H:%M:%fZ', 'now', $1)
                 RETURNING id, stored_bytes",
            )
            .bind(format!("-{:.3} seconds", older_than.as_secs_f64()))
            .fetch_all(pool)
            .await?;
            if !rows.is_empty() {
                sqlx::query("PRAGMA incremental_vacuum").execute(pool).await?;
                sqlx::query("PRAGMA wal_checkpoint(TRUNCATE)").execute(pool).await?;
            }
            rows
        }
        Db::Postgres(pool) => {
            let mut transaction = pool.begin().await?;
            let (ours,): (bool,) = sqlx::query_as("SELECT pg_try_advisory_xact_lock($1)")
                .bind(PRUNE_LOCK)
                .fetch_one(&mut *transaction)
                .await?;
            if !ours {
                return Ok(None);
            }
            let rows = sqlx::query_as(
                "DELETE FROM jobs WHERE status IN ('done', 'failed', 'cancelled')
                     AND finished_at < now() - make_interval(secs => $1)
                 RETURNING id, stored_bytes",
            )
            .bind(older_than.as_secs_f64())
            .fetch_all(&mut *transaction)
            .await?;
            transaction.commit_checked().await?;
            rows
        }
    };
    rows.sort_unstable();
    Ok(Some(Pruned {
        bytes: rows.iter().map(|(_, bytes)| bytes).sum(),
        ids: rows.into_iter().map(|(id, _)| id).collect(),
    }))
}

/// How an SQLite file gives freed space back: `true` when it has incremental vacuum (files
/// created since migration 0004), `false` for older files (freed pages are reused, the file does
/// not shrink until [`convert_to_incremental_vacuum`]). Always `true` in PostgreSQL.
pub async fn incremental_vacuum(db: &Db) -> AppResult<bool> {
    let Db::Sqlite(pool) = db else { return Ok(true) };
    let (mode,): (i64,) = sqlx::query_as("PRAGMA auto_vacuum").fetch_one(pool).await?;
    Ok(mode == 2)
}

/// Rewrites an SQLite file with incremental vacuum (one full `VACUUM`: it needs the file's size
/// again in free disk space and no other process using the file), giving all free pages back.
/// Nothing to do in PostgreSQL.
pub async fn convert_to_incremental_vacuum(db: &Db) -> AppResult<()> {
    let Db::Sqlite(pool) = db else { return Ok(()) };
    // The mode and the VACUUM that applies it must run on one connection.
    let mut connection = pool.acquire().await?;
    sqlx::query("PRAGMA auto_vacuum = INCREMENTAL").execute(&mut *connection).await?;
    sqlx::query("VACUUM").execute(&mut *connection).await?;
    sqlx::query("PRAGMA wal_checkpoint(TRUNCATE)").execute(&mut *connection).await?;
    Ok(())
}
