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

/// Every move of one layer: down from the clearance plane at the lead point, each pass with its
/// lead-in and lead-out, back up. Without a lead point the first pass starts by plunging at its S,
/// and later passes are reached by a straight link where it clears the contour, else over the
/// clearance plane.
#[allow(clippy::too_many_arguments)]
pub(super) fn layer_moves(
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
