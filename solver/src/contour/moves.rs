//! One layer's moves (docs/spec/contour.md §3.9.1 layers, §3.11 steps): the lead point on the
//! start edge's normal, the descent and entry (plunge or ramp), each pass's elements as chords
//! with their feeds and tool axes, the links between passes and the retract.

use super::answer::{ArcSpan, ContourMove, MoveKind};
use super::element::{Element, ElementKind};
use super::job::Job;
use super::layer::Layer;
use super::pass::{GOUGE_TOLERANCE, MAX_ARC_STEPS, PassPlan};
use crate::geometry::Vec3;
use crate::planar::{Vec2, cross};

/// Height above the previous layer (or the top) where the rapid descent ends, mm.
const APPROACH_GAP: f64 = 1.0;

/// The lead point above which every pass of the layer starts, and the lead length used: on the
/// normal of the start edge's middle, `lead` beyond the outermost pass, shortened until the
/// leads to every pass's S clear the contour; `None` when no lead along that normal does (the
/// passes then start by plunging at their S).
pub(super) fn lead_point(job: &Job, layer: &Layer, passes: &[PassPlan]) -> Option<(Vec2, f64)> {
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

/// One pass's moves as chords in the layer plane, with its arcs' spans (from its first move): the
/// same at every height but for the moves' z, so layers that share their passes (walls that are
/// not tilted) make them once and copy them ([`PassMoves::lift`]).
pub(super) struct PassMoves {
    moves: Vec<ContourMove>,
    arcs: Vec<ArcSpan>,
}

impl PassMoves {
    /// The moves of `pass` at height `z`.
    pub(super) fn new(job: &Job, layer: &Layer, pass: &PassPlan, z: f64) -> Self {
        let mut out = LayerWriter { moves: Vec::new(), arcs: Vec::new(), start_axis: None, z };
        out.pass(job, layer, pass, job.loop_feed.unwrap_or(job.feed));
        Self { moves: out.moves, arcs: out.arcs }
    }

    /// Every pass of a layer at height `z`.
    pub(super) fn all(job: &Job, layer: &Layer, passes: &[PassPlan], z: f64) -> Vec<Self> {
        passes.iter().map(|pass| Self::new(job, layer, pass, z)).collect()
    }

    fn len(&self) -> usize {
        self.moves.len()
    }
}

/// Every move of one layer: down from the clearance plane at the lead point, each pass with its
/// lead-in and lead-out, back up. Without a lead point the first pass starts by plunging at its S,
/// and later passes are reached by a straight link where it clears the contour, else over the
/// clearance plane. `made` holds each pass's moves ([`PassMoves`], at any height).
#[allow(clippy::too_many_arguments)]
pub(super) fn layer_moves(
    job: &Job,
    layer: &Layer,
    passes: &[PassPlan],
    made: &[PassMoves],
    lead_point: Option<Vec2>,
    first: bool,
    previous_z: f64,
    z: f64,
) -> (Vec<ContourMove>, Vec<ArcSpan>) {
    let start_axis = axis(job, layer, 0).map(|a| Box::new([a.x, a.y, a.z]));
    let Some(first_start) = passes.first().map(|p| p.start) else {
        return (Vec::new(), Vec::new());
    };
    // The passes, and a few moves round each: descent, entry, links, retract.
    let capacity = made.iter().map(|pass| pass.len() + 8).sum::<usize>() + 8;
    let arcs = made.iter().map(|pass| pass.arcs.len()).sum();
    let mut out = LayerWriter { moves: Vec::with_capacity(capacity), arcs: Vec::with_capacity(arcs), start_axis, z };
    let entry = lead_point.unwrap_or(first_start);
    let approach = (previous_z + APPROACH_GAP.min(job.safe_z - previous_z)).max(z);
    if first {
        out.push(MoveKind::Rapid, at(&entry, job.safe_z), None);
    }
    if approach < job.safe_z {
        out.push(MoveKind::Rapid, at(&entry, approach), None);
    }
    let route = if entry == first_start { Route::Pass(&passes[0]) } else { Route::Lead(first_start, &passes[0]) };
    for (to, feed) in entry_moves(job, entry, route, approach.min(job.safe_z), z) {
        out.push(MoveKind::Link, to, Some(feed));
    }
    let mut here = entry;
    for (pass, pass_moves) in passes.iter().zip(made) {
        if here != pass.start {
            out.link(job, layer, here, pass, lead_point.is_some(), approach);
        }
        out.lift(pass_moves);
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

    /// Appends a pass's moves at this layer's height, its arcs' spans after the moves so far.
    fn lift(&mut self, pass: &PassMoves) {
        let (z, from) = (self.z, self.moves.len());
        self.moves.extend(pass.moves.iter().map(|step| {
            let [x, y, _] = step.to;
            ContourMove { kind: step.kind, to: [x, y, z], feed: step.feed, axis: step.axis.clone() }
        }));
        self.arcs.extend(pass.arcs.iter().map(|span| ArcSpan {
            first: span.first + from,
            last: span.last + from,
            ..*span
        }));
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
            for (to, feed) in entry_moves(job, pass.start, Route::Pass(pass), approach.min(job.safe_z), z) {
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

/// What a ramp entry runs along: from a lead point to S and on along the pass, or along the pass
/// from its S.
#[derive(Clone, Copy)]
enum Route<'a> {
    Lead(Vec2, &'a PassPlan),
    Pass(&'a PassPlan),
}

impl Route<'_> {
    /// The first point the ramp runs towards: S from a lead point, else the end of the pass's
    /// first chord.
    fn towards(self, job: &Job) -> Option<Vec2> {
        match self {
            Self::Lead(start, _) => Some(start),
            Self::Pass(pass) => pass.elements.first()?.chords(&job.chording, MAX_ARC_STEPS).first().copied(),
        }
    }

    /// The points after the ramp's start along the route, until they are `length` long or the
    /// pass ends: S (from a lead point), then the ends of the pass's chords.
    fn points(self, job: &Job, from: Vec2, length: f64) -> Vec<Vec2> {
        let (mut points, pass) = match self {
            Self::Lead(start, pass) => (vec![start], pass),
            Self::Pass(pass) => (Vec::new(), pass),
        };
        let mut travelled = points.first().map_or(0.0, |start| (start - from).norm());
        let mut here = points.last().copied().unwrap_or(from);
        for element in &pass.elements {
            if travelled >= length {
                break;
            }
            for point in element.chords(&job.chording, MAX_ARC_STEPS) {
                travelled += (point - here).norm();
                points.push(point);
                here = point;
                if travelled >= length {
                    break;
                }
            }
        }
        points
    }
}

/// The feed moves (end, feed) from `point` at `from_z` down to `point` at `z`: one
/// plunge when the tool cuts at its centre (at the cutting feed in the answer; the post writes it
/// at the plunge feed); otherwise a ramp at the plunge feed that runs from `point` towards
/// the route's first point and back, legs of at most [`MAX_RAMP_RADII`] tool radii, each
/// descending the same height at no more than the ramp angle, ending at `point` at `z`. When
/// that first stretch is too short to descend within [`MAX_RAMP_LEGS`] legs at the angle (a
/// pass whose first chord is a few micrometres long), the legs follow the route further, along
/// the pass's path, which keeps the tool radius from the contour. Without a direction (no lead
/// and a zero-length first move) the tool plunges.
fn entry_moves(job: &Job, point: Vec2, route: Route<'_>, from_z: f64, z: f64) -> Vec<([f64; 3], f64)> {
    let bottom = vec![([point.x, point.y, z], job.feed)];
    let drop = from_z - z;
    let Some(angle) = job.ramp else { return bottom };
    let Some((direction, length)) = route
        .towards(job)
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
    let legs = legs + legs % 2;
    if legs > MAX_RAMP_LEGS
        && let Some(moves) = route_ramp(job, point, route, angle, (from_z, z), feed)
    {
        return moves;
    }
    let legs = legs.clamp(2, MAX_RAMP_LEGS);
    let far = point + direction * length;
    (1..=legs)
        .map(|leg| {
            let at = if leg % 2 == 1 { far } else { point };
            let height = if leg == legs { z } else { from_z - drop * leg as f64 / legs as f64 };
            ([at.x, at.y, height], feed)
        })
        .collect()
}

/// A ramp whose legs run from `point` along `route` up to [`MAX_RAMP_RADII`] tool radii and
/// back, each point's height falling with the distance travelled, from `from_z` to `z`; `None`
/// when even that route is too short for [`MAX_RAMP_LEGS`] legs at `angle`.
fn route_ramp(
    job: &Job,
    point: Vec2,
    route: Route<'_>,
    angle: f64,
    (from_z, z): (f64, f64),
    feed: f64,
) -> Option<Vec<([f64; 3], f64)>> {
    let reach = MAX_RAMP_RADII * job.radius;
    // The leg: `point`, then the route's points clipped at `reach`, none repeated.
    let mut leg = vec![point];
    let mut travelled = 0.0;
    for next in route.points(job, point, reach) {
        let here = leg[leg.len() - 1];
        let step = (next - here).norm();
        if step <= 1e-12 {
            continue;
        }
        if travelled + step >= reach {
            leg.push(here + (next - here) * ((reach - travelled) / step));
            break;
        }
        leg.push(next);
        travelled += step;
    }
    // Distance along the leg of every point of it.
    let along: Vec<f64> = leg
        .iter()
        .scan((point, 0.0), |(here, sum), next| {
            *sum += (next - *here).norm();
            *here = *next;
            Some(*sum)
        })
        .collect();
    let travelled = along[along.len() - 1];
    let drop = from_z - z;
    let legs = (drop / (travelled * angle.tan())).ceil() as usize;
    let legs = (legs + legs % 2).max(2);
    if travelled <= 1e-6 || legs > MAX_RAMP_LEGS {
        return None;
    }
    let mut moves = Vec::with_capacity(legs * (leg.len() - 1));
    for index in 0..legs {
        let top = from_z - drop * index as f64 / legs as f64;
        let low = if index + 1 == legs { z } else { from_z - drop * (index + 1) as f64 / legs as f64 };
        let height = |distance: f64| top - (top - low) * distance / travelled;
        if index % 2 == 0 {
            for (at, &distance) in leg.iter().zip(&along).skip(1) {
                let h = if distance >= travelled { low } else { height(distance) };
                moves.push(([at.x, at.y, h], feed));
            }
        } else {
            for (at, &distance) in leg.iter().zip(&along).rev().skip(1) {
                let h = if distance <= 0.0 { low } else { height(travelled - distance) };
                moves.push(([at.x, at.y, h], feed));
            }
        }
    }
    Some(moves)
}
