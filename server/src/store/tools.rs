//! The tool table (docs/spec/api.md, Tools).

use crate::store::CommitChecked;
use kerf_solver::tool::{Tool, ToolRef};

use super::on;
use crate::db::Db;
use crate::error::{AppError, AppResult};

/// How often a guarded write reads again when a concurrent writer created the item between its
/// read and its insert (each time the guard sees the new item) before it answers 409.
pub const WRITE_ATTEMPTS: u32 = 3;

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

/// Stores `tool` (whose `number` is set) if `guard` accepts the tool stored under its number now
/// (`None`: none is), and says whether it was new. The read, the guard and the write are one
/// transaction, so no other write falls between what the guard saw and what is written.
pub async fn put(db: &Db, tool: &Tool, guard: impl Fn(Option<&Tool>) -> AppResult<()>) -> AppResult<bool> {
    let number = i64::from(tool.number.ok_or_else(|| AppError::Internal(anyhow::anyhow!("tool without number")))?);
    let json = serde_json::to_string(tool).map_err(|error| AppError::Internal(error.into()))?;
    let (kind, radius, name) = (tool.kind.as_str(), tool.radius, &tool.name);
    macro_rules! put_in {
        ($begin:expr, $select:expr, $update:expr) => {{
            let mut transaction = $begin.await?;
            let mut attempts = 0;
            let created = loop {
                let row: Option<(String,)> =
                    sqlx::query_as($select).bind(number).fetch_optional(&mut *transaction).await?;
                let current = row.map(|(json,)| decode(&json)).transpose()?;
                guard(current.as_ref())?;
                if current.is_some() {
                    sqlx::query($update)
                        .bind(number)
                        .bind(kind)
                        .bind(radius)
                        .bind(name)
                        .bind(&json)
                        .execute(&mut *transaction)
                        .await?;
                    break false;
                }
                let inserted = sqlx::query(
                    "INSERT INTO tools (number, kind, radius, name, tool_json) VALUES ($1, $2, $3, $4, $5)
                     ON CONFLICT (number) DO NOTHING",
                )
                .bind(number)
                .bind(kind)
                .bind(radius)
                .bind(name)
                .bind(&json)
                .execute(&mut *transaction)
                .await?;
                if inserted.rows_affected() == 1 {
                    break true;
                }
                // Another writer stored the number after the read: read it again and guard that.
                attempts += 1;
                if attempts == WRITE_ATTEMPTS {
                    return Err(AppError::Conflict(format!("tool {number} was written concurrently; try again")));
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
            "SELECT tool_json FROM tools WHERE number = $1",
            "UPDATE tools SET kind = $2, radius = $3, name = $4, tool_json = $5, revision = revision + 1,
                 updated_at = strftime('%Y-%m-%dT%H:%M:%fZ', 'now') WHERE number = $1"
        ),
        // FOR UPDATE holds the row until the commit; a number not stored yet is claimed by the
        // INSERT, which waits for a concurrent one and then does nothing.
        Db::Postgres(pool) => put_in!(
            pool.begin(),
            "SELECT tool_json FROM tools WHERE number = $1 FOR UPDATE",
            "UPDATE tools SET kind = $2, radius = $3, name = $4, tool_json = $5, revision = revision + 1,
                 updated_at = now() WHERE number = $1"
        ),
    }
}

/// Deletes the tool if `guard` accepts the tool stored now (`None`: none is), in one transaction;
/// false if there was none.
pub async fn delete(db: &Db, number: u32, guard: impl Fn(Option<&Tool>) -> AppResult<()>) -> AppResult<bool> {
    let number = i64::from(number);
    macro_rules! delete_in {
        ($begin:expr, $select:expr) => {{
            let mut transaction = $begin.await?;
            let row: Option<(String,)> = sqlx::query_as($select).bind(number).fetch_optional(&mut *transaction).await?;
            let current = row.map(|(json,)| decode(&json)).transpose()?;
            guard(current.as_ref())?;
            let deleted =
                sqlx::query("DELETE FROM tools WHERE number = $1").bind(number).execute(&mut *transaction).await?;
            transaction.commit_checked().await?;
            Ok(deleted.rows_affected() > 0)
        }};
    }
    match db {
        Db::Sqlite(pool) => {
            delete_in!(pool.begin_with("BEGIN IMMEDIATE"), "SELECT tool_json FROM tools WHERE number = $1")
        }
        Db::Postgres(pool) => delete_in!(pool.begin(), "SELECT tool_json FROM tools WHERE number = $1 FOR UPDATE"),
    }
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
