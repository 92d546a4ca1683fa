//! The tool path as ball-centre segments in program order (docs/spec/predict.md §3.2): passes
//! (one feed line or arc chord each, with its NC line), the global arclength that splits the
//! motion into T1 (before) and T2 (after), and an xy grid of segments for the neighbour queries of
//! §6.1 (`sweep`).

use crate::geometry::Vec3;

/// Most cells of the segment grid.
const MAX_CELLS: usize = 4_000_000;

/// One straight piece of tool motion between two nodes.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segment {
    pub(crate) start_node: usize,
    pub(crate) end_node: usize,
    /// Arclength of the whole path at the start node.
    pub(crate) sigma: f64,
    pub(crate) length: f64,
    /// The pass this segment is, for feed moves.
    pub(crate) pass: Option<usize>,
    /// NC line of a rapid move (feed moves carry theirs in the pass source).
    pub(crate) rapid_line: Option<usize>,
}

/// Cutting conditions and origin of one pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PassSource {
    /// NC line (1-based) for G-code paths.
    pub(crate) line: Option<usize>,
    /// `N` number of the block.
    pub(crate) block_number: Option<u64>,
    /// Feed, mm/min.
    pub(crate) feed: f64,
    /// Spindle speed, rpm.
    pub(crate) spindle_rpm: f64,
    /// s_rot: −1 for M03 (clockwise seen from +Z), +1 for M04.
    pub(crate) rotation_sign: f64,
}

/// A pass: one feed segment.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pass {
    pub(crate) segment: usize,
    pub(crate) source: PassSource,
}

/// The path, ready for queries.
#[derive(Debug, Clone)]
pub(crate) struct PathModel {
    pub(crate) nodes: Vec<Vec3>,
    pub(crate) segments: Vec<Segment>,
    pub(crate) passes: Vec<Pass>,
    grid: SegmentGrid,
    /// The segments ranked by their lowest end's z (ties in path order): `by_height[k]` is the
    /// segment of rank k, `height_rank[i]` the rank of segment i.
    by_height: Vec<u32>,
    height_rank: Vec<u32>,
}

/// Builds a path from runs of connected nodes; within a run, consecutive nodes are joined by a
/// segment whose pass source is `Some` for feed moves and `None` for rapids.
#[derive(Debug, Default)]
pub(crate) struct PathBuilder {
    nodes: Vec<Vec3>,
    segments: Vec<Segment>,
    passes: Vec<Pass>,
    sigma: f64,
    open_run: bool,
}

impl PathBuilder {
    /// Starts a new run at `point` (after a position the program did not know); returns its node.
    pub(crate) fn start(&mut self, point: Vec3) -> usize {
        self.nodes.push(point);
        self.open_run = true;
        self.nodes.len() - 1
    }

    /// Whether a run is open.
    pub(crate) fn is_open(&self) -> bool {
        self.open_run
    }

    /// Ends the current run: the position becomes unknown.
    pub(crate) fn break_run(&mut self) {
        self.open_run = false;
    }

    /// Moves on to `point` by a feed move (`source`) or a rapid; returns the new node. Needs an
    /// open run.
    pub(crate) fn to(&mut self, point: Vec3, source: Option<PassSource>) -> usize {
        self.move_to(point, source, None)
    }

    /// A rapid move from NC line `line`.
    pub(crate) fn rapid_to(&mut self, point: Vec3, line: usize) -> usize {
        self.move_to(point, None, Some(line))
    }

    fn move_to(&mut self, point: Vec3, source: Option<PassSource>, rapid_line: Option<usize>) -> usize {
        let start_node = self.nodes.len() - 1;
        let length = (point - self.nodes[start_node]).norm();
        self.nodes.push(point);
        let pass = source.map(|source| {
            self.passes.push(Pass { segment: self.segments.len(), source });
            self.passes.len() - 1
        });
        self.segments.push(Segment {
            start_node,
            end_node: start_node + 1,
            sigma: self.sigma,
            length,
            pass,
            rapid_line,
        });
        self.sigma += length;
        self.nodes.len() - 1
    }

    pub(crate) fn node_count(&self) -> usize {
        self.nodes.len()
    }

    pub(crate) fn pass_count(&self) -> usize {
        self.passes.len()
    }

