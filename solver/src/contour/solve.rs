//! Layers, passes and links (docs/spec/contour.md §3.8 several passes, §3.9.1 layers, §3.11 steps): plans
//! every pass of every layer, joins them with leads at the start edge and retracts to the
//! clearance plane between layers, and assembles the answer with its corner reports and
//! warnings.

use super::answer::{
    ArcSpan, ContourCorner, ContourLayer, ContourMove, ContourSolution, ContourSummary, Convexity, CornerAction,
    LoopReport, MaterialReport, MoveKind, PassReport, ReliefReport,
};
use super::blocks;
use super::element::{Chording, Element, ElementKind};
use super::job::Job;
use super::layer::Layer;
use super::material::{self, Material};
use super::pass::{self, Action, GOUGE_TOLERANCE, MAX_ARC_STEPS, PassInput, PassPlan, Stock};
use super::prepare::list_indices;
use super::request::{ContourRequest, CutDirection, Join, LoopStyle, MAX_MOVES, Side};
use crate::capability::Control;
use crate::error::ErrorCode;
use crate::error::{SolverError, Warning};
use crate::geometry::Vec3;
use crate::machine::MachineProfile;
use crate::planar::{SegmentGrid, Vec2, array2, cross, miter_point};
use crate::tool::{Tool, ToolKind};

/// Largest number of vertex-layers planned one by one (tilted walls plan every layer).
const MAX_TILTED_VERTEX_LAYERS: usize = 20_000_000;
/// Height above the previous layer (or the top) where the rapid descent ends, mm.
const APPROACH_GAP: f64 = 1.0;
/// Material angle below which a corner is reported as a fragile tip (`W_ACUTE_TIP`), degrees.
const ACUTE_TIP_DEG: f64 = 15.0;

/// The 2-D plan of every pass in the first layer (for diagnostics, reference cases and the
/// division coordinates of claim 1).
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// σ: +1 with the material on the left of travel, −1 on the right.
    pub sigma: f64,
    /// Z of the layer planned.
    pub z: f64,
    /// The passes, outermost first.
    pub passes: Vec<PassPlan>,
    /// Warnings of preparation and planning.
    pub warnings: Vec<Warning>,
}

/// How the job travels the contour.
struct Setup {
    sigma: f64,
    counter_clockwise: bool,
    request_order: bool,
    cell: f64,
}

impl Setup {
    fn new(job: &Job) -> Self {
        let sigma = match job.direction {
            CutDirection::Conventional => 1.0,
            CutDirection::Climb => -1.0,
        };
        let counter_clockwise = (job.side == Side::Outside) == (sigma > 0.0);
        let largest = job.passes.iter().map(|p| p.allowance).fold(0.0, f64::max);
        Self {
            sigma,
            counter_clockwise,
            request_order: counter_clockwise != job.contour.reversed,
            cell: job.radius + largest,
        }
    }
}

/// Plans the first layer only.
///
/// # Errors
/// As [`solve`].
pub fn plan(request: &ContourRequest, tool: &Tool) -> Result<Plan, SolverError> {
    let job = request.validate(tool, None)?;
    let setup = Setup::new(&job);
    let z = job.layers.first().copied().unwrap_or(job.bottom);
    let layer = build_layer(&job, &setup, z)?;
    let passes = plan_passes(&job, &setup, &layer)?;
    let mut warnings = job.warnings.clone();
    for pass in &passes {
        warnings.extend(pass.warnings.iter().cloned());
    }
    Ok(Plan { sigma: setup.sigma, z, passes, warnings })
}

/// Solves a contour request with its resolved tool.
///
/// # Errors
/// `E_INPUT` naming the field for bad numbers; the contour codes of preparation
/// (`E_DEGENERATE`, `E_DUPLICATE_POINT`, `E_SELF_INTERSECTION`, `E_ORIENTATION`); the tool-fit
/// codes `E_OFFSET_COLLAPSE` and `E_OFFSET_SELF_INTERSECTION` (naming `contour[k]`); limits
/// `E_TOO_MANY_POINTS`, `E_TOO_MANY_LAYERS`, `E_TOO_MANY_MOVES`, `E_TOO_COMPLEX`.
pub fn solve(request: &ContourRequest, tool: &Tool) -> Result<ContourSolution, SolverError> {
    solve_within(request, tool, MAX_MOVES)
}

/// [`solve`] with a smaller move budget than [`MAX_MOVES`] (a JSON answer, which the server
/// limits further than a G-code program): `E_TOO_MANY_MOVES` at `depths.step` when the layers
/// would hold more than `max_moves` moves, decided from the first layer's plan before the
/// layers are built (and checked again on the exact count).
///
/// # Errors
/// As [`solve`].
pub fn solve_within(request: &ContourRequest, tool: &Tool, max_moves: usize) -> Result<ContourSolution, SolverError> {
    solve_with(request, tool, None, max_moves, Control::default())
}

/// [`solve_within`] for a request that names a machine: `machine` is the profile its
/// `machine` names (block time, margin and minimum chord error as defaults of the block-time
/// rule; `W_FEED_ABOVE_MACHINE_MAX` when `feed` is above its `max_feed`).
///
/// # Errors
/// As [`solve`], and `E_CANCELLED` once `control`'s cancel flag is set (checked per layer).
/// `machine` is the profile the request's `machine` names, resolved by the caller
/// (`capability::resolve`).
pub fn solve_with(
    request: &ContourRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    max_moves: usize,
    control: Control<'_>,
) -> Result<ContourSolution, SolverError> {
    let prepared = Prepared::new(request, tool, machine, max_moves)?;
    let layers = prepared.layers(0..prepared.job.layers.len(), control)?;
    prepared.answer(machine, max_moves, layers)
}

