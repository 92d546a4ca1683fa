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
    let previous: Vec<usize> = (0..n).map(|k| layer.previous(k)).collect();
    let next: Vec<usize> = (0..n).map(|k| layer.next(k)).collect();
    // start[e]: the CL point where edge e begins (intersection with its active predecessor).
    let mut start: Vec<Vec2> = Vec::with_capacity(n);
    for (k, &before) in previous.iter().enumerate() {
        start.push(offset_corner(layer, offsets, before, k).ok_or_else(|| {
            let field = edge_field(edge_source, k);
            SolverError::new(ErrorCode::Degenerate, format!("the contour reverses by 180° at {field}")).at(field)
        })?);
    }
    let links = Links { previous, next, start };
    let survivors = drop_short_edges(layer, offsets, edge_source, describe_tool, links)?;
    let Some(anchor) = (0..n).find(|&k| survivors.active[k]) else {
        return Err(collapse(describe_tool, &edge_field(edge_source, 0), layer.lengths[0], 0.0));
    };
    Ok(chains(layer, &survivors.start, survivors.active, anchor))
}

/// The request field of traversal edge `edge`.
fn edge_field(edge_source: &[usize], edge: usize) -> String {
    format!("contour[{}]", edge_source[edge])
}

/// Where the offset lines of edges `before` and `after` meet; `None` for parallel lines of
/// edges that are not neighbours.
fn offset_corner(layer: &Layer, offsets: &[f64], before: usize, after: usize) -> Option<Vec2> {
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
}

/// The offset edges as a doubly linked list: each surviving edge's neighbours and the CL point
/// where it begins.
struct Links {
    previous: Vec<usize>,
    next: Vec<usize>,
    start: Vec<Vec2>,
}

/// Which edges survive and where the surviving ones begin.
struct Survivors {
    active: Vec<bool>,
    start: Vec<Vec2>,
}

/// Edge events (O4): removes offset edges of no length, shortest first, joining their
/// neighbours' offset lines, until every edge left has a length.
///
/// # Errors
/// `E_OFFSET_COLLAPSE` when three edges or fewer would be left, or the neighbours do not meet.
fn drop_short_edges(
    layer: &Layer,
    offsets: &[f64],
    edge_source: &[usize],
    describe_tool: &str,
    links: Links,
) -> Result<Survivors, SolverError> {
    let n = layer.len();
    let Links { mut previous, mut next, mut start } = links;
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
            return Err(collapse(describe_tool, &edge_field(edge_source, edge), layer.lengths[edge], event.length));
        }
        let (before, after) = (previous[edge], next[edge]);
        let Some(point) = offset_corner(layer, offsets, before, after) else {
            return Err(collapse(describe_tool, &edge_field(edge_source, edge), layer.lengths[edge], event.length));
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
    Ok(Survivors { active, start })
}

/// Each vertex takes the CL point of the first surviving edge at or after it; the vertices
/// sharing one CL point form a chain, recorded by its first vertex. `anchor` is a surviving
/// edge.
fn chains(layer: &Layer, start: &[Vec2], active: Vec<bool>, anchor: usize) -> Offset {
    let n = layer.len();
    let mut cl = vec![Vec2::zeros(); n];
    let mut chain_start = vec![0; n];
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
    Offset { cl, active, chain_start }
}

fn collapse(describe_tool: &str, field: &str, length: f64, offset_length: f64) -> SolverError {
    SolverError::new(
        ErrorCode::OffsetCollapse,
        format!(
            "{describe_tool} does not fit at the edge from {field} (length {length:.6} mm): its offset edge has length {offset_length:.6} mm and the neighbouring offsets do not meet"
        ),
    )
    .at(field.to_owned())
}
