//! Cutting the program (docs/spec/verify.md §4 Sweeping, §6 Findings): every move of the program
//! sweeps its tool's cutter through the stock's dexels, removing what it meets; the neck, shank
//! and holder are then checked against what is left; removals inside the part are gouges, and
//! after the last move what is left outside the part is measured.

use serde::{Deserialize, Serialize};

use crate::capability::Run;
use crate::error::{ErrorCode, SolverError};
use crate::gcode::reader::{MoveKind, ReadMove};

use super::assembly::{Body, Member, Shape};
use super::dexel::{self, Field, Interval, STRIP_ROWS, Tops};
use super::job::{CallableTool, Job, PowerModel};
use super::solid::PartCheck;
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

/// The worst of one kind of finding over one move, or over the rays of one strip of it.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Worst {
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

    /// Adds the worst of the rays after these (a later strip): the volumes summed, the first of
    /// equal depths kept.
    fn merge(&mut self, next: &Self) {
        if !next.seen {
            return;
        }
        self.volume += next.volume;
        if !self.seen || next.depth > self.depth {
            self.depth = next.depth;
            self.position = next.position;
        }
        self.seen = true;
    }

    /// As a part hands it on: depth, volume and position, if seen.
    fn to_record(self) -> Option<[f64; 5]> {
        let [x, y, z] = self.position;
        self.seen.then_some([self.depth, self.volume, x, y, z])
    }

    fn from_record(record: Option<[f64; 5]>) -> Self {
        record.map_or_else(Self::default, |[depth, volume, x, y, z]| Self {
            depth,
            volume,
            position: [x, y, z],
            seen: true,
        })
    }
}

/// A move as planned: its tool, the straight segments it is cut along, its length, and its time
/// at the programmed feed (feed moves).
struct MovePlan<'a> {
    tool: &'a CallableTool,
    /// The tool's number, or the one the program called.
    number: Option<u32>,
    segments: Vec<Segment>,
    rapid: bool,
    time: Option<f64>,
}

/// The plan of move `read`; `None` when the program has not yet set every axis of its end.
fn plan_move<'a>(job: &'a Job, read: &ReadMove) -> Result<Option<MovePlan<'a>>, SolverError> {
    let Some(to) = read.to_xyz() else {
        return Ok(None);
    };
    let called = read.modal.tool;
    let tool = job.tool(called, read.line)?;
    let from = read.from_xyz().unwrap_or(to);
    let points = match read.kind {
        MoveKind::Arc { .. } if read.from_xyz().is_some() => {
            read.points(ARC_CHORD_TOLERANCE).unwrap_or_else(|| vec![to])
        }
        _ => vec![to],
    };
    let mut length = 0.0;
    let mut start = from;
    let mut segments = Vec::with_capacity(points.len());
    for end in points {
        segments.push(Segment::new(start, end));
        length += (0..3).map(|k| (end[k] - start[k]).powi(2)).sum::<f64>().sqrt();
        start = end;
    }
    let rapid = read.kind == MoveKind::Rapid;
    let time = if rapid { None } else { read.modal.feed.filter(|feed| *feed > 0.0).map(|feed| 60.0 * length / feed) };
    Ok(Some(MovePlan { tool, number: tool.number.or(called), segments, rapid, time }))
}

/// What one move did, over the rays of one strip or, strips merged in order, over all of them.
#[derive(Debug, Clone, Copy, Default)]
struct MoveOutcome {
    removed: f64,
    /// The longest piece removed (kept for rapid moves only, the one kind that reports it).
    deepest: Worst,
    gouge: Worst,
    /// Neck, shank, holder.
    contacts: [Worst; 3],
}

impl MoveOutcome {
    fn is_empty(&self) -> bool {
        self.removed == 0.0 && !self.deepest.seen && !self.gouge.seen && self.contacts.iter().all(|worst| !worst.seen)
    }

