//! The clearance checks of a pass (docs/spec/contour.md §3.3 O5 and the global clearance, §3.5.5
//! loop gouge fallbacks, §3.5.7 stock contact): the loop move budget, the CL polygon's validity,
//! loops that clear the contour by r + δ, the loops' clearance from the stock, and the cut moves'
//! clearance from the contour.

use super::{GOUGE_TOLERANCE, MAX_ARC_STEPS, PassInput, Stock, field};
use crate::contour::element::{Chording, Element, ElementKind};
use crate::contour::layer::{Class, Layer};
use crate::contour::loops::{self, LoopShape};
use crate::contour::offset::Offset;
use crate::contour::request::{LoopStyle, MAX_MOVES};
use crate::control::Control;
use crate::error::ErrorCode;
use crate::error::SolverError;
use crate::planar::{CheckStopped, Vec2, find_self_intersection, signed_area};
use crate::validate::Measure;

/// Refuses before building any loop when the loops alone would need more moves than an answer
/// may hold (huge loop radii with a fine chord tolerance on many corners).
pub(super) fn check_loop_budget(layer: &Layer, offset: &Offset, input: &PassInput<'_>) -> Result<(), SolverError> {
    if !input.pass.loops || input.loop_config.style == LoopStyle::None {
        return Ok(());
    }
    let mut moves = 0usize;
    for k in 0..layer.len() {
        if offset.merged(layer, k) || layer.class(k) != Class::Convex {
            continue;
        }
        let (d1, d2) = layer.corner_directions(k);
        if let Some((shape, _)) = loops::sized(input.loop_config, &offset.cl[k], &d1, &d2, layer.sigma) {
            moves += shape
                .elements(&offset.cl[k])
                .iter()
                .map(|e| e.chords_count(&input.chording, MAX_ARC_STEPS))
                .sum::<usize>();
        }
        if moves > MAX_MOVES {
            return Err(SolverError::new(
                ErrorCode::TooManyMoves,
                format!(
                    "the corner loops alone need more than {} moves: use a coarser tolerance or smaller loops",
                    MAX_MOVES
                ),
            )
            .at("tolerance"));
        }
    }
    Ok(())
}

/// O5 (the CL polygon is simple) and its orientation; O4 is the edge events of `offset`.
pub(super) fn check_offset(
    layer: &Layer,
    offset: &Offset,
    input: &PassInput<'_>,
    tool: &str,
    control: Control<'_>,
) -> Result<(), SolverError> {
    let edges: Vec<usize> = (0..layer.len()).filter(|&k| offset.active[k]).collect();
    let polygon = offset.polygon(layer);
    match find_self_intersection(&polygon, control) {
        Ok(None) => {}
        Ok(Some((i, j))) => {
            let (first, second) = (input.edge_source[edges[i]], input.edge_source[edges[j]]);
            return Err(SolverError::new(
                ErrorCode::OffsetSelfIntersection,
                format!(
                    "{tool} does not fit between the edges from {} and {}: their offsets cross",
                    field(first),
                    field(second)
                ),
            )
            .at(field(second)));
        }
        Err(CheckStopped::Cancelled) => return control.check(),
        Err(CheckStopped::Budget) => {
            return Err(SolverError::new(
                ErrorCode::TooComplex,
                "the offset path's edges are too crowded to check in bounded time",
            )
            .at("contour"));
        }
    }
    if signed_area(&polygon) * signed_area(&layer.vertices) <= 0.0 {
        return Err(SolverError::new(ErrorCode::OffsetCollapse, format!("{tool} does not fit inside the contour"))
            .at("contour"));
    }
    Ok(())
}

/// The loop, or a smaller or simpler one, that clears the contour by r + δ (§3.5.5): halve the
/// size up to 4 times, then the triangle with the smallest legs. Returns the shape and its
/// clearance, or the first clearance when every variant gouges.
#[allow(clippy::too_many_arguments)]
pub(super) fn gouge_fallbacks(
    layer: &Layer,
    shape: &LoopShape,
    p: &Vec2,
    d1: &Vec2,
    d2: &Vec2,
    vertex: &Vec2,
    clear: f64,
    input: &PassInput<'_>,
    scratch: &mut Vec<usize>,
) -> Result<(LoopShape, f64), f64> {
    let mut first = None;
    let mut candidate = *shape;
    for attempt in 0..6 {
        if attempt == 5 {
            candidate = LoopShape::triangle(p, d1, d2, candidate.leg);
        }
        let clearance = loop_clearance(layer, &candidate, p, vertex, clear, &input.chording, scratch);
        if clearance >= -GOUGE_TOLERANCE {
            return Ok((candidate, clearance));
        }
        first.get_or_insert(clearance);
        if attempt < 4 {
            candidate = candidate.scaled(p, d1, d2, layer.sigma, 0.5);
        }
    }
    Err(first.unwrap_or(f64::NEG_INFINITY))
}