    /// Finishes the path; `cell` is the preferred grid cell size (the ball radius).
    pub(crate) fn build(self, cell: f64) -> PathModel {
        PathModel::new(self.nodes, self.segments, self.passes, cell)
    }
}

impl PathModel {
    fn new(nodes: Vec<Vec3>, segments: Vec<Segment>, passes: Vec<Pass>, cell: f64) -> Self {
        let grid = SegmentGrid::new(&nodes, &segments, cell);
        let lowest = |s: &Segment| nodes[s.start_node].z.min(nodes[s.end_node].z);
        let mut by_height: Vec<u32> = (0..segments.len() as u32).collect();
        by_height.sort_by(|&i, &j| lowest(&segments[i as usize]).total_cmp(&lowest(&segments[j as usize])));
        let mut height_rank = vec![0; segments.len()];
        for (rank, &index) in by_height.iter().enumerate() {
            height_rank[index as usize] = rank as u32;
        }
        Self { nodes, segments, passes, grid, by_height, height_rank }
    }

    pub(crate) fn ends(&self, segment: usize) -> (Vec3, Vec3) {
        let s = &self.segments[segment];
        (self.nodes[s.start_node], self.nodes[s.end_node])
    }

    /// The path point at global arclength `sigma`, if the path is continuous (no unknown move)
    /// between the segment `near` and that point.
    pub(crate) fn point_at(&self, near: usize, sigma: f64) -> Option<Vec3> {
        let mut index = near;
        loop {
            let s = &self.segments[index];
            if sigma < s.sigma {
                let previous = index.checked_sub(1)?;
                if self.segments[previous].end_node != s.start_node {
                    return None;
                }
                index = previous;
            } else if sigma > s.sigma + s.length {
                let next = index + 1;
                if next >= self.segments.len() || self.segments[next].start_node != s.end_node {
                    return None;
                }
                index = next;
            } else {
                let (a, b) = self.ends(index);
                let t = if s.length > 0.0 { (sigma - s.sigma) / s.length } else { 0.0 };
                return Some(a + t * (b - a));
            }
        }
    }

    /// Appends to `out` the indices of segments whose xy bounding box meets the square of half
    /// side `reach` about `centre`, each once, in the grid's order; `stamps` is per-thread scratch.
    pub(crate) fn near(&self, centre: &Vec3, reach: f64, stamps: &mut Stamps, out: &mut Vec<u32>) {
        stamps.reserve(self.segments.len());
        let first = out.len();
        self.grid.visit(centre.x - reach, centre.y - reach, centre.x + reach, centre.y + reach, |index| {
            if stamps.mark(index) {
                out.push(index);
            }
        });
        for &index in &out[first..] {
            stamps.unmark(index);
        }
    }

    /// [`Self::near`] in increasing index order (path order), read off the marks instead of
    /// sorting.
    pub(crate) fn near_in_order(&self, centre: &Vec3, reach: f64, stamps: &mut Stamps, out: &mut Vec<u32>) {
        stamps.reserve(self.segments.len());
        let (mut lowest, mut highest) = (u32::MAX, 0);
        self.grid.visit(centre.x - reach, centre.y - reach, centre.x + reach, centre.y + reach, |index| {
            stamps.mark(index);
            lowest = lowest.min(index);
            highest = highest.max(index);
        });
        if lowest <= highest {
            stamps.drain(lowest, highest, out);
        }
    }

    /// [`Self::near`] ordered by the segments' lowest points (ties in path order), read off the
    /// marks of their height ranks instead of sorting: the order the scenes keep their capsules
    /// in (§6.2), so that a scene built from pieces in this order needs no sort.
    pub(crate) fn near_by_height(&self, centre: &Vec3, reach: f64, stamps: &mut Stamps, out: &mut Vec<u32>) {
        stamps.reserve(self.segments.len());
        let (mut lowest, mut highest) = (u32::MAX, 0);
        self.grid.visit(centre.x - reach, centre.y - reach, centre.x + reach, centre.y + reach, |index| {
            let rank = self.height_rank[index as usize];
            stamps.mark(rank);
            lowest = lowest.min(rank);
            highest = highest.max(rank);
        });
        let first = out.len();
        if lowest <= highest {
            stamps.drain(lowest, highest, out);
        }
        for entry in &mut out[first..] {
            *entry = self.by_height[*entry as usize];
        }
    }