    /// Adds what the move did on a later strip.
    fn merge(&mut self, next: &Self) {
        self.removed += next.removed;
        self.deepest.merge(&next.deepest);
        self.gouge.merge(&next.gouge);
        for (contact, next) in self.contacts.iter_mut().zip(&next.contacts) {
            contact.merge(next);
        }
    }
}

/// What move `index` did on strip `strip`, as a part of a split cut hands it on (moves that did
/// nothing there are left out).
#[derive(Debug, Clone, Serialize, Deserialize)]
struct StripRecord {
    index: usize,
    strip: usize,
    removed: f64,
    /// The worsts seen, by slot: 0 the deepest piece, 1 the gouge, 2–4 the contacts.
    worsts: Vec<(u8, [f64; 5])>,
}

impl StripRecord {
    fn new(index: usize, strip: usize, outcome: &MoveOutcome) -> Self {
        let all = [outcome.deepest, outcome.gouge, outcome.contacts[0], outcome.contacts[1], outcome.contacts[2]];
        let worsts =
            (0u8..).zip(all).filter_map(|(slot, worst)| worst.to_record().map(|record| (slot, record))).collect();
        Self { index, strip, removed: outcome.removed, worsts }
    }

    fn outcome(&self) -> MoveOutcome {
        let mut all = [Worst::default(); 5];
        for &(slot, record) in &self.worsts {
            if let Some(worst) = all.get_mut(usize::from(slot)) {
                *worst = Worst::from_record(Some(record));
            }
        }
        let [deepest, gouge, neck, shank, holder] = all;
        MoveOutcome { removed: self.removed, deepest, gouge, contacts: [neck, shank, holder] }
    }
}

/// The stock as cut so far and the part, on all or some rows of the grid, and what the move
/// being cut did on each strip.
struct Sweeper<'a> {
    job: &'a Job,
    stock: Field,
    /// Bounds of the stock's highest material over tiles of rays.
    tops: Tops,
    part: Option<Field>,
    updates: u64,
    scratch: Scratch,
    /// What the move did on each strip of the grid.
    strips: Vec<MoveOutcome>,
    /// The strips it reached: `[first, last + 1)`, empty when none.
    reached: [usize; 2],
}

impl<'a> Sweeper<'a> {
    fn new(job: &'a Job, stock: Field, part: Option<Field>) -> Self {
        let tops = Tops::new(&stock);
        let strips = vec![MoveOutcome::default(); stock.grid.strips()];
        Self { job, stock, tops, part, updates: 0, scratch: Scratch::default(), strips, reached: [usize::MAX, 0] }
    }

    /// Cuts the move `plan`: each segment sweeps the cutter, removing material, then the other
    /// bodies are checked against what is left.
    fn sweep(&mut self, plan: &MovePlan<'_>) {
        let assembly = &plan.tool.assembly;
        for segment in &plan.segments {
            self.cut(assembly.cutter(), segment, plan.rapid);
            for body in &assembly.bodies[1..] {
                let slot = match body.member {
                    Member::Neck => 0,
                    Member::Shank => 1,
                    Member::Cutter | Member::Holder => 2,
                };
                self.touch(body, slot, segment);
            }
        }
    }

    /// Hands on what the move did on each strip it reached, in strip order, and clears it for
    /// the next move.
    fn take(&mut self, mut each: impl FnMut(usize, &MoveOutcome)) {
        let [first, end] = std::mem::replace(&mut self.reached, [usize::MAX, 0]);
        for strip in first..end {
            let outcome = std::mem::take(&mut self.strips[strip]);
            if !outcome.is_empty() {
                each(strip, &outcome);
            }
        }
    }

