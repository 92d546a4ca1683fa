//! Cutting the program (docs/spec/verify.md §4 Sweeping, §6 Findings): every move of the program
//! sweeps its tool's cutter through the stock's dexels, removing what it meets; the neck, shank
//! and holder are then checked against what is left; removals inside the part are gouges, and
//! after the last move what is left outside the part is measured.

use serde::Serialize;

use crate::capability::Run;
use crate::error::{ErrorCode, SolverError};
use crate::gcode::reader::{MoveKind, ReadMove};

use super::assembly::{Body, Member, Shape};
use super::dexel::{self, Field, Interval, Tops};
use super::job::{Job, PowerModel};
use super::sweep::Segment;

/// Most findings listed; the rest are counted in `findings_left_off`.
pub const MAX_FINDINGS: usize = 1000;
/// Largest sagitta of the chords an arc is cut along, mm.
pub const ARC_CHORD_TOLERANCE: f64 = 0.001;

/// What a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum FindingKind {
    /// The cutter removed material inside the part deeper than `tolerance`.
    Gouge,
    /// Material thicker than `allowance` is left outside the part after the program.
    LeftMaterial,
    /// A rapid move (G0) cut material.
    RapidThroughMaterial,
    /// The neck met the stock.
    NeckContact,
    /// The shank met the stock.
    ShankContact,
    /// The holder met the stock.
    HolderContact,
    /// Feed moves cut nothing for more than `air_share_limit` of the cutting time.
    AirCutting,
    /// A block needs more spindle power than the machine has at its spindle speed.
    SpindlePower,
}

/// One finding, at the G-code line of the move that caused it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Finding {
    /// What was found.
    pub kind: FindingKind,
    /// Source line of the move (1-based); none for `left_material`, which no one move causes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    /// The `T` number of the tool, when the program called one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tool: Option<u32>,
    /// Where it is worst, mm: the ray's x and y and the lowest z of the material concerned (for
    /// `air_cutting`, the start of the longest move in air).
    pub position: [f64; 3],
    /// The deepest extent along one ray, mm: the gouge's depth into the part, the thickness
    /// left, the length of material the rapid cut or the member overlapped (0 for air cutting).
    pub depth: f64,
    /// The volume concerned, mm³ (0 for contacts and air cutting, which remove nothing).
    pub volume_mm3: f64,
    /// For `air_cutting`, the share of the cutting time in air (0–1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub share: Option<f64>,
    /// For `spindle_power`, the power the block needs, kW.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub power_kw: Option<f64>,
    /// For `spindle_power`, the machine's spindle power at the block's speed, kW.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit_kw: Option<f64>,
}

/// The material one block removed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct BlockRemoval {
    /// Source line (1-based).
    pub line: usize,
    /// The `T` number of the tool, when the program called one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tool: Option<u32>,
    /// Removed volume, mm³.
    pub removed_mm3: f64,
    /// Time of the move at its programmed feed, s (none for rapids and moves without a feed).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// Material-removal rate, mm³/min (removed volume over the move's time).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub removal_rate_mm3_per_min: Option<f64>,
    /// With a `material`: the spindle power the removal rate needs, kW (feed moves).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spindle_power_kw: Option<f64>,
}

/// What cutting the program gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Cut {
    /// Whether nothing was found.
    pub ok: bool,
    /// The findings in program order (`left_material` last), at most 1000.
    pub findings: Vec<Finding>,
    /// Findings beyond the first 1000, counted only.
    pub findings_left_off: usize,
    /// The dexel spacing used, mm.
    pub resolution: f64,
    /// Rays of the stock model (x by y).
    pub rays: [usize; 2],
    /// Stock volume before the program, mm³ (as the dexels hold it).
    pub stock_volume_mm3: f64,
    /// Part volume, mm³, with a part.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub part_volume_mm3: Option<f64>,
    /// Volume the program removed, mm³.
    pub removed_volume_mm3: f64,
    /// Stock volume after the program, mm³.
    pub final_volume_mm3: f64,
    /// Time of the feed moves (G1–G3) at their programmed feed, s.
    pub cutting_time_s: f64,
    /// Time of the feed moves that removed nothing, s.
    pub air_time_s: f64,
    /// `air_time_s` / `cutting_time_s` (0 without feed moves).
    pub air_share: f64,
    /// Motion blocks read.
    pub moves: usize,
    /// Moves not cut because the program had not yet set every axis of their end.
    pub moves_unplaced: usize,
    /// Ray queries the sweeps made (a measure of the work).
    pub dexel_updates: u64,
    /// Every block that removed material, in program order.
    pub blocks: Vec<BlockRemoval>,
}