    /// The same path with its nodes moved (same segments and passes).
    pub(crate) fn with_nodes(&self, nodes: Vec<Vec3>, cell: f64) -> Self {
        let mut segments = self.segments.clone();
        let mut sigma = 0.0;
        for s in &mut segments {
            s.sigma = sigma;
            s.length = (nodes[s.end_node] - nodes[s.start_node]).norm();
            sigma += s.length;
        }
        Self::new(nodes, segments, self.passes.clone(), cell)
    }
}

/// Per-thread marks of the segments one neighbour query has visited (one bit each, all clear
/// between queries), for visiting each segment once.
#[derive(Debug, Default)]
pub(crate) struct Stamps {
    bits: Vec<u64>,
}

impl Stamps {
    fn reserve(&mut self, count: usize) {
        let words = count.div_ceil(64);
        if self.bits.len() < words {
            self.bits.resize(words, 0);
        }
    }

    /// Marks `index`; whether it was unmarked.
    fn mark(&mut self, index: u32) -> bool {
        let (word, bit) = (index as usize / 64, 1u64 << (index % 64));
        let unmarked = self.bits[word] & bit == 0;
        self.bits[word] |= bit;
        unmarked
    }

    fn unmark(&mut self, index: u32) {
        self.bits[index as usize / 64] &= !(1u64 << (index % 64));
    }

    /// Appends the marked indices in `lowest..=highest` (all of them) in increasing order and
    /// clears their marks.
    fn drain(&mut self, lowest: u32, highest: u32, out: &mut Vec<u32>) {
        for word in lowest as usize / 64..=highest as usize / 64 {
            let mut bits = std::mem::take(&mut self.bits[word]);
            while bits != 0 {
                out.push((word * 64) as u32 + bits.trailing_zeros());
                bits &= bits - 1;
            }
        }
    }
}

/// Uniform xy grid of segment bounding boxes (CSR layout).
#[derive(Debug, Clone)]
struct SegmentGrid {
    origin: [f64; 2],
    cell: f64,
    nx: usize,
    ny: usize,
    start: Vec<u32>,
    items: Vec<u32>,
}

