//! The outline of a polygon stock: several rings read together under the even-odd rule with an
//! inclusive boundary band (docs/spec/engagement.md §2.2, §5.3.2), indexed for the exact engine's queries
//! and checked for crossings.
//!
//! The plane geometry is [`crate::planar`]'s: orientation and signed area, segment intersection,
//! point–segment distance, the [`SegmentGrid`] index and [`find_self_intersection`]. What stays
//! here is what planar has no notion of, because it works on one polygon at a time:
//!
//! * **several rings as one region**: containment across all rings at once (outlines, holes and
//!   separate regions), with the ±1e-9 mm boundary band of §5.3.2. `planar::point_in_polygon`
//!   takes one ring, walks every vertex and has an exact boundary; here the even-odd count runs
//!   along a ray straight up, which is one column of a fine grid, so a query costs a few edges
//!   even for 100 000 vertices (a second grid, with cells as large as the tool, answers the
//!   "edges near the tool circle" query in a few columns);
//! * **rings that must not cross or touch each other** (they would cancel under even-odd):
//!   `find_self_intersection` checks each ring alone, and the pairs of edges of different rings
//!   that share grid cells are tested here with `planar::segments_intersect`.

use super::P2;
use crate::control::Control;
use crate::planar::{CheckStopped, SegmentGrid, find_self_intersection, point_segment_distance, segments_intersect};

