//! One pass around one layer's contour (docs/spec/contour.md §3.3 offset, §3.5 loops with the global gouge
//! check and its fallbacks, §3.5.7 stock contact, §3.11 `plan_pass`): the miter CL polygon and
//! its validity (O4, O5, global clearance; the checks are in `clearance`), the action at every
//! corner, and the element list from S round to S.

mod clearance;

use super::element::{Chording, Element, ElementKind};
use super::job::{CornerChoice, LoopConfig, PassJob};
use super::layer::{Class, Layer};
use super::loops::{self, LoopShape};
use super::offset::{self, Offset};
use super::relief::{self, ReliefShape};
use super::request::{Join, LoopStyle, Relief};
use crate::control::Control;
use crate::error::{SolverError, Warning};
use crate::planar::{SegmentGrid, Vec2};
use crate::validate::Measure;
use clearance::{check_clearance, check_loop_budget, check_offset, gouge_fallbacks, stock_clearance};

/// Clearance below which a move gouges, mm.
pub const GOUGE_TOLERANCE: f64 = 1e-9;
/// Most straight moves one arc may be chorded into.
pub const MAX_ARC_STEPS: usize = 100_000;

/// What the pass does at a corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// Arc loop (claim 4).
    LoopArc,
    /// Triangle loop (claim 5).
    LoopTriangle,
    /// Parallelogram loop (claim 5).
    LoopParallelogram,
    /// Straight to the miter point and on.
    Miter,
    /// Arc about the vertex.
    Round,
    /// Inside corner: to its miter point and on (the tool leaves a fillet).
    Reflex,
    /// On a stretch the tool cannot follow (an edge too short for the tool next to an inside
    /// corner): the tool cuts past it at the merged miter point and leaves material.
    Unreached,
    /// Inside corner with a dogbone relief.
    Dogbone,
    /// Inside corner with a T-bone relief.
    Tbone,
}

impl Action {
    /// The name used in the reference cases and answers.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::LoopArc => "loop_arc",
            Self::LoopTriangle => "loop_triangle",
            Self::LoopParallelogram => "loop_parallelogram",
            Self::Miter => "miter",
            Self::Round => "round",
            Self::Reflex => "reflex",
            Self::Unreached => "unreached",
            Self::Dogbone => "dogbone",
            Self::Tbone => "tbone",
        }
    }
}

/// The plan at one corner of one pass.
#[derive(Debug, Clone, PartialEq)]
pub struct CornerPlan {
    /// Vertex index along the traversal.
    pub k: usize,
    /// Index of the vertex in the request's `contour`.
    pub source: usize,
    /// The vertex V.
    pub vertex: Vec2,
    /// φ: signed turn along the traversal, radians.
    pub turn: f64,
    /// α: material angle, radians.
    pub material_angle: f64,
    /// Whether the material protrudes (α < π).
    pub convex: bool,
    /// P: the miter point of the CL polygon (shared by the corners of a stretch the tool cannot
    /// follow).
    pub cl_point: Vec2,
    /// The first corner (traversal index) of the stretch sharing this CL point; `k` itself for an
    /// ordinary corner.
    pub chain_start: usize,
    /// What the pass does there.
    pub action: Action,
    /// The loop, if one is made.
    pub loop_shape: Option<LoopShape>,
    /// The relief, if one is cut.
    pub relief: Option<ReliefShape>,
    /// Smallest distance of the loop's moves to the contour minus r + δ, mm.
    pub clearance: Option<f64>,
    /// Smallest distance of the loop's moves to the stock before this pass minus r, mm.
    pub stock_clearance: Option<f64>,
    /// Whether the loop proper may run at the loop feed (it clears the stock).
    pub loop_feed: bool,
}