/// The worst of one kind of finding over one move.
#[derive(Debug, Clone, Copy, Default)]
struct Worst {
    depth: f64,
    volume: f64,
    position: [f64; 3],
    seen: bool,
}

impl Worst {
    fn add(&mut self, depth: f64, volume: f64, position: [f64; 3]) {
        self.volume += volume;
        if !self.seen || depth > self.depth {
            self.depth = depth;
            self.position = position;
        }
        self.seen = true;
    }
}

/// A move as cut: the volume it removed, its time at the programmed feed (feed moves), the
/// number of its tool and the tool's flutes.
#[derive(Debug, Clone, Copy)]
struct MoveCut {
    removed: f64,
    time: Option<f64>,
    tool: Option<u32>,
    flutes: u32,
}

/// What one move did.
#[derive(Debug, Default)]
struct MoveOutcome {
    removed: f64,
    deepest: Worst,
    gouge: Worst,
    contacts: [Worst; 3],
}

/// The simulation's state: the stock as cut so far, the part, and what was found.
struct Simulation<'a> {
    job: &'a Job,
    stock: Field,
    /// Bounds of the stock's highest material over tiles of rays.
    tops: Tops,
    part: Option<Field>,
    findings: Vec<Finding>,
    left_off: usize,
    updates: u64,
    scratch: Scratch,
    /// Whether a non-cutting member met the stock.
    touched: bool,
}