/// What every layer of a contour is made from: the validated job, how it travels the contour,
/// and the first layer with its passes (every layer's, unless the walls are tilted). Solving
/// whole or in layer ranges (a job split into parts) makes it the same way.
pub(crate) struct Prepared {
    pub(crate) job: Job,
    setup: Setup,
    first_layer: Layer,
    first_passes: Vec<PassPlan>,
}

/// One layer's moves and the lead its passes start from (0 without a lead point).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub(crate) struct LayerMoves {
    pub(crate) z: f64,
    pub(crate) moves: Vec<ContourMove>,
    pub(crate) arcs: Vec<ArcSpan>,
    pub(crate) lead: f64,
}

impl Prepared {
    /// Validates the request and plans the first layer; refuses a contour over `max_moves` (at
    /// most [`MAX_MOVES`]) before any other layer is made.
    ///
    /// # Errors
    /// As [`solve`].
    pub(crate) fn new(
        request: &ContourRequest,
        tool: &Tool,
        machine: Option<&MachineProfile>,
        max_moves: usize,
    ) -> Result<Self, SolverError> {
        let max_moves = max_moves.min(MAX_MOVES);
        let job = request.validate(tool, machine)?;
        let setup = Setup::new(&job);
        let first_z = job.layers.first().copied().unwrap_or(job.bottom);
        let first_layer = build_layer(&job, &setup, first_z)?;
        let first_passes = plan_passes(&job, &setup, &first_layer)?;
        let per_layer = layer_move_count(&first_passes, &job.chording);
        let total = per_layer.saturating_mul(job.layers.len());
        if total > max_moves {
            return Err(too_many_moves(job.layers.len(), per_layer, total, max_moves));
        }
        if job.tilt.is_some() && job.layers.len().saturating_mul(first_layer.len()) > MAX_TILTED_VERTEX_LAYERS {
            return Err(SolverError::new(
                ErrorCode::TooManyMoves,
                format!(
                    "tilted walls plan every layer: {} layers × {} corners exceed {MAX_TILTED_VERTEX_LAYERS}",
                    job.layers.len(),
                    first_layer.len()
                ),
            )
            .at("depths.step"));
        }
        Ok(Self { job, setup, first_layer, first_passes })
    }

    /// The vertices of one layer's contour.
    pub(crate) fn corners(&self) -> usize {
        self.first_layer.len()
    }

    /// The moves of one layer (of the first; a tilted wall's layers have about as many).
    pub(crate) fn moves_per_layer(&self) -> usize {
        layer_move_count(&self.first_passes, &self.job.chording)
    }

    /// The moves of the layers `range` (indices into the job's layers), in order.
    ///
    /// # Errors
    /// Tilted walls: the tool-fit codes of a layer's plan; `E_CANCELLED` once `control`'s cancel
    /// flag is set (checked per layer).
    pub(crate) fn layers(
        &self,
        range: std::ops::Range<usize>,
        control: Control<'_>,
    ) -> Result<Vec<LayerMoves>, SolverError> {
        let job = &self.job;
        let mut layers = Vec::with_capacity(range.len());
        let (from, count) = (range.start, range.len());
        for index in range {
            let z = job.layers[index];
            control.check()?;
            control.report(index - from, count);
            let tilted;
            let (layer, passes) = if index == 0 || job.tilt.is_none() {
                (&self.first_layer, &self.first_passes)
            } else {
                let layer = build_layer(job, &self.setup, z)?;
                let passes = plan_passes(job, &self.setup, &layer)?;
                tilted = (layer, passes);
                (&tilted.0, &tilted.1)
            };
            let lead_point = lead_point(job, layer, passes);
            let lead = lead_point.map_or(0.0, |(_, lead)| lead);
            let previous_z = if index == 0 { job.top } else { job.layers[index - 1] };
            let (moves, arcs) =
                layer_moves(job, layer, passes, lead_point.map(|(point, _)| point), index == 0, previous_z, z);
            layers.push(LayerMoves { z, moves, arcs, lead });
        }
        Ok(layers)
    }