/// One pass around one layer's contour.
#[derive(Debug, Clone, PartialEq)]
pub struct PassPlan {
    /// Pass number from 0, outermost first.
    pub index: usize,
    /// δ, mm.
    pub allowance: f64,
    /// r + δ, mm (the CL distance from a vertical wall).
    pub offset: f64,
    /// Offset o_e of every traversal edge (r/cos β_e + δ), mm.
    pub edge_offsets: Vec<f64>,
    /// Whether this pass makes loops.
    pub loops: bool,
    /// Join at corners without a loop.
    pub join: Join,
    /// S: where the pass starts and ends.
    pub start: Vec2,
    /// The traversal edge S lies on (edge 0 unless the tool cannot follow it).
    pub start_edge: usize,
    /// The miter CL point of every corner, in traversal order (corners on a stretch the tool
    /// cannot follow share one).
    pub cl: Vec<Vec2>,
    /// Traversal edges the tool cannot follow (removed by edge events).
    pub unreached_edges: Vec<usize>,
    /// The path from S round to S.
    pub elements: Vec<Element>,
    /// Per element: the edges whose tool axes it starts and ends with, and whether it may run at
    /// the loop feed.
    pub meta: Vec<ElementMeta>,
    /// Every corner, in traversal order (index k).
    pub corners: Vec<CornerPlan>,
    /// Smallest loop clearance of the pass (§3.5.5), mm.
    pub gouge_min_clearance: Option<f64>,
    /// Smallest stock clearance of the exit, loop and entry moves (§3.5.7), mm.
    pub stock_min_clearance: Option<f64>,
    /// Warnings about this pass.
    pub warnings: Vec<Warning>,
}

/// Bookkeeping of one element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ElementMeta {
    /// Traversal edge whose tool axis holds at the element's start.
    pub from_edge: usize,
    /// Traversal edge whose tool axis holds at its end.
    pub to_edge: usize,
    /// A loop element that clears the stock (may run at the loop feed).
    pub fast: bool,
}

/// Elements with their bookkeeping, as a pass is assembled.
#[derive(Default)]
struct Path {
    elements: Vec<Element>,
    meta: Vec<ElementMeta>,
}

impl Path {
    fn push(&mut self, element: Element, from_edge: usize, to_edge: usize, fast: bool) {
        self.elements.push(element);
        self.meta.push(ElementMeta { from_edge, to_edge, fast });
    }
}

/// The stock standing before a pass, as segments at known distances (§3.5.7 S1/S2 models).
pub(crate) struct Stock {
    /// Each grid's stock boundary lies `inset` inside the indexed segments' distance (the round
    /// model measures from the contour minus the previous allowance).
    pub parts: Vec<(SegmentGrid, f64)>,
}

/// Everything a pass needs besides the layer.
pub(crate) struct PassInput<'a> {
    pub index: usize,
    pub pass: PassJob,
    pub radius: f64,
    /// o_e per traversal edge.
    pub edge_offsets: Vec<f64>,
    pub loop_config: &'a LoopConfig,
    /// Per traversal vertex.
    pub choices: Vec<CornerChoice>,
    /// Per traversal vertex: whether "previous" in request order is the traversal's previous
    /// edge.
    pub request_order: bool,
    pub chording: Chording,
    pub stock: Option<&'a Stock>,
    /// Request index of every traversal vertex.
    pub source: Vec<usize>,
    /// Request index of the start (in request order) of every traversal edge.
    pub edge_source: Vec<usize>,
}

fn field(source: usize) -> String {
    format!("contour[{source}]")
}

