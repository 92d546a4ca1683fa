//! Verifying the program a capability writes by cutting it on the capability's own model
//! (docs/spec/verify.md §9): the stock and the part the capability knows, as dexel fields; the
//! program as the post writes it, read back by kerf's reader and cut by the simulation; what it
//! finds becomes the answer's `verification` section, and its gouges, rapids through material
//! and holder contacts warnings of the answer and comments in the program's header.

use serde::{Deserialize, Serialize};

use super::assembly::Assembly;
pub(crate) use super::dexel::Grid;
use super::dexel::{Field, RAY_BYTES, Ray};
use super::job::{CallableTool, DEFAULT_TOLERANCE, Job, MAX_DEXEL_BYTES};
use super::mesh::Against;
use super::simulate::{self, Finding, FindingKind};
use super::solid::{Axis, SolidModel};
use crate::capability::{Control, Run};
use crate::error::{ErrorCode, SolverError, Warning};
use crate::gcode::reader::{self, ReadOptions};
use crate::geometry::Vec3;
use crate::planar::{Vec2, point_segment_distance, vec2};
use crate::stock::StockModel;
use crate::tool::Tool;
use crate::units::{Scale, Units};
use crate::validate::{Measure, positive};

/// Most rays the default resolution of a capability's own verification gives: a coarser grid
/// than `POST /api/v1/verify`'s, so that verifying adds little to the request (docs/spec/verify.md
/// §9.3).
pub const OWN_MAX_DEFAULT_RAYS: f64 = 250_000.0;
/// The default resolution, in radii of the capability's tool (before the ray cap coarsens it).
pub const OWN_RESOLUTION_RADII: f64 = 0.1;
/// Most bytes of a `verification` section in an answer: its figures and at most
/// [`MAX_FINDINGS`](super::MAX_FINDINGS) findings of at most 300 bytes of JSON each (the answer
/// bounds of the capabilities that verify add it).
pub const VERIFICATION_BYTES: u64 = 4096 + super::simulate::MAX_FINDINGS as u64 * 300;
/// Thickness of the floor modelled under the deepest cut, mm: a move below the last layer cuts
/// into it and gouges.
pub const FLOOR_THICKNESS: f64 = 1.0;

/// How a capability verifies its program: request field `verification`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct VerificationOptions {
    /// Cut the program on the capability's own model and answer `verification` (default true).
    #[serde(default = "enabled")]
    pub enabled: bool,
    /// Dexel spacing, mm (> 0). Default: a tenth of the tool radius, coarsened so the grid holds
    /// at most 250 000 rays. A spacing whose grid would exceed the memory limit is refused
    /// (`E_GRID_MEMORY` at `verification.resolution`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<f64>,
}

fn enabled() -> bool {
    true
}

impl Default for VerificationOptions {
    fn default() -> Self {
        Self { enabled: true, resolution: None }
    }
}

/// The `verification` section of an answer: the capability's program cut on its own stock and
/// compared with its own part.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Verification {
    /// Whether nothing was found.
    pub ok: bool,
    /// The findings, as `POST /api/v1/verify` answers them (the `line` is the program's line as
    /// written with the default output options), at most 1000.
    pub findings: Vec<Finding>,
    /// Findings beyond the first 1000, counted only.
    pub findings_left_off: usize,
    /// Why `ok` is false without findings: the program never meets the model's stock.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
    /// What was cut and compared: the stock and the part as modelled.
    pub model: String,
    /// What the cut assumed of a tool that does not say (the defaults of docs/spec/verify.md §2),
    /// one sentence per such tool: where the holder sits and how wide it is, which decide every
    /// holder contact found. Absent when every tool gives its `stickout` and `holder_diameter`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub assumed: Vec<String>,
    /// The dexel spacing used, mm.
    pub resolution: f64,
    /// Rays of the model (x by y).
    pub rays: [usize; 2],
    /// Depth inside the part (along z) that counts as a gouge, mm.
    pub tolerance: f64,
    /// Thickness left outside the part (along z) that counts as material left, mm.
    pub allowance: f64,
    /// Horizontal band about the part's vertical walls left out of both fields, mm: a z-dexel
    /// meets a wall only along its height, so a wall is checked to within this distance.
    pub wall_tolerance: f64,
    /// Stock volume before the program, mm³.
    pub stock_volume_mm3: f64,
    /// Part volume, mm³ (0 when the capability knows no part: predict and engagement).
    pub part_volume_mm3: f64,
    /// Volume the program removed, mm³.
    pub removed_volume_mm3: f64,
    /// Share of the feed-move time that cut nothing (leads, loops and links run in air by
    /// design, so it is reported, never a finding).
    pub air_share: f64,
    /// Motion blocks read from the program.
    pub moves: usize,
    /// Ray queries the sweeps made (a measure of the work).
    pub dexel_updates: u64,
}

