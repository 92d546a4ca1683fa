//! Job files: a name, optional tools, output options and a list of operations, each with the
//! same request its endpoint takes. JSON or TOML; errors point at the line and the field.
//!
//! ```toml
//! name = "manifold deburr"
//! [output]
//! dialect = "linuxcnc"
//!
//! [[tools]]
//! number = 7
//! kind = "ball"
//! radius = 3
//!
//! [[operations]]
//! operation = "deburr"
//! tool = 7
//! edge = "outer"
//! cut_amount = 0.2
//! workpiece = { kind = "tube", origin = [0, 0, 0], inner_radius = 15, outer_radius = 25 }
//! hole = { shape = "round", radius = 5 }
//! ```
//!
//! Machines and materials work like tools: `[[machines]]` and `[[materials]]` entries (each with
//! its `name`) are used before the machines registry and the materials library when an operation
//! names a `machine` or a `material`.
//!
//! Reading a file is `parse` (the text into a [`JobFile`]) and `check` (what its shape does not
//! say); this module holds the job file's types and its resolution against the store.

use kerf_solver::capability::{self, Lookup, Refs, Units};
use kerf_solver::gcode::job::Coolant;
use kerf_solver::gcode::{Arcs, Dialect, Reference};
use kerf_solver::machine::MachineProfile;
use kerf_solver::material::Material;
use kerf_solver::tool::{Tool, ToolRef};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use utoipa::ToSchema;

use crate::capabilities::{Catalog, Operation, machine_in, material_in, tool_in};
use crate::db::Db;
use crate::error::AppResult;
use crate::store;

mod check;
mod parse;

pub use parse::{Format, parse};

/// Most operations one job may hold.
pub const MAX_OPERATIONS: usize = 100;
/// Deepest nesting of arrays and tables accepted in a job file.
pub const MAX_NESTING: usize = 32;

/// A job file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct JobFile {
    /// Free-text name shown in job lists.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Tools the operations may name by number; they take precedence over the tool table. Once
    /// submitted, the job holds exactly the tools its operations name by number, from the file or
    /// the tool table.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tools: Vec<Tool>,
    /// Machines (controller profiles, each with its `name`) the operations may name; they take
    /// precedence over the machines registry. Once submitted, the job holds exactly the machines
    /// its operations name, from the file or the registry.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub machines: Vec<MachineProfile>,
    /// Work materials (Kienzle values, each with its `name`) the operations may name; they take
    /// precedence over the materials library. Once submitted, the job holds exactly the
    /// materials its operations name, from the file or the library.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub materials: Vec<Material>,
    /// `mm` or `inch`: the units of every operation that does not say its own `units` (before its
    /// machine's; default: each operation's machine's, else mm).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<Units>,
    /// How the G-code of every operation is written.
    #[serde(default)]
    pub output: OutputOptions,
    /// The operations, run in order (1–100).
    pub operations: Vec<Operation>,
}

impl store::jobs::Submission for JobFile {
    fn job_name(&self) -> Option<&str> {
        self.name.as_deref()
    }

    fn operation_names(&self) -> Vec<&str> {
        self.operations.iter().map(Operation::name).collect()
    }
}

/// G-code options of a job.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct OutputOptions {
    /// The post (`fanuc`, `haas`, `linuxcnc`, `sinumerik`, `heidenhain`, `heidenhain_iso`, `grbl`;
    /// docs/guide/gcode.md); default: each operation's machine's, else `fanuc`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dialect: Option<Dialect>,
    /// `tip` or `centre`; default `tip` (a predict operation's G-code path keeps its own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<Reference>,
    /// `g2g3` (circular moves as G02/G03) or `chords`; default each operation's machine's
    /// `arcs`, else `chords`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arcs: Option<Arcs>,
    /// Number of the job's one program (`GET /api/v1/jobs/{id}/program`): 1–7999; default
    /// `2000 + (id − 1) mod 6000` (`kerf run`: 2000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = 1, maximum = 7999)]
    pub program_number: Option<u32>,
    /// Coolant of every operation in the job's one program: `off` (default), `flood` (M08) or
    /// `mist` (M07); M09 after each operation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coolant: Option<Coolant>,
}

impl OutputOptions {
    /// The options every operation's program is written with.
    pub fn for_programs(&self) -> capability::OutputOptions {
        capability::OutputOptions {
            dialect: self.dialect,
            reference: self.reference,
            candidate: None,
            arcs: self.arcs,
            units: None,
        }
    }
}

impl JobFile {
    /// The job with exactly the tools, machines and materials its operations name, each from the
    /// file, else the tool table, machines registry and materials library of `db` (when given),
    /// so it runs anywhere without the database. Every reference is resolved here once, with the
    /// capability's own resolution.
    ///
    /// # Errors
    /// 404 naming `operations[i].tool`, `operations[i].machine` or `operations[i].material` for
    /// an unknown reference.
    pub async fn resolve(mut self, db: Option<&Db>) -> AppResult<Self> {
        let given = Catalog {
            tools: std::mem::take(&mut self.tools),
            machines: std::mem::take(&mut self.machines),
            materials: std::mem::take(&mut self.materials),
        };
        let all_refs: Vec<Refs<'_>> = self.operations.iter().flat_map(|operation| operation.all_refs()).collect();
        let found = match db {
            Some(db) => crate::capabilities::catalog(db, all_refs, given).await?,
            None => given,
        };
        for (index, operation) in self.operations.iter().enumerate() {
            operation.check_refs(&found).map_err(|error| error.under(&format!("operations[{index}]")))?;
        }
        let refs: Vec<_> = self.operations.iter().flat_map(|operation| operation.all_refs()).collect();
        let numbers: Vec<u32> = refs
            .iter()
            .filter_map(|r| match r.tool {
                Some(ToolRef::Number(number)) => Some(*number),
                _ => None,
            })
            .collect();
        let names: Vec<&str> = refs.iter().filter_map(|r| r.machine).collect();
        let material_names: Vec<&str> = refs.iter().filter_map(|r| r.material).collect();
        let tools = found.tools.into_iter().filter(|t| t.number.is_some_and(|n| numbers.contains(&n))).collect();
        let machines =
            found.machines.into_iter().filter(|m| m.name.as_deref().is_some_and(|n| names.contains(&n))).collect();
        self.tools = tools;
        self.machines = machines;
        self.materials = found
            .materials
            .into_iter()
            .filter(|m| m.name.as_deref().is_some_and(|n| material_names.contains(&n)))
            .collect();
        Ok(self)
    }

    /// SHA-256 of the resolved job's canonical JSON: identical jobs have identical hashes.
    pub fn content_hash(&self) -> String {
        let bytes = serde_json::to_vec(self).unwrap_or_default();
        Sha256::digest(bytes).iter().map(|b| format!("{b:02x}")).collect()
    }
}

/// A resolved job is its own lookup: its operations find their tools, machines and materials in
/// it.
impl Lookup for JobFile {
    fn tool(&self, number: u32) -> Option<Tool> {
        tool_in(&self.tools, number)
    }

    fn machine(&self, name: &str) -> Option<MachineProfile> {
        machine_in(&self.machines, name)
    }

    fn material(&self, name: &str) -> Option<Material> {
        material_in(&self.materials, name)
    }

    fn units(&self) -> Option<Units> {
        self.units
    }
}
