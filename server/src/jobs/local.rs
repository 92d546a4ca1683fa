//! `kerf run JOB_FILE [-o OUT_DIR]`: runs a job file without the server, through the same parser,
//! resolution and execution as the job workers, and writes the results as files.

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use anyhow::{Context, bail};

use super::execute::{JobFailure, execute};
use super::file::{self, Format};
use super::program::{self, OperationOutput};
use crate::db::{self, Database};
use crate::error::AppError;

/// What `kerf run` wrote.
#[derive(Debug)]
pub struct RunReport {
    /// Files written, in order.
    pub files: Vec<PathBuf>,
}

fn describe(error: &AppError) -> String {
    let problem = error.problem();
    format!("{} ({})", problem.detail, problem.code)
}

/// Runs the job file at `path`, resolving tool numbers (and machine names) against `database`
/// when it exists, and writes `job.json`, one `NN-operation.json` per operation and its
/// `NN-operation.nc` program, and the job's one program `program.nc` into `out` (the files of
/// `GET /api/v1/jobs/{id}/outputs.zip`).
///
/// # Errors
/// When the file cannot be read or parsed, a tool is unknown, an operation is refused, or the
/// outputs cannot be written; the message names the line and field where known.
pub async fn run(path: &Path, out: &Path, database: Option<&Database>) -> anyhow::Result<RunReport> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let format = Format::detect(path.file_name().and_then(|n| n.to_str()), None, &text);
    let job = file::parse(&text, format).map_err(|e| anyhow::anyhow!("{}: {}", path.display(), describe(&e)))?;
    let pool = match database {
        Some(database) => db::open_read_only(database).await?,
        None => None,
    };
    let job = job.resolve(pool.as_ref()).await.map_err(|e| anyhow::anyhow!("{}: {}", path.display(), describe(&e)))?;

    let terminal = std::io::stderr().is_terminal();
    let show = move |fraction: f64| {
        if terminal {
            let filled = (fraction * 30.0).round() as usize;
            eprint!("\r[{}{}] {:3.0}%", "#".repeat(filled), " ".repeat(30 - filled.min(30)), fraction * 100.0);
            let _ = std::io::stderr().flush();
        }
    };
    show(0.0);
    let job_for_task = job.clone();
    let outputs = tokio::task::spawn_blocking(move || execute(&job_for_task, &show, &AtomicBool::new(false))).await?;
    if terminal {
        eprintln!();
    }
    let outputs = match outputs {
        Ok(outputs) => outputs,
        Err(JobFailure::Cancelled) => bail!("cancelled"),
        Err(JobFailure::Refused(problem)) => {
            let field = problem.errors.first().map(|error| format!(" [field {}]", error.path)).unwrap_or_default();
            bail!("{} ({}){field}", problem.detail, problem.code)
        }
    };

    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let mut files = Vec::new();
    let mut write = |name: String, contents: &[u8]| -> anyhow::Result<()> {
        let target = out.join(name);
        std::fs::write(&target, contents).with_context(|| format!("writing {}", target.display()))?;
        files.push(target);
        Ok(())
    };
    let rows: Vec<OperationOutput<'_>> = outputs
        .iter()
        .map(|output| OperationOutput {
            operation: &output.operation,
            result: output.result.get(),
            gcode: output.gcode.as_deref(),
            gcode_problem: output.gcode_problem.as_deref(),
        })
        .collect();
    // No job id here: the program number is the file's, else the first job number.
    let number = program::program_number(&job, None);
    for (name, contents) in program::files(&job, number, &rows) {
        write(name, &contents)?;
    }
    Ok(RunReport { files })
}