thread_local! {
    /// Candidate buffer of [`Outline::contains`] (called for every sub-arc of every sample).
    static SCRATCH: std::cell::RefCell<Vec<usize>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Where an edge sits: (ring index, index of its start vertex in the ring).
pub(crate) type EdgeAt = (usize, usize);

/// Closed rings (each without its closing repeat) and grids over their edges.
#[derive(Debug, Clone)]
pub(crate) struct Outline {
    rings: Vec<Vec<P2>>,
    /// The ring and vertex of each indexed edge, in index order.
    owners: Vec<EdgeAt>,
    /// Cells of about the median edge: containment rays and the crossing check.
    grid: SegmentGrid,
    /// Cells at least as large as the query radius: edges near the tool circle.
    near: SegmentGrid,
    /// Above every vertex: where the containment ray ends.
    top: f64,
}

impl Outline {
    /// The outline of `rings` (each closed implicitly; at least 3 points, finite coordinates),
    /// for [`Self::edges_near`] queries of about `reach` (the tool radius).
    pub(crate) fn new(rings: Vec<Vec<P2>>, reach: f64) -> Self {
        let mut segments = Vec::new();
        let mut owners = Vec::new();
        let mut top = f64::NEG_INFINITY;
        for (ring_index, ring) in rings.iter().enumerate() {
            for (vertex, from) in ring.iter().enumerate() {
                segments.push((*from, ring[(vertex + 1) % ring.len()]));
                owners.push((ring_index, vertex));
                top = top.max(from.y);
            }
        }
        Self {
            near: SegmentGrid::new(segments.clone(), reach),
            grid: SegmentGrid::new(segments, 0.0),
            rings,
            owners,
            top: top + 1.0,
        }
    }

    /// The rings as given.
    pub(crate) fn rings(&self) -> &[Vec<P2>] {
        &self.rings
    }

    /// Every edge as (from, to).
    pub(crate) fn edges(&self) -> impl Iterator<Item = (P2, P2)> + '_ {
        (0..self.grid.len()).filter_map(|index| self.grid.segment(index))
    }

    /// Even-odd containment over all rings, boundary inclusive within `tolerance`; adds the
    /// number of edges examined to `work`.
    pub(crate) fn contains(&self, q: P2, tolerance: f64, work: &mut u64) -> bool {
        // One query along the ray from q straight up (one grid column), widened by the band:
        // it holds every edge near q and every edge the ray crosses.
        SCRATCH.with_borrow_mut(|candidates| {
            candidates.clear();
            self.grid.candidates(&q, &P2::new(q.x, self.top.max(q.y)), tolerance, candidates);
            let mut inside = false;
            for (a, b) in candidates.iter().filter_map(|&index| self.grid.segment(index)) {
                *work += 1;
                if point_segment_distance(&q, &a, &b) <= tolerance {
                    return true;
                }
                // Half-open in x so that a vertex on the ray is counted once.
                if (a.x > q.x) != (b.x > q.x) {
                    let y = a.y + (q.x - a.x) / (b.x - a.x) * (b.y - a.y);
                    if y > q.y {
                        inside = !inside;
                    }
                }
            }
            inside
        })
    }

    /// Calls `visit(from, to)` for every edge whose bounding box comes within `reach` of
    /// `centre` in x and y (a superset of the edges within `reach`). An edge spanning several
    /// grid cells may come more than once: the caller's answers must not depend on repeats.
    pub(crate) fn edges_near(&self, centre: P2, reach: f64, mut visit: impl FnMut(P2, P2)) {
        let (low, high) = (centre.add_scalar(-reach), centre.add_scalar(reach));
        self.near.visit(&centre, &centre, reach, |index| {
            if let Some((a, b)) = self.near.segment(index)
                && a.x.max(b.x) >= low.x
                && a.x.min(b.x) <= high.x
                && a.y.max(b.y) >= low.y
                && a.y.min(b.y) <= high.y
            {
                visit(a, b);
            }
        });
    }

    /// The first pair of edges that cross or touch where they must not: inside one ring (the
    /// pair [`find_self_intersection`] reports), else between two rings (the first edge in ring
    /// order that meets a later ring's edge, with the first such edge). `Ok(None)` when every
    /// ring is simple and no two rings meet.
    ///
    /// # Errors
    /// [`CheckStopped::Budget`] when a ring, or the rings together, crowd so many edges into the
    /// same grid cells that more than `64·n + 10⁶` pairs would need testing.
    pub(crate) fn first_crossing(&self) -> Result<Option<(EdgeAt, EdgeAt)>, CheckStopped> {
        for (ring_index, ring) in self.rings.iter().enumerate() {
            // A stock's rings are checked whole, as the request is read.
            if let Some((i, j)) = find_self_intersection(ring, Control::default())? {
                return Ok(Some(((ring_index, i), (ring_index, j))));
            }
        }
        if self.rings.len() < 2 {
            return Ok(None);
        }
        let budget = 64 * self.owners.len() + 1_000_000;
        let mut tests = 0_usize;
        let mut candidates = Vec::new();
        for (index, &(ring, _)) in self.owners.iter().enumerate() {
            let Some((a, b)) = self.grid.segment(index) else { continue };
            candidates.clear();
            self.grid.candidates(&a, &b, 0.0, &mut candidates);
            // Sorted: the first hit is the smallest index.
            for &other in &candidates {
                if other <= index || self.owners.get(other).is_none_or(|o| o.0 == ring) {
                    continue;
                }
                tests += 1;
                if tests > budget {
                    return Err(CheckStopped::Budget);
                }
                if let Some((c, d)) = self.grid.segment(other)
                    && segments_intersect(&a, &b, &c, &d)
                {
                    return Ok(Some((self.owners[index], self.owners[other])));
                }
            }
        }
        Ok(None)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, y0: f64, size: f64) -> Vec<P2> {
        vec![P2::new(x0, y0), P2::new(x0 + size, y0), P2::new(x0 + size, y0 + size), P2::new(x0, y0 + size)]
    }

    #[test]
    fn even_odd_with_hole_and_inclusive_boundary() {
        let outline = Outline::new(vec![square(0.0, 0.0, 10.0), square(4.0, 4.0, 2.0)], 1.0);
        let inside = |x: f64, y: f64| outline.contains(P2::new(x, y), 1e-9, &mut 0);
        assert!(inside(1.0, 1.0));
        assert!(!inside(5.0, 5.0));
        assert!(inside(4.0, 5.0));
        assert!(inside(10.0, 3.0));
        assert!(!inside(10.1, 3.0));
        assert!(inside(10.0 + 5e-10, 3.0), "within the boundary band");
        // A ray through a vertex is counted once.
        assert!(inside(4.0, 1.0));
        assert!(inside(6.0, 1.0));
        assert!(!inside(-1.0, 10.0));
        assert!(!inside(0.0, 12.0));
        assert!(!inside(5.0, -3.0));
    }

    #[test]
    fn containment_agrees_with_planar_on_a_detailed_ring() {
        // A star of 2000 points: every query agrees with planar's one-ring test.
        let ring: Vec<P2> = (0..2000)
            .map(|i| {
                let angle = std::f64::consts::TAU * f64::from(i) / 2000.0;
                let radius = if i % 2 == 0 { 50.0 } else { 45.0 };
                P2::new(radius * angle.cos(), radius * angle.sin())
            })
            .collect();
        let outline = Outline::new(vec![ring.clone()], 5.0);
        for i in 0..400 {
            let q = P2::new(-55.0 + 0.27 * f64::from(i), -48.0 + 0.241 * f64::from(i % 397));
            let expected = crate::planar::point_in_polygon(&q, &ring) != crate::planar::Containment::Outside;
            assert_eq!(outline.contains(q, 0.0, &mut 0), expected, "{q:?}");
        }
    }

    #[test]
    fn crossing_rings_are_found() {
        let bow_tie = vec![vec![P2::new(0.0, 0.0), P2::new(2.0, 2.0), P2::new(2.0, 0.0), P2::new(0.0, 2.0)]];
        assert_eq!(Outline::new(bow_tie, 1.0).first_crossing(), Ok(Some(((0, 0), (0, 2)))));
        let apart = vec![square(0.0, 0.0, 1.0), square(3.0, 3.0, 1.0)];
        assert_eq!(Outline::new(apart, 1.0).first_crossing(), Ok(None));
        let overlapping = vec![square(0.0, 0.0, 2.0), square(1.0, 1.0, 2.0)];
        assert_eq!(Outline::new(overlapping, 1.0).first_crossing(), Ok(Some(((0, 1), (1, 0)))));
        let touching = vec![square(0.0, 0.0, 1.0), square(1.0, 1.0, 1.0)];
        assert!(Outline::new(touching, 1.0).first_crossing().unwrap().is_some());
        let spike = vec![vec![P2::new(0.0, 0.0), P2::new(2.0, 0.0), P2::new(1.0, 0.0), P2::new(1.0, 1.0)]];
        assert!(Outline::new(spike, 1.0).first_crossing().unwrap().is_some());
    }

    #[test]
    fn edges_near_a_circle() {
        let outline = Outline::new(vec![square(0.0, 0.0, 10.0), square(40.0, 40.0, 2.0)], 2.0);
        let mut found = Vec::new();
        outline.edges_near(P2::new(5.0, -1.0), 2.0, |a, b| found.push((a, b)));
        assert!(found.contains(&(P2::new(0.0, 0.0), P2::new(10.0, 0.0))));
        assert!(found.iter().all(|(a, _)| a.x < 20.0), "the far square is not near");
        assert_eq!(outline.edges().count(), 8);
    }
}