    /// Sweeps the cutter `body` along `segment`, removing material; `rapid`: keeping the
    /// deepest piece.
    fn cut(&mut self, body: &Body, segment: &Segment, rapid: bool) {
        let area = self.stock.grid.cell_area();
        let (part, tolerance) = (&self.part, self.job.tolerance);
        let (strips, reached) = (&mut self.strips, &mut self.reached);
        self.updates += sweep_cutter(
            &mut self.stock,
            &mut self.tops,
            body,
            segment,
            &mut self.scratch,
            |index, j, x, y, pieces| {
                let strip = j / STRIP_ROWS;
                reach(reached, strip);
                let outcome = &mut strips[strip];
                for &[low, high] in pieces {
                    outcome.removed += (high - low) * area;
                    if rapid {
                        outcome.deepest.add(high - low, (high - low) * area, [x, y, low]);
                    }
                    if let Some(part) = part
                        && let Some((depth, lowest)) = dexel::overlap(&part.rays[index], [low, high])
                        && depth > tolerance
                    {
                        outcome.gouge.add(depth, depth * area, [x, y, lowest]);
                    }
                }
            },
        );
    }

    /// Checks the non-cutting `body` (slot `slot` of the contacts) along `segment` against the
    /// stock left.
    fn touch(&mut self, body: &Body, slot: usize, segment: &Segment) {
        let grid = self.stock.grid;
        let (lo, hi) = segment.reach(body.radius);
        let floor = segment.low_z() + body.bottom();
        let rows = self.stock.within(grid.span(1, lo[1], hi[1]));
        if !self.tops.above(&self.stock, grid.span(0, lo[0], hi[0]), rows.clone(), floor) {
            return;
        }
        for j in rows {
            let y = grid.y(j);
            let Some([from, to]) = segment.row(body.radius, y) else {
                continue;
            };
            let base = self.stock.index(0, j);
            for i in grid.span(0, from, to) {
                let ray = &self.stock.rays[base + i];
                if dexel::top(ray) <= floor {
                    continue;
                }
                let x = grid.x(i);
                self.updates += 1;
                if let Some(probe) = segment.cut(body, x, y)
                    && let Some((depth, lowest)) = dexel::overlap(ray, probe)
                    && depth > self.job.tolerance
                {
                    let strip = j / STRIP_ROWS;
                    reach(&mut self.reached, strip);
                    self.strips[strip].contacts[slot].add(depth, 0.0, [x, y, lowest]);
                }
            }
        }
    }

    /// After the last move: the length of material left on each strip's rays and, with a part,
    /// each strip's thickest material left outside it thicker than `allowance`.
    fn left(&self, allowance: f64) -> (Vec<f64>, Vec<Worst>) {
        let lengths = self.stock.strip_lengths();
        let Some(part) = &self.part else {
            return (lengths, Vec::new());
        };
        let (stock, grid) = (&self.stock, self.stock.grid);
        let mut pieces = Vec::new();
        let left = stock
            .strips()
            .map(|strip| {
                let mut worst = Worst::default();
                for j in stock.within(grid.strip_rows(strip..strip + 1)) {
                    for i in 0..grid.nx {
                        let index = stock.index(i, j);
                        pieces.clear();
                        dexel::outside(&stock.rays[index], &part.rays[index], 0.0, &mut pieces);
                        for &[low, high] in &pieces {
                            if high - low > allowance {
                                worst.add(high - low, (high - low) * grid.cell_area(), [grid.x(i), grid.y(j), low]);
                            }
                        }
                    }
                }
                worst
            })
            .collect();
        (lengths, left)
    }
}

/// Widens `reached` to hold `strip`.
#[inline(always)]
fn reach(reached: &mut [usize; 2], strip: usize) {
    reached[0] = reached[0].min(strip);
    reached[1] = reached[1].max(strip + 1);
}

