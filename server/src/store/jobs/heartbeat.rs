//! Heartbeats of running work: progress, and (PostgreSQL) the chunk's lease pushed forward.

use super::{Claimant, Work, set_job_progress};
use crate::db::Db;
use crate::error::AppResult;
use crate::store::CommitChecked;

/// Records progress and the heartbeat of running work (PostgreSQL: of the chunk, extending its
/// lease; the job's progress is the weighted sum of its chunks', written in the same transaction
/// so the two always agree). Returns false when the work is no
/// longer the claimant's to run: its job was cancelled or failed, or (PostgreSQL) the chunk was
/// claimed by another worker after this one's lease expired. The worker then stops it.
pub async fn heartbeat(db: &Db, work: Work, claimant: &Claimant, progress: f64) -> AppResult<bool> {
    let progress = progress.clamp(0.0, 1.0);
    match db {
        Db::Sqlite(pool) => {
            let updated = sqlx::query(concat!(
                "UPDATE jobs SET progress = $1, heartbeat_at = ",
                now!(),
                " WHERE id = $2 AND status = 'running'"
            ))
            .bind(progress)
            .bind(work.id)
            .execute(pool)
            .await?;
            Ok(updated.rows_affected() > 0)
        }
        Db::Postgres(pool) => {
            let mut transaction = pool.begin().await?;
            let updated = sqlx::query(
                "UPDATE job_chunks SET progress = $1, lease_expires_at = now() + make_interval(secs => $4)
                 WHERE job_id = $2 AND position = $5 AND worker = $3 AND status = 'running'
                   AND EXISTS (SELECT 1 FROM jobs WHERE id = $2 AND status = 'running')",
            )
            .bind(progress)
            .bind(work.id)
            .bind(&claimant.worker)
            .bind(claimant.lease.as_secs_f64())
            .bind(work.position())
            .execute(&mut *transaction)
            .await?;
            if updated.rows_affected() == 0 {
                transaction.rollback().await?;
                return Ok(false);
            }
            set_job_progress(&mut transaction, work.id).await?;
            transaction.commit_checked().await?;
            Ok(true)
        }
    }
}
