//! The machines registry (api.md, Machines): controller profiles keyed by name.

use kerf_solver::gcode::Dialect;
use kerf_solver::machine::MachineProfile;
use sqlx::SqlitePool;

use crate::error::{AppError, AppResult};

fn decode(json: &str) -> AppResult<MachineProfile> {
    serde_json::from_str(json)
        .map_err(|error| AppError::Internal(anyhow::anyhow!("stored machine is unreadable: {error}")))
}

fn dialect_name(dialect: Dialect) -> &'static str {
    match dialect {
        Dialect::Fanuc => "fanuc",
        Dialect::Linuxcnc => "linuxcnc",
    }
}

/// The machine called `name`, if registered.
pub async fn get(db: &SqlitePool, name: &str) -> AppResult<Option<MachineProfile>> {
    let row: Option<(String,)> =
        sqlx::query_as("SELECT machine_json FROM machines WHERE name = ?").bind(name).fetch_optional(db).await?;
    row.map(|(json,)| decode(&json)).transpose()
}

/// All machines ordered by name.
pub async fn list(db: &SqlitePool) -> AppResult<Vec<MachineProfile>> {
    let rows: Vec<(String,)> = sqlx::query_as("SELECT machine_json FROM machines ORDER BY name").fetch_all(db).await?;
    rows.iter().map(|(json,)| decode(json)).collect()
}

/// Stores `machine` (whose `name` is set) and says whether it was new.
pub async fn put(db: &SqlitePool, machine: &MachineProfile) -> AppResult<bool> {
    let name = machine.name.as_deref().ok_or_else(|| AppError::Internal(anyhow::anyhow!("machine without name")))?;
    let json = serde_json::to_string(machine).map_err(|error| AppError::Internal(error.into()))?;
    let (revision,): (i64,) = sqlx::query_as(
        "INSERT INTO machines (name, block_time_ms, max_feed, dialect, machine_json) VALUES (?, ?, ?, ?, ?)
         ON CONFLICT (name) DO UPDATE SET block_time_ms = excluded.block_time_ms, max_feed = excluded.max_feed,
             dialect = excluded.dialect, machine_json = excluded.machine_json, revision = revision + 1,
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')
         RETURNING revision",
    )
    .bind(name)
    .bind(machine.block_time_ms)
    .bind(machine.max_feed)
    .bind(dialect_name(machine.dialect))
    .bind(json)
    .fetch_one(db)
    .await?;
    Ok(revision == 1)
}

/// Deletes the machine; false if there was none.
pub async fn delete(db: &SqlitePool, name: &str) -> AppResult<bool> {
    let result = sqlx::query("DELETE FROM machines WHERE name = ?").bind(name).execute(db).await?;
    Ok(result.rows_affected() > 0)
}

/// The machine a solver request names in its `machine` field: `None` when it names none, 404
/// naming `machine` when it is not registered.
pub async fn resolve(db: &SqlitePool, name: Option<&str>) -> AppResult<Option<MachineProfile>> {
    let Some(name) = name else { return Ok(None) };
    get(db, name).await?.map(Some).ok_or_else(|| {
        AppError::unknown("machine", format!("machine {name:?} is not registered (GET /api/v1/machines)"))
    })
}