impl SegmentGrid {
    fn new(nodes: &[Vec3], segments: &[Segment], preferred_cell: f64) -> Self {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for n in nodes {
            lo = [lo[0].min(n.x), lo[1].min(n.y)];
            hi = [hi[0].max(n.x), hi[1].max(n.y)];
        }
        if nodes.is_empty() {
            lo = [0.0; 2];
            hi = [0.0; 2];
        }
        let width = (hi[0] - lo[0]).max(1e-9);
        let height = (hi[1] - lo[1]).max(1e-9);
        let cell = preferred_cell.max((width * height / MAX_CELLS as f64).sqrt()).max(1e-6);
        let nx = ((width / cell).floor() as usize + 1).min(MAX_CELLS);
        let ny = ((height / cell).floor() as usize + 1).min(MAX_CELLS / nx.max(1)).max(1);
        let mut grid = Self { origin: lo, cell, nx, ny, start: vec![0; nx * ny + 1], items: Vec::new() };
        let boxes: Vec<(usize, usize, usize, usize)> = segments
            .iter()
            .map(|s| {
                let (a, b) = (nodes[s.start_node], nodes[s.end_node]);
                let (x0, y0) = grid.cell_of(a.x.min(b.x), a.y.min(b.y));
                let (x1, y1) = grid.cell_of(a.x.max(b.x), a.y.max(b.y));
                (x0, x1, y0, y1)
            })
            .collect();
        for &(x0, x1, y0, y1) in &boxes {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    grid.start[y * nx + x + 1] += 1;
                }
            }
        }
        for i in 1..grid.start.len() {
            grid.start[i] += grid.start[i - 1];
        }
        let mut fill = grid.start.clone();
        grid.items = vec![0; grid.start[grid.start.len() - 1] as usize];
        for (index, &(x0, x1, y0, y1)) in boxes.iter().enumerate() {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    let slot = &mut fill[y * nx + x];
                    grid.items[*slot as usize] = index as u32;
                    *slot += 1;
                }
            }
        }
        grid
    }

    fn cell_of(&self, x: f64, y: f64) -> (usize, usize) {
        let cx = ((x - self.origin[0]) / self.cell).floor().max(0.0) as usize;
        let cy = ((y - self.origin[1]) / self.cell).floor().max(0.0) as usize;
        (cx.min(self.nx - 1), cy.min(self.ny - 1))
    }

    fn visit(&self, x0: f64, y0: f64, x1: f64, y1: f64, mut f: impl FnMut(u32)) {
        let right = self.origin[0] + self.nx as f64 * self.cell;
        let top = self.origin[1] + self.ny as f64 * self.cell;
        if x1 < self.origin[0] || y1 < self.origin[1] || x0 > right || y0 > top {
            return;
        }
        let (cx0, cy0) = self.cell_of(x0, y0);
        let (cx1, cy1) = self.cell_of(x1, y1);
        for y in cy0..=cy1 {
            for x in cx0..=cx1 {
                let cell = y * self.nx + x;
                for &item in &self.items[self.start[cell] as usize..self.start[cell + 1] as usize] {
                    f(item);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn source() -> PassSource {
        PassSource { line: None, block_number: None, feed: 1000.0, spindle_rpm: 6000.0, rotation_sign: -1.0 }
    }

    #[test]
    fn neighbour_query_finds_every_segment_once() {
        let mut builder = PathBuilder::default();
        builder.start(Vec3::new(0.0, 0.0, 0.0));
        for i in 1..200 {
            let x = f64::from(i % 20) * 0.5;
            let y = f64::from(i / 20) * 0.5;
            builder.to(Vec3::new(x, y, f64::from(i % 7) * 0.1), Some(source()));
        }
        let path = builder.build(1.0);
        let mut stamps = Stamps::default();
        for probe in [Vec3::new(2.0, 2.0, 0.0), Vec3::new(9.0, 0.0, 0.0), Vec3::new(-5.0, 1.0, 0.0)] {
            let mut found = Vec::new();
            path.near(&probe, 1.2, &mut stamps, &mut found);
            let mut sorted = found.clone();
            sorted.sort_unstable();
            sorted.dedup();
            assert_eq!(sorted.len(), found.len());
            let mut in_order = Vec::new();
            path.near_in_order(&probe, 1.2, &mut stamps, &mut in_order);
            assert_eq!(in_order, sorted);
            let mut by_height = Vec::new();
            path.near_by_height(&probe, 1.2, &mut stamps, &mut by_height);
            let lowest = |i: u32| {
                let (a, b) = path.ends(i as usize);
                a.z.min(b.z)
            };
            let mut expected = sorted.clone();
            expected.sort_by(|&i, &j| lowest(i).total_cmp(&lowest(j)).then(i.cmp(&j)));
            assert_eq!(by_height, expected);
            for (index, _) in path.segments.iter().enumerate() {
                let (a, b) = path.ends(index);
                let overlaps = a.x.min(b.x) <= probe.x + 1.2
                    && a.x.max(b.x) >= probe.x - 1.2
                    && a.y.min(b.y) <= probe.y + 1.2
                    && a.y.max(b.y) >= probe.y - 1.2;
                if overlaps {
                    assert!(found.contains(&(index as u32)), "segment {index} missed");
                }
            }
        }
    }

    #[test]
    fn points_along_the_path_stop_at_breaks() {
        let mut builder = PathBuilder::default();
        builder.start(Vec3::zeros());
        builder.to(Vec3::new(1.0, 0.0, 0.0), Some(source()));
        builder.to(Vec3::new(1.0, 1.0, 0.0), Some(source()));
        builder.start(Vec3::new(5.0, 5.0, 0.0));
        builder.to(Vec3::new(6.0, 5.0, 0.0), Some(source()));
        let path = builder.build(1.0);
        assert_eq!(path.point_at(0, 1.5), Some(Vec3::new(1.0, 0.5, 0.0)));
        assert_eq!(path.point_at(1, 0.25), Some(Vec3::new(0.25, 0.0, 0.0)));
        assert_eq!(path.point_at(1, 2.5), None);
        assert_eq!(path.point_at(2, 2.5), Some(Vec3::new(5.5, 5.0, 0.0)));
        assert_eq!(path.point_at(2, 1.5), None);
    }
}