    /// The answer from every layer's moves, in order: corners, passes, summary, warnings.
    ///
    /// # Errors
    /// `E_TOO_MANY_MOVES` over `max_moves`; `E_INPUT` without a pass.
    pub(crate) fn answer(
        &self,
        machine: Option<&MachineProfile>,
        max_moves: usize,
        made: Vec<LayerMoves>,
    ) -> Result<ContourSolution, SolverError> {
        let max_moves = max_moves.min(MAX_MOVES);
        let Self { job, setup, first_layer, first_passes } = self;
        let job: &Job = job;
        let mut warnings = job.warnings.clone();
        for pass in first_passes {
            warnings.extend(pass.warnings.iter().cloned());
        }
        let (layers, lead_used) = answer_layers(job, made, &mut warnings);

        let final_pass = first_passes
            .last()
            .ok_or_else(|| SolverError::new(ErrorCode::Input, "at least one pass is needed").at("passes"))?;
        let corners = corner_reports(job, setup, first_layer, final_pass);
        warnings.extend(corner_warnings(job, first_passes, &corners));
        let passes: Vec<PassReport> = first_passes.iter().map(pass_report).collect();

        let (feed_length, time_min, moves) = feed_travel(&layers);
        if moves > max_moves {
            return Err(too_many_moves(layers.len(), moves / layers.len().max(1), moves, max_moves));
        }
        let blocks = block_figures(job, first_passes, &layers, &mut warnings)?;
        let loop_feed = job.loop_feed.unwrap_or(job.feed);
        let summary = ContourSummary {
            side: job.side,
            direction: job.direction,
            tool_radius: job.radius,
            corners: first_layer.len(),
            layers: layers.len(),
            passes: job.passes.len(),
            moves,
            feed_length,
            feed: job.feed,
            loop_feed,
            spindle_rpm: job.spindle_rpm,
            safe_z: job.safe_z,
            lead: lead_used,
            tolerance: job.tolerance,
            estimated_time_s: time_min * 60.0,
            blocks,
            cycle_time: machine.and_then(|m| contour_cycle_time(&layers, m, job.plunge_feed)),
        };
        let description = describe(job, &summary);
        let centre_height = centre_height(job);
        Ok(ContourSolution {
            layers,
            corners,
            passes,
            summary,
            warnings,
            tool_kind: job.tool.kind,
            centre_height,
            description,
            tilted: job.tilt.is_some(),
        })
    }
}

/// The answer's layers from the moves made, the shortest lead any layer used, and a warning when
/// a lead had to be shortened.
fn answer_layers(job: &Job, made: Vec<LayerMoves>, warnings: &mut Vec<Warning>) -> (Vec<ContourLayer>, f64) {
    let mut lead_used = job.lead;
    let mut shortened = false;
    let mut layers = Vec::with_capacity(made.len());
    for LayerMoves { z, moves, arcs, lead } in made {
        if lead < job.lead {
            shortened = true;
        }
        lead_used = lead_used.min(lead);
        layers.push(ContourLayer { z, moves, arcs });
    }
    if shortened {
        warnings.push(Warning::new(
            "W_LEAD_SHORTENED",
            format!("the lead of {} mm would gouge the contour; {lead_used:.4} mm is used", job.lead),
        ));
    }
    (layers, lead_used)
}

/// Length (mm) and time (min) of the feed moves, and the count of all moves.
fn feed_travel(layers: &[ContourLayer]) -> (f64, f64, usize) {
    let mut feed_length = 0.0;
    let mut time_min = 0.0;
    let mut moves = 0;
    for layer in layers {
        let mut from: Option<[f64; 3]> = None;
        for step in &layer.moves {
            if let (Some(a), Some(feed)) = (from, step.feed) {
                let length = Vec3::from(step.to).metric_distance(&Vec3::from(a));
                feed_length += length;
                time_min += length / feed;
            }
            from = Some(step.to);
        }
        moves += layer.moves.len();
    }
    (feed_length, time_min, moves)
}

/// Under the block-time rule, the block figures of every move and the warnings on arcs and
/// short blocks; `None` without the rule.
fn block_figures(
    job: &Job,
    first_passes: &[PassPlan],
    layers: &[ContourLayer],
    warnings: &mut Vec<Warning>,
) -> Result<Option<crate::machine::PathBlocks>, SolverError> {
    Ok(match &job.chording.rules {
        None => None,
        Some((rule, _)) => {
            let (finest, arc_warnings) = blocks::arc_report(first_passes, &job.chording);
            warnings.extend(arc_warnings);
            let moves = layers.iter().flat_map(|layer| &layer.moves).map(|step| (Vec3::from(step.to), step.feed));
            let figures = crate::machine::path_blocks(moves, rule.block_time_ms, job.feed, finest)?;
            warnings.extend(crate::machine::short_block_warning(&figures, rule));
            Some(figures)
        }
    })
}

/// Height of the tool's centre above its tip: the G-code reference point of ball and bull tools.
fn centre_height(job: &Job) -> f64 {
    match job.tool.kind {
        ToolKind::Flat => 0.0,
        ToolKind::Ball => job.radius,
        ToolKind::Bull => job.tool.corner_radius.unwrap_or(0.0),
    }
}

fn too_many_moves(layers: usize, per_layer: usize, total: usize, limit: usize) -> SolverError {
    SolverError::new(
        ErrorCode::TooManyMoves,
        format!(
            "{layers} layers of about {per_layer} moves make {total} moves; the limit is {limit}: use a larger depths.step, tolerance or fewer points"
        ),
    )
    .at("depths.step")
}

/// The layer's contour at height `z` (tilted walls move with z).
fn build_layer(job: &Job, setup: &Setup, z: f64) -> Result<Layer, SolverError> {
    let shift: Option<Vec<f64>> =
        job.tilt.as_ref().map(|tilt| tilt.iter().map(|beta| (z - job.bottom) * beta.tan()).collect());
    Layer::new(&job.contour, job.start_edge, setup.counter_clockwise, setup.sigma, shift.as_deref(), setup.cell)
}