/// Sweeps the cutter `body` along `segment` through `stock`, removing material: over the rays
/// of the swept footprint (on the field's rows), row by row, those whose material reaches above
/// the body's lowest point there. A ray holding one interval that the body's top clears (the
/// common case of a z-map) is clipped from above; any other goes through the general interval
/// subtraction. `removed` is called with the ray's index in the field, its row, x and y and the
/// pieces removed from it; the answer is the number of rays queried.
pub(crate) fn sweep_cutter(
    stock: &mut Field,
    tops: &mut Tops,
    body: &Body,
    segment: &Segment,
    scratch: &mut Scratch,
    mut removed: impl FnMut(usize, usize, f64, f64, &[Interval]),
) -> u64 {
    let grid = stock.grid;
    let (lo, hi) = segment.reach(body.radius);
    let floor = segment.low_z() + body.bottom();
    let rows = stock.within(grid.span(1, lo[1], hi[1]));
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
        let base = stock.index(0, j);
        for i in grid.span(0, from, to) {
            let index = base + i;
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
            removed(index, j, x, y, pieces);
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

/// The findings, times and removal of the moves in program order, from what each did over all
/// strips: the same whether one process swept every strip or parts of a split cut did.
struct Tally<'a> {
    job: &'a Job,
    findings: Vec<Finding>,
    left_off: usize,
    removed: f64,
    cutting_time: f64,
    air_time: f64,
    longest_air: Option<(f64, usize, [f64; 3], Option<u32>)>,
    blocks: Vec<BlockRemoval>,
    unplaced: usize,
    /// Whether a non-cutting member met the stock.
    touched: bool,
}

/// The dexel fields' totals after the last move, over every strip in order.
struct Totals {
    stock_lengths: Vec<f64>,
    part_lengths: Option<Vec<f64>>,
    final_lengths: Vec<f64>,
    /// With a part: each strip's thickest material left outside it.
    left: Vec<Worst>,
    updates: u64,
}

impl<'a> Tally<'a> {
    fn new(job: &'a Job) -> Self {
        Self {
            job,
            findings: Vec::new(),
            left_off: 0,
            removed: 0.0,
            cutting_time: 0.0,
            air_time: 0.0,
            longest_air: None,
            blocks: Vec::new(),
            unplaced: 0,
            touched: false,
        }
    }

    fn find(&mut self, finding: Finding) {
        if self.findings.len() < MAX_FINDINGS {
            self.findings.push(finding);
        } else {
            self.left_off += 1;
        }
    }

    /// Move `index` (`read`, planned as `plan`) did `outcome`: its findings, time and removal.
    ///
    /// # Errors
    /// As [`spindle_power`]; `E_TOO_LARGE_ANSWER` over the run's budget.
    fn record(
        &mut self,
        index: usize,
        read: &ReadMove,
        plan: &MovePlan<'_>,
        outcome: &MoveOutcome,
        run: &Run<'_>,
    ) -> Result<(), SolverError> {
        let (line, number) = (Some(read.line), plan.number);
        let finding = |kind, worst: Worst, volume| Finding {
            kind,
            line,
            tool: number,
            position: worst.position,
            depth: worst.depth,
            volume_mm3: volume,
            share: None,
            power_kw: None,
            limit_kw: None,
        };
        if plan.rapid && outcome.deepest.seen && outcome.deepest.depth > self.job.tolerance {
            self.find(finding(FindingKind::RapidThroughMaterial, outcome.deepest, outcome.deepest.volume));
        }
        if outcome.gouge.seen {
            self.find(finding(FindingKind::Gouge, outcome.gouge, outcome.gouge.volume));
        }
        let kinds = [FindingKind::NeckContact, FindingKind::ShankContact, FindingKind::HolderContact];
        for (worst, kind) in outcome.contacts.into_iter().zip(kinds) {
            if worst.seen {
                self.find(finding(kind, worst, 0.0));
            }
        }
        self.touched |= outcome.contacts.iter().any(|worst| worst.seen);
        let (volume, time, tool) = (outcome.removed, plan.time, plan.number);
        self.removed += volume;
        if let Some(time) = time {
            self.cutting_time += time;
            if volume == 0.0 {
                self.air_time += time;
                if self.longest_air.is_none_or(|(longest, ..)| time > longest) {
                    let start = read.from_xyz().or(read.to_xyz()).unwrap_or_default();
                    self.longest_air = Some((time, read.line, start, tool));
                }
            }
        }
        if volume > 0.0 {
            let rate = time.filter(|t| *t > 0.0).map(|t| volume / t * 60.0);
            let power = match (&self.job.power, rate) {
                (Some(model), Some(rate)) => Some(spindle_power(self, model, read, rate, plan.tool.flutes, tool)?),
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
            let moves = self.job.program.moves.len();
            run.charge(crate::capability::json_bytes(&block), index + 1, moves)?;
            self.blocks.push(block);
        }
        Ok(())
    }

    /// The answer, after the last move.
    ///
    /// # Errors
    /// `E_STOCK` at `stock` when no tool reached the stock.
    fn finish(mut self, totals: Totals) -> Result<Cut, SolverError> {
        let job = self.job;
        if self.removed == 0.0 && !self.touched {
            return Err(SolverError::new(
                ErrorCode::Stock,
                "no tool of the program reaches the stock: check the stock's position against the program's coordinates",
            )
            .at("stock"));
        }
        let air_share = if self.cutting_time > 0.0 { self.air_time / self.cutting_time } else { 0.0 };
        if air_share > job.air_share_limit
            && let Some((_, line, start, tool)) = self.longest_air
        {
            self.find(Finding {
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
        let mut left = Worst::default();
        for strip in &totals.left {
            left.merge(strip);
        }
        if left.seen {
            self.find(Finding {
                kind: FindingKind::LeftMaterial,
                line: None,
                tool: None,
                position: left.position,
                depth: left.depth,
                volume_mm3: left.volume,
                share: None,
                power_kw: None,
                limit_kw: None,
            });
        }
        let grid = job.grid;
        let area = grid.cell_area();
        Ok(Cut {
            ok: self.findings.is_empty(),
            findings: self.findings,
            findings_left_off: self.left_off,
            resolution: grid.spacing,
            rays: [grid.nx, grid.ny],
            stock_volume_mm3: dexel::volume(&totals.stock_lengths, area),
            part_volume_mm3: totals.part_lengths.map(|lengths| dexel::volume(&lengths, area)),
            removed_volume_mm3: self.removed,
            final_volume_mm3: dexel::volume(&totals.final_lengths, area),
            cutting_time_s: self.cutting_time,
            air_time_s: self.air_time,
            air_share,
            moves: job.program.moves.len(),
            moves_unplaced: self.unplaced,
            dexel_updates: totals.updates,
            blocks: self.blocks,
        })
    }
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
/// Every sum over rays is taken strip by strip and the strips' sums added in strip order, as
/// [`finish_parts`] adds those of a split cut's parts.
///
/// # Errors
/// As [`cut`].
pub(crate) fn cut_fields(
    job: &Job,
    stock: Field,
    part: Option<Field>,
    run: &Run<'_>,
) -> Result<(Cut, Field), SolverError> {
    let stock_lengths = stock.strip_lengths();
    let part_lengths = part.as_ref().map(Field::strip_lengths);
    let mut sweeper = Sweeper::new(job, stock, part);
    let mut tally = Tally::new(job);
    let moves = &job.program.moves;
    for (index, read) in moves.iter().enumerate() {
        run.control.check()?;
        run.control.report(index, moves.len());
        let Some(plan) = plan_move(job, read)? else {
            tally.unplaced += 1;
            continue;
        };
        sweeper.sweep(&plan);
        let mut outcome = MoveOutcome::default();
        sweeper.take(|_, strip| outcome.merge(strip));
        tally.record(index, read, &plan, &outcome, run)?;
    }
    let (final_lengths, left) = sweeper.left(job.allowance);
    let totals = Totals { stock_lengths, part_lengths, final_lengths, left, updates: sweeper.updates };
    Ok((tally.finish(totals)?, sweeper.stock))
}

/// What one part of a split cut hands on: the strips it cut, the part's check on them, and per
/// strip the material before and after and what each move did there.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct PartCut {
    /// The strips, `[first, end)`.
    strips: [usize; 2],
    /// With a part: the check of the part against the stock on these strips.
    check: Option<PartCheck>,
    stock_lengths: Vec<f64>,
    part_lengths: Option<Vec<f64>>,
    final_lengths: Vec<f64>,
    /// With a part: each strip's thickest material left outside it.
    left: Vec<Option<[f64; 5]>>,
    /// What the moves did, move by move, strip by strip.
    records: Vec<StripRecord>,
    updates: u64,
}

/// Cuts `job`'s program on the rays of strips `strips` only (a part of a split cut): each ray's
/// material changes only by the moves that reach it, so these rays end as one process leaves
/// them. A part whose own rays show the part outside the stock (which refuses the request) cuts
/// nothing.
///
/// # Errors
/// As [`cut`], but for what only the whole tells (`E_STOCK`, the spindle power, the budget).
pub(crate) fn cut_part(job: &Job, strips: std::ops::Range<usize>, run: &Run<'_>) -> Result<PartCut, SolverError> {
    let grid = job.grid;
    let rows = grid.strip_rows(strips.clone());
    let stock = job.stock.field_rows(grid, rows.clone());
    let part = job.part.as_ref().map(|part| part.field_rows(grid, rows));
    let check = part.as_ref().map(|part| PartCheck::of(part, &stock, job.tolerance));
    let mut cut = PartCut {
        strips: [strips.start, strips.end],
        check,
        stock_lengths: stock.strip_lengths(),
        part_lengths: part.as_ref().map(Field::strip_lengths),
        final_lengths: Vec::new(),
        left: Vec::new(),
        records: Vec::new(),
        updates: 0,
    };
    if check.is_some_and(|check| check.worst.is_some()) {
        return Ok(cut);
    }
    let mut sweeper = Sweeper::new(job, stock, part);
    let moves = &job.program.moves;
    for (index, read) in moves.iter().enumerate() {
        run.control.check()?;
        run.control.report(index, moves.len());
        let Some(plan) = plan_move(job, read)? else {
            continue;
        };
        sweeper.sweep(&plan);
        sweeper.take(|strip, outcome| cut.records.push(StripRecord::new(index, strip, outcome)));
    }
    let (final_lengths, left) = sweeper.left(job.allowance);
    cut.final_lengths = final_lengths;
    cut.left = left.into_iter().map(Worst::to_record).collect();
    cut.updates = sweeper.updates;
    Ok(cut)
}

/// The answer of a cut split into `parts` (in strip order, together every strip once), equal to
/// [`cut`]'s: the part's check merged, then each move's strips merged in strip order and tallied
/// in program order.
///
/// # Errors
/// As [`cut`]; `E_INTERNAL` when the parts do not make up the grid's strips.
pub(crate) fn finish_parts(job: &Job, parts: &[PartCut], run: &Run<'_>) -> Result<Cut, SolverError> {
    let mut next = 0;
    for part in parts {
        let [first, end] = part.strips;
        let count = end.saturating_sub(first);
        let lengths_fit = part.stock_lengths.len() == count
            && part.part_lengths.as_ref().is_none_or(|lengths| lengths.len() == count)
            && part.part_lengths.is_some() == job.part.is_some();
        if first != next || end <= first || !lengths_fit {
            return Err(mismatch(format!("a part of strips {first}..{end} after strip {next}")));
        }
        next = end;
    }
    if next != job.grid.strips() {
        return Err(mismatch(format!("the parts end at strip {next} of {}", job.grid.strips())));
    }
    if job.part.is_some() {
        let check = parts.iter().filter_map(|part| part.check).reduce(PartCheck::merge);
        check.ok_or_else(|| mismatch("no part checked the part".to_owned()))?.verdict()?;
    }
    if parts.iter().any(|part| part.final_lengths.len() != part.stock_lengths.len()) {
        return Err(mismatch("a part did not cut its strips".to_owned()));
    }
    let mut tally = Tally::new(job);
    let mut cursors = vec![0; parts.len()];
    let moves = &job.program.moves;
    for (index, read) in moves.iter().enumerate() {
        run.control.check()?;
        run.control.report(index, moves.len());
        let Some(plan) = plan_move(job, read)? else {
            tally.unplaced += 1;
            continue;
        };
        let mut outcome = MoveOutcome::default();
        for (part, cursor) in parts.iter().zip(&mut cursors) {
            while let Some(record) = part.records.get(*cursor).filter(|record| record.index == index) {
                outcome.merge(&record.outcome());
                *cursor += 1;
            }
        }
        tally.record(index, read, &plan, &outcome, run)?;
    }
    if parts.iter().zip(&cursors).any(|(part, cursor)| *cursor != part.records.len()) {
        return Err(mismatch("a part holds records of no move".to_owned()));
    }
    let concat = |each: fn(&PartCut) -> &Vec<f64>| parts.iter().flat_map(each).copied().collect::<Vec<f64>>();
    let totals = Totals {
        stock_lengths: concat(|part| &part.stock_lengths),
        part_lengths: job
            .part
            .is_some()
            .then(|| parts.iter().flat_map(|part| part.part_lengths.iter().flatten()).copied().collect::<Vec<f64>>()),
        final_lengths: concat(|part| &part.final_lengths),
        left: parts.iter().flat_map(|part| part.left.iter().map(|record| Worst::from_record(*record))).collect(),
        updates: parts.iter().map(|part| part.updates).sum(),
    };
    tally.finish(totals)
}

/// The rays the cutter's footprints cover on each strip over the whole program (the work of a
/// strip: [`super::capability`]'s cost model), with the program's moves; `None` when a move
/// calls a tool the request does not name (solving whole refuses it at its line).
pub(crate) fn strip_work(job: &Job) -> Option<Vec<f64>> {
    let grid = job.grid;
    let mut work = vec![0.0; grid.strips()];
    for read in &job.program.moves {
        let plan = plan_move(job, read).ok()?;
        let Some(plan) = plan else {
            continue;
        };
        let radius = plan.tool.assembly.cutter().radius;
        for segment in &plan.segments {
            let (lo, hi) = segment.reach(radius);
            let rows = grid.span(1, lo[1], hi[1]);
            if rows.is_empty() {
                continue;
            }
            let along = (segment.to[0] - segment.from[0]).hypot(segment.to[1] - segment.from[1]);
            let area = 2.0 * radius * along + std::f64::consts::PI * radius * radius;
            let per_row = area / grid.cell_area() / rows.len() as f64;
            let strips = rows.start / STRIP_ROWS..rows.end.div_ceil(STRIP_ROWS);
            for (strip, rays) in strips.clone().zip(&mut work[strips]) {
                let within = grid.strip_rows(strip..strip + 1);
                let overlap = within.end.min(rows.end) - within.start.max(rows.start);
                *rays += overlap as f64 * per_row;
            }
        }
    }
    Some(work)
}

fn mismatch(detail: String) -> SolverError {
    SolverError::new(ErrorCode::Internal, format!("the parts do not belong to this verification: {detail}"))
}

/// The spindle power, kW, block `read` needs to remove `rate` mm³/min with `flutes` teeth (tool
/// `tool`), with a finding when it is more than the machine's spindle gives.
///
/// # Errors
/// `E_INPUT` at `program` when the block cuts before the program sets a spindle speed.
fn spindle_power(
    tally: &mut Tally<'_>,
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
        tally.find(Finding {
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
        Field::new(grid, rays)
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
                sweep_cutter(&mut fast, &mut tops, &body, &segment, &mut Scratch::default(), |index, _, _, _, pieces| {
                    removed.extend(pieces.iter().map(|&piece| (index, piece)));
                });
                prop_assert_eq!(&removed, &sweep_every_ray(&mut every, &body, &segment));
                prop_assert!(fast.rays == every.rays);
            }
        }
    }
}