/// Plans one pass.
///
/// # Errors
/// `E_DEGENERATE` (180° reversal), `E_OFFSET_COLLAPSE` (O4), `E_OFFSET_SELF_INTERSECTION` (O5 or
/// the global clearance of the cut moves), `E_TOO_COMPLEX`.
pub(crate) fn plan_pass(layer: &Layer, input: &PassInput<'_>, control: Control<'_>) -> Result<PassPlan, SolverError> {
    let n = layer.len();
    let offsets = &input.edge_offsets;
    let clear = input.radius + input.pass.allowance;
    let tool = format!(
        "the tool (radius {} + allowance {})",
        Measure::Length.quote(input.radius),
        Measure::Length.quote(input.pass.allowance)
    );
    let offset = offset::offset(layer, offsets, &input.edge_source, &tool)?;
    control.check()?;
    check_offset(layer, &offset, input, &tool, control)?;
    let cl = offset.cl.clone();

    check_loop_budget(layer, &offset, input)?;
    // S lies on edge 0, or on the first edge the tool follows.
    let first_edge = (0..n).find(|&k| offset.active[k]).unwrap_or(0);
    let start = start_point(layer, &cl, offsets, first_edge);
    let mut walk = Walk {
        path: Path::default(),
        current: start,
        skipped: Vec::new(),
        fallbacks: Vec::new(),
        reliefs_skipped: Vec::new(),
        scratch: Vec::new(),
    };
    let mut corners: Vec<Option<CornerPlan>> = vec![None; n];
    for step in 1..=n {
        control.check_at(step)?;
        let k = (first_edge + step) % n;
        corners[k] = Some(walk.corner(layer, input, &offset, clear, k));
    }
    walk.path.push(cut(walk.current, start), first_edge, first_edge, false);
    check_clearance(layer, &walk.path.elements, clear, input, &mut walk.scratch, control)?;

    let warnings = pass_warnings(input, &offset, &walk, &tool);
    let corners: Vec<CornerPlan> = corners.into_iter().flatten().collect();
    let gouge_min_clearance = corners.iter().filter_map(|c| c.clearance).reduce(f64::min);
    let stock_min_clearance = corners.iter().filter_map(|c| c.stock_clearance).reduce(f64::min);
    Ok(PassPlan {
        index: input.index,
        allowance: input.pass.allowance,
        offset: clear,
        edge_offsets: offsets.clone(),
        loops: input.pass.loops,
        join: input.pass.join,
        start,
        start_edge: first_edge,
        cl,
        unreached_edges: (0..n).filter(|&k| !offset.active[k]).collect(),
        elements: walk.path.elements,
        meta: walk.path.meta,
        corners,
        gouge_min_clearance,
        stock_min_clearance,
        warnings,
    })
}

/// The walk from S round the contour as one pass is planned: the path so far, where the tool
/// stands, and the corners whose loop or relief had to be left out (for the warnings).
struct Walk {
    path: Path,
    current: Vec2,
    /// Request indices of convex corners whose loop gouged even after the fallbacks.
    skipped: Vec<usize>,
    /// Why a loop was resized or restyled to clear the contour, per corner.
    fallbacks: Vec<String>,
    /// Request indices of inside corners whose relief would gouge another face.
    reliefs_skipped: Vec<usize>,
    scratch: Vec<usize>,
}

impl Walk {
    /// Plans the corner at traversal vertex `k` and appends its moves (the cut up to it and the
    /// loop, join or relief there).
    fn corner(&mut self, layer: &Layer, input: &PassInput<'_>, offset: &Offset, clear: f64, k: usize) -> CornerPlan {
        let vertex = layer.vertices[k];
        let turn = layer.turn(k);
        let class = layer.class(k);
        let p = offset.cl[k];
        let mut plan = CornerPlan {
            k,
            source: input.source[k],
            vertex,
            turn,
            material_angle: layer.material_angle(k),
            convex: class == Class::Convex,
            cl_point: p,
            chain_start: offset.chain_start[k],
            action: Action::Reflex,
            loop_shape: None,
            relief: None,
            clearance: None,
            stock_clearance: None,
            loop_feed: false,
        };
        let incoming = layer.previous(k);
        if offset.merged(layer, k) {
            plan.action = Action::Unreached;
            if offset.chain_start[k] == k {
                self.path.push(cut(self.current, p), incoming, incoming, false);
                self.current = p;
            }
            return plan;
        }
        match class {
            Class::Convex => self.convex(layer, input, clear, &mut plan),
            Class::Reflex => self.reflex(layer, input, clear, &mut plan),
        }
        plan
    }