/// Every pass of one layer, each with the stock the previous one left.
fn plan_passes(job: &Job, setup: &Setup, layer: &Layer) -> Result<Vec<PassPlan>, SolverError> {
    let source: Vec<usize> = layer.prepared_vertex.iter().map(|&v| job.contour.source[v]).collect();
    let edge_source: Vec<usize> =
        (0..layer.len()).map(|k| source[if setup.request_order { k } else { layer.next(k) }]).collect();
    let choices: Vec<_> = layer.prepared_vertex.iter().map(|&v| job.choices[v]).collect();
    let mut plans: Vec<PassPlan> = Vec::with_capacity(job.passes.len());
    for (index, pass) in job.passes.iter().enumerate() {
        let edge_offsets: Vec<f64> = (0..layer.len())
            .map(|k| {
                let beta = job.tilt.as_ref().and_then(|t| t.get(layer.prepared_edge[k]).copied()).unwrap_or(0.0);
                job.radius / beta.cos() + pass.allowance
            })
            .collect();
        let stock = stock_before(job, layer, plans.last());
        let input = PassInput {
            index,
            pass: *pass,
            radius: job.radius,
            edge_offsets,
            loop_config: &job.loop_config,
            choices: choices.clone(),
            request_order: setup.request_order,
            chording: job.chording,
            stock: stock.as_ref(),
            source: source.clone(),
            edge_source: edge_source.clone(),
        };
        plans.push(pass::plan_pass(layer, &input)?);
    }
    Ok(plans)
}

/// The stock before a pass (§3.5.7): after a round pass the contour grown by its allowance
/// (S1); after a miter or loop pass the sharp offset (S2); before the first pass the sharp offset
/// by `stock_allowance`, or unknown. Inside corners add the fillet the previous tool left.
fn stock_before(job: &Job, layer: &Layer, previous: Option<&PassPlan>) -> Option<Stock> {
    let n = layer.len();
    let sharp = |allowance: f64| -> Option<SegmentGrid> {
        let points: Option<Vec<Vec2>> = (0..n)
            .map(|k| {
                let before = layer.previous(k);
                miter_point(&layer.vertices[k], &layer.air_normal(before), allowance, &layer.air_normal(k), allowance)
            })
            .collect();
        let points = points?;
        Some(SegmentGrid::new((0..n).map(|k| (points[k], points[(k + 1) % n])).collect(), job.radius))
    };
    let Some(previous) = previous else {
        return job.stock_allowance.and_then(sharp).map(|grid| Stock { parts: vec![(grid, 0.0)] });
    };
    let allowance = previous.allowance;
    let mut parts = Vec::new();
    if previous.join == Join::Round && !previous.loops {
        parts.push((layer.grid.clone(), allowance));
    } else {
        parts.push((sharp(allowance)?, 0.0));
    }
    let fillets: Vec<(Vec2, Vec2)> = previous
        .corners
        .iter()
        .filter(|c| !c.convex)
        .flat_map(|corner| {
            let k = corner.k;
            let before = layer.previous(k);
            let (n1, n2) = (layer.air_normal(before), layer.air_normal(k));
            let corner_point = miter_point(&corner.vertex, &n1, allowance, &n2, allowance).unwrap_or(corner.vertex);
            let t1 = corner.cl_point - (previous.edge_offsets[before] - allowance) * n1;
            let t2 = corner.cl_point - (previous.edge_offsets[k] - allowance) * n2;
            [(corner_point, t1), (t1, t2), (t2, corner_point)]
        })
        .collect();
    if !fillets.is_empty() {
        parts.push((SegmentGrid::new(fillets, job.radius), 0.0));
    }
    Some(Stock { parts })
}

/// Moves of one layer, without the layer links.
fn layer_move_count(passes: &[PassPlan], chording: &Chording) -> usize {
    passes
        .iter()
        .map(|pass| pass.elements.iter().map(|e| e.chords_count(chording, MAX_ARC_STEPS)).sum::<usize>() + 2)
        .sum::<usize>()
        + 4
}

/// The lead point above which every pass of the layer starts, and the lead length used: on the
/// normal of the start edge's middle, `lead` beyond the outermost pass, shortened until the
/// leads to every pass's S clear the contour; `None` when no lead along that normal does (the
/// passes then start by plunging at their S).
fn lead_point(job: &Job, layer: &Layer, passes: &[PassPlan]) -> Option<(Vec2, f64)> {
    let edge = passes.first().map_or(0, |p| p.start_edge);
    let middle = 0.5 * (layer.vertices[edge] + layer.vertices[layer.next(edge)]);
    let normal = layer.air_normal(edge);
    let outermost = passes.iter().filter_map(|p| p.edge_offsets.get(edge).copied()).fold(0.0, f64::max);
    let mut lead = job.lead;
    let mut scratch = Vec::new();
    for _ in 0..40 {
        let point = middle + (outermost + lead) * normal;
        let clear = passes.iter().all(|pass| {
            layer.grid.nearest(&point, &pass.start, pass.offset - GOUGE_TOLERANCE, &mut scratch, |_| false).is_none()
        });
        if clear {
            return Some((point, lead));
        }
        lead *= 0.5;
    }
    None
}

/// Whether the straight move `[a, b]` keeps `clear` from the contour.
fn clears(layer: &Layer, a: &Vec2, b: &Vec2, clear: f64) -> bool {
    let mut scratch = Vec::new();
    layer.grid.nearest(a, b, clear - GOUGE_TOLERANCE, &mut scratch, |_| false).is_none()
}

