//! The machines registry (docs/spec/api.md, Machines): controller profiles keyed by name.

use super::on;
use crate::db::Db;
use crate::error::{AppError, AppResult};
use kerf_solver::gcode::Dialect;
use kerf_solver::machine::MachineProfile;

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

/// Stores `machine` (whose `name` is set) and says whether it was new.
pub async fn put(db: &Db, machine: &MachineProfile) -> AppResult<bool> {
    let name = machine.name.as_deref().ok_or_else(|| AppError::Internal(anyhow::anyhow!("machine without name")))?;
    let json = serde_json::to_string(machine).map_err(|error| AppError::Internal(error.into()))?;
    let (revision,): (i64,) = on!(db, query_as,
        sqlite: "INSERT INTO machines (name, block_time_ms, max_feed, dialect, machine_json) VALUES ($1, $2, $3, $4, $5)
         ON CONFLICT (name) DO UPDATE SET block_time_ms = excluded.block_time_ms, max_feed = excluded.max_feed,
             dialect = excluded.dialect, machine_json = excluded.machine_json, revision = revision + 1,
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')
         RETURNING revision",
        postgres: "INSERT INTO machines (name, block_time_ms, max_feed, dialect, machine_json) VALUES ($1, $2, $3, $4, $5)
         ON CONFLICT (name) DO UPDATE SET block_time_ms = excluded.block_time_ms, max_feed = excluded.max_feed,
             dialect = excluded.dialect, machine_json = excluded.machine_json, revision = machines.revision + 1,
             updated_at = now()
         RETURNING revision",
        [name, machine.block_time_ms, machine.max_feed, dialect_name(machine.dialect), &json],
        fetch_one)?;
    Ok(revision == 1)
}

/// Deletes the machine; false if there was none.
pub async fn delete(db: &Db, name: &str) -> AppResult<bool> {
    let result = on!(db, query, both: "DELETE FROM machines WHERE name = $1", [name], execute)?;
    Ok(result > 0)
}

/// The machine a solver request names in its `machine` field: `None` when it names none, 404
/// naming `machine` when it is not registered.
pub async fn resolve(db: &Db, name: Option<&str>) -> AppResult<Option<MachineProfile>> {
    let Some(name) = name else { return Ok(None) };
    get(db, name).await?.map(Some).ok_or_else(|| {
        AppError::unknown("machine", format!("machine {name:?} is not registered (GET /api/v1/machines)"))
    })
}
