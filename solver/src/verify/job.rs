//! The validated verify request (docs/spec/verify.md §1 Request, §5 Limits): the tools' assemblies
//! by number, the stock and part models, the dexel grid with its memory bound checked before any
//! work, and the program as kerf's reader reads it.

use crate::capability::Control;
use crate::error::{ErrorCode, SolverError};
use crate::gcode::reader::{self, ReadOptions, ReadProgram};
use crate::machine::MachineProfile;
use crate::material::{Kienzle, Material};
use crate::tool::{Tool, ToolRef};
use crate::validate::{Measure, non_negative, positive};

use super::assembly::Assembly;
use super::dexel::{Grid, RAY_BYTES};
use super::request::{MAX_TOOLS, Meshes, VerifyRequest};
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

/// One tool of the request: the `T` number that calls it (none: it cuts every move), its
/// assembly and its number of flutes.
#[derive(Debug, Clone)]
pub(crate) struct CallableTool {
    pub number: Option<u32>,
    pub assembly: Assembly,
    pub flutes: u32,
}

/// The spindle power a cut needs (docs/spec/verify.md §6 Spindle power): Kienzle's specific
/// cutting force at the mean chip thickness of a full-width slot, times the removal rate; and
/// the machine whose spindle it is checked against.
#[derive(Debug, Clone)]
pub(crate) struct PowerModel {
    pub kienzle: Kienzle,
    pub machine: Option<MachineProfile>,
}

impl PowerModel {
    /// The power in kW that removing `rate` mm³/min takes at `feed` mm/min and `spindle_rpm`
    /// with `flutes` teeth: f_z = F/(N·z), h_m = 2·f_z/π, k_c = k_c1.1·h_m^(−m_c) (N/mm², that is
    /// J/mm³), P = k_c·Q/(60·10⁶).
    pub fn kilowatts(&self, rate: f64, feed: f64, spindle_rpm: f64, flutes: u32) -> f64 {
        let per_tooth = feed / (spindle_rpm * f64::from(flutes));
        let mean_chip = 2.0 * per_tooth / std::f64::consts::PI;
        let specific = self.kienzle.kc11 * mean_chip.powf(-self.kienzle.mc);
        specific * rate / 60.0e6
    }

    /// The power the machine's spindle gives at `spindle_rpm`, kW, if the machine says.
    pub fn limit(&self, spindle_rpm: f64) -> Option<f64> {
        self.machine.as_ref()?.spindle_at(spindle_rpm).spindle_power_kw
    }
}

/// The material and machine the request names, as resolved.
#[derive(Debug, Clone, Copy, Default)]
pub struct Found<'a> {
    /// The work material.
    pub material: Option<&'a Material>,
    /// The machine.
    pub machine: Option<&'a MachineProfile>,
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
    pub power: Option<PowerModel>,
    pub program: ReadProgram,
}

impl VerifyRequest {
    /// The dexel grid over the stock at the request's resolution (default: from the smallest of
    /// `tools`).
    ///
    /// # Errors
    /// A bad stock or resolution; `E_GRID_MEMORY` at `resolution` when the fields would take
    /// more than [`MAX_DEXEL_BYTES`].
    pub(crate) fn grid(&self, stock: &SolidModel, tools: &[Tool]) -> Result<Grid, SolverError> {
        let (lo, hi) = stock.footprint();
        let fields = if self.part.is_some() { 2 } else { 1 };
        let spacing = match self.resolution {
            Some(spacing) => positive("resolution", spacing, Measure::Length)?,
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
                    "a dexel spacing of {spacing} mm over the stock's {:.1} mm × {:.1} mm needs {rays:.3e} rays ({:.0} MiB); \
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

    /// Validates the request with its resolved `tools` (in the order of `tools`) and its
    /// uploaded STL files (`upload`, laid out as [`Meshes`] says), then reads the program under
    /// `control`.
    pub(crate) fn validate(
        &self,
        tools: &[Tool],
        refs: Found<'_>,
        upload: Option<&[u8]>,
        control: Control<'_>,
    ) -> Result<Job, SolverError> {
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
            callable.push(CallableTool { number, assembly: Assembly::new(tool, &field)?, flutes: tool.flutes });
        }
        if callable.len() > 1 && callable.iter().any(|tool| tool.number.is_none()) {
            return Err(SolverError::input(
                "tools",
                "with several tools each needs its number (the T word that calls it)",
            ));
        }
        let meshes = Meshes::unpack(self, upload)?;
        let stock = self.stock.model("stock", meshes.stock)?;
        let part = self.part.as_ref().map(|part| part.model("part", meshes.part)).transpose()?;
        let tolerance = non_negative("tolerance", self.tolerance.unwrap_or(DEFAULT_TOLERANCE), Measure::Length)?;
        if let Some(part) = &part {
            within_footprint(part, &stock, tolerance)?;
        }
        let allowance = non_negative("allowance", self.allowance.unwrap_or(DEFAULT_ALLOWANCE), Measure::Length)?;
        let air_share_limit =
            non_negative("air_share_limit", self.air_share_limit.unwrap_or(DEFAULT_AIR_SHARE_LIMIT), Measure::Number)?;
        if air_share_limit > 1.0 {
            return Err(SolverError::input("air_share_limit", "air_share_limit is a share: 0 to 1"));
        }
        let power = match (refs.material, refs.machine) {
            (Some(material), machine) => Some(PowerModel { kienzle: material.kienzle(), machine: machine.cloned() }),
            (None, Some(_)) => {
                return Err(SolverError::input(
                    "machine",
                    "the machine's spindle power is checked against the power the cuts need, which needs `material`",
                ));
            }
            (None, None) => None,
        };
        let grid = self.grid(&stock, tools)?;
        let options = ReadOptions { block_delete: self.block_delete, ..ReadOptions::default() };
        let program = reader::read_cancellable(&self.program, "program", &options, control)?;
        Ok(Job { tools: callable, stock, part, grid, tolerance, allowance, air_share_limit, power, program })
    }
}

/// Refuses a `part` whose xy footprint reaches outside the `stock`'s by more than `tolerance`: the
/// dexel grid covers the stock only, so the part beyond it would go unchecked.
fn within_footprint(part: &SolidModel, stock: &SolidModel, tolerance: f64) -> Result<(), SolverError> {
    let ((part_lo, part_hi), (stock_lo, stock_hi)) = (part.footprint(), stock.footprint());
    for (k, axis) in ["x", "y"].into_iter().enumerate() {
        let beyond = (stock_lo[k] - part_lo[k]).max(part_hi[k] - stock_hi[k]);
        if beyond > tolerance {
            return Err(SolverError::input(
                "part",
                format!(
                    "the part reaches {beyond:.3} mm beyond the stock in {axis} (part {:.3} mm to {:.3} mm, stock {:.3} mm \
                     to {:.3} mm): the part must lie in the stock, in the program's coordinates",
                    part_lo[k], part_hi[k], stock_lo[k], stock_hi[k]
                ),
            ));
        }
    }
    Ok(())
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