/// The tool axis of traversal edge `edge`: cos β·ẑ + sin β·n(t_e) (O6).
fn axis(job: &Job, layer: &Layer, edge: usize) -> Option<Vec3> {
    let tilt = job.tilt.as_ref()?;
    let beta = tilt.get(layer.prepared_edge.get(edge).copied()?).copied()?;
    let normal = layer.air_normal(edge);
    Some(Vec3::new(beta.sin() * normal.x, beta.sin() * normal.y, beta.cos()))
}

/// Whether `line` is a straight element of some length that lies on the line from `a` to `b`
/// and runs the same way (an arc's end tangent it continues).
fn continues(line: &Element, a: &Vec2, b: &Vec2) -> bool {
    let Element::Line { start, end, .. } = line else { return false };
    let (along, tangent) = (end - start, b - a);
    let scale = along.norm() * tangent.norm();
    along.norm() > 1e-9 && scale > 0.0 && along.dot(&tangent) > 0.0 && cross(&along, &tangent).abs() <= 1e-9 * scale
}

/// Every move of one layer: down from the clearance plane at the lead point, each pass with its
/// lead-in and lead-out, back up. Without a lead point the first pass starts by plunging at its S,
/// and later passes are reached by a straight link where it clears the contour, else over the
/// clearance plane.
#[allow(clippy::too_many_arguments)]
fn layer_moves(
    job: &Job,
    layer: &Layer,
    passes: &[PassPlan],
    lead_point: Option<Vec2>,
    first: bool,
    previous_z: f64,
    z: f64,
) -> (Vec<ContourMove>, Vec<ArcSpan>) {
    let start_axis = axis(job, layer, 0).map(|a| Box::new([a.x, a.y, a.z]));
    let Some(first_start) = passes.first().map(|p| p.start) else {
        return (Vec::new(), Vec::new());
    };
    let mut out = LayerWriter { moves: Vec::new(), arcs: Vec::new(), start_axis, z };
    let entry = lead_point.unwrap_or(first_start);
    let approach = (previous_z + APPROACH_GAP.min(job.safe_z - previous_z)).max(z);
    if first {
        out.push(MoveKind::Rapid, at(&entry, job.safe_z), None);
    }
    if approach < job.safe_z {
        out.push(MoveKind::Rapid, at(&entry, approach), None);
    }
    let towards = if entry == first_start { first_chord_end(job, &passes[0]) } else { Some(first_start) };
    for (to, feed) in entry_moves(job, entry, towards, approach.min(job.safe_z), z) {
        out.push(MoveKind::Link, to, Some(feed));
    }
    let mut here = entry;
    let loop_feed = job.loop_feed.unwrap_or(job.feed);
    for pass in passes {
        if here != pass.start {
            out.link(job, layer, here, pass, lead_point.is_some(), approach);
        }
        out.pass(job, layer, pass, loop_feed);
        here = pass.start;
        if let Some(lead) = lead_point {
            out.push(MoveKind::Link, at(&lead, z), Some(job.feed));
            here = lead;
        }
    }
    out.push(MoveKind::Rapid, at(&here, job.safe_z), None);
    (out.moves, out.arcs)
}

/// The point `p` at `height`.
fn at(p: &Vec2, height: f64) -> [f64; 3] {
    [p.x, p.y, height]
}

/// One layer's moves and arc spans as they are written at height `z`.
struct LayerWriter {
    moves: Vec<ContourMove>,
    arcs: Vec<ArcSpan>,
    /// The tool axis at the start edge (tilted walls), given to every move but the cuts.
    start_axis: Option<Box<[f64; 3]>>,
    z: f64,
}

impl LayerWriter {
    /// Appends a move with the start edge's tool axis.
    fn push(&mut self, kind: MoveKind, to: [f64; 3], feed: Option<f64>) {
        self.moves.push(ContourMove { kind, to, feed, axis: self.start_axis.clone() });
    }

    /// From `here` to the start of `pass`: straight at the layer's height where that clears the
    /// contour (always from a lead point), else up, over and down again with an entry.
    fn link(&mut self, job: &Job, layer: &Layer, here: Vec2, pass: &PassPlan, from_lead: bool, approach: f64) {
        let z = self.z;
        if from_lead || clears(layer, &here, &pass.start, pass.offset) {
            self.push(MoveKind::Link, at(&pass.start, z), Some(job.feed));
        } else {
            self.push(MoveKind::Rapid, at(&here, job.safe_z), None);
            self.push(MoveKind::Rapid, at(&pass.start, job.safe_z), None);
            if approach < job.safe_z {
                self.push(MoveKind::Rapid, at(&pass.start, approach), None);
            }
            let towards = first_chord_end(job, pass);
            for (to, feed) in entry_moves(job, pass.start, towards, approach.min(job.safe_z), z) {
                self.push(MoveKind::Link, to, Some(feed));
            }
        }
    }