/// A capability's own model: the stock and the part on a grid.
pub(crate) trait OwnModel {
    /// The xy rectangle holding the stock and every ray the tool may reach.
    fn footprint(&self) -> ([f64; 2], [f64; 2]);
    /// The stock and the part on `grid` (`None`: the capability knows no part, so nothing is
    /// compared with one). `lowest` is the lowest tip height the program reaches: a stock with
    /// no bottom of its own is floored [`FLOOR_THICKNESS`] under it.
    fn fields(&self, grid: Grid, lowest: f64, control: Control<'_>) -> Result<(Field, Option<Field>), SolverError>;
    /// What is modelled, in a sentence.
    fn describe(&self) -> String;
}

/// What a cut-stock request asks besides its model: the last line cut (every line: `None`) and
/// the units of the answer.
#[derive(Debug, Clone, Copy)]
pub(crate) struct StockAsk {
    pub upto_line: Option<usize>,
    pub units: Units,
}

/// How the model is compared: tolerances along z and across walls.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    pub tolerance: f64,
    pub allowance: f64,
    pub wall_tolerance: f64,
}

impl Limits {
    /// The limits of a model without a part (predict's, engagement's): the defaults, there being
    /// no part to set them by.
    pub(crate) const WITHOUT_PART: Self =
        Self { tolerance: OWN_TOLERANCE, allowance: crate::verify::DEFAULT_ALLOWANCE, wall_tolerance: 0.0 };
}

/// The program a capability's own verification cuts: the one its answer writes with the default
/// output options (Fanuc), whose lines the findings and a playback's `upto_line` count.
///
/// # Errors
/// As the capability's program writer.
pub(crate) fn program<C: crate::capability::Capability>(
    request: &C::Request,
    answer: &C::Answer,
    run: &Run<'_>,
) -> Result<String, SolverError> {
    let output = crate::capability::OutputOptions {
        dialect: Some(crate::gcode::Dialect::Fanuc),
        ..crate::capability::OutputOptions::default()
    };
    crate::capability::program::<C>(request, answer, &output, run.control)
}

/// The grid of `footprint` at the request's resolution, or the default for `tool`.
///
/// # Errors
/// `E_INPUT` for a resolution that is not positive, `E_GRID_MEMORY` when the stock and part
/// fields would exceed [`MAX_DEXEL_BYTES`]; both at `verification.resolution`.
pub(crate) fn grid(
    footprint: ([f64; 2], [f64; 2]),
    tool: &Tool,
    options: &VerificationOptions,
) -> Result<Grid, SolverError> {
    let (lo, hi) = footprint;
    let spacing = match options.resolution {
        Some(spacing) => positive("verification.resolution", spacing, Measure::Length)?,
        None => {
            let spacing = OWN_RESOLUTION_RADII * tool.radius;
            let rays = Grid::rays_for(lo, hi, spacing);
            if rays > OWN_MAX_DEFAULT_RAYS { spacing * (rays / OWN_MAX_DEFAULT_RAYS).sqrt() * 1.001 } else { spacing }
        }
    };
    let rays = Grid::rays_for(lo, hi, spacing);
    // The stock's and the part's rays, and a distance per ray while the model is built.
    let bytes = rays * (2 * RAY_BYTES + 8) as f64;
    if bytes > MAX_DEXEL_BYTES as f64 {
        return Err(SolverError::new(
            ErrorCode::GridMemory,
            format!(
                "a verification spacing of {spacing} mm over {:.1} mm × {:.1} mm needs {rays:.3e} rays ({:.0} MiB); the \
                 limit is {} MiB: use a coarser verification.resolution or turn verification off",
                hi[0] - lo[0],
                hi[1] - lo[1],
                bytes / 1024.0 / 1024.0,
                MAX_DEXEL_BYTES / 1024 / 1024
            ),
        )
        .at("verification.resolution"));
    }
    Ok(Grid::covering(lo, hi, spacing))
}

/// Cuts `program` (a program kerf wrote, every move by `tool`) out of `model`'s stock on `grid`
/// and compares what is left with its part.
///
/// # Errors
/// The reader's refusals of the program (a bug: kerf reads what it writes), `E_CANCELLED`.
pub(crate) fn verify(
    model: &dyn OwnModel,
    grid: Grid,
    program: &str,
    tool: &Tool,
    limits: Limits,
    run: &Run<'_>,
) -> Result<Verification, SolverError> {
    verify_tools(model, grid, program, &[(None, tool)], limits, run)
}

