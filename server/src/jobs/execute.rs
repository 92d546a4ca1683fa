//! Runs a resolved job: each operation in order through the same code as its endpoint, with
//! progress and cancellation. Pure apart from the two callbacks, so it runs the same in the
//! server's workers and in `kerf run`.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};

use kerf_solver::SolverError;
use kerf_solver::chord::MachineProfile;
use kerf_solver::predict::Control;
use kerf_solver::tool::{Tool, ToolRef};
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

/// The tool of operation `index`, which resolution has made inline.
fn resolved_tool(index: usize, tool: &ToolRef) -> Result<Tool, JobFailure> {
    match tool {
        ToolRef::Inline(tool) => Ok(tool.clone()),
        ToolRef::Number(_) => Err(JobFailure::Refused {
            message: format!("operation {index}: the tool was not resolved"),
            field: Some(format!("operations[{index}].tool")),
        }),
    }
}

/// The stored output of operation `index`: its answer as JSON and its program, or why none.
fn output<T: Serialize>(
    index: usize,
    operation: &Operation,
    answer: &T,
    program: Result<String, SolverError>,
) -> Result<OperationOutput, JobFailure> {
    Ok(OperationOutput {
        operation: operation.kind().to_owned(),
        result: serde_json::to_value(answer).map_err(|e| JobFailure::Refused {
            message: format!("operation {index}: result not serialisable: {e}"),
            field: None,
        })?,
        gcode_problem: program.as_ref().err().map(|e| format!("{} ({})", e.message(), e.code())),
        gcode: program.ok(),
    })
}

/// The machine operation `index` names, which resolution has put in the job's `machines`.
fn resolved_machine(job: &JobFile, index: usize, name: Option<&str>) -> Result<Option<MachineProfile>, JobFailure> {
    let Some(name) = name else { return Ok(None) };
    job.machine(name).cloned().map(Some).ok_or_else(|| JobFailure::Refused {
        message: format!("operation {index}: the machine {name:?} was not resolved"),
        field: Some(format!("operations[{index}].machine")),
    })
}

/// Runs `job` (already resolved: tools inline). `progress` receives the fraction done (0–1),
/// also within long operations (from their worker threads).
pub fn execute(
    job: &JobFile,
    progress: &(dyn Fn(f64) + Sync),
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
                let machine = resolved_machine(job, index, request.machine.as_deref())?;
                let answer = http::deburr::run(request, resolved_tool(index, &request.tool)?, machine)
                    .map_err(|e| refused(index, &e))?;
                let program = http::deburr::program(&answer, job.output.dialect, job.output.reference);
                output(index, operation, &answer, program)?
            }
            Operation::Segment(request) => {
                let tool = request.tool.as_ref().map(|tool| resolved_tool(index, tool)).transpose()?;
                let machine = resolved_machine(job, index, request.machine.as_deref())?;
                let answer = http::segment::run(request, machine, tool).map_err(|e| refused(index, &e))?;
                let program = http::segment::program(&answer, job.output.dialect);
                output(index, operation, &answer, program)?
            }
            Operation::Contour(request) => {
                // A job goes up to the solver's move limit; its stored JSON keeps what fits.
                let tool = resolved_tool(index, &request.tool)?;
                let machine = resolved_machine(job, index, request.machine.as_deref())?;
                let mut answer = http::contour::run(request, tool, machine, kerf_solver::corners::request::MAX_MOVES)
                    .map_err(|e| refused(index, &e))?;
                let program = http::contour::program(&answer, job.output.dialect, job.output.reference);
                http::contour::limit_stored_moves(&mut answer);
                output(index, operation, &answer, program)?
            }
            Operation::Engagement(request) => {
                let tool = resolved_tool(index, &request.tool)?;
                let machine = resolved_machine(job, index, request.machine.as_deref())?;
                let answer = http::engagement::run(request, tool, machine).map_err(|e| refused(index, &e))?;
                // One program per operation: the first path's.
                let program = http::engagement::program(&answer, 0, job.output.dialect, job.output.reference);
                output(index, operation, &answer, program)?
            }
            Operation::Predict(request) => {
                let tool = resolved_tool(index, &request.tool)?;
                // The solver reports from its worker threads, not always in order: pass on
                // increases only, scaled into this operation's share of the job.
                let reached = Mutex::new(0.0_f64);
                let within = |fraction: f64| {
                    let mut reached = reached.lock().unwrap_or_else(PoisonError::into_inner);
                    if fraction > *reached {
                        *reached = fraction;
                        progress((index as f64 + fraction) / count as f64);
                    }
                };
                let control = Control { progress: Some(&within), cancel: Some(cancelled) };
                let answer = match http::predict::run(request, tool, None, &control) {
                    Ok(answer) => answer,
                    Err(error) if error.code() == "E_CANCELLED" => return Err(JobFailure::Cancelled),
                    Err(error) => return Err(refused(index, &error)),
                };
                let program = http::predict::job_program(request, &answer, job.output.dialect, job.output.reference);
                output(index, operation, &answer, program)?
            }
        };
        outputs.push(output);
        progress((index + 1) as f64 / count as f64);
    }
    Ok(outputs)
}
