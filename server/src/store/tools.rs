//! The tool table (api.md, Tools).

use kerf_solver::tool::{Tool, ToolRef};
use sqlx::SqlitePool;

use crate::error::{AppError, AppResult};

fn decode(json: &str) -> AppResult<Tool> {
    serde_json::from_str(json)
        .map_err(|error| AppError::Internal(anyhow::anyhow!("stored tool is unreadable: {error}")))
}

/// The tool with `number`, if registered.
pub async fn get(db: &SqlitePool, number: u32) -> AppResult<Option<Tool>> {
    let row: Option<(String,)> =
        sqlx::query_as("SELECT tool_json FROM tools WHERE number = ?").bind(number).fetch_optional(db).await?;
    row.map(|(json,)| decode(&json)).transpose()
}

/// All tools ordered by number.
pub async fn list(db: &SqlitePool) -> AppResult<Vec<Tool>> {
    let rows: Vec<(String,)> = sqlx::query_as("SELECT tool_json FROM tools ORDER BY number").fetch_all(db).await?;
    rows.iter().map(|(json,)| decode(json)).collect()
}

/// Stores `tool` (whose `number` is set) and says whether it was new.
pub async fn put(db: &SqlitePool, tool: &Tool) -> AppResult<bool> {
    let number = tool.number.ok_or_else(|| AppError::Internal(anyhow::anyhow!("tool without number")))?;
    let json = serde_json::to_string(tool).map_err(|error| AppError::Internal(error.into()))?;
    let (revision,): (i64,) = sqlx::query_as(
        "INSERT INTO tools (number, kind, radius, name, tool_json) VALUES (?, ?, ?, ?, ?)
         ON CONFLICT (number) DO UPDATE SET kind = excluded.kind, radius = excluded.radius, name = excluded.name,
             tool_json = excluded.tool_json, revision = revision + 1,
             updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now')
         RETURNING revision",
    )
    .bind(number)
    .bind(tool.kind.as_str())
    .bind(tool.radius)
    .bind(&tool.name)
    .bind(json)
    .fetch_one(db)
    .await?;
    Ok(revision == 1)
}

/// Deletes the tool; false if there was none.
pub async fn delete(db: &SqlitePool, number: u32) -> AppResult<bool> {
    let result = sqlx::query("DELETE FROM tools WHERE number = ?").bind(number).execute(db).await?;
    Ok(result.rows_affected() > 0)
}

/// The tool a solver request names: looked up by number (404 if unknown) or given inline.
pub async fn resolve(db: &SqlitePool, tool: &ToolRef) -> AppResult<Tool> {
    match tool {
        ToolRef::Inline(tool) => Ok(tool.clone()),
        ToolRef::Number(number) => get(db, *number)
            .await?
            .ok_or_else(|| AppError::unknown("tool", format!("tool {number} is not in the tool table"))),
    }
}