/// [`verify`] with several tools, each with the `T` number the program calls it by (one tool
/// without a number cuts every move).
///
/// # Errors
/// As [`verify`].
pub(crate) fn verify_tools(
    model: &dyn OwnModel,
    grid: Grid,
    program: &str,
    tools: &[(Option<u32>, &Tool)],
    limits: Limits,
    run: &Run<'_>,
) -> Result<Verification, SolverError> {
    let job = own_job(model, grid, program, tools, limits, run)?;
    let (stock, part) = model.fields(grid, lowest_tip(&job), run.control)?;
    let description = model.describe();
    let assumed = assumed_holders(tools);
    let cut = match simulate::cut_fields(&job, stock, part, &unbudgeted(run)).map(|(cut, _)| cut) {
        Ok(cut) => cut,
        // The model and the program disagree (the tool never meets the stock): said, not refused,
        // since the program itself was solved.
        Err(error) if error.code() == ErrorCode::Stock => {
            return Ok(Verification {
                ok: false,
                findings: Vec::new(),
                findings_left_off: 0,
                note: Some("the program never reaches its own stock: the model does not fit the program".to_owned()),
                model: description,
                assumed,
                resolution: grid.spacing,
                rays: [grid.nx, grid.ny],
                tolerance: limits.tolerance,
                allowance: limits.allowance,
                wall_tolerance: limits.wall_tolerance,
                stock_volume_mm3: 0.0,
                part_volume_mm3: 0.0,
                removed_volume_mm3: 0.0,
                air_share: 0.0,
                moves: job.program.moves.len(),
                dexel_updates: 0,
            });
        }
        Err(error) => return Err(error),
    };
    Ok(verification_of(cut, description, assumed, limits))
}

/// The holder each tool of `tools` that does not give its `stickout` or `holder_diameter` is
/// assumed to have ([`Verification::assumed`]), from the assembly the cut used.
pub(crate) fn assumed_holders(tools: &[(Option<u32>, &Tool)]) -> Vec<String> {
    tools
        .iter()
        .filter_map(|&(number, tool)| {
            if tool.stickout.is_some() && tool.holder_diameter.is_some() {
                return None;
            }
            let assembly = Assembly::new(tool, "tool").ok()?;
            let holder = assembly.bodies.last()?;
            let super::assembly::Shape::Cylinder { base: face } = holder.shape else { return None };
            let mut assumed = Vec::new();
            let mut missing = Vec::new();
            if tool.stickout.is_none() {
                assumed.push(format!("the holder face {face:.3} mm above the tip"));
                missing.push("stickout");
            }
            if tool.holder_diameter.is_none() {
                assumed.push(format!("the holder {:.3} mm across", 2.0 * holder.radius));
                missing.push("holder_diameter");
            }
            let name = number.map_or_else(|| "the tool".to_owned(), |number| format!("T{number}"));
            Some(format!("{name}: {} assumed (the tool gives no {})", assumed.join(" and "), missing.join(" or ")))
        })
        .collect()
}

/// The simulation's job for `program` on `model`'s grid: the fields are built by the caller, the
/// job's solids are only their bounds.
fn own_job(
    model: &dyn OwnModel,
    grid: Grid,
    program: &str,
    tools: &[(Option<u32>, &Tool)],
    limits: Limits,
    run: &Run<'_>,
) -> Result<Job, SolverError> {
    let options = ReadOptions { max_lines: usize::MAX, ..ReadOptions::default() };
    let read = reader::read_cancellable(program, "program", &options, run.control)?;
    let (lo, hi) = model.footprint();
    Ok(Job {
        tools: tools
            .iter()
            .map(|(number, tool)| {
                Ok(CallableTool { number: *number, assembly: Assembly::new(tool, "tool")?, flutes: tool.flutes })
            })
            .collect::<Result<_, SolverError>>()?,
        stock: SolidModel::Stock(StockModel::Box {
            lo: Vec3::new(lo[0], lo[1], 0.0),
            hi: Vec3::new(hi[0], hi[1], 0.0),
        }),
        part: None,
        grid,
        tolerance: limits.tolerance,
        allowance: limits.allowance,
        air_share_limit: 1.0,
        power: None,
        program: read,
    })
}

