//! What a finished job's one program and its outputs archive are made of: the
//! stored job file and every operation's stored answer and program.

use crate::db::Db;
use crate::error::{AppError, AppResult};
use crate::store::on;
use crate::store::packed::StoredText;

/// The stored (resolved) job file of job `id` as JSON, if the job exists.
pub async fn job_file(db: &Db, id: i64) -> AppResult<Option<String>> {
    Ok(on!(db, query_scalar, both: "SELECT job_json FROM jobs WHERE id = $1", [id], fetch_optional)?)
}

/// One operation's stored outputs: operation, answer JSON, program, why there is no program.
pub type OperationRow = (String, String, Option<String>, Option<String>);

/// The bytes a finished job's answers and programs take uncompressed: what [`outputs`] holds.
pub async fn length(db: &Db, id: i64) -> AppResult<usize> {
    let (length,): (i64,) = on!(db, query_as,
        sqlite: "SELECT COALESCE(SUM(result_bytes + gcode_bytes), 0) FROM job_results WHERE job_id = $1",
        postgres: "SELECT COALESCE(SUM(result_bytes + gcode_bytes), 0)::BIGINT FROM job_results WHERE job_id = $1",
        [id], fetch_one)?;
    Ok(usize::try_from(length).unwrap_or(usize::MAX))
}

/// Every operation's outputs of a finished job, in operation order, decompressed (rows stored
/// before compression are read as they are).
pub async fn outputs(db: &Db, id: i64) -> AppResult<Vec<OperationRow>> {
    type Row = (String, Option<String>, Option<Vec<u8>>, i64, Option<String>, Option<Vec<u8>>, i64, Option<String>);
    let rows: Vec<Row> = on!(db, query_as,
        both: "SELECT operation, result_json, result_gz, result_bytes, gcode, gcode_gz, gcode_bytes, gcode_problem
               FROM job_results WHERE job_id = $1 ORDER BY position",
        [id], fetch_all)?;
    // Decompressing is CPU work: off the async threads.
    tokio::task::spawn_blocking(move || {
        rows.into_iter()
            .map(|(operation, result, result_gz, result_bytes, gcode, gcode_gz, gcode_bytes, problem)| {
                let result = StoredText::from_columns(result, result_gz, result_bytes)
                    .map(StoredText::into_string)
                    .transpose()?
                    .unwrap_or_default();
                let gcode =
                    StoredText::from_columns(gcode, gcode_gz, gcode_bytes).map(StoredText::into_string).transpose()?;
                Ok((operation, result, gcode, problem))
            })
            .collect()
    })
    .await
    .map_err(|error| AppError::Internal(error.into()))?
}