impl Simulation<'_> {
    fn find(&mut self, finding: Finding) {
        if self.findings.len() < MAX_FINDINGS {
            self.findings.push(finding);
        } else {
            self.left_off += 1;
        }
    }

    /// Sweeps the cutter `body` along `segment`, removing material.
    fn cut(&mut self, body: &Body, segment: &Segment, outcome: &mut MoveOutcome) {
        let area = self.stock.grid.cell_area();
        let (part, tolerance) = (&self.part, self.job.tolerance);
        self.updates +=
            sweep_cutter(&mut self.stock, &mut self.tops, body, segment, &mut self.scratch, |index, x, y, pieces| {
                for &[low, high] in pieces {
                    outcome.removed += (high - low) * area;
                    outcome.deepest.add(high - low, (high - low) * area, [x, y, low]);
                    if let Some(part) = part
                        && let Some((depth, lowest)) = dexel::overlap(&part.rays[index], [low, high])
                        && depth > tolerance
                    {
                        outcome.gouge.add(depth, depth * area, [x, y, lowest]);
                    }
                }
            });
    }

    /// Checks the non-cutting `body` (slot `slot` of the contacts) along `segment` against the
    /// stock left.
    fn touch(&mut self, body: &Body, slot: usize, segment: &Segment, outcome: &mut MoveOutcome) {
        let grid = self.stock.grid;
        let (lo, hi) = segment.reach(body.radius);
        let floor = segment.low_z() + body.bottom();
        let rows = grid.span(1, lo[1], hi[1]);
        if !self.tops.above(&self.stock, grid.span(0, lo[0], hi[0]), rows.clone(), floor) {
            return;
        }
        for j in rows {
            let y = grid.y(j);
            let Some([from, to]) = segment.row(body.radius, y) else {
                continue;
            };
            for i in grid.span(0, from, to) {
                let ray = &self.stock.rays[j * grid.nx + i];
                if dexel::top(ray) <= floor {
                    continue;
                }
                let x = grid.x(i);
                self.updates += 1;
                if let Some(probe) = segment.cut(body, x, y)
                    && let Some((depth, lowest)) = dexel::overlap(ray, probe)
                    && depth > self.job.tolerance
                {
                    outcome.contacts[slot].add(depth, 0.0, [x, y, lowest]);
                }
            }
        }
    }

    /// Cuts one move; its removal record when it removed anything, and its feed time.
    fn run_move(&mut self, read: &ReadMove) -> Result<Option<MoveCut>, SolverError> {
        let Some(to) = read.to_xyz() else {
            return Ok(None);
        };
        let called = read.modal.tool;
        let job = self.job;
        let tool = job.tool(called, read.line)?;
        let number = tool.number.or(called);
        let from = read.from_xyz().unwrap_or(to);
        let points = match read.kind {
            MoveKind::Arc { .. } if read.from_xyz().is_some() => {
                read.points(ARC_CHORD_TOLERANCE).unwrap_or_else(|| vec![to])
            }
            _ => vec![to],
        };
        let assembly = &tool.assembly;
        let mut outcome = MoveOutcome::default();
        let mut length = 0.0;
        let mut start = from;
        for end in points {
            let segment = Segment::new(start, end);
            length += (0..3).map(|k| (end[k] - start[k]).powi(2)).sum::<f64>().sqrt();
            self.cut(assembly.cutter(), &segment, &mut outcome);
            for body in &assembly.bodies[1..] {
                let slot = match body.member {
                    Member::Neck => 0,
                    Member::Shank => 1,
                    Member::Cutter | Member::Holder => 2,
                };
                self.touch(body, slot, &segment, &mut outcome);
            }
            start = end;
        }
        let line = Some(read.line);
        let rapid = read.kind == MoveKind::Rapid;
        if rapid && outcome.deepest.seen && outcome.deepest.depth > self.job.tolerance {
            let worst = outcome.deepest;
            self.find(Finding {
                kind: FindingKind::RapidThroughMaterial,
                line,
                tool: number,
                position: worst.position,
                depth: worst.depth,
                volume_mm3: worst.volume,
                share: None,
                power_kw: None,
                limit_kw: None,
            });
        }
        if outcome.gouge.seen {
            let worst = outcome.gouge;
            self.find(Finding {
                kind: FindingKind::Gouge,
                line,
                tool: number,
                position: worst.position,
                depth: worst.depth,
                volume_mm3: worst.volume,
                share: None,
                power_kw: None,
                limit_kw: None,
            });
        }
        let kinds = [FindingKind::NeckContact, FindingKind::ShankContact, FindingKind::HolderContact];
        for (worst, kind) in outcome.contacts.into_iter().zip(kinds) {
            if worst.seen {
                self.find(Finding {
                    kind,
                    line,
                    tool: number,
                    position: worst.position,
                    depth: worst.depth,
                    volume_mm3: 0.0,
                    share: None,
                    power_kw: None,
                    limit_kw: None,
                });
            }
        }
        let time =
            if rapid { None } else { read.modal.feed.filter(|feed| *feed > 0.0).map(|feed| 60.0 * length / feed) };
        let touched = outcome.contacts.iter().any(|worst| worst.seen);
        self.touched |= touched;
        Ok(Some(MoveCut { removed: outcome.removed, time, tool: number, flutes: tool.flutes }))
    }
}

/// Sweeps the cutter `body` along `segment` through `stock`, removing material: over the rays
/// of the swept footprint, row by row, those whose material reaches above the body's lowest
/// point there. A ray holding one interval that the body's top clears (the common case of a
/// z-map) is clipped from above; any other goes through the general interval subtraction.
/// `removed` is called with the ray's index, x and y and the pieces removed from it; the answer
/// is the number of rays queried.
pub(crate) fn sweep_cutter(
    stock: &mut Field,
    tops: &mut Tops,
    body: &Body,
    segment: &Segment,
    scratch: &mut Scratch,
    mut removed: impl FnMut(usize, f64, f64, &[Interval]),
) -> u64 {
    let grid = stock.grid;
    let (lo, hi) = segment.reach(body.radius);
    let floor = segment.low_z() + body.bottom();
    let rows = grid.span(1, lo[1], hi[1]);
    if !tops.above(stock, grid.span(0, lo[0], hi[0]), rows.clone(), floor) {
        return 0;
    }
    // The body's top along the move is at least this high on every ray it reaches.
    let roof = match body.shape {
        Shape::Sphere => f64::NEG_INFINITY,
        Shape::Rounded { .. } | Shape::Cylinder { .. } => segment.low_z() + body.top,
    };
    let bound = segment.low_bound(body);
    let mut queries = 0;
    for j in rows {
        let y = grid.y(j);
        let Some([from, to]) = segment.row(body.radius, y) else {
            continue;
        };
        for i in grid.span(0, from, to) {
            let index = j * grid.nx + i;
            let ray = &mut stock.rays[index];
            let top = dexel::top(ray);
            if top <= floor {
                continue;
            }
            let x = grid.x(i);
            queries += 1;
            // Most rays of a finishing pass are already at or below the body (cut by the
            // moves before): the bound passes them over without the lowest point's roots.
            if bound.is_some_and(|bound| top <= bound.at(x, y)) {
                continue;
            }
            let Some(low) = segment.lowest(body, x, y) else {
                continue;
            };
            if top <= low {
                continue;
            }
            tops.cut(i, j);
            let pieces = &mut scratch.pieces;
            pieces.clear();
            if ray.len() == 1 && top <= roof {
                let [bottom, _] = ray[0];
                pieces.push([bottom.max(low), top]);
                if low <= bottom {
                    ray.clear();
                } else {
                    ray[0][1] = low;
                }
            } else {
                let Some(cut) = segment.cut(body, x, y) else {
                    continue;
                };
                dexel::subtract(ray, cut, pieces);
            }
            removed(index, x, y, pieces);
        }
    }
    queries
}

