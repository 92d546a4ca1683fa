//! The miter CL polygon of a pass (docs/spec/contour.md §3.3, O2/O3) with its edge events: an offset edge
//! whose length O4 drops to zero or below is one the tool cannot follow (a short edge next to an
//! inside corner, a tessellated concave arc tighter than the tool). Such edges are removed, most
//! negative first, and their neighbours' offset lines intersected instead, as a straight-skeleton
//! offset does; the material there stays and is reported. When the neighbours' offset lines do
//! not meet (a parallel-sided notch narrower than the tool), or fewer than three edges remain,
//! the tool does not fit: `E_OFFSET_COLLAPSE`.

use crate::error::ErrorCode;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

use super::layer::Layer;
use crate::error::SolverError;
use crate::planar::{Vec2, line_intersection, miter_point};

/// The CL polygon after edge events.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Offset {
    /// Per traversal vertex: the CL corner point its corner uses (vertices merged by removed
    /// edges share one).
    pub cl: Vec<Vec2>,
    /// Per traversal edge: whether it survived.
    pub active: Vec<bool>,
    /// Per traversal vertex: the first vertex (in traversal order) of its CL corner.
    pub chain_start: Vec<usize>,
}

impl Offset {
    /// Whether vertex `k` lies on a stretch the tool cannot follow (an edge next to it was
    /// removed).
    pub fn merged(&self, layer: &Layer, k: usize) -> bool {
        !self.active[k] || !self.active[layer.previous(k)]
    }

    /// The CL polygon: one point per surviving edge's start, in traversal order.
    pub fn polygon(&self, layer: &Layer) -> Vec<Vec2> {
        (0..layer.len()).filter(|&k| self.active[k]).map(|k| self.cl[k]).collect()
    }
}

/// Heap entry: the most negative offset length first, ties by edge index (deterministic).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Event {
    length: f64,
    edge: usize,
    version: u32,
}

impl Eq for Event {}

impl Ord for Event {
    fn cmp(&self, other: &Self) -> Ordering {
        other.length.total_cmp(&self.length).then(other.edge.cmp(&self.edge))
    }
}

impl PartialOrd for Event {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Offsets the layer's edges by `offsets` (per traversal edge) towards the air.
///
/// # Errors
/// `E_DEGENERATE` for a 180° reversal, `E_OFFSET_COLLAPSE` when the tool does not fit.
pub(crate) fn offset(
    layer: &Layer,
    offsets: &[f64],
    edge_source: &[usize],
    describe_tool: &str,
) -> Result<Offset, SolverError> {
    let n = layer.len();
    let field = |edge: usize| format!("contour[{}]", edge_source[edge]);
    let mut previous: Vec<usize> = (0..n).map(|k| layer.previous(k)).collect();
    let mut next: Vec<usize> = (0..n).map(|k| layer.next(k)).collect();
    let corner = |before: usize, after: usize| {
        if layer.next(before) == after {
            // Adjacent edges meet at their common vertex: O2/O3.
            return miter_point(
                &layer.vertices[after],
                &layer.air_normal(before),
                offsets[before],
                &layer.air_normal(after),
                offsets[after],
            );
        }
        // Edges with removed edges between them: intersect their offset lines.
        let on_before = layer.vertices[before] + offsets[before] * layer.air_normal(before);
        let on_after = layer.vertices[after] + offsets[after] * layer.air_normal(after);
        let (t1, t2) = (layer.directions[before], layer.directions[after]);
        if crate::planar::cross(&t1, &t2).abs() <= 1e-12 {
            return None;
        }
        line_intersection(&on_before, &t1, &on_after, &t2)
    };
    // start[e]: the CL point where edge e begins (intersection with its active predecessor).
    let mut start: Vec<Vec2> = Vec::with_capacity(n);
    for (k, &before) in previous.iter().enumerate() {
        start.push(corner(before, k).ok_or_else(|| {
            SolverError::new(ErrorCode::Degenerate, format!("the contour reverses by 180° at {}", field(k)))
                .at(field(k))
        })?);
    }
    let scale = layer.lengths.iter().copied().fold(0.0, f64::max).max(1.0);
    let limit = 1e-12 * scale;
    let length =
        |edge: usize, start: &[Vec2], next: &[usize]| (start[next[edge]] - start[edge]).dot(&layer.directions[edge]);
    let mut active = vec![true; n];
    let mut remaining = n;
    let mut version = vec![0u32; n];
    let mut heap = BinaryHeap::new();
    for edge in 0..n {
        let l = length(edge, &start, &next);
        if l <= limit {
            heap.push(Event { length: l, edge, version: 0 });
        }
    }
    while let Some(event) = heap.pop() {
        let edge = event.edge;
        if !active[edge] || event.version != version[edge] {
            continue;
        }
        if remaining <= 3 {
            return Err(collapse(describe_tool, &field(edge), layer.lengths[edge], event.length));
        }
        let (before, after) = (previous[edge], next[edge]);
        let Some(point) = corner(before, after) else {
            return Err(collapse(describe_tool, &field(edge), layer.lengths[edge], event.length));
        };
        active[edge] = false;
        remaining -= 1;
        next[before] = after;
        previous[after] = before;
        start[after] = point;
        for neighbour in [before, after] {
            version[neighbour] += 1;
            let l = length(neighbour, &start, &next);
            if l <= limit {
                heap.push(Event { length: l, edge: neighbour, version: version[neighbour] });
            }
        }
    }
    // Each vertex takes the CL point of the first surviving edge at or after it.
    let mut cl = vec![Vec2::zeros(); n];
    let mut chain_start = vec![0; n];
    let Some(anchor) = (0..n).find(|&k| active[k]) else {
        return Err(collapse(describe_tool, &field(0), layer.lengths[0], 0.0));
    };
    for step in 0..n {
        let edge = (anchor + step) % n;
        if !active[edge] {
            continue;
        }
        let mut vertex = edge;
        loop {
            cl[vertex] = start[edge];
            let before = layer.previous(vertex);
            if active[before] {
                break;
            }
            vertex = before;
        }
        let first = vertex;
        let mut member = first;
        loop {
            chain_start[member] = first;
            if member == edge {
                break;
            }
            member = layer.next(member);
        }
    }
    Ok(Offset { cl, active, chain_start })
}

fn collapse(describe_tool: &str, field: &str, length: f64, offset_length: f64) -> SolverError {
    SolverError::new(
        ErrorCode::OffsetCollapse,
        format!(
            "{describe_tool} does not fit at the edge from {field} (length {length:.6}): its offset edge has length {offset_length:.6} and the neighbouring offsets do not meet"
        ),
    )
    .at(field.to_owned())
}
