//! Runs a resolved job: each operation in order through the same code as its endpoint, with
//! progress and cancellation. Pure apart from the two callbacks, so it runs the same in the
//! server's workers and in `kerf run`.

use std::sync::atomic::{AtomicBool, Ordering};

use kerf_solver::SolverError;
use kerf_solver::tool::ToolRef;
use serde::Serialize;
use utoipa::ToSchema;

use super::file::{JobFile, Operation};
use crate::http;

/// The result of one operation.
#[derive(Debug, Clone, PartialEq, Serialize, ToSchema)]
pub struct OperationOutput {
    /// The operation's name (`deburr`, ...).
    pub operation: String,
    /// Its answer, exactly as its endpoint answers JSON.
    pub result: serde_json::Value,
    /// Its G-code program in the job's output options, when one could be written.
    #[serde(skip)]
    pub gcode: Option<String>,
    /// Why no program could be written, if so.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gcode_problem: Option<String>,
}

/// Why a job did not finish.
#[derive(Debug, Clone, PartialEq)]
pub enum JobFailure {
    /// The job was cancelled.
    Cancelled,
    /// An operation was refused: its message and the field at fault (prefixed `operations[i].`).
    Refused { message: String, field: Option<String> },
}

fn refused(index: usize, error: &SolverError) -> JobFailure {
    JobFailure::Refused {
        message: format!("operation {index}: {} ({})", error.message(), error.code()),
        field: Some(match error.field() {
            Some(field) => format!("operations[{index}].{field}"),
            None => format!("operations[{index}]"),
        }),
    }
}

/// An operation whose `field` (tool or machine) was not resolved at submission.
fn unresolved(index: usize, field: &str) -> JobFailure {
    JobFailure::Refused {
        message: format!("operation {index}: the {field} was not resolved"),
        field: Some(format!("operations[{index}].{field}")),
    }
}

/// Runs `job` (already resolved: tools inline). `progress` receives the fraction done (0–1).
pub fn execute(
    job: &JobFile,
    progress: &dyn Fn(f64),
    cancelled: &AtomicBool,
) -> Result<Vec<OperationOutput>, JobFailure> {
    let count = job.operations.len();
    let mut outputs = Vec::with_capacity(count);
    for (index, operation) in job.operations.iter().enumerate() {
        if cancelled.load(Ordering::Relaxed) {
            return Err(JobFailure::Cancelled);
        }
        let output = match operation {
            Operation::Deburr(request) => {
                let ToolRef::Inline(tool) = &request.tool else {
                    return Err(JobFailure::Refused {
                        message: format!("operation {index}: the tool was not resolved"),
                        field: Some(format!("operations[{index}].tool")),
                    });
                };
                let machine = match &request.machine {
                    None => None,
                    Some(name) => Some(job.machine(name).cloned().ok_or_else(|| unresolved(index, "machine"))?),
                };
                let answer = http::deburr::run(request, tool.clone(), machine).map_err(|e| refused(index, &e))?;
                let program = http::deburr::program(&answer, job.output.dialect, job.output.reference);
                OperationOutput {
                    operation: operation.kind().to_owned(),
                    result: serde_json::to_value(&answer).map_err(|e| JobFailure::Refused {
                        message: format!("operation {index}: result not serialisable: {e}"),
                        field: None,
                    })?,
                    gcode_problem: program.as_ref().err().map(|e| format!("{} ({})", e.message(), e.code())),
                    gcode: program.ok(),
                }
            }
            Operation::Segment(request) => {
                let tool = match &request.tool {
                    None => None,
                    Some(ToolRef::Inline(tool)) => Some(tool.clone()),
                    Some(ToolRef::Number(_)) => return Err(unresolved(index, "tool")),
                };
                let machine = match &request.machine {
                    None => None,
                    Some(name) => Some(job.machine(name).cloned().ok_or_else(|| unresolved(index, "machine"))?),
                };
                let answer = http::segment::run(request, machine, tool).map_err(|e| refused(index, &e))?;
                let program = http::segment::program(&answer, job.output.dialect);
                OperationOutput {
                    operation: operation.kind().to_owned(),
                    result: serde_json::to_value(&answer).map_err(|e| JobFailure::Refused {
                        message: format!("operation {index}: result not serialisable: {e}"),
                        field: None,
                    })?,
                    gcode_problem: program.as_ref().err().map(|e| format!("{} ({})", e.message(), e.code())),
                    gcode: program.ok(),
                }
            }
            Operation::Contour(request) => {
                let ToolRef::Inline(tool) = &request.tool else {
                    return Err(JobFailure::Refused {
                        message: format!("operation {index}: the tool was not resolved"),
                        field: Some(format!("operations[{index}].tool")),
                    });
                };
                // A job goes up to the solver's move limit; its stored JSON keeps what fits.
                let mut answer = http::contour::run(request, tool.clone(), kerf_solver::corners::request::MAX_MOVES)
                    .map_err(|e| refused(index, &e))?;
                let program = http::contour::program(&answer, job.output.dialect, job.output.reference);
                http::contour::limit_stored_moves(&mut answer);
                OperationOutput {
                    operation: operation.kind().to_owned(),
                    result: serde_json::to_value(&answer).map_err(|e| JobFailure::Refused {
                        message: format!("operation {index}: result not serialisable: {e}"),
                        field: None,
                    })?,
                    gcode_problem: program.as_ref().err().map(|e| format!("{} ({})", e.message(), e.code())),
                    gcode: program.ok(),
                }
            }
        };
        outputs.push(output);
        progress((index + 1) as f64 / count as f64);
    }
    Ok(outputs)
}
