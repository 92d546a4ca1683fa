//! A finished job's stored results and programs, read back.

use super::bytes;
use crate::db::Db;
use crate::error::AppResult;
use crate::store::on;
use crate::store::packed::StoredText;

/// One operation's stored result.
#[derive(Debug)]
pub struct ResultRow {
    /// The operation's name.
    pub operation: String,
    /// Its result JSON.
    pub result: StoredText,
    /// Whether a program exists.
    pub gcode: bool,
    /// Why no program could be written, if so.
    pub gcode_problem: Option<String>,
}

/// A finished job's results, in operation order.
pub async fn results(db: &Db, id: i64) -> AppResult<Vec<ResultRow>> {
    type Row = (String, Option<String>, Option<Vec<u8>>, i64, bool, Option<String>);
    let rows: Vec<Row> = on!(db, query_as,
        both: "SELECT operation, result_json, result_gz, result_bytes, gcode IS NOT NULL OR gcode_gz IS NOT NULL,
                   gcode_problem
               FROM job_results WHERE job_id = $1 ORDER BY position",
        [id], fetch_all)?;
    Ok(rows
        .into_iter()
        .map(|(operation, json, compressed, length, gcode, gcode_problem)| ResultRow {
            operation,
            result: StoredText::from_columns(json, compressed, length).unwrap_or(StoredText::Plain(String::new())),
            gcode,
            gcode_problem,
        })
        .collect())
}

/// The bytes a finished job's results take uncompressed (what showing them holds in memory).
pub async fn results_length(db: &Db, id: i64) -> AppResult<i64> {
    let (length,): (i64,) = on!(db, query_as,
        sqlite: "SELECT COALESCE(SUM(result_bytes), 0) FROM job_results WHERE job_id = $1",
        postgres: "SELECT COALESCE(SUM(result_bytes), 0)::BIGINT FROM job_results WHERE job_id = $1",
        [id], fetch_one)?;
    Ok(length)
}

/// For each operation of a finished job, in order: whether it has a program, and why not.
pub async fn programs(db: &Db, id: i64) -> AppResult<Vec<(bool, Option<String>)>> {
    Ok(on!(db, query_as,
        both: "SELECT gcode IS NOT NULL OR gcode_gz IS NOT NULL, gcode_problem FROM job_results WHERE job_id = $1
               ORDER BY position",
        [id], fetch_all)?)
}

/// The program of operation `position` of a finished job, if it has one.
pub async fn program(db: &Db, id: i64, position: usize) -> AppResult<Option<StoredText>> {
    let row: Option<(Option<String>, Option<Vec<u8>>, i64)> = on!(db, query_as,
        both: "SELECT gcode, gcode_gz, gcode_bytes FROM job_results WHERE job_id = $1 AND position = $2",
        [id, bytes(position)], fetch_optional)?;
    Ok(row.and_then(|(text, compressed, length)| StoredText::from_columns(text, compressed, length)))
}