/// Space a sweep reuses from move to move.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// The pieces removed from one ray.
    pieces: Vec<Interval>,
}

/// Cuts `job`'s program under `run` (progress, cancellation, the answer budget).
///
/// # Errors
/// `E_CANCELLED`; `E_INPUT` at `tools` when a move's tool is not named; `E_STOCK` at `stock`
/// when no tool ever reaches the stock; `E_TOO_LARGE_ANSWER` over the budget.
pub(crate) fn cut(job: &Job, run: &Run<'_>) -> Result<Cut, SolverError> {
    cut_stock(job, run).map(|(cut, _)| cut)
}

/// As [`cut`], with the stock as the program left it (the mesh is built from it).
pub(crate) fn cut_stock(job: &Job, run: &Run<'_>) -> Result<(Cut, Field), SolverError> {
    let stock = job.stock.field(job.grid);
    let part = job.part.as_ref().map(|part| part.field(job.grid));
    if let Some(part) = &part {
        super::solid::check_part_in_stock(part, &stock, job.tolerance)?;
    }
    cut_fields(job, stock, part, run)
}

/// [`cut_stock`] out of `stock`, compared with `part`, both already on `job.grid`: a capability's own
/// model, which no request solid describes (`own`).
///
/// # Errors
/// As [`cut`].
pub(crate) fn cut_fields(
    job: &Job,
    stock: Field,
    part: Option<Field>,
    run: &Run<'_>,
) -> Result<(Cut, Field), SolverError> {
    let stock_volume = stock.volume();
    let part_volume = part.as_ref().map(Field::volume);
    let tops = Tops::new(&stock);
    let mut simulation = Simulation {
        job,
        stock,
        tops,
        part,
        findings: Vec::new(),
        left_off: 0,
        updates: 0,
        scratch: Scratch::default(),
        touched: false,
    };
    let moves = &job.program.moves;
    let (mut removed, mut cutting_time, mut air_time) = (0.0, 0.0, 0.0);
    let mut longest_air: Option<(f64, usize, [f64; 3], Option<u32>)> = None;
    let mut blocks = Vec::new();
    let mut unplaced = 0;
    for (index, read) in moves.iter().enumerate() {
        run.control.check()?;
        run.control.report(index, moves.len());
        let Some(MoveCut { removed: volume, time, tool, flutes }) = simulation.run_move(read)? else {
            unplaced += 1;
            continue;
        };
        removed += volume;
        if let Some(time) = time {
            cutting_time += time;
            if volume == 0.0 {
                air_time += time;
                if longest_air.is_none_or(|(longest, ..)| time > longest) {
                    let start = read.from_xyz().or(read.to_xyz()).unwrap_or_default();
                    longest_air = Some((time, read.line, start, tool));
                }
            }
        }
        if volume > 0.0 {
            let rate = time.filter(|t| *t > 0.0).map(|t| volume / t * 60.0);
            let power = match (&job.power, rate) {
                (Some(model), Some(rate)) => Some(spindle_power(&mut simulation, model, read, rate, flutes, tool)?),
                _ => None,
            };
            let block = BlockRemoval {
                line: read.line,
                tool,
                removed_mm3: volume,
                time_s: time,
                removal_rate_mm3_per_min: rate,
                spindle_power_kw: power,
            };
            run.charge(crate::capability::json_bytes(&block), index + 1, moves.len())?;
            blocks.push(block);
        }
    }
    if removed == 0.0 && !simulation.touched {
        return Err(SolverError::new(
            ErrorCode::Stock,
            "no tool of the program reaches the stock: check the stock's position against the program's coordinates",
        )
        .at("stock"));
    }
    let air_share = if cutting_time > 0.0 { air_time / cutting_time } else { 0.0 };
    if air_share > job.air_share_limit
        && let Some((_, line, start, tool)) = longest_air
    {
        simulation.find(Finding {
            kind: FindingKind::AirCutting,
            line: Some(line),
            tool,
            position: start,
            depth: 0.0,
            volume_mm3: 0.0,
            share: Some(air_share),
            power_kw: None,
            limit_kw: None,
        });
    }
    if let Some(left) = left_material(&simulation, job.allowance) {
        simulation.find(left);
    }
    let final_volume = simulation.stock.volume();
    let grid = job.grid;
    let cut = Cut {
        ok: simulation.findings.is_empty(),
        findings: simulation.findings,
        findings_left_off: simulation.left_off,
        resolution: grid.spacing,
        rays: [grid.nx, grid.ny],
        stock_volume_mm3: stock_volume,
        part_volume_mm3: part_volume,
        removed_volume_mm3: removed,
        final_volume_mm3: final_volume,
        cutting_time_s: cutting_time,
        air_time_s: air_time,
        air_share,
        moves: moves.len(),
        moves_unplaced: unplaced,
        dexel_updates: simulation.updates,
        blocks,
    };
    Ok((cut, simulation.stock))
}

