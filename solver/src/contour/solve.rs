//! Layers, passes and links (docs/spec/contour.md §3.8 several passes, §3.9.1 layers, §3.11 steps): plans
//! every pass of every layer, has each layer's moves made (joined by leads at the start edge,
//! retracts to the clearance plane between layers: `moves`), and assembles the answer with its
//! summary, corner reports and warnings (`report`).

use super::answer::{ArcSpan, ContourLayer, ContourMove, ContourSolution, ContourSummary, PassReport};
use super::blocks;
use super::element::Chording;
use super::job::Job;
use super::layer::Layer;
use super::moves::{PassMoves, layer_moves, lead_point};
use super::pass::{self, MAX_ARC_STEPS, PassInput, PassPlan, Stock};
use super::report::{contour_cycle_time, corner_reports, corner_warnings, describe, pass_report};
use super::request::{ContourRequest, CutDirection, Join, MAX_MOVES, Side};
use crate::capability::Control;
use crate::error::ErrorCode;
use crate::error::{SolverError, Warning};
use crate::geometry::Vec3;
use crate::machine::MachineProfile;
use crate::planar::{SegmentGrid, Vec2, miter_point};
use crate::tool::{Tool, ToolKind};

/// Largest number of vertex-layers planned one by one (tilted walls plan every layer).
const MAX_TILTED_VERTEX_LAYERS: usize = 20_000_000;

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
    let job = request.validate(tool, None, Control::default())?;
    let setup = Setup::new(&job);
    let z = job.layers.first().copied().unwrap_or(job.bottom);
    let layer = build_layer(&job, &setup, z)?;
    let passes = plan_passes(&job, &setup, &layer, Control::default())?;
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
/// rule; its `max_feed` caps `feed`, `loop_feed` and `plunge_feed`, `W_FEED_ABOVE_MACHINE_MAX`).
///
/// # Errors
/// As [`solve`], and `E_CANCELLED` once `control`'s cancel flag is set (checked per layer, per
/// pass of the plan and between the steps of the answer).
/// `machine` is the profile the request's `machine` names, resolved by the caller
/// (`capability::resolve`).
pub fn solve_with(
    request: &ContourRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    max_moves: usize,
    control: Control<'_>,
) -> Result<ContourSolution, SolverError> {
    solve_charged(request, tool, machine, max_moves, control, |_, _, _| Ok(()))
}

/// As [`solve_with`], handing each layer as it is made to `charge` with its place (1-based) and
/// the count of layers (an answer budget's unit of work).
///
/// # Errors
/// As [`solve_with`], and what `charge` refuses.
pub(crate) fn solve_charged(
    request: &ContourRequest,
    tool: &Tool,
    machine: Option<&MachineProfile>,
    max_moves: usize,
    control: Control<'_>,
    mut charge: impl FnMut(&LayerMoves, usize, usize) -> Result<(), SolverError>,
) -> Result<ContourSolution, SolverError> {
    let prepared = Prepared::new(request, tool, machine, max_moves, control)?;
    let count = prepared.job.layers.len();
    let layers = prepared.layers_with(0..count, control, |layer, done| charge(layer, done, count))?;
    prepared.answer(machine, max_moves, layers, control)
}

/// What every layer of a contour is made from: the validated job, how it travels the contour,
/// and the first layer with its passes (every layer's, unless the walls are tilted). Solving
/// whole or in layer ranges (a job split into parts) makes it the same way.
pub(crate) struct Prepared {
    pub(crate) job: Job,
    setup: Setup,
    first_layer: Layer,
    first_passes: Vec<PassPlan>,
    /// Whether layers with the same passes share their moves (always, but in the test that
    /// compares the answers made each way).
    share: bool,
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
    /// As [`solve`]; `E_CANCELLED` once `control`'s cancel flag is set.
    pub(crate) fn new(
        request: &ContourRequest,
        tool: &Tool,
        machine: Option<&MachineProfile>,
        max_moves: usize,
        control: Control<'_>,
    ) -> Result<Self, SolverError> {
        let max_moves = max_moves.min(MAX_MOVES);
        let job = request.validate(tool, machine, control)?;
        control.check()?;
        let setup = Setup::new(&job);
        let first_z = job.layers.first().copied().unwrap_or(job.bottom);
        let first_layer = build_layer(&job, &setup, first_z)?;
        control.check()?;
        let first_passes = plan_passes(&job, &setup, &first_layer, control)?;
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
        Ok(Self { job, setup, first_layer, first_passes, share: true })
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
        self.layers_with(range, control, |_, _| Ok(()))
    }

