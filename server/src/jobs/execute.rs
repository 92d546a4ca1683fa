//! Runs a resolved job: each operation in order through its capability (the registry's
//! [`crate::capabilities::Operation::run`]), with progress and cancellation. Pure apart from the two callbacks, so it
//! runs the same in the server's workers and in `kerf run`.

use kerf_solver::ErrorCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, PoisonError};

use kerf_solver::capability::{AnswerBudget, Control, Part, Purpose, Run, Split};

use super::file::JobFile;
use super::parts::{StoredParts, sizing};
use crate::capabilities::{Operation, PartBytes, Stored};
use crate::error::{AppError, Problem};

/// Why a job did not finish.
#[derive(Debug, Clone, PartialEq)]
pub enum JobFailure {
    /// The job was cancelled.
    Cancelled,
    /// An operation was refused: the problem its endpoint would answer, its field paths under
    /// `operations[i]`.
    Refused(Box<Problem>),
}

/// Runs `job` (already resolved: its tools and machines in it). `progress` receives the fraction
/// done (0–1), also within long operations (from their worker threads). Each operation's answer
/// (in memory, its JSON and its program) is built within `answer_limit` bytes, and refused with
/// `E_TOO_LARGE_ANSWER` when it would not fit, so a job's memory is bounded before it starts.
///
/// # Errors
/// The first refused operation's problem, or the cancellation.
pub fn execute(
    job: &JobFile,
    progress: &(dyn Fn(f64) + Sync),
    cancelled: &AtomicBool,
    answer_limit: u64,
) -> Result<Vec<Stored>, JobFailure> {
    let count = job.operations.len();
    let mut outputs = Vec::with_capacity(count);
    for index in 0..count {
        let within = |fraction: f64| progress((index as f64 + fraction) / count as f64);
        outputs.push(execute_operation(job, index, &within, cancelled, answer_limit)?);
        progress((index + 1) as f64 / count as f64);
    }
    Ok(outputs)
}

/// Runs operation `index` of `job` alone (a chunk of the job: what one worker claims on
/// PostgreSQL), exactly as [`execute`] runs it among the others. `progress` receives the
/// fraction of this operation done (0–1), increasing only.
///
/// # Errors
/// The operation's refusal (its fields under `operations[index]`), or the cancellation.
pub fn execute_operation(
    job: &JobFile,
    index: usize,
    progress: &(dyn Fn(f64) + Sync),
    cancelled: &AtomicBool,
    answer_limit: u64,
) -> Result<Stored, JobFailure> {
    within(job, index, progress, cancelled, answer_limit, |operation, run| {
        operation.run(job, run, &job.output.for_programs())
    })
}

/// How operation `index` of `job` divides into parts for different workers ([`sizing`]), or
/// `None` to solve it whole. CPU work (the capability reads the request): call it on a blocking
/// thread.
pub fn plan(job: &JobFile, index: usize) -> Option<Split> {
    job.operations.get(index)?.split(job, &sizing())
}

/// Solves part `part` of operation `index` (a chunk of an operation split by [`plan`]); its
/// output, for the finish step. `progress` as for [`execute_operation`], of this part.
///
/// # Errors
/// As [`execute_operation`].
pub fn execute_part(
    job: &JobFile,
    index: usize,
    part: &Part,
    progress: &(dyn Fn(f64) + Sync),
    cancelled: &AtomicBool,
    answer_limit: u64,
) -> Result<PartBytes, JobFailure> {
    within(job, index, progress, cancelled, answer_limit, |operation, run| operation.run_part(job, part, run))
}

/// The finish step of operation `index`, split by [`plan`]: merges its parts' outputs (in order)
/// into the operation's result and program, equal byte for byte to what [`execute_operation`]
/// stores (apart from the time an answer reports it took: `seconds`, the parts' solve time, plus
/// the finish step's).
///
/// # Errors
/// As [`execute_operation`].
pub fn execute_finish(
    job: &JobFile,
    index: usize,
    parts: Vec<Vec<u8>>,
    seconds: f64,
    progress: &(dyn Fn(f64) + Sync),
    cancelled: &AtomicBool,
    answer_limit: u64,
) -> Result<Stored, JobFailure> {
    let mut parts = StoredParts::new(parts);
    within(job, index, progress, cancelled, answer_limit, |operation, run| {
        operation.finish(job, &mut parts, run, &job.output.for_programs(), seconds)
    })
}

/// Runs `work` on operation `index` of `job` as a job runs it: with progress (passed on when it
/// increases) and cancellation, its answer within `answer_limit` bytes, its time recorded, its
/// refusal under `operations[index]`.
fn within<T>(
    job: &JobFile,
    index: usize,
    progress: &(dyn Fn(f64) + Sync),
    cancelled: &AtomicBool,
    answer_limit: u64,
    work: impl FnOnce(&Operation, &Run<'_>) -> Result<T, AppError>,
) -> Result<T, JobFailure> {
    let Some(operation) = job.operations.get(index) else {
        let error = AppError::Internal(anyhow::anyhow!("the job has no operation {index}"));
        return Err(JobFailure::Refused(Box::new(error.problem())));
    };
    if cancelled.load(Ordering::Relaxed) {
        return Err(JobFailure::Cancelled);
    }
    // Solvers report from their worker threads, not always in order: pass on increases only.
    let reached = Mutex::new(0.0_f64);
    let within = |fraction: f64| {
        let mut reached = reached.lock().unwrap_or_else(PoisonError::into_inner);
        if fraction > *reached {
            *reached = fraction;
            progress(fraction);
        }
    };
    let budget = AnswerBudget::new(answer_limit);
    let run = Run {
        control: Control { progress: Some(&within), cancel: Some(cancelled) },
        upload: None,
        purpose: Purpose::Job,
        budget: Some(&budget),
    };
    let started = std::time::Instant::now();
    let output = work(operation, &run).map_err(|error| failure(index, error))?;
    crate::metrics::observe_solver(operation.name(), started.elapsed().as_secs_f64());
    Ok(output)
}

fn failure(index: usize, error: AppError) -> JobFailure {
    if matches!(&error, AppError::Unprocessable(e) if e.code() == ErrorCode::Cancelled) {
        return JobFailure::Cancelled;
    }
    JobFailure::Refused(Box::new(error.under(&format!("operations[{index}]")).problem()))
}