    /// The elements of `pass` as chords, loops at `loop_feed` where they clear the stock, each
    /// move with its tool axis blended along the element, and the arcs' spans.
    fn pass(&mut self, job: &Job, layer: &Layer, pass: &PassPlan, loop_feed: f64) {
        let z = self.z;
        let merge = job.chording.rules.is_some();
        for (position, (element, meta)) in pass.elements.iter().zip(&pass.meta).enumerate() {
            let kind = if element.kind() == ElementKind::Loop { MoveKind::Loop } else { MoveKind::Cut };
            let feed = if meta.fast { loop_feed } else { job.feed };
            let points = element.chords(&job.chording, MAX_ARC_STEPS);
            let count = points.len() as f64;
            let from_axis = axis(job, layer, meta.from_edge);
            let to_axis = axis(job, layer, meta.to_edge);
            // Under the block-time rule an arc's half-length end segments (along its end
            // tangents) join the straight moves they continue, so no block is half a block.
            let (mut first, mut last) = (0, points.len());
            if merge && matches!(element, Element::Arc { .. }) && points.len() > 1 {
                let before = position.checked_sub(1).and_then(|k| pass.elements.get(k));
                if before.is_some_and(|line| continues(line, &element.start(), &points[0]))
                    && let Some(previous) = self.moves.last_mut()
                    && previous.to == at(&element.start(), z)
                {
                    previous.to = at(&points[0], z);
                    first = 1;
                }
                let after = pass.elements.get(position + 1);
                if after.is_some_and(|line| continues(line, &points[points.len() - 2], &element.end())) {
                    last -= 1;
                }
            }
            if let Element::Arc { start, end, centre, sweep, .. } = element
                && last > first
            {
                self.arcs.push(ArcSpan {
                    first: self.moves.len(),
                    last: self.moves.len() + last - first - 1,
                    start: [start.x, start.y],
                    end: [end.x, end.y],
                    centre: [centre.x, centre.y],
                    sweep: *sweep,
                });
            }
            for (index, point) in points.iter().enumerate().take(last).skip(first) {
                let axis = from_axis.zip(to_axis).map(|(a, b)| {
                    let s = (index as f64 + 1.0) / count;
                    let mixed = (a * (1.0 - s) + b * s).try_normalize(0.0).unwrap_or(b);
                    Box::new([mixed.x, mixed.y, mixed.z])
                });
                self.moves.push(ContourMove { kind, to: at(point, z), feed: Some(feed), axis });
            }
        }
    }
}

/// Longest leg of a ramp entry, in tool radii: long enough for a shallow angle, short enough to
/// stay near the entry point.
const MAX_RAMP_RADII: f64 = 4.0;

/// Most legs of one ramp entry.
const MAX_RAMP_LEGS: usize = 10_000;

/// The end of the first chord of `pass`: the direction a ramp entry at its start runs along.
fn first_chord_end(job: &Job, pass: &PassPlan) -> Option<Vec2> {
    let element = pass.elements.first()?;
    element.chords(&job.chording, MAX_ARC_STEPS).first().copied()
}

/// The feed moves (end, feed) from `point` at `from_z` down to `point` at `z`: one
/// plunge when the tool cuts at its centre (at the cutting feed in the answer; the post writes it
/// at the plunge feed); otherwise a ramp at the plunge feed that runs from `point` towards
/// `towards` and back, legs of at most [`MAX_RAMP_RADII`] tool radii, each descending the same
/// height at no more than the ramp angle, ending at `point` at `z`. Without a direction (no lead
/// and a zero-length first move) the tool plunges.
fn entry_moves(job: &Job, point: Vec2, towards: Option<Vec2>, from_z: f64, z: f64) -> Vec<([f64; 3], f64)> {
    let bottom = vec![([point.x, point.y, z], job.feed)];
    let drop = from_z - z;
    let Some(angle) = job.ramp else { return bottom };
    let Some((direction, length)) = towards
        .map(|t| t - point)
        .and_then(|d| d.try_normalize(1e-9).map(|u| (u, d.norm().min(MAX_RAMP_RADII * job.radius))))
    else {
        return bottom;
    };
    if drop <= 0.0 || length <= 1e-6 {
        return bottom;
    }
    let feed = crate::gcode::plunge_feed(job.feed, job.plunge_feed);
    let legs = (drop / (length * angle.tan())).ceil() as usize;
    let legs = (legs + legs % 2).clamp(2, MAX_RAMP_LEGS);
    let far = point + direction * length;
    (1..=legs)
        .map(|leg| {
            let at = if leg % 2 == 1 { far } else { point };
            let height = if leg == legs { z } else { from_z - drop * leg as f64 / legs as f64 };
            ([at.x, at.y, height], feed)
        })
        .collect()
}

/// The cycle time of the program of `layers` on `machine` (None without its `max_accel`):
/// cuts in the material, loops and links in the air, plunges at the plunge feed as the program
/// writes them.
fn contour_cycle_time(
    layers: &[ContourLayer],
    machine: &MachineProfile,
    tool_plunge_feed: Option<f64>,
) -> Option<crate::machine::cycle::CycleTime> {
    use crate::machine::cycle::{Step, cycle_time};
    let dynamics = machine.dynamics()?;
    let plunge = tool_plunge_feed.or(machine.plunge_feed);
    let first = layers.first()?.moves.first()?;
    let mut here = Vec3::from(first.to);
    let mut steps = Vec::new();
    for step in layers.iter().flat_map(|layer| &layer.moves) {
        let to = Vec3::from(step.to);
        steps.push(match (step.kind, step.feed) {
            (MoveKind::Rapid, _) | (_, None) => Step::Rapid(to),
            (kind, Some(feed)) => {
                let down = to.z < here.z && (to.x - here.x).abs() <= 1e-9 && (to.y - here.y).abs() <= 1e-9;
                let feed = if down { crate::gcode::plunge_feed(feed, plunge) } else { feed };
                Step::Feed { to, feed, air: kind != MoveKind::Cut }
            }
        });
        here = to;
    }
    Some(cycle_time(Vec3::from(first.to), &steps, &dynamics, 1))
}

