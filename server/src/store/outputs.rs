//! What a finished job's one program and its outputs archive are made of (issue 15, item 1): the
//! stored job file and every operation's stored answer and program.

use crate::db::Db;
use crate::error::AppResult;
use crate::store::on;

/// The stored (resolved) job file of job `id` as JSON, if the job exists.
pub async fn job_file(db: &Db, id: i64) -> AppResult<Option<String>> {
    Ok(on!(db, query_scalar, both: "SELECT job_json FROM jobs WHERE id = $1", [id], fetch_optional)?)
}

/// One operation's stored outputs: operation, answer JSON, program, why there is no program.
pub type OperationRow = (String, String, Option<String>, Option<String>);

/// Every operation's outputs of a finished job, in operation order.
pub async fn outputs(db: &Db, id: i64) -> AppResult<Vec<OperationRow>> {
    Ok(on!(db, query_as,
        both: "SELECT operation, result_json, gcode, gcode_problem FROM job_results WHERE job_id = $1
               ORDER BY position",
        [id], fetch_all)?)
}
