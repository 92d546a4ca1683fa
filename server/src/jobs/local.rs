//! `kerf run JOB_FILE [-o OUT_DIR]`: runs a job file without the server, through the same parser,
//! resolution and execution as the job workers, and writes the results as files.
//!
//! The database is only read, as it is: `kerf run` never migrates it (a `kerf serve` of the
//! version that wrote it may still use it, and sqlx refuses to start on a schema with migrations
//! it does not know). A database from before a library's migration (the machines registry,
//! 0003; the materials library, 0006) therefore lacks its table: an operation that names a
//! machine or material the job file does not define is refused with the field
//! (`operations[i].material`), the migration the database predates and the ways out (`kerf
//! migrate`, or defining it in the file), not with an error of the missing table. Anything else
//! the database fails with is reported with its cause (there is no log here to point to).

use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use anyhow::{Context, bail};

use super::execute::{JobFailure, execute};
use super::file::{self, Format, JobFile};
use super::program::{self, OperationOutput};
use crate::db::{self, Database, Db};
use crate::error::AppError;
use crate::store;
use kerf_solver::tool::ToolRef;

/// What `kerf run` wrote.
#[derive(Debug)]
pub struct RunReport {
    /// Files written, in order.
    pub files: Vec<PathBuf>,
}

/// The problem as one line: its detail, code and field; an internal error with its cause (the
/// service logs that and answers without it, but here the one who reads this is the operator).
fn describe(error: &AppError) -> String {
    if let AppError::Internal(cause) = error {
        return format!("{cause:#}");
    }
    let problem = error.problem();
    let field = problem.errors.first().map(|error| format!(" [field {}]", error.path)).unwrap_or_default();
    format!("{} ({}){field}", problem.detail, problem.code)
}

/// A library an older database may lack: its table, the migration that made it, its name, what
/// the job file can give instead.
struct Library {
    table: &'static str,
    migration: &'static str,
    name: &'static str,
    instead: &'static str,
}

const TOOLS: Library = Library {
    table: "tools",
    migration: "0001",
    name: "tool table",
    instead: "define the tool under [[tools]] in the job file, or give it inline (tool = { kind = ..., radius = ... })",
};
const MACHINES: Library = Library {
    table: "machines",
    migration: "0003",
    name: "machines registry",
    instead: "define the machine under [[machines]] (with its name) in the job file",
};
const MATERIALS: Library = Library {
    table: "materials",
    migration: "0006",
    name: "materials library",
    instead: "define the material under [[materials]] (name, kc11, mc) in the job file, or give the operation \
              kienzle = { kc11 = ..., mc = ... } instead of material",
};

/// Refuses a job that needs a library `db` does not have yet (a database from before the
/// library's migration): the 404 naming the operation's field, the migration and how to get
/// on. References the job file defines itself need no library.
async fn check_libraries(db: &Db, database: &Database, job: &JobFile) -> Result<(), AppError> {
    let mut missing = Vec::new();
    for library in [TOOLS, MACHINES, MATERIALS] {
        if !store::has_table(db, library.table).await? {
            missing.push(library.table);
        }
    }
    if missing.is_empty() {
        return Ok(());
    }
    let refuse = |index: usize, field: &str, what: String, library: &Library| {
        AppError::unknown(
            format!("operations[{index}].{field}"),
            format!(
                "{what} is not defined in the job file, and the database {database} predates the {} (migration {}; \
                 kerf run reads a database as it is and never migrates it): upgrade it with `kerf migrate --database \
                 {database}` (or start kerf serve on it once), or {}",
                library.name, library.migration, library.instead
            ),
        )
    };
    for (index, operation) in job.operations.iter().enumerate() {
        let refs = operation.refs();
        if let Some(ToolRef::Number(number)) = refs.tool
            && missing.contains(&TOOLS.table)
            && !job.tools.iter().any(|tool| tool.number == Some(*number))
        {
            return Err(refuse(index, "tool", format!("tool {number}"), &TOOLS));
        }
        if let Some(name) = refs.machine
            && missing.contains(&MACHINES.table)
            && !job.machines.iter().any(|machine| machine.name.as_deref() == Some(name))
        {
            return Err(refuse(index, "machine", format!("machine {name:?}"), &MACHINES));
        }
        if let Some(name) = refs.material
            && missing.contains(&MATERIALS.table)
            && !job.materials.iter().any(|material| material.name.as_deref() == Some(name))
        {
            return Err(refuse(index, "material", format!("material {name:?}"), &MATERIALS));
        }
    }
    Ok(())
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
    if let (Some(db), Some(database)) = (&pool, database) {
        check_libraries(db, database, &job).await.map_err(|e| match e {
            AppError::Internal(cause) => anyhow::anyhow!("reading the database {database}: {cause:#}"),
            refused => anyhow::anyhow!("{}: {}", path.display(), describe(&refused)),
        })?;
    }
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
    // Alone in its process, with nothing else to keep alive: no limit but the machine's memory.
    let answer_limit = u64::MAX;
    let outputs =
        tokio::task::spawn_blocking(move || execute(&job_for_task, &show, &AtomicBool::new(false), answer_limit))
            .await?;
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
