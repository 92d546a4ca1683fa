//! A job's outputs as files: the one program that runs every operation
//! (`kerf_solver::gcode::job`), and the set of files `kerf run -o DIR` writes and
//! `GET /api/v1/jobs/{id}/outputs.zip` holds: `job.json`, `NN-operation.json`,
//! `NN-operation.nc` and `program.nc`.

use kerf_solver::SolverError;
use kerf_solver::capability::Lookup;
use kerf_solver::gcode::{self, Dialect, job};
use kerf_solver::machine::MachineProfile;
use kerf_solver::tool::ToolRef;

use super::file::JobFile;

/// File name of the job's one program.
pub const PROGRAM_FILE: &str = "program.nc";

/// One operation's stored outputs.
#[derive(Debug, Clone, Copy)]
pub struct OperationOutput<'a> {
    /// The capability's name.
    pub operation: &'a str,
    /// Its answer as JSON, as its endpoint answers it.
    pub result: &'a str,
    /// Its program, if one was written.
    pub gcode: Option<&'a str>,
    /// Why none was written, if so.
    pub gcode_problem: Option<&'a str>,
}

/// The program number of a job: the file's `[output] program_number`, else one derived from the
/// job id (`None`: a local run, which has no id: 2000).
pub fn program_number(job: &JobFile, id: Option<i64>) -> u32 {
    job.output.program_number.unwrap_or_else(|| job::number_for_job(id.unwrap_or(1)))
}

/// The job's machine: the first operation's that names one.
fn machine(job: &JobFile) -> Option<MachineProfile> {
    job.operations.iter().find_map(|operation| operation.refs().machine.and_then(|name| job.machine(name)))
}

/// The dialect of the job program: the job's `[output] dialect`, else the job's machine's, else
/// Fanuc.
pub fn dialect(job: &JobFile) -> Dialect {
    job.output.dialect.unwrap_or_else(|| machine(job).map_or_else(Dialect::default, |machine| machine.dialect))
}

/// The post of operation `index`'s program: the job's `[output] dialect`, else its machine's,
/// else Fanuc (as its program was written).
pub fn operation_dialect(job: &JobFile, index: usize) -> Dialect {
    job.output
        .dialect
        .or_else(|| {
            let operation = job.operations.get(index)?;
            operation.refs().machine.and_then(|name| job.machine(name)).map(|machine| machine.dialect)
        })
        .unwrap_or_default()
}

/// The one program of `job` (numbered `number`) from its operations' outputs.
///
/// # Errors
/// `E_NO_PROGRAM` when no operation has a program.
pub fn job_program(job: &JobFile, number: u32, outputs: &[OperationOutput<'_>]) -> Result<String, SolverError> {
    let tools: Vec<Option<String>> = job
        .operations
        .iter()
        .map(|operation| {
            // A stored tool is in mm; an inline one in its operation's units.
            let (tool, radius_mm) = match operation.refs().tool? {
                ToolRef::Number(number) => {
                    let tool = job.tool(*number)?;
                    let radius = tool.radius;
                    (tool, radius)
                }
                ToolRef::Inline(tool) => (tool.clone(), tool.radius * operation.units(job).mm_per_unit()),
            };
            let name = tool.name.as_deref().map(|name| format!(" {name}")).unwrap_or_default();
            Some(format!("{} radius {} mm{name}", tool.kind.as_str(), gcode::mm(radius_mm)))
        })
        .collect();
    let machines: Vec<_> =
        job.operations.iter().map(|operation| operation.refs().machine.and_then(|name| job.machine(name))).collect();
    let operations: Vec<job::Operation<'_>> = outputs
        .iter()
        .enumerate()
        .map(|(index, output)| {
            let machine = machines.get(index).and_then(Option::as_ref);
            job::Operation {
                name: output.operation,
                program: output.gcode,
                problem: output.gcode_problem,
                tool: tools.get(index).and_then(Option::as_deref),
                rapid_feed: machine.map(|m| m.rapid_feed.unwrap_or(m.max_feed)),
                tool_change_s: machine.and_then(|m| m.tool_change_s),
            }
        })
        .collect();
    let title = match &job.name {
        Some(name) => format!("kerf job {name}"),
        None => "kerf job".to_owned(),
    };
    let coolant = job.output.coolant.unwrap_or_default();
    let haas_smoothing = machine(job).and_then(|machine| machine.haas_smoothing);
    job::write(&job::Job { dialect: dialect(job), number, title: &title, coolant, haas_smoothing }, &operations)
}

/// Every output file of a job, in order: `job.json` (name, program number, and per operation
/// whether it has a program), each operation's answer and program, and the job's program.
pub fn files(job: &JobFile, number: u32, outputs: &[OperationOutput<'_>]) -> Vec<(String, Vec<u8>)> {
    let program = job_program(job, number, outputs);
    let summary = serde_json::json!({
        "name": job.name,
        "program_number": number,
        "program": program.as_ref().ok().map(|_| PROGRAM_FILE),
        "program_problem": program.as_ref().err().map(|e| format!("{} ({})", e.message(), e.code())),
        "operations": outputs.iter().map(|o| serde_json::json!({
            "operation": o.operation, "gcode": o.gcode.is_some(), "gcode_problem": o.gcode_problem
        })).collect::<Vec<_>>(),
    });
    let mut files = vec![("job.json".to_owned(), serde_json::to_vec_pretty(&summary).unwrap_or_default())];
    for (index, output) in outputs.iter().enumerate() {
        files.push((format!("{index:02}-{}.json", output.operation), output.result.as_bytes().to_vec()));
        if let Some(gcode) = output.gcode {
            files.push((format!("{index:02}-{}.nc", output.operation), gcode.as_bytes().to_vec()));
        }
    }
    if let Ok(program) = program {
        files.push((PROGRAM_FILE.to_owned(), program.into_bytes()));
    }
    files
}