/// The lowest tip height the program `job` moves to (+∞ with no move): the models of a
/// capability with no part of its own are floored under it.
fn lowest_tip(job: &Job) -> f64 {
    job.program.moves.iter().filter_map(|read| read.to_xyz().map(|[_, _, z]| z)).fold(f64::INFINITY, f64::min)
}

/// `run` without its budget and progress: the answer's budget is the capability's (the
/// verification's own records are capped), and the capability's solve has reported its progress
/// up to here; the simulation's own 0 → 1 would send a job's bar back, so it reports none
/// (cancellation still reaches it).
fn unbudgeted<'a>(run: &Run<'a>) -> Run<'a> {
    Run { budget: None, control: Control { progress: None, ..run.control }, ..*run }
}

/// The `verification` section of `cut`.
fn verification_of(cut: simulate::Cut, model: String, assumed: Vec<String>, limits: Limits) -> Verification {
    Verification {
        ok: cut.ok,
        findings: cut.findings,
        findings_left_off: cut.findings_left_off,
        note: None,
        model,
        assumed,
        resolution: cut.resolution,
        rays: cut.rays,
        tolerance: limits.tolerance,
        allowance: limits.allowance,
        wall_tolerance: limits.wall_tolerance,
        stock_volume_mm3: cut.stock_volume_mm3,
        part_volume_mm3: cut.part_volume_mm3.unwrap_or(0.0),
        removed_volume_mm3: cut.removed_volume_mm3,
        air_share: cut.air_share,
        moves: cut.moves,
        dexel_updates: cut.dexel_updates,
    }
}

/// The cut stock of a capability's own model without a part (predict's, engagement's): the
/// program its answer writes ([`program`]) cut with its one tool, coloured by what it cut.
///
/// # Errors
/// As [`program`] and [`cut_stock_glb`].
pub(crate) fn partless_cut_stock<C: crate::capability::Capability>(
    model: &dyn OwnModel,
    grid: Grid,
    request: &C::Request,
    answer: &C::Answer,
    tool: &Tool,
    ask: StockAsk,
    run: &Run<'_>,
) -> Result<Option<Vec<u8>>, SolverError> {
    let program = program::<C>(request, answer, run)?;
    cut_stock_glb(model, grid, &program, &[(None, tool)], Limits::WITHOUT_PART, ask, run).map(Some)
}

/// The stock of `model` as `program`'s moves on lines up to `upto_line` (every line: `None`) left
/// it, as binary glTF coloured by deviation from the model's part, or for a model without a part
/// by what the program cut (`extras.colouring`, docs/spec/verify.md §9.4), its positions and that
/// cut's `verification` (in the glTF's `extras.verification`, with the `units` it is in) in
/// `units`. A program that has not reached the stock by then answers the stock as modelled,
/// without `extras.verification`.
///
/// # Errors
/// As [`verify_tools`]; `E_TOO_LARGE_ANSWER` at `verification.resolution` when the mesh's bound
/// (two intervals a ray, a tube's), checked before cutting, or the mesh as it is built passes the
/// run's answer budget.
pub(crate) fn cut_stock_glb(
    model: &dyn OwnModel,
    grid: Grid,
    program: &str,
    tools: &[(Option<u32>, &Tool)],
    limits: Limits,
    StockAsk { upto_line, units }: StockAsk,
    run: &Run<'_>,
) -> Result<Vec<u8>, SolverError> {
    let bound = super::mesh::mesh_bound(grid.len(), 2);
    if let Some(budget) = run.budget
        && bound > budget.limit()
    {
        return Err(crate::capability::too_large_answer(bound, budget.limit()).at("verification.resolution"));
    }
    let mut job = own_job(model, grid, program, tools, limits, run)?;
    // The whole program's lowest tip, so every step of a playback cuts the same model.
    let lowest = lowest_tip(&job);
    if let Some(last) = upto_line {
        job.program.moves.retain(|read| read.line <= last);
    }
    let (stock, part) = model.fields(grid, lowest, run.control)?;
    // Coloured against the part, or without one against the stock as modelled.
    let reference = part.clone().unwrap_or_else(|| stock.clone());
    let against = if part.is_some() {
        Against::Part { part: &reference, tolerance: limits.tolerance, allowance: limits.allowance }
    } else {
        Against::Given(&reference)
    };
    match simulate::cut_fields(&job, stock, part, &unbudgeted(run)) {
        Ok((cut, left)) => {
            let mut verification = verification_of(cut, model.describe(), assumed_holders(tools), limits);
            if let Some(scaling) = units.from_mm() {
                verification.scale(scaling);
            }
            let extras = serde_json::json!({"verification": verification, "units": units.as_str()});
            super::mesh::fields_glb(&left, against, extras, units, run)
        }
        Err(error) if error.code() == ErrorCode::Stock => {
            let (stock, _) = model.fields(grid, lowest, run.control)?;
            super::mesh::fields_glb(&stock, against, serde_json::json!({"units": units.as_str()}), units, run)
        }
        Err(error) => Err(error),
    }
}