/// The straight moves of a loop (exit, chorded loop, entry) from P.
fn loop_moves(shape: &LoopShape, p: &Vec2, chording: &Chording) -> Vec<(Vec2, Vec2)> {
    let mut moves = Vec::new();
    let mut from = *p;
    for element in shape.elements(p) {
        for to in element.chords(chording, MAX_ARC_STEPS) {
            moves.push((from, to));
            from = to;
        }
    }
    moves
}

/// min over the loop's moves of their distance to the contour, minus `clear`. The search radius
/// |PV| + `clear` is enough: P is on the loop and V on the contour.
fn loop_clearance(
    layer: &Layer,
    shape: &LoopShape,
    p: &Vec2,
    vertex: &Vec2,
    clear: f64,
    chording: &Chording,
    scratch: &mut Vec<usize>,
) -> f64 {
    let radius = (p - vertex).norm().max(clear) + 1e-6;
    loop_moves(shape, p, chording)
        .iter()
        .filter_map(|(a, b)| layer.grid.nearest(a, b, radius, scratch, |_| false))
        .map(|(distance, _)| distance)
        .fold(radius, f64::min)
        - clear
}

/// Smallest clearance of the loop's moves to the stock before this pass, minus r.
pub(super) fn stock_clearance(
    stock: &Stock,
    shape: &LoopShape,
    p: &Vec2,
    vertex: &Vec2,
    input: &PassInput<'_>,
    scratch: &mut Vec<usize>,
) -> f64 {
    let radius = (p - vertex).norm() + input.radius + 1.0;
    let moves = loop_moves(shape, p, &input.chording);
    let mut best = f64::INFINITY;
    for (grid, inset) in &stock.parts {
        for (a, b) in &moves {
            if let Some((distance, _)) = grid.nearest(a, b, radius, scratch, |_| false) {
                best = best.min(distance - inset);
            }
        }
    }
    best.min(radius) - input.radius
}

/// The global check of the cut moves: no point closer than r + δ to the contour (§3.3, the CL
/// polygon keeps its distance from every contour).
pub(super) fn check_clearance(
    layer: &Layer,
    elements: &[Element],
    clear: f64,
    input: &PassInput<'_>,
    scratch: &mut Vec<usize>,
    control: Control<'_>,
) -> Result<(), SolverError> {
    let radius = clear - GOUGE_TOLERANCE;
    for (index, element) in elements.iter().filter(|e| e.kind() == ElementKind::Cut).enumerate() {
        control.check_at(index)?;
        let mut from = element.start();
        for to in element.chords(&input.chording, MAX_ARC_STEPS) {
            // An edge whose middle lies farther from the move's middle than the radius and both
            // half-lengths cannot come within the radius (each point of a segment lies within
            // its half-length of its middle): passed over without its exact distance, most of
            // the edges near a finely tessellated contour. The margin keeps the test on the safe
            // side of rounding.
            let (middle, half) = (0.5 * (from + to), 0.5 * (to - from).norm());
            let far = |edge: usize| {
                let edge_middle = 0.5 * (layer.vertices[edge] + layer.vertices[layer.next(edge)]);
                let reach = radius + half + 0.5 * layer.lengths[edge];
                (edge_middle - middle).norm_squared() > reach * reach * (1.0 + 1e-9)
            };
            if let Some((distance, edge)) = layer.grid.nearest(&from, &to, radius, scratch, far) {
                let source = input.edge_source[edge];
                return Err(SolverError::new(
                    ErrorCode::OffsetSelfIntersection,
                    format!(
                        "the tool (radius {} + allowance {}) does not fit: near ({:.4} mm, {:.4} mm) the path comes within {distance:.6} mm of the edge from {} (a neck narrower than twice that)",
                        Measure::Length.quote(input.radius),
                        Measure::Length.quote(input.pass.allowance),
                        to.x,
                        to.y,
                        field(source)
                    ),
                )
                .at(field(source)));
            }
            from = to;
        }
    }
    Ok(())
}