    /// As [`Prepared::layers`], handing each layer as it is made to `each` with its place in the
    /// range (1-based), so its moves are charged to an answer budget before the next is made.
    ///
    /// # Errors
    /// As [`Prepared::layers`], and what `each` refuses.
    pub(crate) fn layers_with(
        &self,
        range: std::ops::Range<usize>,
        control: Control<'_>,
        mut each: impl FnMut(&LayerMoves, usize) -> Result<(), SolverError>,
    ) -> Result<Vec<LayerMoves>, SolverError> {
        let job = &self.job;
        let mut layers = Vec::with_capacity(range.len());
        let (from, count) = (range.start, range.len());
        // Walls that are not tilted: every layer has the first layer's passes, so their moves and
        // the lead point are made once and lifted to each layer's height.
        let shared = (self.share && job.tilt.is_none() && !range.is_empty()).then(|| {
            let (layer, passes) = (&self.first_layer, &self.first_passes);
            (lead_point(job, layer, passes), PassMoves::all(job, layer, passes, job.layers[from]))
        });
        for index in range {
            let z = job.layers[index];
            control.check()?;
            control.report(index - from, count);
            let tilted;
            let (layer, passes) = if index == 0 || job.tilt.is_none() {
                (&self.first_layer, &self.first_passes)
            } else {
                let layer = build_layer(job, &self.setup, z)?;
                let passes = plan_passes(job, &self.setup, &layer, control)?;
                tilted = (layer, passes);
                (&tilted.0, &tilted.1)
            };
            let alone;
            let (lead_point, made) = match &shared {
                Some((lead_point, made)) => (*lead_point, made),
                None => {
                    alone = PassMoves::all(job, layer, passes, z);
                    (lead_point(job, layer, passes), &alone)
                }
            };
            let lead = lead_point.map_or(0.0, |(_, lead)| lead);
            let previous_z = if index == 0 { job.top } else { job.layers[index - 1] };
            let (moves, arcs) =
                layer_moves(job, layer, passes, made, lead_point.map(|(point, _)| point), index == 0, previous_z, z);
            let made = LayerMoves { z, moves, arcs, lead };
            each(&made, index - from + 1)?;
            layers.push(made);
        }
        Ok(layers)
    }

