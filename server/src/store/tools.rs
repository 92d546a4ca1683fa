//! The tool table (docs/spec/api.md, Tools).

use kerf_solver::tool::{Tool, ToolRef};

use super::{Bind, Registry, guarded_delete, guarded_put, on};
use crate::db::Db;
use crate::error::{AppError, AppResult};

fn decode(json: &str) -> AppResult<Tool> {
    serde_json::from_str(json)
        .map_err(|error| AppError::Internal(anyhow::anyhow!("stored tool is unreadable: {error}")))
}

/// The tool with `number`, if registered.
pub async fn get(db: &Db, number: u32) -> AppResult<Option<Tool>> {
    let row: Option<(String,)> =
        on!(db, query_as, both: "SELECT tool_json FROM tools WHERE number = $1", [i64::from(number)], fetch_optional)?;
    row.map(|(json,)| decode(&json)).transpose()
}

/// Up to `limit` tools numbered above `after`, ordered by number.
pub async fn list(db: &Db, after: u32, limit: i64) -> AppResult<Vec<Tool>> {
    let rows: Vec<(String,)> = on!(db, query_as,
        both: "SELECT tool_json FROM tools WHERE number > $1 ORDER BY number LIMIT $2",
        [i64::from(after), limit], fetch_all)?;
    rows.iter().map(|(json,)| decode(json)).collect()
}

/// The statements of the tool table's guarded writes.
fn registry(number: i64) -> Registry {
    Registry {
        item: format!("tool {number}"),
        select_sqlite: "SELECT tool_json FROM tools WHERE number = $1",
        select_postgres: "SELECT tool_json FROM tools WHERE number = $1 FOR UPDATE",
        update_sqlite: "UPDATE tools SET kind = $2, radius = $3, name = $4, tool_json = $5, revision = revision + 1,
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE number = $1",
        update_postgres: "UPDATE tools SET kind = $2, radius = $3, name = $4, tool_json = $5, revision = revision + 1,
             updated_at = now() WHERE number = $1",
        insert: "INSERT INTO tools (number, kind, radius, name, tool_json) VALUES ($1, $2, $3, $4, $5)
             ON CONFLICT (number) DO NOTHING",
        delete: "DELETE FROM tools WHERE number = $1",
    }
}

/// Stores `tool` (whose `number` is set) if `guard` accepts the tool stored under its number now
/// (`None`: none is), and says whether it was new (`guarded_put`).
pub async fn put(db: &Db, tool: &Tool, guard: impl Fn(Option<&Tool>) -> AppResult<()>) -> AppResult<bool> {
    let number = i64::from(tool.number.ok_or_else(|| AppError::Internal(anyhow::anyhow!("tool without number")))?);
    let json = serde_json::to_string(tool).map_err(|error| AppError::Internal(error.into()))?;
    let values = [
        Bind::Text(tool.kind.as_str()),
        Bind::Real(tool.radius),
        Bind::OptionalText(tool.name.as_deref()),
        Bind::Text(&json),
    ];
    guarded_put(db, &registry(number), Bind::Integer(number), &values, |(json,): (String,)| decode(&json), guard).await
}

/// Deletes the tool if `guard` accepts the tool stored now (`None`: none is), in one transaction;
/// false if there was none.
pub async fn delete(db: &Db, number: u32, guard: impl Fn(Option<&Tool>) -> AppResult<()>) -> AppResult<bool> {
    let number = i64::from(number);
    guarded_delete(db, &registry(number), Bind::Integer(number), |(json,): (String,)| decode(&json), guard).await
}

/// The tool a solver request names: looked up by number (404 if unknown) or given inline.
pub async fn resolve(db: &Db, tool: &ToolRef) -> AppResult<Tool> {
    match tool {
        ToolRef::Inline(tool) => Ok(tool.clone()),
        ToolRef::Number(number) => get(db, *number)
            .await?
            .ok_or_else(|| AppError::unknown("tool", format!("tool {number} is not in the tool table"))),
    }
}
