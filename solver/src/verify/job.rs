//! The validated verify request (docs/spec/verify.md §1 Request, §5 Limits): the tools' assemblies
//! by number, the stock and part models, the dexel grid with its memory bound checked before any
//! work, and the program as kerf's reader reads it.

use crate::capability::Control;
use crate::error::{ErrorCode, SolverError};
use crate::gcode::reader::{self, ReadOptions, ReadProgram};
use crate::tool::{Tool, ToolRef};
use crate::validate::{non_negative, positive};

use super::assembly::Assembly;
use super::dexel::{Grid, RAY_BYTES};
use super::request::{MAX_TOOLS, VerifyRequest};
use super::solid::SolidModel;

/// Most bytes the dexel fields of one request may take (the stock's and the part's rays).
pub const MAX_DEXEL_BYTES: u64 = 256 * 1024 * 1024;
/// Most rays the default resolution gives (a finer spacing must be asked for).
pub const MAX_DEFAULT_RAYS: f64 = 4_000_000.0;
/// The default resolution, in cutter radii of the smallest tool.
pub const DEFAULT_RESOLUTION_RADII: f64 = 0.05;
/// Default gouge tolerance, mm.
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Default allowance for material left, mm.
pub const DEFAULT_ALLOWANCE: f64 = 0.1;
/// Default share of cutting time in air before it is a finding.
pub const DEFAULT_AIR_SHARE_LIMIT: f64 = 0.5;

/// One tool of the request: the `T` number that calls it (none: it cuts every move) and its
/// assembly.
#[derive(Debug, Clone)]
pub(crate) struct CallableTool {
    pub number: Option<u32>,
    pub assembly: Assembly,
}

/// A validated request.
#[derive(Debug, Clone)]
pub(crate) struct Job {
    pub tools: Vec<CallableTool>,
    pub stock: SolidModel,
    pub part: Option<SolidModel>,
    pub grid: Grid,
    pub tolerance: f64,
    pub allowance: f64,
    pub air_share_limit: f64,
    pub program: ReadProgram,
}

impl VerifyRequest {
    /// The dexel grid over the stock at the request's resolution (default: from the smallest of
    /// `tools`).
    ///
    /// # Errors
    /// A bad stock or resolution; `E_GRID_MEMORY` at `resolution` when the fields would take
    /// more than [`MAX_DEXEL_BYTES`].
    pub(crate) fn grid(&self, tools: &[Tool]) -> Result<Grid, SolverError> {
        let stock = self.stock.model("stock")?;
        let (lo, hi) = stock.footprint();
        let fields = if self.part.is_some() { 2 } else { 1 };
        let spacing = match self.resolution {
            Some(spacing) => positive("resolution", spacing)?,
            None => {
                let smallest = tools.iter().map(|tool| tool.radius).fold(f64::INFINITY, f64::min);
                let spacing = DEFAULT_RESOLUTION_RADII * smallest;
                let rays = Grid::rays_for(lo, hi, spacing);
                if rays > MAX_DEFAULT_RAYS { spacing * (rays / MAX_DEFAULT_RAYS).sqrt() * 1.001 } else { spacing }
            }
        };
        let rays = Grid::rays_for(lo, hi, spacing);
        let bytes = rays * (RAY_BYTES * fields) as f64;
        if bytes > MAX_DEXEL_BYTES as f64 {
            return Err(SolverError::new(
                ErrorCode::GridMemory,
                format!(
                    "a dexel spacing of {spacing} mm over the stock's {:.1} × {:.1} mm needs {rays:.3e} rays ({:.0} MiB); \
                     the limit is {} MiB: use a coarser resolution",
                    hi[0] - lo[0],
                    hi[1] - lo[1],
                    bytes / 1024.0 / 1024.0,
                    MAX_DEXEL_BYTES / 1024 / 1024
                ),
            )
            .at("resolution"));
        }
        Ok(Grid::covering(lo, hi, spacing))
    }

    /// Validates the request with its resolved `tools` (in the order of `tools`), then reads the
    /// program under `control`.
    pub(crate) fn validate(&self, tools: &[Tool], control: Control<'_>) -> Result<Job, SolverError> {
        if self.tools.is_empty() || self.tools.len() > MAX_TOOLS {
            return Err(SolverError::input("tools", format!("give 1 to {MAX_TOOLS} tools (got {})", self.tools.len())));
        }
        let mut callable = Vec::with_capacity(tools.len());
        for (index, (reference, tool)) in self.tools.iter().zip(tools).enumerate() {
            let field = format!("tools[{index}]");
            tool.validate(&format!("{field}."))?;
            let number = match reference {
                ToolRef::Number(number) => Some(*number),
                ToolRef::Inline(inline) => inline.number,
            };
            if callable.iter().any(|other: &CallableTool| other.number == number) {
                return Err(SolverError::input(
                    field,
                    match number {
                        Some(number) => format!("two tools answer to T{number}"),
                        None => "only one tool may go without a number".to_owned(),
                    },
                ));
            }
            callable.push(CallableTool { number, assembly: Assembly::new(tool, &field)? });
        }
        if callable.len() > 1 && callable.iter().any(|tool| tool.number.is_none()) {
            return Err(SolverError::input(
                "tools",
                "with several tools each needs its number (the T word that calls it)",
            ));
        }
        let stock = self.stock.model("stock")?;
        let part = self.part.as_ref().map(|part| part.model("part")).transpose()?;
        let tolerance = non_negative("tolerance", self.tolerance.unwrap_or(DEFAULT_TOLERANCE))?;
        let allowance = non_negative("allowance", self.allowance.unwrap_or(DEFAULT_ALLOWANCE))?;
        let air_share_limit = non_negative("air_share_limit", self.air_share_limit.unwrap_or(DEFAULT_AIR_SHARE_LIMIT))?;
        if air_share_limit > 1.0 {
            return Err(SolverError::input("air_share_limit", "air_share_limit is a share: 0 to 1"));
        }
        let grid = self.grid(tools)?;
        let options = ReadOptions { block_delete: self.block_delete, ..ReadOptions::default() };
        let program = reader::read_cancellable(&self.program, "program", &options, control)?;
        Ok(Job { tools: callable, stock, part, grid, tolerance, allowance, air_share_limit, program })
    }
}

impl Job {
    /// The tool that cuts a move made while `called` was the last `T` word, at `line`.
    pub(crate) fn tool(&self, called: Option<u32>, line: usize) -> Result<&CallableTool, SolverError> {
        if let [only] = self.tools.as_slice()
            && (only.number.is_none() || called.is_none() || only.number == called)
        {
            return Ok(only);
        }
        let Some(number) = called else {
            return Err(SolverError::input(
                "tools",
                format!("line {line}: the program moves before any T word, and tools names several tools"),
            ));
        };
        self.tools.iter().find(|tool| tool.number == Some(number)).ok_or_else(|| {
            SolverError::input("tools", format!("line {line}: the program calls T{number}, which tools does not name"))
        })
    }
}