    /// The answer from every layer's moves, in order: corners, passes, summary, warnings.
    ///
    /// # Errors
    /// `E_TOO_MANY_MOVES` over `max_moves`; `E_INPUT` without a pass; `E_CANCELLED` once
    /// `control`'s cancel flag is set.
    pub(crate) fn answer(
        &self,
        machine: Option<&MachineProfile>,
        max_moves: usize,
        made: Vec<LayerMoves>,
        control: Control<'_>,
    ) -> Result<ContourSolution, SolverError> {
        let max_moves = max_moves.min(MAX_MOVES);
        let Self { job, setup, first_layer, first_passes, .. } = self;
        let job: &Job = job;
        let mut warnings = job.warnings.clone();
        for pass in first_passes {
            warnings.extend(pass.warnings.iter().cloned());
        }
        let (layers, lead_used) = answer_layers(job, made, &mut warnings);
        control.check()?;

        let final_pass = first_passes
            .last()
            .ok_or_else(|| SolverError::new(ErrorCode::Input, "at least one pass is needed").at("passes"))?;
        let corners = corner_reports(job, setup.request_order, first_layer, final_pass);
        warnings.extend(corner_warnings(job, first_passes, &corners));
        let passes: Vec<PassReport> = first_passes.iter().map(pass_report).collect();
        control.check()?;

        let (feed_length, time_min, moves) = feed_travel(&layers);
        if moves > max_moves {
            return Err(too_many_moves(layers.len(), moves / layers.len().max(1), moves, max_moves));
        }
        let blocks = block_figures(job, first_passes, &layers, &mut warnings)?;
        control.check()?;
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
// Not inlined: inside `Prepared::answer` the two sums were kept in memory, each addition waiting
// on a store and a load.
#[inline(never)]
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
fn plan_passes(job: &Job, setup: &Setup, layer: &Layer, control: Control<'_>) -> Result<Vec<PassPlan>, SolverError> {
    let source: Vec<usize> = layer.prepared_vertex.iter().map(|&v| job.contour.source[v]).collect();
    let edge_source: Vec<usize> =
        (0..layer.len()).map(|k| source[if setup.request_order { k } else { layer.next(k) }]).collect();
    let choices: Vec<_> = layer.prepared_vertex.iter().map(|&v| job.choices[v]).collect();
    let mut plans: Vec<PassPlan> = Vec::with_capacity(job.passes.len());
    for (index, pass) in job.passes.iter().enumerate() {
        control.check()?;
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
        plans.push(pass::plan_pass(layer, &input, control)?);
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The answer with every layer's pass moves and lead point made for that layer alone, as
    /// tilted walls make them.
    fn solve_alone(request: &ContourRequest, tool: &Tool) -> Result<ContourSolution, SolverError> {
        let mut prepared = Prepared::new(request, tool, None, MAX_MOVES, Control::default())?;
        prepared.share = false;
        let layers = prepared.layers(0..prepared.job.layers.len(), Control::default())?;
        prepared.answer(None, MAX_MOVES, layers, Control::default())
    }

    fn same_either_way(body: serde_json::Value) -> Result<(), TestCaseError> {
        let request: ContourRequest = serde_json::from_value(body).unwrap();
        let crate::tool::ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        let shared = solve(&request, tool);
        let alone = solve_alone(&request, tool);
        match (shared, alone) {
            (Ok(shared), Ok(alone)) => {
                prop_assert_eq!(serde_json::to_string(&shared).unwrap(), serde_json::to_string(&alone).unwrap());
                // Arcs as G02/G03: the arcs' spans among the moves match too.
                let post = crate::gcode::Post {
                    dialect: crate::gcode::Dialect::default(),
                    reference: crate::gcode::Reference::default(),
                    tool: crate::gcode::ToolCall::Table(1),
                    arcs: crate::gcode::Arcs::G2g3,
                    plunge_feed: None,
                    units: crate::units::Units::Mm,
                };
                prop_assert_eq!(
                    crate::contour::program(&shared, &post).unwrap(),
                    crate::contour::program(&alone, &post).unwrap()
                );
            }
            (shared, alone) => prop_assert_eq!(shared.err(), alone.err()),
        }
        Ok(())
    }

    #[test]
    fn layers_sharing_their_passes_answer_as_layers_made_alone() {
        for side in ["outside", "inside"] {
            for block_time in [None, Some(2.0)] {
                let mut body = serde_json::json!({
                    "tool": {"kind": "flat", "radius": 1.5, "centre_cutting": side == "inside"},
                    "contour": [[0, 0], [40, 0], [40, 30], [25, 30], [20, 12], [15, 30], [0, 30]],
                    "side": side, "depths": {"top": 0, "bottom": -3.5, "step": 1},
                    "corner_loop": {"style": "arc"}, "feed": 800, "loop_feed": 1500,
                    "passes": [{"allowance": 0.3, "join": "round"}, {"allowance": 0}],
                    "inside_corner_relief": "dogbone", "stock_allowance": 0.5
                });
                if let Some(block_time) = block_time {
                    body["block_time_ms"] = serde_json::json!(block_time);
                }
                same_either_way(body).unwrap();
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        #[test]
        fn random_contours_answer_the_same_with_shared_layers(
            radii in prop::collection::vec(2.0f64..10.0, 3..12),
            radius in 0.02f64..0.4,
            outside in any::<bool>(),
            climb in any::<bool>(),
            two_passes in any::<bool>(),
            centre_cutting in any::<bool>(),
            block_time in prop::option::of(0.5f64..8.0),
            step in 0.3f64..1.5,
        ) {
            // Star-shaped about the origin, so simple and counter-clockwise.
            let n = radii.len();
            let contour: Vec<[f64; 2]> = radii
                .iter()
                .enumerate()
                .map(|(k, r)| {
                    let angle = std::f64::consts::TAU * k as f64 / n as f64;
                    [r * angle.cos(), r * angle.sin()]
                })
                .collect();
            let mut body = serde_json::json!({
                "tool": {"kind": "flat", "radius": radius, "centre_cutting": centre_cutting},
                "contour": contour,
                "side": if outside { "outside" } else { "inside" },
                "direction": if climb { "climb" } else { "conventional" },
                "depths": {"top": 0.0, "bottom": -3.0, "step": step},
                "corner_loop": {"style": "arc"}, "feed": 600, "loop_feed": 2000, "tolerance": 0.005
            });
            if two_passes {
                body["passes"] = serde_json::json!([{"allowance": 0.2, "join": "round"}, {"allowance": 0.0}]);
            }
            if let Some(block_time) = block_time {
                body["block_time_ms"] = serde_json::json!(block_time);
            }
            same_either_way(body)?;
        }
    }
}