/// The warning code of a finding that is also a warning of the answer: a gouge, a rapid through
/// material, the holder touching the stock.
pub fn warning_code(kind: FindingKind) -> Option<&'static str> {
    match kind {
        FindingKind::Gouge => Some("W_VERIFY_GOUGE"),
        FindingKind::RapidThroughMaterial => Some("W_VERIFY_RAPID_THROUGH_MATERIAL"),
        FindingKind::HolderContact => Some("W_VERIFY_HOLDER_CONTACT"),
        _ => None,
    }
}

fn kind_name(kind: FindingKind) -> &'static str {
    match kind {
        FindingKind::Gouge => "gouge",
        FindingKind::LeftMaterial => "material left",
        FindingKind::RapidThroughMaterial => "rapid through material",
        FindingKind::NeckContact => "neck contact",
        FindingKind::ShankContact => "shank contact",
        FindingKind::HolderContact => "holder contact",
        FindingKind::AirCutting => "air cutting",
        FindingKind::SpindlePower => "spindle power",
    }
}

/// A finding in words: what, where, how much.
fn sentence(finding: &Finding) -> String {
    let [x, y, z] = finding.position;
    let line = finding.line.map_or_else(String::new, |line| format!(" at line {line}"));
    format!(
        "{}{line}: {:.3} mm deep at x = {x:.3} mm, y = {y:.3} mm, z = {z:.3} mm",
        kind_name(finding.kind),
        finding.depth
    )
}

/// One warning per kind of warning finding: its count and the worst.
pub(crate) fn warnings(verification: &Verification) -> Vec<Warning> {
    let mut warnings = Vec::new();
    for kind in [FindingKind::Gouge, FindingKind::RapidThroughMaterial, FindingKind::HolderContact] {
        let found: Vec<&Finding> = verification.findings.iter().filter(|finding| finding.kind == kind).collect();
        let (Some(code), Some(worst)) = (warning_code(kind), found.iter().max_by(|a, b| a.depth.total_cmp(&b.depth)))
        else {
            continue;
        };
        let assumed = if kind == FindingKind::HolderContact && !verification.assumed.is_empty() {
            format!("; {}", verification.assumed.join("; "))
        } else {
            String::new()
        };
        warnings.push(Warning::new(
            code,
            format!(
                "cutting the program on its own model found {} {} moves; the worst: {} (see verification){assumed}",
                found.len(),
                kind_name(kind),
                sentence(worst)
            ),
        ));
    }
    warnings
}

/// The program's header comments: one line per warning finding (the first 5), or none.
pub(crate) fn comments(verification: &Verification) -> Vec<String> {
    let found: Vec<&Finding> =
        verification.findings.iter().filter(|finding| warning_code(finding.kind).is_some()).collect();
    if found.is_empty() {
        return Vec::new();
    }
    let mut lines = vec![format!("WARNING verification found {} problems cutting this program", found.len())];
    lines.extend(found.iter().take(5).map(|finding| format!("WARNING {}", sentence(finding))));
    // A holder contact is only as real as the holder it was found with.
    if found.iter().any(|finding| finding.kind == FindingKind::HolderContact) {
        lines.extend(verification.assumed.iter().map(|sentence| format!("WARNING {sentence}")));
    }
    lines
}

/// Adds what `verification` found to an answer's `warnings` and program header lines. The header
/// comments come before every move, one line each, so the findings' lines are moved down by as
/// many: they are then the lines of the program the answer writes.
pub(crate) fn report(verification: &mut Verification, warnings: &mut Vec<Warning>, description: &mut Vec<String>) {
    let added = comments(verification).len();
    for finding in &mut verification.findings {
        finding.line = finding.line.map(|line| line + added);
    }
    warnings.extend(self::warnings(verification));
    description.extend(comments(verification));
}

