//! Checks of a parsed job file beyond its shape.

use kerf_solver::machine::{MachineProfile, validate_machine_name};
use kerf_solver::material::{Material, validate_material_name};
use kerf_solver::stock::Stock;

use super::parse::file_error;
use super::{JobFile, MAX_OPERATIONS};
use crate::capabilities::Operation;
use crate::error::AppResult;

/// Longest job name.
const MAX_JOB_NAME_CHARS: usize = 200;

/// Checks what a job file's shape does not say: 1 to [`MAX_OPERATIONS`] operations, a short
/// name, tools, machines and materials each once and valid, and no operation that needs an
/// upload.
pub(super) fn check(job: &JobFile) -> AppResult<()> {
    if job.operations.is_empty() || job.operations.len() > MAX_OPERATIONS {
        return Err(file_error("operations", None, &format!("a job needs 1 to {MAX_OPERATIONS} operations")));
    }
    if let Some(name) = &job.name {
        kerf_solver::validate::text("name", name, MAX_JOB_NAME_CHARS)?;
    }
    for (index, tool) in job.tools.iter().enumerate() {
        let field = format!("tools[{index}]");
        let Some(number) = tool.number else {
            return Err(file_error(&format!("{field}.number"), None, "tools in a job file need their number"));
        };
        tool.validate(&format!("{field}."))?;
        if job.tools[..index].iter().any(|t| t.number == Some(number)) {
            return Err(file_error(&format!("{field}.number"), None, &format!("tool {number} is defined twice")));
        }
    }
    if let Some(number) = job.output.program_number {
        kerf_solver::gcode::job::check_number("output.program_number", number)?;
    }
    for (index, operation) in job.operations.iter().enumerate() {
        if let Operation::Predict(request) = operation
            && matches!(request.stock, Stock::Mesh { .. })
        {
            return Err(file_error(
                &format!("operations[{index}].stock.kind"),
                None,
                "a job file cannot carry the STL file of a mesh stock: use a box, plane, cylinder or height grid \
                 stock, or send the request to POST /api/v1/predict as multipart/form-data",
            ));
        }
        if let Operation::Verify(request) = operation {
            let meshes = [("part", request.part.as_ref()), ("stock", Some(&request.stock))];
            if let Some((name, _)) = meshes.into_iter().find(|(_, solid)| solid.is_some_and(|solid| solid.is_mesh())) {
                return Err(file_error(
                    &format!("operations[{index}].{name}.kind"),
                    None,
                    &format!(
                        "a job file cannot carry the STL file of a mesh {name}: use a box, cylinder, tube or height \
                         grid, or send the request to POST /api/v1/verify as multipart/form-data"
                    ),
                ));
            }
        }
    }
    check_machines(&job.machines)?;
    check_materials(&job.materials)
}

/// Every material of a job file has a valid name, once, and valid values (422 like a PUT).
fn check_materials(materials: &[Material]) -> AppResult<()> {
    for (index, material) in materials.iter().enumerate() {
        let field = format!("materials[{index}]");
        let Some(name) = &material.name else {
            return Err(file_error(&format!("{field}.name"), None, "materials in a job file need their name"));
        };
        let prefixed = |error: kerf_solver::SolverError| {
            let at = error.field().map_or_else(|| field.clone(), |inner| format!("{field}.{inner}"));
            error.at(at)
        };
        validate_material_name(name).map_err(prefixed)?;
        material.validate().map_err(prefixed)?;
        if materials[..index].iter().any(|m| m.name == material.name) {
            return Err(file_error(&format!("{field}.name"), None, &format!("material {name:?} is defined twice")));
        }
    }
    Ok(())
}

/// Every machine of a job file has a valid name, once, and valid values (422 like a PUT).
fn check_machines(machines: &[MachineProfile]) -> AppResult<()> {
    for (index, machine) in machines.iter().enumerate() {
        let field = format!("machines[{index}]");
        let Some(name) = &machine.name else {
            return Err(file_error(&format!("{field}.name"), None, "machines in a job file need their name"));
        };
        let prefixed = |error: kerf_solver::SolverError| {
            let at = error.field().map_or_else(|| field.clone(), |inner| format!("{field}.{inner}"));
            error.at(at)
        };
        validate_machine_name(name).map_err(prefixed)?;
        machine.validate().map_err(prefixed)?;
        if machines[..index].iter().any(|m| m.name == machine.name) {
            return Err(file_error(&format!("{field}.name"), None, &format!("machine {name:?} is defined twice")));
        }
    }
    Ok(())
}
