//! The machines registry (docs/spec/api.md, Machines): controller profiles keyed by name.

use super::on;
use super::tools::WRITE_ATTEMPTS;
use crate::db::Db;
use crate::error::{AppError, AppResult};
use crate::store::CommitChecked;
use kerf_solver::machine::MachineProfile;

fn decode(json: &str) -> AppResult<MachineProfile> {
    serde_json::from_str(json)
        .map_err(|error| AppError::Internal(anyhow::anyhow!("stored machine is unreadable: {error}")))
}

/// The machine called `name`, if registered.
pub async fn get(db: &Db, name: &str) -> AppResult<Option<MachineProfile>> {
    let row: Option<(String,)> =
        on!(db, query_as, both: "SELECT machine_json FROM machines WHERE name = $1", [name], fetch_optional)?;
    row.map(|(json,)| decode(&json)).transpose()
}

/// All machines ordered by name.
pub async fn list(db: &Db) -> AppResult<Vec<MachineProfile>> {
    let rows: Vec<(String,)> =
        on!(db, query_as, both: "SELECT machine_json FROM machines ORDER BY name", [], fetch_all)?;
    rows.iter().map(|(json,)| decode(json)).collect()
}

/// Stores `machine` (whose `name` is set) if `guard` accepts the machine stored under its name
/// now (`None`: none is), and says whether it was new. The read, the guard and the write are one
/// transaction, so no other write falls between what the guard saw and what is written.
pub async fn put(
    db: &Db,
    machine: &MachineProfile,
    guard: impl Fn(Option<&MachineProfile>) -> AppResult<()>,
) -> AppResult<bool> {
    let name = machine.name.as_deref().ok_or_else(|| AppError::Internal(anyhow::anyhow!("machine without name")))?;
    let json = serde_json::to_string(machine).map_err(|error| AppError::Internal(error.into()))?;
    let (block_time_ms, max_feed, dialect) = (machine.block_time_ms, machine.max_feed, machine.dialect.as_str());
    macro_rules! put_in {
        ($begin:expr, $select:expr, $update:expr) => {{
            let mut transaction = $begin.await?;
            let mut attempts = 0;
            let created = loop {
                let row: Option<(String,)> =
                    sqlx::query_as($select).bind(name).fetch_optional(&mut *transaction).await?;
                let current = row.map(|(json,)| decode(&json)).transpose()?;
                guard(current.as_ref())?;
                if current.is_some() {
                    sqlx::query($update)
                        .bind(name).bind(block_time_ms).bind(max_feed).bind(dialect).bind(&json)
                        .execute(&mut *transaction).await?;
                    break false;
                }
                let inserted = sqlx::query(
                    "INSERT INTO machines (name, block_time_ms, max_feed, dialect, machine_json) VALUES ($1, $2, $3, $4, $5)
                     ON CONFLICT (name) DO NOTHING",
                )
                .bind(name).bind(block_time_ms).bind(max_feed).bind(dialect).bind(&json)
                .execute(&mut *transaction).await?;
                if inserted.rows_affected() == 1 {
                    break true;
                }
                // Another writer stored the name after the read: read it again and guard that.
                attempts += 1;
                if attempts == WRITE_ATTEMPTS {
                    return Err(AppError::Conflict(format!("machine {name:?} was written concurrently; try again")));
                }
            };
            transaction.commit_checked().await?;
            Ok(created)
        }};
    }
    match db {
        // IMMEDIATE: the write lock from the read on, so no writer comes between.
        Db::Sqlite(pool) => put_in!(
            pool.begin_with("BEGIN IMMEDIATE"),
            "SELECT machine_json FROM machines WHERE name = $1",
            "UPDATE machines SET block_time_ms = $2, max_feed = $3, dialect = $4, machine_json = $5,
                 revision = revision + 1, updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE name = $1"
        ),
        // FOR UPDATE holds the row until the commit; a name not stored yet is claimed by the
        // INSERT, which waits for a concurrent one and then does nothing.
        Db::Postgres(pool) => put_in!(
            pool.begin(),
            "SELECT machine_json FROM machines WHERE name = $1 FOR UPDATE",
            "UPDATE machines SET block_time_ms = $2, max_feed = $3, dialect = $4, machine_json = $5,
                 revision = revision + 1, updated_at = now() WHERE name = $1"
        ),
    }
}

/// Deletes the machine if `guard` accepts the machine stored now (`None`: none is), in one
/// transaction; false if there was none.
pub async fn delete(db: &Db, name: &str, guard: impl Fn(Option<&MachineProfile>) -> AppResult<()>) -> AppResult<bool> {
    macro_rules! delete_in {
        ($begin:expr, $select:expr) => {{
            let mut transaction = $begin.await?;
            let row: Option<(String,)> = sqlx::query_as($select).bind(name).fetch_optional(&mut *transaction).await?;
            let current = row.map(|(json,)| decode(&json)).transpose()?;
            guard(current.as_ref())?;
            let deleted =
                sqlx::query("DELETE FROM machines WHERE name = $1").bind(name).execute(&mut *transaction).await?;
            transaction.commit_checked().await?;
            Ok(deleted.rows_affected() > 0)
        }};
    }
    match db {
        Db::Sqlite(pool) => {
            delete_in!(pool.begin_with("BEGIN IMMEDIATE"), "SELECT machine_json FROM machines WHERE name = $1")
        }
        Db::Postgres(pool) => delete_in!(pool.begin(), "SELECT machine_json FROM machines WHERE name = $1 FOR UPDATE"),
    }
}

/// The machine a solver request names in its `machine` field: `None` when it names none, 404
/// naming `machine` when it is not registered.
pub async fn resolve(db: &Db, name: Option<&str>) -> AppResult<Option<MachineProfile>> {
    let Some(name) = name else { return Ok(None) };
    get(db, name).await?.map(Some).ok_or_else(|| {
        AppError::unknown("machine", format!("machine {name:?} is not registered (GET /api/v1/machines)"))
    })
}
