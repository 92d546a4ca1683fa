//! The machines registry (docs/spec/api.md, Machines): controller profiles keyed by name.

use super::{Bind, Registry, guarded_delete, guarded_put, on};
use crate::db::Db;
use crate::error::{AppError, AppResult};
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

/// Up to `limit` machines named after `after` (all when `None`), ordered by name.
pub async fn list(db: &Db, after: Option<&str>, limit: i64) -> AppResult<Vec<MachineProfile>> {
    let rows: Vec<(String,)> = on!(db, query_as,
        both: "SELECT machine_json FROM machines WHERE $1 IS NULL OR name > $1 ORDER BY name LIMIT $2",
        [after, limit], fetch_all)?;
    rows.iter().map(|(json,)| decode(json)).collect()
}

/// The statements of the machines registry's guarded writes.
fn registry(name: &str) -> Registry {
    Registry {
        item: format!("machine {name:?}"),
        select_sqlite: "SELECT machine_json FROM machines WHERE name = $1",
        select_postgres: "SELECT machine_json FROM machines WHERE name = $1 FOR UPDATE",
        update_sqlite: "UPDATE machines SET block_time_ms = $2, max_feed = $3, dialect = $4, machine_json = $5, units = $6,
             revision = revision + 1, updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE name = $1",
        update_postgres: "UPDATE machines SET block_time_ms = $2, max_feed = $3, dialect = $4, machine_json = $5, units = $6,
             revision = revision + 1, updated_at = now() WHERE name = $1",
        insert:
            "INSERT INTO machines (name, block_time_ms, max_feed, dialect, machine_json, units) VALUES ($1, $2, $3, $4, $5, $6)
             ON CONFLICT (name) DO NOTHING",
        delete: "DELETE FROM machines WHERE name = $1",
    }
}

/// Stores `machine` (whose `name` is set) if `guard` accepts the machine stored under its name
/// now (`None`: none is), and says whether it was new (`guarded_put`).
pub async fn put(
    db: &Db,
    machine: &MachineProfile,
    guard: impl Fn(Option<&MachineProfile>) -> AppResult<()>,
) -> AppResult<bool> {
    let name = machine.name.as_deref().ok_or_else(|| AppError::Internal(anyhow::anyhow!("machine without name")))?;
    let json = serde_json::to_string(machine).map_err(|error| AppError::Internal(error.into()))?;
    let values = [
        Bind::Real(machine.block_time_ms),
        Bind::Real(machine.max_feed),
        Bind::Text(machine.dialect.as_str()),
        Bind::Text(&json),
        Bind::Text(machine.units.unwrap_or_default().as_str()),
    ];
    guarded_put(db, &registry(name), Bind::Text(name), &values, |(json,): (String,)| decode(&json), guard).await
}

/// Deletes the machine if `guard` accepts the machine stored now (`None`: none is), in one
/// transaction; false if there was none.
pub async fn delete(db: &Db, name: &str, guard: impl Fn(Option<&MachineProfile>) -> AppResult<()>) -> AppResult<bool> {
    guarded_delete(db, &registry(name), Bind::Text(name), |(json,): (String,)| decode(&json), guard).await
}

/// The machine a solver request names in its `machine` field: `None` when it names none, 404
/// naming `machine` when it is not registered.
pub async fn resolve(db: &Db, name: Option<&str>) -> AppResult<Option<MachineProfile>> {
    let Some(name) = name else { return Ok(None) };
    get(db, name).await?.map(Some).ok_or_else(|| {
        AppError::unknown("machine", format!("machine {name:?} is not registered (GET /api/v1/machines)"))
    })
}
