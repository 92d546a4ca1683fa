//! A static bounding-box tree: which path pieces (of the path and of earlier cuts) can reach a
//! query box (the pruning of docs/spec/engagement.md §5.3.3, for long paths).
//!
//! The stock outline's edges use `planar::SegmentGrid` instead (see `outline`); the path keeps
//! this tree because its pieces are arcs as well as lines, and the grid indexes straight
//! segments only (an arc would have to be chorded, which the exact engine must not do).

use super::P2;

/// Axis-aligned box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct BBox {
    pub min: P2,
    pub max: P2,
}

impl BBox {
    /// The box spanned by two points.
    pub(crate) fn of(a: P2, b: P2) -> Self {
        Self { min: P2::new(a.x.min(b.x), a.y.min(b.y)), max: P2::new(a.x.max(b.x), a.y.max(b.y)) }
    }

    /// The square of half-side `reach` around `centre`.
    pub(crate) fn around(centre: P2, reach: f64) -> Self {
        Self { min: P2::new(centre.x - reach, centre.y - reach), max: P2::new(centre.x + reach, centre.y + reach) }
    }

    /// This box grown by `margin` on every side.
    #[must_use]
    pub(crate) fn grown(&self, margin: f64) -> Self {
        Self {
            min: P2::new(self.min.x - margin, self.min.y - margin),
            max: P2::new(self.max.x + margin, self.max.y + margin),
        }
    }

    /// The smallest box holding both.
    #[must_use]
    pub(crate) fn union(&self, other: &Self) -> Self {
        Self {
            min: P2::new(self.min.x.min(other.min.x), self.min.y.min(other.min.y)),
            max: P2::new(self.max.x.max(other.max.x), self.max.y.max(other.max.y)),
        }
    }

    /// The common part, if any.
    pub(crate) fn intersection(&self, other: &Self) -> Option<Self> {
        let result = Self {
            min: P2::new(self.min.x.max(other.min.x), self.min.y.max(other.min.y)),
            max: P2::new(self.max.x.min(other.max.x), self.max.y.min(other.max.y)),
        };
        (result.min.x <= result.max.x && result.min.y <= result.max.y).then_some(result)
    }

    /// Whether the boxes share a point.
    pub(crate) fn overlaps(&self, other: &Self) -> bool {
        self.min.x <= other.max.x && other.min.x <= self.max.x && self.min.y <= other.max.y && other.min.y <= self.max.y
    }

    /// Grows the box to hold `p`.
    pub(crate) fn include(&mut self, p: P2) {
        self.min = P2::new(self.min.x.min(p.x), self.min.y.min(p.y));
        self.max = P2::new(self.max.x.max(p.x), self.max.y.max(p.y));
    }
}

/// Items per leaf.
const LEAF_SIZE: usize = 4;

#[derive(Debug, Clone)]
struct Node {
    bbox: BBox,
    /// Leaf: range into `items`; inner: children indices.
    first: usize,
    second: usize,
    leaf: bool,
}

/// Boxes of items (indices into the caller's list) in a median-split hierarchy.
#[derive(Debug, Clone, Default)]
pub(crate) struct BoxTree {
    nodes: Vec<Node>,
    items: Vec<usize>,
    boxes: Vec<BBox>,
}

impl BoxTree {
    /// A tree over `boxes`; item `i` is `boxes[i]`.
    pub(crate) fn new(boxes: &[BBox]) -> Self {
        let mut tree = Self {
            nodes: Vec::with_capacity(2 * boxes.len() / LEAF_SIZE + 1),
            items: (0..boxes.len()).collect(),
            boxes: boxes.to_vec(),
        };
        if !boxes.is_empty() {
            tree.build(0, boxes.len());
        }
        tree
    }

    fn build(&mut self, start: usize, end: usize) -> usize {
        let mut bbox = self.boxes[self.items[start]];
        for &item in &self.items[start + 1..end] {
            bbox = bbox.union(&self.boxes[item]);
        }
        let index = self.nodes.len();
        self.nodes.push(Node { bbox, first: start, second: end, leaf: true });
        if end - start > LEAF_SIZE {
            let wide = bbox.max.x - bbox.min.x >= bbox.max.y - bbox.min.y;
            let key = |b: &BBox| {
                if wide { b.min.x + b.max.x } else { b.min.y + b.max.y }
            };
            let middle = start + (end - start) / 2;
            let boxes = &self.boxes;
            self.items[start..end].select_nth_unstable_by(middle - start, |a, b| {
                key(&boxes[*a]).total_cmp(&key(&boxes[*b])).then(a.cmp(b))
            });
            let left = self.build(start, middle);
            let right = self.build(middle, end);
            self.nodes[index] = Node { bbox, first: left, second: right, leaf: false };
        }
        index
    }

    /// Calls `visit` once for every item whose box overlaps `region`.
    pub(crate) fn query(&self, region: &BBox, visit: &mut dyn FnMut(usize)) {
        if self.nodes.is_empty() {
            return;
        }
        // A median split halves the items at each level, so the tree is under 64 levels deep and
        // this depth-first stack (at most one waiting node per level) never fills: no allocation
        // per query, which runs several times per engagement sample.
        let mut stack = [0_usize; 128];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let index = stack[top];
            let node = &self.nodes[index];
            if !node.bbox.overlaps(region) {
                continue;
            }
            if node.leaf {
                for &item in &self.items[node.first..node.second] {
                    if self.boxes[item].overlaps(region) {
                        visit(item);
                    }
                }
            } else {
                stack[top] = node.second;
                stack[top + 1] = node.first;
                top += 2;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn query_finds_exactly_the_overlapping_boxes() {
        let boxes: Vec<BBox> = (0..100)
            .map(|i| {
                let x = f64::from(i % 10);
                let y = f64::from(i / 10);
                BBox::of(P2::new(x, y), P2::new(x + 0.5, y + 0.5))
            })
            .collect();
        let tree = BoxTree::new(&boxes);
        let region = BBox::of(P2::new(2.2, 3.2), P2::new(4.1, 5.0));
        let mut found = Vec::new();
        tree.query(&region, &mut |i| found.push(i));
        found.sort_unstable();
        let expected: Vec<usize> = (0..100).filter(|&i| boxes[i].overlaps(&region)).collect();
        assert_eq!(found, expected);
        assert!(!expected.is_empty());
        let empty = BoxTree::new(&[]);
        empty.query(&region, &mut |_| panic!("empty tree"));
    }
}
