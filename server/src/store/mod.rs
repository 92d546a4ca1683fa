//! Repositories: the only place with SQL. Handlers call these functions.

pub mod jobs;
pub mod machines;
pub mod tools;

use kerf_solver::capability::Refs;
use kerf_solver::machine::MachineProfile;
use kerf_solver::tool::ToolRef;
use sqlx::SqlitePool;

use crate::capabilities::Catalog;
use crate::error::AppResult;

/// `catalog` completed with the tools and machines `refs` name that it lacks, from the tool table
/// and the machines registry (those that exist; resolution reports the others).
pub async fn catalog<'a>(
    db: &SqlitePool,
    refs: impl IntoIterator<Item = Refs<'a>>,
    mut catalog: Catalog,
) -> AppResult<Catalog> {
    for refs in refs {
        if let Some(ToolRef::Number(number)) = refs.tool
            && !catalog.tools.iter().any(|tool| tool.number == Some(*number))
            && let Some(tool) = tools::get(db, *number).await?
        {
            catalog.tools.push(tool);
        }
        if let Some(name) = refs.machine
            && !catalog.machines.iter().any(|machine| machine.name.as_deref() == Some(name))
            && let Some(machine) = machines::get(db, name).await?
        {
            catalog.machines.push(MachineProfile { name: Some(name.to_owned()), ..machine });
        }
    }
    Ok(catalog)
}