/// A prism of vertical walls about a closed outline: the contour's part and stock.
///
/// The part is the outline's material side, its walls moved out by the finishing allowance, from
/// a floor [`FLOOR_THICKNESS`] under `bottom` up to `top`, less the relief discs; under `bottom`
/// the floor is part everywhere. The stock adds the band of `stock` width the contour cuts.
#[derive(Debug, Clone)]
pub(crate) struct Prism {
    pub outline: Vec<Vec2>,
    /// Whether the material is inside the outline (`side: outside`).
    pub material_inside: bool,
    pub top: f64,
    pub bottom: f64,
    /// Width of the stock band beyond the outline, mm.
    pub stock: f64,
    /// Thickness the last pass leaves on the walls, mm.
    pub finish: f64,
    /// Centres and radius of the relief discs cut into the part at inside corners.
    pub reliefs: Vec<Vec2>,
    pub relief_radius: f64,
    /// The reach of the tool beyond the stock band, mm.
    pub reach: f64,
    pub wall_tolerance: f64,
}

impl Prism {
    /// The rays' distances from the outline (up to `limit`; beyond: `limit`), row by row.
    fn distances(&self, grid: Grid, limit: f64, control: Control<'_>) -> Result<Vec<f64>, SolverError> {
        let mut distance = vec![limit; grid.len()];
        let n = self.outline.len();
        for (index, a) in self.outline.iter().enumerate() {
            control.check_at(index)?;
            let b = &self.outline[(index + 1) % n];
            for j in grid.span(1, a.y.min(b.y) - limit, a.y.max(b.y) + limit) {
                let y = grid.y(j);
                for i in grid.span(0, a.x.min(b.x) - limit, a.x.max(b.x) + limit) {
                    let d = point_segment_distance(&Vec2::new(grid.x(i), y), a, b);
                    let slot = &mut distance[j * grid.nx + i];
                    if d < *slot {
                        *slot = d;
                    }
                }
            }
        }
        Ok(distance)
    }
}

impl OwnModel for Prism {
    fn footprint(&self) -> ([f64; 2], [f64; 2]) {
        let grow = self.stock + self.reach;
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for p in &self.outline {
            lo = [lo[0].min(p.x - grow), lo[1].min(p.y - grow)];
            hi = [hi[0].max(p.x + grow), hi[1].max(p.y + grow)];
        }
        (lo, hi)
    }

    fn fields(&self, grid: Grid, _lowest: f64, control: Control<'_>) -> Result<(Field, Option<Field>), SolverError> {
        let limit = self.stock.max(self.finish + self.wall_tolerance) + grid.spacing;
        let distance = self.distances(grid, limit, control)?;
        let floor = self.bottom - FLOOR_THICKNESS;
        let (mut stock, mut part) = (Vec::with_capacity(grid.len()), Vec::with_capacity(grid.len()));
        let relief = self.relief_radius + self.wall_tolerance;
        let mut crossings = Vec::new();
        for j in 0..grid.ny {
            control.check()?;
            let y = grid.y(j);
            // Where the outline crosses the row (even-odd rule): a ray is inside past an odd count.
            crossings.clear();
            let n = self.outline.len();
            for (index, a) in self.outline.iter().enumerate() {
                let b = &self.outline[(index + 1) % n];
                if (a.y > y) != (b.y > y) {
                    crossings.push(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
                }
            }
            crossings.sort_by(f64::total_cmp);
            let mut passed = 0;
            for i in 0..grid.nx {
                let x = grid.x(i);
                while passed < crossings.len() && crossings[passed] < x {
                    passed += 1;
                }
                let d = distance[j * grid.nx + i];
                let inside = passed % 2 == 1;
                // Signed distance from the designed wall, positive in the part.
                let s = if inside == self.material_inside { d } else { -d } + self.finish;
                let in_relief = self.reliefs.iter().any(|centre| (x - centre.x).hypot(y - centre.y) < relief);
                let column = |material: bool| -> Ray {
                    let top = if material { self.top } else { self.bottom };
                    let mut ray = Ray::new();
                    ray.push([floor, top]);
                    ray
                };
                let near_wall = s.abs() < self.wall_tolerance || in_relief;
                let part_material = s >= self.wall_tolerance && !in_relief;
                let stock_material = part_material || (!near_wall && s >= self.finish - self.stock);
                stock.push(column(stock_material));
                part.push(column(part_material));
            }
        }
        Ok((Field::new(grid, stock), Some(Field::new(grid, part))))
    }

    fn describe(&self) -> String {
        let side = if self.material_inside { "inside" } else { "outside" };
        format!(
            "stock: the material {side} the outline and a band {:.3} mm wide beyond it, from height {:.3} mm up to \
             {:.3} mm over a floor {FLOOR_THICKNESS} mm thick; part: the material {side} the outline{}, {} relief disc(s) cut out",
            self.stock,
            self.bottom,
            self.top,
            if self.finish > 0.0 {
                format!(" with its walls {:.3} mm out (the last pass's allowance)", self.finish)
            } else {
                String::new()
            },
            self.reliefs.len()
        )
    }
}

/// What a point of a sampled solid is: outside the stock, stock to be cut away, or the part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Matter {
    Air,
    Cut,
    Part,
}

