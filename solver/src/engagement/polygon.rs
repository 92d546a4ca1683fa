//! Plane polygon helpers the engagement solver needs: orientation, segment intersection,
//! even-odd point-in-polygon and the simple-polygon check (engagement.md §2.2). To be replaced by
//! `crate::planar` when it lands.

use super::P2;
use super::bbox_tree::{BBox, BoxTree};

/// Twice the signed area of a closed ring (positive when counter-clockwise).
pub(crate) fn twice_signed_area(ring: &[P2]) -> f64 {
    let mut sum = 0.0;
    for (index, a) in ring.iter().enumerate() {
        let b = ring[(index + 1) % ring.len()];
        sum += a.x * b.y - b.x * a.y;
    }
    sum
}

/// Orientation of `c` relative to the directed line `a → b`: positive left, negative right.
pub(crate) fn orient(a: P2, b: P2, c: P2) -> f64 {
    (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)
}

/// Whether the closed segments `[a0, a1]` and `[b0, b1]` share a point (touching counts).
pub(crate) fn segments_intersect(a0: P2, a1: P2, b0: P2, b1: P2) -> bool {
    let scale = [a0, a1, b0, b1].iter().fold(0.0_f64, |m, p| m.max(p.x.abs()).max(p.y.abs())).max(1.0);
    // Orientation values are areas: scale the zero test with the coordinates squared.
    let eps = 1e-12 * scale * scale;
    let sign = |v: f64| {
        if v > eps {
            1
        } else if v < -eps {
            -1
        } else {
            0
        }
    };
    let d1 = sign(orient(b0, b1, a0));
    let d2 = sign(orient(b0, b1, a1));
    let d3 = sign(orient(a0, a1, b0));
    let d4 = sign(orient(a0, a1, b1));
    if d1 * d2 < 0 && d3 * d4 < 0 {
        return true;
    }
    let on = |p: P2, q0: P2, q1: P2| {
        p.x >= q0.x.min(q1.x) - eps.sqrt()
            && p.x <= q0.x.max(q1.x) + eps.sqrt()
            && p.y >= q0.y.min(q1.y) - eps.sqrt()
            && p.y <= q0.y.max(q1.y) + eps.sqrt()
    };
    (d1 == 0 && on(a0, b0, b1))
        || (d2 == 0 && on(a1, b0, b1))
        || (d3 == 0 && on(b0, a0, a1))
        || (d4 == 0 && on(b1, a0, a1))
}

/// Distance from `p` to the closed segment `[a, b]`.
pub(crate) fn distance_to_segment(p: P2, a: P2, b: P2) -> f64 {
    let ab = b - a;
    let length_squared = ab.norm_squared();
    if length_squared == 0.0 {
        return (p - a).norm();
    }
    let t = ((p - a).dot(&ab) / length_squared).clamp(0.0, 1.0);
    (p - (a + t * ab)).norm()
}

/// The edges of a set of closed rings with a bounding-box tree over them.
#[derive(Debug, Clone)]
pub(crate) struct EdgeSet {
    /// Every edge as (start, end, ring index, index of its start vertex in the ring).
    pub edges: Vec<Edge>,
    /// Tree over the edges' boxes.
    pub tree: BoxTree,
}

/// One polygon edge.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Edge {
    pub from: P2,
    pub to: P2,
    pub ring: usize,
    pub vertex: usize,
}

impl EdgeSet {
    /// The edges of `rings` (each closed implicitly).
    pub(crate) fn new(rings: &[Vec<P2>]) -> Self {
        let mut edges = Vec::new();
        for (ring_index, ring) in rings.iter().enumerate() {
            for (vertex, from) in ring.iter().enumerate() {
                edges.push(Edge { from: *from, to: ring[(vertex + 1) % ring.len()], ring: ring_index, vertex });
            }
        }
        let boxes: Vec<BBox> = edges.iter().map(|e| BBox::of(e.from, e.to)).collect();
        Self { tree: BoxTree::new(&boxes), edges }
    }

    /// Even-odd containment, boundary inclusive within `tolerance`; adds the number of edges
    /// examined to `work`.
    pub(crate) fn contains(&self, q: P2, tolerance: f64, work: &mut u64) -> bool {
        let mut on_boundary = false;
        self.tree.query(&BBox::around(q, tolerance), &mut |index| {
            *work += 1;
            if let Some(edge) = self.edges.get(index)
                && distance_to_segment(q, edge.from, edge.to) <= tolerance
            {
                on_boundary = true;
            }
        });
        if on_boundary {
            return true;
        }
        let ray = BBox { min: q, max: P2::new(f64::INFINITY, q.y) };
        let mut inside = false;
        self.tree.query(&ray, &mut |index| {
            *work += 1;
            if let Some(edge) = self.edges.get(index) {
                let (a, b) = (edge.from, edge.to);
                // Half-open in y so a vertex on the ray is counted once.
                if (a.y > q.y) != (b.y > q.y) {
                    let x = a.x + (q.y - a.y) / (b.y - a.y) * (b.x - a.x);
                    if x > q.x {
                        inside = !inside;
                    }
                }
            }
        });
        inside
    }

