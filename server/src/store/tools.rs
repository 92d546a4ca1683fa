//! The tool table (docs/spec/api.md, Tools).

use kerf_solver::tool::{Tool, ToolRef};

use super::on;
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

/// All tools ordered by number.
pub async fn list(db: &Db) -> AppResult<Vec<Tool>> {
    let rows: Vec<(String,)> = on!(db, query_as, both: "SELECT tool_json FROM tools ORDER BY number", [], fetch_all)?;
    rows.iter().map(|(json,)| decode(json)).collect()
}

/// Stores `tool` (whose `number` is set) and says whether it was new.
pub async fn put(db: &Db, tool: &Tool) -> AppResult<bool> {
    let number = tool.number.ok_or_else(|| AppError::Internal(anyhow::anyhow!("tool without number")))?;
    let json = serde_json::to_string(tool).map_err(|error| AppError::Internal(error.into()))?;
    let (revision,): (i64,) = on!(db, query_as,
        sqlite: "INSERT INTO tools (number, kind, radius, name, tool_json) VALUES ($1, $2, $3, $4, $5)
         ON CONFLICT (number) DO UPDATE SET kind = excluded.kind, radius = excluded.radius, name = excluded.name,
             tool_json = excluded.tool_json, revision = revision + 1,
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')
         RETURNING revision",
        postgres: "INSERT INTO tools (number, kind, radius, name, tool_json) VALUES ($1, $2, $3, $4, $5)
         ON CONFLICT (number) DO UPDATE SET kind = excluded.kind, radius = excluded.radius, name = excluded.name,
             tool_json = excluded.tool_json, revision = tools.revision + 1, updated_at = now()
         RETURNING revision",
        [i64::from(number), tool.kind.as_str(), tool.radius, &tool.name, &json],
        fetch_one)?;
    Ok(revision == 1)
}

/// Deletes the tool; false if there was none.
pub async fn delete(db: &Db, number: u32) -> AppResult<bool> {
    let result = on!(db, query, both: "DELETE FROM tools WHERE number = $1", [i64::from(number)], execute)?;
    Ok(result > 0)
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