/// A tube (its material between `inner` and `outer` from the axis `start`–`end`) whose rays
/// through the `windows` are sampled with `classify`: holes (air) and the bands to be cut away
/// near them (deburr's chamfers), found along each ray at steps of `step` and placed by
/// bisection.
pub(crate) struct SampledTube {
    pub start: Vec3,
    pub end: Vec3,
    pub outer: f64,
    pub inner: f64,
    /// Boxes outside which the tube is whole: only the rays through one are sampled, and only
    /// within its heights.
    pub windows: Vec<([f64; 3], [f64; 3])>,
    /// What a point inside the tube's material is.
    pub classify: Box<dyn Fn(&Vec3) -> Matter + Send + Sync>,
    /// Largest sampling step along a ray, mm: smaller than the thinnest band.
    pub step: f64,
    pub description: String,
}

/// Steps of the bisection placing a boundary on a ray: 2⁻⁴⁰ of the sampling step.
const BISECTIONS: usize = 40;

impl SampledTube {
    fn tube(&self) -> SolidModel {
        let length = (self.end - self.start).norm();
        SolidModel::Tube {
            axis: Axis { start: self.start, axis: (self.end - self.start) / length, length },
            outer: self.outer,
            inner: self.inner,
            holes: Vec::new(),
        }
    }

    /// The runs of matter along `[low, high]` of the ray through `(x, y)`: (start, matter).
    fn runs(&self, x: f64, y: f64, [low, high]: [f64; 2], runs: &mut Vec<(f64, Matter)>) {
        let at = |z: f64| (self.classify)(&Vec3::new(x, y, z));
        let steps = ((high - low) / self.step).ceil().max(1.0) as usize;
        let mut previous = (low, at(low));
        runs.push((low, previous.1));
        for k in 1..=steps {
            let z = low + (high - low) * k as f64 / steps as f64;
            let matter = at(z);
            if matter != previous.1 {
                // The boundary between the two samples, by bisection.
                let (mut a, mut b) = (previous.0, z);
                for _ in 0..BISECTIONS {
                    let middle = 0.5 * (a + b);
                    if at(middle) == previous.1 { a = middle } else { b = middle }
                }
                runs.push((0.5 * (a + b), matter));
            }
            previous = (z, matter);
        }
    }
}

impl OwnModel for SampledTube {
    fn footprint(&self) -> ([f64; 2], [f64; 2]) {
        self.tube().footprint()
    }

    fn fields(&self, grid: Grid, _lowest: f64, control: Control<'_>) -> Result<(Field, Option<Field>), SolverError> {
        let tube = self.tube();
        let (mut stock, mut part) = (Vec::with_capacity(grid.len()), Vec::with_capacity(grid.len()));
        let (mut runs, mut heights) = (Vec::new(), Vec::new());
        for j in 0..grid.ny {
            control.check()?;
            let y = grid.y(j);
            for i in 0..grid.nx {
                let x = grid.x(i);
                let whole = tube.ray(x, y, &mut heights);
                let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
                for (lo, hi) in &self.windows {
                    if x >= lo[0] && x <= hi[0] && y >= lo[1] && y <= hi[1] {
                        (low, high) = (low.min(lo[2]), high.max(hi[2]));
                    }
                }
                if low > high {
                    part.push(whole.clone());
                    stock.push(whole);
                    continue;
                }
                let (mut stock_ray, mut part_ray) = (Ray::new(), Ray::new());
                for &interval in &whole {
                    runs.clear();
                    // Whole part below and above the heights of the windows.
                    let (from, to) = (interval[0].max(low), interval[1].min(high));
                    if to > from {
                        if from > interval[0] {
                            runs.push((interval[0], Matter::Part));
                        }
                        self.runs(x, y, [from, to], &mut runs);
                        if to < interval[1] {
                            runs.push((to, Matter::Part));
                        }
                    } else {
                        runs.push((interval[0], Matter::Part));
                    }
                    for (index, &(from, matter)) in runs.iter().enumerate() {
                        let to = runs.get(index + 1).map_or(interval[1], |next| next.0);
                        if to <= from || matter == Matter::Air {
                            continue;
                        }
                        push_merged(&mut stock_ray, [from, to]);
                        if matter == Matter::Part {
                            push_merged(&mut part_ray, [from, to]);
                        }
                    }
                }
                stock.push(stock_ray);
                part.push(part_ray);
            }
        }
        Ok((Field::new(grid, stock), Some(Field::new(grid, part))))
    }