    /// A protruding corner: a loop when wanted and one clears the contour, else the pass's join
    /// (round when both faces have the same offset, else miter).
    fn convex(&mut self, layer: &Layer, input: &PassInput<'_>, clear: f64, plan: &mut CornerPlan) {
        let (k, vertex, turn, p) = (plan.k, plan.vertex, plan.turn, plan.cl_point);
        let (d1, d2) = layer.corner_directions(k);
        let choice = input.choices[k];
        let offsets = &input.edge_offsets;
        let (o1, o2) = (offsets[layer.previous(k)], offsets[k]);
        let big_enough = turn.abs() >= input.loop_config.min_turn;
        let incoming = layer.previous(k);
        let wanted =
            input.pass.loops && input.loop_config.style != LoopStyle::None && choice.loops.unwrap_or(big_enough);
        let found = if wanted {
            loops::sized(input.loop_config, &p, &d1, &d2, layer.sigma).and_then(|(shape, fallback)| {
                let chosen = gouge_fallbacks(layer, &shape, &p, &d1, &d2, &vertex, clear, input, &mut self.scratch);
                match &chosen {
                    Ok(_) => {
                        if let Some(reason) = fallback {
                            self.fallbacks.push(format!("{}: {reason}", field(input.source[k])));
                        }
                    }
                    Err(_) => self.skipped.push(input.source[k]),
                }
                chosen.ok()
            })
        } else {
            None
        };
        if let Some((shape, clearance)) = found {
            plan.action = match shape.style {
                LoopStyle::Triangle => Action::LoopTriangle,
                LoopStyle::Parallelogram => Action::LoopParallelogram,
                LoopStyle::Arc | LoopStyle::None => Action::LoopArc,
            };
            plan.clearance = Some(clearance);
            if let Some(stock) = input.stock {
                let stock_clearance = stock_clearance(stock, &shape, &p, &vertex, input, &mut self.scratch);
                plan.stock_clearance = Some(stock_clearance);
                plan.loop_feed = stock_clearance >= -GOUGE_TOLERANCE;
            }
            self.path.push(cut(self.current, p), incoming, incoming, false);
            for element in shape.elements(&p) {
                let (from, to) = match element.kind() {
                    ElementKind::Exit => (incoming, incoming),
                    ElementKind::Entry => (k, k),
                    _ => (incoming, k),
                };
                let fast = element.kind() == ElementKind::Loop && plan.loop_feed;
                self.path.push(element, from, to, fast);
            }
            plan.loop_shape = Some(shape);
            self.current = p;
        } else if input.pass.join == Join::Round && o1 == o2 {
            plan.action = Action::Round;
            let e1 = vertex + o1 * layer.air_normal(layer.previous(k));
            let e2 = vertex + o2 * layer.air_normal(k);
            self.path.push(cut(self.current, e1), incoming, incoming, false);
            self.path.push(
                Element::Arc { start: e1, end: e2, centre: vertex, radius: o1, sweep: turn, kind: ElementKind::Cut },
                incoming,
                k,
                false,
            );
            self.current = e2;
        } else {
            plan.action = Action::Miter;
            self.path.push(cut(self.current, p), incoming, incoming, false);
            self.current = p;
        }
    }