/// The spindle power, kW, block `read` needs to remove `rate` mm³/min with `flutes` teeth (tool
/// `tool`), with a finding when it is more than the machine's spindle gives.
///
/// # Errors
/// `E_INPUT` at `program` when the block cuts before the program sets a spindle speed.
fn spindle_power(
    simulation: &mut Simulation<'_>,
    model: &PowerModel,
    read: &ReadMove,
    rate: f64,
    flutes: u32,
    tool: Option<u32>,
) -> Result<f64, SolverError> {
    let (Some(feed), Some(spindle_rpm)) = (read.modal.feed, read.modal.spindle_rpm.filter(|rpm| *rpm > 0.0)) else {
        return Err(SolverError::input(
            "program",
            format!(
                "line {}: the block cuts before the program sets a spindle speed (S word), which the spindle power \
                 with `material` needs",
                read.line
            ),
        ));
    };
    let power = model.kilowatts(rate, feed, spindle_rpm, flutes);
    if let Some(limit) = model.limit(spindle_rpm)
        && power > limit
    {
        simulation.find(Finding {
            kind: FindingKind::SpindlePower,
            line: Some(read.line),
            tool,
            position: read.to_xyz().unwrap_or_default(),
            depth: 0.0,
            volume_mm3: 0.0,
            share: None,
            power_kw: Some(power),
            limit_kw: Some(limit),
        });
    }
    Ok(power)
}