    fn describe(&self) -> String {
        self.description.clone()
    }
}

/// Appends `[from, to]` (above everything on `ray`) to `ray`, joined to the last interval when
/// they touch.
fn push_merged(ray: &mut Ray, [from, to]: [f64; 2]) {
    match ray.last_mut() {
        Some(last) if last[1] >= from => last[1] = last[1].max(to),
        _ => ray.push([from, to]),
    }
}

/// A stock the request gives as a solid (predict's), with no part: the program is checked for
/// rapids through material and for the neck, shank and holder touching the stock, and its air
/// share reported. The stock is modelled down to [`FLOOR_THICKNESS`] under the program's lowest
/// tip, which no move reaches below: a plane or a height grid without a bottom has a floor. `lift` is the programmed point's height above the tip (the
/// ball's radius for a program of ball centres): the stock is raised by it, so the tip the
/// engine moves to the programmed point meets it where the real tip would, and the findings
/// are at the program's coordinates.
pub(crate) struct GivenStock {
    pub stock: StockModel,
    pub lift: f64,
    pub description: String,
}

impl OwnModel for GivenStock {
    fn footprint(&self) -> ([f64; 2], [f64; 2]) {
        self.stock.footprint()
    }

    fn fields(&self, grid: Grid, lowest: f64, control: Control<'_>) -> Result<(Field, Option<Field>), SolverError> {
        let floor = lowest - FLOOR_THICKNESS;
        let solid = SolidModel::Stock(self.stock.clone());
        let mut rays = Vec::with_capacity(grid.len());
        let mut heights = Vec::new();
        for j in 0..grid.ny {
            control.check()?;
            let y = grid.y(j);
            for i in 0..grid.nx {
                let x = grid.x(i);
                let mut ray = match &self.stock {
                    StockModel::Plane { point, normal, lo, hi } => {
                        let mut ray = Ray::new();
                        if x > lo[0] && x < hi[0] && y > lo[1] && y < hi[1] {
                            // The plane's height over (x, y): (q − point)·normal = 0.
                            let top = point.z - ((x - point.x) * normal.x + (y - point.y) * normal.y) / normal.z;
                            ray.push([f64::NEG_INFINITY, top]);
                        }
                        ray
                    }
                    _ => solid.ray(x, y, &mut heights),
                };
                // Raised into the program's coordinates, cut at the floor.
                ray.retain(|interval| {
                    *interval = [(interval[0] + self.lift).max(floor), interval[1] + self.lift];
                    interval[1] > interval[0]
                });
                rays.push(ray);
            }
        }
        Ok((Field::new(grid, rays), None))
    }

    fn describe(&self) -> String {
        self.description.clone()
    }
}

/// A plan-view stock extruded (engagement's): the material where `inside` holds, from a floor
/// [`FLOOR_THICKNESS`] under the program's lowest tip up to `top`, with no part: checked as a
/// [`GivenStock`] is.
pub(crate) struct Extrusion {
    pub lo: [f64; 2],
    pub hi: [f64; 2],
    pub top: f64,
    pub inside: Box<dyn Fn(f64, f64) -> bool + Send + Sync>,
    pub description: String,
}

impl OwnModel for Extrusion {
    fn footprint(&self) -> ([f64; 2], [f64; 2]) {
        (self.lo, self.hi)
    }

    fn fields(&self, grid: Grid, lowest: f64, control: Control<'_>) -> Result<(Field, Option<Field>), SolverError> {
        let floor = lowest - FLOOR_THICKNESS;
        let mut rays = Vec::with_capacity(grid.len());
        for j in 0..grid.ny {
            control.check()?;
            let y = grid.y(j);
            for i in 0..grid.nx {
                let mut ray = Ray::new();
                if self.top > floor && (self.inside)(grid.x(i), y) {
                    ray.push([floor, self.top]);
                }
                rays.push(ray);
            }
        }
        Ok((Field::new(grid, rays), None))
    }

    fn describe(&self) -> String {
        self.description.clone()
    }
}

/// The outline `points` as planar points.
pub(crate) fn outline(points: &[[f64; 2]]) -> Vec<Vec2> {
    points.iter().map(|p| vec2(*p)).collect()
}

/// The default tolerance along z of a capability's verification, mm.
pub const OWN_TOLERANCE: f64 = DEFAULT_TOLERANCE;