    /// The first pair of edges that cross or touch other than at the vertex two neighbours
    /// share, as (ring, vertex) of each; `None` when every ring is simple and no two rings meet.
    pub(crate) fn first_crossing(&self, rings: &[Vec<P2>]) -> Option<((usize, usize), (usize, usize))> {
        for (index, edge) in self.edges.iter().enumerate() {
            let mut found: Option<usize> = None;
            self.tree.query(&BBox::of(edge.from, edge.to).grown(1e-9), &mut |other| {
                if other <= index || found.is_some() {
                    return;
                }
                let Some(second) = self.edges.get(other) else {
                    return;
                };
                let length = rings.get(edge.ring).map_or(0, Vec::len);
                let adjacent = second.ring == edge.ring
                    && (second.vertex == (edge.vertex + 1) % length || edge.vertex == (second.vertex + 1) % length);
                let crosses = if adjacent {
                    folds_back(edge, second)
                } else {
                    segments_intersect(edge.from, edge.to, second.from, second.to)
                };
                if crosses {
                    found = Some(other);
                }
            });
            if let Some(other) = found.and_then(|o| self.edges.get(o)) {
                return Some(((edge.ring, edge.vertex), (other.ring, other.vertex)));
            }
        }
        None
    }
}

/// Two neighbouring edges overlap when they are collinear and the second turns straight back
/// (or a ring of two edges is degenerate).
fn folds_back(first: &Edge, second: &Edge) -> bool {
    let (shared, a, b) =
        if first.to == second.from { (first.to, first.from, second.to) } else { (first.from, first.to, second.from) };
    let (u, v) = (a - shared, b - shared);
    let cross = u.x * v.y - u.y * v.x;
    cross.abs() <= 1e-12 * u.norm() * v.norm() && u.dot(&v) > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, size: f64) -> Vec<P2> {
        vec![P2::new(x0, y0), P2::new(x0 + size, y0), P2::new(x0 + size, y0 + size), P2::new(x0, y0 + size)]
    }

    #[test]
    fn area_sign_follows_orientation() {
        let ring = square(0.0, 0.0, 2.0);
        assert!((twice_signed_area(&ring) - 8.0).abs() < 1e-12);
        let reversed: Vec<P2> = ring.iter().rev().copied().collect();
        assert!((twice_signed_area(&reversed) + 8.0).abs() < 1e-12);
    }

    #[test]
    fn even_odd_with_hole_and_inclusive_boundary() {
        let rings = vec![square(0.0, 0.0, 10.0), square(4.0, 4.0, 2.0)];
        let edges = EdgeSet::new(&rings);
        assert!(edges.contains(P2::new(1.0, 1.0), 1e-9, &mut 0));
        assert!(!edges.contains(P2::new(5.0, 5.0), 1e-9, &mut 0));
        assert!(edges.contains(P2::new(4.0, 5.0), 1e-9, &mut 0));
        assert!(edges.contains(P2::new(10.0, 3.0), 1e-9, &mut 0));
        assert!(!edges.contains(P2::new(10.1, 3.0), 1e-9, &mut 0));
        // A ray through a vertex is counted once.
        assert!(edges.contains(P2::new(2.0, 4.0), 1e-9, &mut 0));
        assert!(!edges.contains(P2::new(-1.0, 0.0 + 10.0), 1e-9, &mut 0));
    }

    #[test]
    fn crossing_rings_are_found() {
        let bow_tie = vec![vec![P2::new(0.0, 0.0), P2::new(2.0, 2.0), P2::new(2.0, 0.0), P2::new(0.0, 2.0)]];
        let edges = EdgeSet::new(&bow_tie);
        assert!(edges.first_crossing(&bow_tie).is_some());
        let simple = vec![square(0.0, 0.0, 1.0), square(3.0, 3.0, 1.0)];
        assert!(EdgeSet::new(&simple).first_crossing(&simple).is_none());
        let overlapping = vec![square(0.0, 0.0, 2.0), square(1.0, 1.0, 2.0)];
        let found = EdgeSet::new(&overlapping).first_crossing(&overlapping);
        assert!(found.is_some());
        let spike = vec![vec![P2::new(0.0, 0.0), P2::new(2.0, 0.0), P2::new(1.0, 0.0), P2::new(1.0, 1.0)]];
        assert!(EdgeSet::new(&spike).first_crossing(&spike).is_some());
    }
}