/// The material left outside the part thicker than `allowance`: one finding at the thickest.
fn left_material(simulation: &Simulation<'_>, allowance: f64) -> Option<Finding> {
    let part = simulation.part.as_ref()?;
    let grid = simulation.stock.grid;
    let mut worst = Worst::default();
    let mut pieces = Vec::new();
    for (index, (ray, part_ray)) in simulation.stock.rays.iter().zip(&part.rays).enumerate() {
        pieces.clear();
        dexel::outside(ray, part_ray, 0.0, &mut pieces);
        for &[low, high] in &pieces {
            if high - low > allowance {
                let (i, j) = (index % grid.nx, index / grid.nx);
                worst.add(high - low, (high - low) * grid.cell_area(), [grid.x(i), grid.y(j), low]);
            }
        }
    }
    worst.seen.then_some(Finding {
        kind: FindingKind::LeftMaterial,
        line: None,
        tool: None,
        position: worst.position,
        depth: worst.depth,
        volume_mm3: worst.volume,
        share: None,
        power_kw: None,
        limit_kw: None,
    })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::assembly::Shape;
    use super::super::dexel::{Grid, Ray};
    use super::*;

    /// The sweep without its shortcuts: every ray of the move's bounding rectangle, the body's
    /// interval on it subtracted from the interval list.
    fn sweep_every_ray(stock: &mut Field, body: &Body, segment: &Segment) -> Vec<(usize, Interval)> {
        let grid = stock.grid;
        let (lo, hi) = segment.reach(body.radius);
        let mut removed = Vec::new();
        for j in grid.span(1, lo[1], hi[1]) {
            for i in grid.span(0, lo[0], hi[0]) {
                let index = j * grid.nx + i;
                if let Some(cut) = segment.cut(body, grid.x(i), grid.y(j)) {
                    let mut pieces = Vec::new();
                    dexel::subtract(&mut stock.rays[index], cut, &mut pieces);
                    removed.extend(pieces.into_iter().map(|piece| (index, piece)));
                }
            }
        }
        removed
    }

    /// A stock on a 0.1 mm grid over [−8, 8]²: a block from −6 to 0 with a bore along x (two
    /// intervals on the rays over it) and, where `stepped`, a step cut into one side.
    fn stock(stepped: bool) -> Field {
        let grid = Grid::covering([-8.0, -8.0], [8.0, 8.0], 0.1);
        let mut rays = Vec::with_capacity(grid.len());
        for j in 0..grid.ny {
            for i in 0..grid.nx {
                let (x, y) = (grid.x(i), grid.y(j));
                let top = if stepped && x > 2.0 { -2.0 } else { 0.0 };
                let mut ray: Ray = smallvec::smallvec![[-6.0, top]];
                if y.abs() < 1.5 {
                    let half = (2.25 - y * y).sqrt();
                    dexel::subtract(&mut ray, [-3.0 - half, -3.0 + half], &mut Vec::new());
                }
                rays.push(ray);
            }
        }
        Field { grid, rays }
    }

    fn shape() -> impl Strategy<Value = (Shape, f64)> {
        (0..4usize, 0.5..3.0f64).prop_map(|(kind, radius)| {
            let shape = match kind {
                0 => Shape::Rounded { corner: radius },
                1 => Shape::Rounded { corner: 0.0 },
                2 => Shape::Rounded { corner: radius / 3.0 },
                _ => Shape::Sphere,
            };
            (shape, radius)
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        #[test]
        fn the_sweep_leaves_the_same_rays_as_subtracting_on_every_ray(
            moves in prop::collection::vec(
                (prop::array::uniform3(-7.0..7.0f64), prop::array::uniform3(-7.0..7.0f64), 0..3usize), 1..5),
            (shape, radius) in shape(),
            short in prop::bool::ANY,
            stepped in prop::bool::ANY,
        ) {
            // Short flutes let material stand above the cutter's top (the general path), long
            // ones clip every ray from above.
            let top = match shape {
                Shape::Sphere => 2.0 * radius,
                _ if short => 1.5,
                _ => 30.0,
            };
            let body = Body { member: Member::Cutter, shape, radius, top };
            let (mut fast, mut every) = (stock(stepped), stock(stepped));
            let mut tops = Tops::new(&fast);
            for (from, to, kind) in moves {
                // Horizontal, vertical and sloping moves.
                let from = [from[0], from[1], from[2] * 0.6 - 2.0];
                let to = match kind {
                    0 => [to[0], to[1], from[2]],
                    1 => [from[0], from[1], to[2] * 0.6 - 2.0],
                    _ => [to[0], to[1], to[2] * 0.6 - 2.0],
                };
                let segment = Segment::new(from, to);
                let mut removed = Vec::new();
                sweep_cutter(&mut fast, &mut tops, &body, &segment, &mut Scratch::default(), |index, _, _, pieces| {
                    removed.extend(pieces.iter().map(|&piece| (index, piece)));
                });
                prop_assert_eq!(&removed, &sweep_every_ray(&mut every, &body, &segment));
                prop_assert!(fast.rays == every.rays);
            }
        }
    }
}