    /// An inside corner: the cut into it, then the dogbone or T-bone relief if one is asked for
    /// and it gouges neither other face.
    fn reflex(&mut self, layer: &Layer, input: &PassInput<'_>, clear: f64, plan: &mut CornerPlan) {
        let (k, turn, p) = (plan.k, plan.turn, plan.cl_point);
        let choice = input.choices[k];
        let offsets = &input.edge_offsets;
        let (o1, o2) = (offsets[layer.previous(k)], offsets[k]);
        let big_enough = turn.abs() >= input.loop_config.min_turn;
        let incoming = layer.previous(k);
        self.path.push(cut(self.current, p), incoming, incoming, false);
        self.current = p;
        let style = if big_enough { choice.relief } else { Relief::None };
        if style == Relief::None {
            return;
        }
        let shape = relief::shape(layer, k, &p, o1.min(o2), style, choice.tbone_edge, input.request_order);
        let moves = [(p, shape.target), (shape.target, p)];
        let (previous_edge, next_edge) = (layer.previous(k), k);
        let scratch = &mut self.scratch;
        let gouges = moves.iter().any(|(a, b)| {
            layer
                .grid
                .nearest(a, b, clear - GOUGE_TOLERANCE, scratch, |e| e == previous_edge || e == next_edge)
                .is_some()
        });
        if gouges {
            self.reliefs_skipped.push(input.source[k]);
        } else {
            plan.action = if style == Relief::Dogbone { Action::Dogbone } else { Action::Tbone };
            for (a, b) in moves {
                self.path.push(
                    Element::Line { start: a, end: b, kind: ElementKind::Relief },
                    incoming,
                    incoming,
                    false,
                );
            }
            plan.relief = Some(shape);
        }
    }
}

/// The pass's warnings: loops left out or resized, edges the tool cannot follow, reliefs left
/// out.
fn pass_warnings(input: &PassInput<'_>, offset: &Offset, walk: &Walk, tool: &str) -> Vec<Warning> {
    let n = offset.active.len();
    let mut warnings = Vec::new();
    if !walk.skipped.is_empty() {
        warnings.push(Warning::new(
            "W_LOOP_SKIPPED_GOUGE",
            format!(
                "pass {}: {} loops would come closer than r + δ to the contour even after the fallbacks and were replaced by the {} join: {}",
                input.index + 1,
                walk.skipped.len(),
                join_name(input.pass.join),
                list(&walk.skipped)
            ),
        ));
    }
    if !walk.fallbacks.is_empty() {
        warnings
            .push(Warning::new("W_LOOP_FALLBACK", format!("pass {}: {}", input.index + 1, first_few(&walk.fallbacks))));
    }
    if !offset.active.iter().all(|a| *a) {
        let unreached: Vec<usize> = (0..n).filter(|&k| !offset.active[k]).map(|k| input.edge_source[k]).collect();
        warnings.push(Warning::new(
            "W_EDGE_UNREACHED",
            format!(
                "pass {}: {tool} cannot follow {} edges (too short next to inside corners, or concave arcs tighter than the tool); material stays there: edges from {}",
                input.index + 1,
                unreached.len(),
                list(&unreached)
            ),
        ));
    }
    if !walk.reliefs_skipped.is_empty() {
        warnings.push(Warning::new(
            "W_RELIEF_SKIPPED",
            format!("pass {}: the relief would gouge another face at {}", input.index + 1, list(&walk.reliefs_skipped)),
        ));
    }
    warnings
}

fn join_name(join: Join) -> &'static str {
    match join {
        Join::Miter => "miter",
        Join::Round => "round",
    }
}

fn list(sources: &[usize]) -> String {
    super::prepare::list_indices(sources)
}

fn first_few(items: &[String]) -> String {
    let mut text = items.iter().take(5).cloned().collect::<Vec<_>>().join("; ");
    if items.len() > 5 {
        text.push_str(&format!("; and {} more", items.len() - 5));
    }
    text
}

fn cut(start: Vec2, end: Vec2) -> Element {
    Element::Line { start, end, kind: ElementKind::Cut }
}

/// S: the offset foot of the middle of edge `edge`, or the middle of the offset edge if that
/// foot falls outside it.
fn start_point(layer: &Layer, cl: &[Vec2], offsets: &[f64], edge: usize) -> Vec2 {
    let after = layer.next(edge);
    let middle = 0.5 * (layer.vertices[edge] + layer.vertices[after]);
    let foot = middle + offsets[edge] * layer.air_normal(edge);
    let t = layer.directions[edge];
    let along = (foot - cl[edge]).dot(&t);
    let length = (cl[after] - cl[edge]).dot(&t);
    if along > 0.0 && along < length { foot } else { 0.5 * (cl[edge] + cl[after]) }
}