fn corner_action(action: Action) -> CornerAction {
    match action {
        Action::LoopArc => CornerAction::LoopArc,
        Action::LoopTriangle => CornerAction::LoopTriangle,
        Action::LoopParallelogram => CornerAction::LoopParallelogram,
        Action::Miter => CornerAction::Miter,
        Action::Round => CornerAction::Round,
        Action::Reflex => CornerAction::Reflex,
        Action::Unreached => CornerAction::Unreached,
        Action::Dogbone => CornerAction::Dogbone,
        Action::Tbone => CornerAction::Tbone,
    }
}

fn material_report(material: &Material) -> MaterialReport {
    MaterialReport {
        left_area: material.left_area,
        left_depth: material.left_depth,
        overcut_area: material.overcut_area,
        overcut_depth: material.overcut_depth,
    }
}

/// The corner reports from the final pass of the first layer, in request order.
fn corner_reports(job: &Job, setup: &Setup, layer: &Layer, final_pass: &PassPlan) -> Vec<ContourCorner> {
    let lag_product = job.servo_time_constant_s.map(|t| (job.feed / 60.0 * t).powi(2));
    let model = job.blend_radius.is_some() || lag_product.is_some();
    let mut corners: Vec<ContourCorner> = final_pass
        .corners
        .iter()
        .map(|corner| {
            let ideal = if corner.action == Action::Unreached {
                if corner.chain_start == corner.k {
                    let chain: Vec<usize> =
                        final_pass.corners.iter().filter(|c| c.chain_start == corner.k).map(|c| c.k).collect();
                    material::unreached(layer, &corner.cl_point, &chain, job.radius)
                } else {
                    Material::default()
                }
            } else {
                material::ideal(layer, corner, job.radius)
            };
            let predicted = model.then(|| {
                material::predicted(corner, &ideal, job.radius, final_pass.offset, job.blend_radius, lag_product)
            });
            let corner_loop = corner.loop_shape.map(|shape| LoopReport {
                style: shape.style,
                leg: shape.leg,
                radius: shape.radius,
                exit_end: array2(&shape.exit_end),
                entry_start: array2(&shape.entry_start),
                centre: shape.centre.as_ref().map(array2),
                far_corner: shape.far_corner.as_ref().map(array2),
                sweep_deg: shape.sweep.map(f64::to_degrees),
                length: shape.length(),
                clearance: corner.clearance.unwrap_or(0.0),
                at_loop_feed: corner.loop_feed && job.loop_feed.is_some(),
            });
            let relief = corner.relief.map(|shape| ReliefReport {
                style: shape.style,
                target: array2(&shape.target),
                along_edge: shape.along_edge.map(|edge| {
                    let start = if setup.request_order { edge } else { layer.next(edge) };
                    job.contour.source[layer.prepared_vertex[start]]
                }),
            });
            ContourCorner {
                index: corner.source,
                vertex: array2(&job.contour.points[layer.prepared_vertex[corner.k]]),
                angle_deg: corner.material_angle.to_degrees(),
                turn_deg: corner.turn.to_degrees(),
                convexity: if corner.convex { Convexity::Convex } else { Convexity::Concave },
                looped: corner.loop_shape.is_some(),
                action: corner_action(corner.action),
                cl_point: array2(&corner.cl_point),
                corner_loop,
                relief,
                material: material_report(&ideal),
                predicted: predicted.as_ref().map(material_report),
            }
        })
        .collect();
    corners.sort_by_key(|c| c.index);
    corners
}

/// Warnings about corners: acute tips, corners too flat to loop, inside corners, loops at the
/// cutting feed, and passes whose allowance does not protect the tip (E1).
fn corner_warnings(job: &Job, passes: &[PassPlan], corners: &[ContourCorner]) -> Vec<Warning> {
    let mut warnings = Vec::new();
    shape_warnings(job, passes, corners, &mut warnings);
    loop_feed_warnings(job, passes, &mut warnings);
    allowance_warnings(job, passes, &mut warnings);
    warnings
}

/// Corners whose shape needs saying: acute tips, convex corners too flat to loop, inside
/// corners left with a fillet.
fn shape_warnings(job: &Job, passes: &[PassPlan], corners: &[ContourCorner], warnings: &mut Vec<Warning>) {
    let acute: Vec<usize> = corners
        .iter()
        .filter(|c| c.convexity == Convexity::Convex && c.angle_deg < ACUTE_TIP_DEG)
        .map(|c| c.index)
        .collect();
    if !acute.is_empty() {
        warnings.push(Warning::new(
            "W_ACUTE_TIP",
            format!(
                "{} corners are sharper than {ACUTE_TIP_DEG}°; the tip is fragile and the loop legs long: {}",
                acute.len(),
                list_indices(&acute)
            ),
        ));
    }
    if let Some(final_pass) = passes.last()
        && final_pass.loops
        && job.loop_config.style != LoopStyle::None
    {
        let flat: Vec<usize> = final_pass
            .corners
            .iter()
            .filter(|c| c.convex && c.turn.abs() < job.loop_config.min_turn && c.loop_shape.is_none())
            .map(|c| c.source)
            .collect();
        if !flat.is_empty() {
            warnings.push(Warning::new(
                "I_NEAR_STRAIGHT",
                format!(
                    "{} convex corners turn by less than {:.1}° and get no loop: {}",
                    flat.len(),
                    job.loop_config.min_turn.to_degrees(),
                    list_indices(&flat)
                ),
            ));
        }
    }
    let inside: Vec<&ContourCorner> = corners.iter().filter(|c| c.action == CornerAction::Reflex).collect();
    if !inside.is_empty() {
        let largest = inside.iter().map(|c| c.material.left_area).fold(0.0, f64::max);
        let indices: Vec<usize> = inside.iter().map(|c| c.index).collect();
        warnings.push(Warning::new(
            "W_INSIDE_CORNER",
            format!(
                "{} inside corners keep a fillet of radius {} (up to {largest:.6} mm² left; set inside_corner_relief to cut them): {}",
                inside.len(),
                job.radius,
                list_indices(&indices)
            ),
        ));
    }
}

/// Loops that run at the cutting feed although a faster loop feed is given, and why.
fn loop_feed_warnings(job: &Job, passes: &[PassPlan], warnings: &mut Vec<Warning>) {
    if job.loop_feed.is_some_and(|f| f != job.feed) {
        for pass in passes {
            let slow: Vec<usize> =
                pass.corners.iter().filter(|c| c.loop_shape.is_some() && !c.loop_feed).map(|c| c.source).collect();
            if !slow.is_empty() {
                let reason = if pass.index == 0 && job.stock_allowance.is_none() {
                    "the stock before the first pass is unknown (give stock_allowance)"
                } else {
                    "they may touch the stock left by the previous pass"
                };
                warnings.push(Warning::new(
                    "W_LOOP_STOCK_CONTACT",
                    format!(
                        "pass {}: {} loops run at the cutting feed because {reason}: {}",
                        pass.index + 1,
                        slow.len(),
                        list_indices(&slow)
                    ),
                ));
            }
        }
    }
}

/// Passes before the last whose allowance does not protect the final tips under the control
/// model (E1): miters against the blend radius, round joins against the servo lag.
fn allowance_warnings(job: &Job, passes: &[PassPlan], warnings: &mut Vec<Warning>) {
    let lag_product = job.servo_time_constant_s.map(|t| (job.feed / 60.0 * t).powi(2));
    for pass in passes.iter().take(passes.len().saturating_sub(1)) {
        let mut needed: f64 = 0.0;
        for corner in pass.corners.iter().filter(|c| c.convex) {
            let alpha = corner.material_angle;
            match corner.action {
                Action::Miter => {
                    if let Some(blend) = job.blend_radius {
                        needed = needed.max((blend - job.radius) * (1.0 - (0.5 * alpha).sin()));
                    }
                }
                Action::Round => {
                    if let Some(product) = lag_product {
                        needed = needed.max(product / (2.0 * pass.offset));
                    }
                }
                _ => {}
            }
        }
        if needed > pass.allowance {
            warnings.push(Warning::new(
                "W_EMBODIMENT1_UNSAFE",
                format!(
                    "pass {} (allowance {}) may cut into the final tips under the control model: it needs an allowance of at least {needed:.6}",
                    pass.index + 1,
                    pass.allowance
                ),
            ));
        }
    }
}

fn pass_report(pass: &PassPlan) -> PassReport {
    let length = |kinds: &[ElementKind]| -> f64 {
        pass.elements
            .iter()
            .filter(|e| kinds.contains(&e.kind()))
            .map(super::element::Element::length)
            .fold(0.0, |total, length| total + length)
    };
    PassReport {
        allowance: pass.allowance,
        offset: pass.offset,
        loops: pass.loops,
        join: pass.join,
        start: array2(&pass.start),
        looped_corners: pass.corners.iter().filter(|c| c.loop_shape.is_some()).count(),
        cut_length: length(&[ElementKind::Cut]),
        leg_length: length(&[ElementKind::Exit, ElementKind::Entry]),
        loop_length: length(&[ElementKind::Loop]),
        relief_length: length(&[ElementKind::Relief]),
        gouge_min_clearance: pass.gouge_min_clearance,
        stock_min_clearance: pass.stock_min_clearance,
    }
}

/// Header lines naming the job parameters for the G-code program.
fn describe(job: &Job, summary: &ContourSummary) -> Vec<String> {
    let style = match job.loop_config.style {
        LoopStyle::Arc => "arc",
        LoopStyle::Triangle => "triangle",
        LoopStyle::Parallelogram => "parallelogram",
        LoopStyle::None => "none",
    };
    vec![
        format!(
            "contour {} {} milling, {} corners, {} layers from {} to {}",
            match job.side {
                Side::Outside => "outside",
                Side::Inside => "inside",
            },
            match job.direction {
                CutDirection::Climb => "climb",
                CutDirection::Conventional => "conventional",
            },
            summary.corners,
            summary.layers,
            job.top,
            job.bottom
        ),
        format!("{} R {} corner loops {style}, {} passes", job.tool.kind.as_str(), job.radius, summary.passes),
        format!("feed {} mm/min loop feed {} mm/min spindle {} rpm", job.feed, summary.loop_feed, job.spindle_rpm),
    ]
}
