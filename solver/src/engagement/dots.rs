//! Engine A, dot removal (docs/spec/engagement.md §5.3.2, the patent's method): the stock as a grid of dots,
//! each sample removing the dots inside the tool circle and reporting their contact angles; the
//! arcs are rebuilt from the removed dots' lateral offsets.
//!
//! All dots inside the previous circle are already gone, so each sample scans only the part of
//! every grid row inside the new circle and outside the previous one (the crescent), which gives
//! exactly the patent's result at a fraction of the cost.

use super::P2;
use super::arcs::{Arc, normalise};
use super::bbox_tree::BBox;
use super::segments::Station;
use super::stock::{Base, REACH_TOLERANCE, Region};
use crate::planar::point_segment_distance;

/// An empty column span.
const EMPTY: (i64, i64) = (0, -1);

/// Relative slack of the disc test |p − c|² ≤ R²(1 + 1e-12) (§5.3.2).
const DISC_SLACK: f64 = 1e-12;

/// The workpiece dots: bit (i, j) is the dot at origin + ((i + ½)g, (j + ½)g); 1 = material.
///
/// The bits are stored in tiles of 8 × 8 dots per word, so the thin crescent a sample removes
/// (one dot wide, 2R tall or wide) touches an eighth of the memory lines a row-major layout
/// would.
#[derive(Debug, Clone)]
pub(crate) struct DotGrid {
    origin: P2,
    cell: f64,
    width: usize,
    height: usize,
    /// Tiles per row of tiles.
    tiles_across: usize,
    bits: Vec<u64>,
    /// Column spans of the last removal's disc per row (valid over `cached_rows`), so the next
    /// sample need not recompute them for its "previous circle".
    spans: Vec<(i64, i64)>,
    cached_rows: std::ops::Range<usize>,
    cached_centre: Option<P2>,
}

impl DotGrid {
    /// The grid over `width` × `height` dots from `origin`, filled from `region` (even-odd,
    /// boundary inclusive; earlier cuts removed). The caller has checked the size limit.
    pub(crate) fn new(region: &Region, origin: P2, cell: f64, width: usize, height: usize) -> Self {
        let tiles_across = width.div_ceil(8);
        let mut grid = Self {
            origin,
            cell,
            width,
            height,
            tiles_across,
            bits: vec![0; tiles_across * height.div_ceil(8)],
            spans: vec![EMPTY; height],
            cached_rows: 0..0,
            cached_centre: None,
        };
        grid.fill(region);
        for cut in &region.cuts {
            for shape in &cut.shapes {
                let points = shape.flatten(cell / 100.0);
                for pair in points.windows(2) {
                    grid.clear_capsule(pair[0], pair[1], cut.radius);
                }
            }
        }
        grid
    }

    /// Bytes held by the bits.
    pub(crate) fn bytes(&self) -> usize {
        self.bits.len() * 8
    }

    /// Dots across and up.
    pub(crate) fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Corner of dot (0, 0)'s cell.
    pub(crate) fn origin(&self) -> P2 {
        self.origin
    }

    fn x_of(&self, column: usize) -> f64 {
        self.origin.x + (column as f64 + 0.5) * self.cell
    }

    fn y_of(&self, row: usize) -> f64 {
        self.origin.y + (row as f64 + 0.5) * self.cell
    }

    /// Sets the dots of row `row` whose centres lie in [x0, x1].
    fn set_span(&mut self, row: usize, x0: f64, x1: f64, value: bool) {
        let Some((first, last)) = self.columns_between(x0, x1) else {
            return;
        };
        for (index, mask) in self.masks(row, first, last) {
            if value {
                self.bits[index] |= mask;
            } else {
                self.bits[index] &= !mask;
            }
        }
    }

    /// Column range whose dot centres lie in [x0, x1], clipped to the grid.
    fn columns_between(&self, x0: f64, x1: f64) -> Option<(usize, usize)> {
        let first = ((x0 - self.origin.x) / self.cell - 0.5).ceil().max(0.0);
        let last = ((x1 - self.origin.x) / self.cell - 0.5).floor().min(self.width as f64 - 1.0);
        (first <= last).then_some((first as usize, last as usize))
    }

    fn fill(&mut self, region: &Region) {
        match &region.base {
            Base::Polygons(outline) => {
                let tolerance = super::stock::BOUNDARY_TOLERANCE;
                // Scanline sweep: edges sorted by their lowest y enter the active list when the
                // row reaches them and leave it once the row has passed their highest y.
                let mut edges: Vec<(P2, P2)> = outline.edges().collect();
                edges.sort_by(|p, q| p.0.y.min(p.1.y).total_cmp(&q.0.y.min(q.1.y)));
                let mut pending = edges.into_iter().peekable();
                let mut active: Vec<(P2, P2)> = Vec::new();
                let mut crossings = Vec::new();
                let mut flats = Vec::new();
                for row in 0..self.height {
                    let y = self.y_of(row);
                    crossings.clear();
                    flats.clear();
                    while let Some(edge) = pending.next_if(|(a, b)| a.y.min(b.y) <= y + tolerance) {
                        active.push(edge);
                    }
                    active.retain(|(a, b)| a.y.max(b.y) >= y - tolerance);
                    for &(a, b) in &active {
                        if (a.y > y) != (b.y > y) {
                            crossings.push(a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x));
                        }
                        // Boundary inclusive: dots on an edge (within the tolerance) are material.
                        if (a.y - y).abs() <= tolerance
                            || (b.y - y).abs() <= tolerance
                            || (a.y - b.y).abs() <= tolerance
                        {
                            flats.push((a.x.min(b.x), a.x.max(b.x)));
                        }
                    }
                    crossings.sort_by(f64::total_cmp);
                    for pair in crossings.chunks_exact(2) {
                        self.set_span(row, pair[0] - tolerance, pair[1] + tolerance, true);
                    }
                    for &(x0, x1) in &flats {
                        self.set_span(row, x0 - tolerance, x1 + tolerance, true);
                    }
                }
            }
            Base::Bitmap(bitmap) => {
                for row in 0..self.height {
                    let y = self.y_of(row);
                    for column in 0..self.width {
                        let (i, j) = bitmap.cell_of(P2::new(self.x_of(column), y));
                        if bitmap.cell_is_material(i, j) {
                            let (index, bit) = self.bit(column, row);
                            self.bits[index] |= bit;
                        }
                    }
                }
            }
        }
    }

    /// Clears the dots closer than `radius` to the segment [a, b] (an earlier cut).
    fn clear_capsule(&mut self, a: P2, b: P2, radius: f64) {
        let limit = radius * (1.0 - REACH_TOLERANCE);
        let box_ = BBox::of(a, b).grown(radius);
        let first_row = ((box_.min.y - self.origin.y) / self.cell - 0.5).ceil().max(0.0);
        let last_row = ((box_.max.y - self.origin.y) / self.cell - 0.5).floor().min(self.height as f64 - 1.0);
        if first_row > last_row {
            return;
        }
        for row in first_row as usize..=last_row as usize {
            let y = self.y_of(row);
            let Some((x0, x1)) = capsule_row(a, b, radius, y) else {
                continue;
            };
            let Some((first, last)) = self.columns_between(x0 - self.cell, x1 + self.cell) else {
                continue;
            };
            for column in first..=last {
                let p = P2::new(self.x_of(column), y);
                if point_segment_distance(&p, &a, &b) < limit {
                    let (index, bit) = self.bit(column, row);
                    self.bits[index] &= !bit;
                }
            }
        }
    }

    /// Column span [first, last] of row `row` inside the disc (`centre`, R² = `limit`), exact
    /// for the test (x − cx)² + dy² ≤ limit; empty when first > last.
    #[inline]
    fn disc_span(&self, centre: P2, limit: f64, row: usize) -> (i64, i64) {
        let dy = self.y_of(row) - centre.y;
        let rest = limit - dy * dy;
        if rest < 0.0 {
            return EMPTY;
        }
        let half = rest.sqrt();
        let width = self.width as i64;
        let inside = |column: i64| {
            (0..width).contains(&column) && {
                let dx = self.x_of(column as usize) - centre.x;
                dx * dx + dy * dy <= limit
            }
        };
        let bound = self.width as f64;
        let low = ((centre.x - half - self.origin.x) / self.cell - 0.5).clamp(-1.0, bound);
        let high = ((centre.x + half - self.origin.x) / self.cell - 0.5).clamp(-1.0, bound);
        // ceil and floor by truncation (both values lie in [−1, width]).
        let mut first = (low as i64 + i64::from((low as i64 as f64) < low)).max(0);
        let mut last = (high as i64 - i64::from((high as i64 as f64) > high)).min(width - 1);
        // Rounding may put an end one dot off the exact test: settle it.
        while first <= last && !inside(first) {
            first += 1;
        }
        while first > 0 && inside(first - 1) {
            first -= 1;
        }
        while last >= first && !inside(last) {
            last -= 1;
        }
        while inside(last + 1) {
            last += 1;
        }
        (first, last)
    }

    fn rows_near(&self, centre: P2, radius: f64) -> std::ops::Range<usize> {
        // Widened like the disc test, so no row the test accepts is skipped.
        let radius = radius * (1.0 + DISC_SLACK);
        let first = ((centre.y - radius - self.origin.y) / self.cell - 0.5).ceil().max(0.0);
        let last = ((centre.y + radius - self.origin.y) / self.cell + 0.5).floor().min(self.height as f64);
        if first >= last { 0..0 } else { first as usize..last as usize }
    }

    /// Removes the material dots inside the circle at `centre` that were not inside the circle
    /// at `previous`, calling `visit` with each removed dot's centre.
    pub(crate) fn remove<F: FnMut(P2)>(&mut self, centre: P2, previous: Option<P2>, radius: f64, visit: &mut F) {
        let limit = radius * radius * (1.0 + DISC_SLACK);
        let cached = previous.is_some() && previous == self.cached_centre;
        let rows = self.rows_near(centre, radius);
        for row in rows.clone() {
            let (first, last) = self.disc_span(centre, limit, row);
            let skip = if cached {
                if self.cached_rows.contains(&row) { self.spans[row] } else { EMPTY }
            } else {
                previous.map_or(EMPTY, |p| self.disc_span(p, limit, row))
            };
            self.spans[row] = (first, last);
            if first > last {
                continue;
            }
            let (a, b) = skip;
            let (left, right) = if a <= b && a <= last && b >= first {
                ((first, a - 1), (b + 1, last))
            } else {
                ((first, last), EMPTY)
            };
            for (start, end) in [left, right] {
                if start <= end {
                    self.take(row, start as usize, end as usize, visit);
                }
            }
        }
        self.cached_rows = rows;
        self.cached_centre = Some(centre);
    }

    /// Word index and bit of dot (column, row).
    #[inline]
    fn bit(&self, column: usize, row: usize) -> (usize, u64) {
        ((row / 8) * self.tiles_across + column / 8, 1 << ((row % 8) * 8 + column % 8))
    }

    /// The words and masks covering columns [start, end] of `row`.
    #[inline]
    fn masks(&self, row: usize, start: usize, end: usize) -> impl Iterator<Item = (usize, u64)> + use<> {
        let base = (row / 8) * self.tiles_across;
        let shift = (row % 8) * 8;
        (start / 8..=end / 8).map(move |tile| {
            let low = if tile == start / 8 { start % 8 } else { 0 };
            let high = if tile == end / 8 { end % 8 } else { 7 };
            let mask = ((1_u64 << (high - low + 1)) - 1) << (low + shift);
            (base + tile, mask)
        })
    }

    /// Clears the set dots of `row` in columns [start, end], visiting each.
    fn take<F: FnMut(P2)>(&mut self, row: usize, start: usize, end: usize, visit: &mut F) {
        let y = self.y_of(row);
        let shift = (row % 8) * 8;
        for (index, mask) in self.masks(row, start, end) {
            let word = &mut self.bits[index];
            let mut found = *word & mask;
            *word &= !mask;
            let first_column = (index % self.tiles_across) * 8;
            while found != 0 {
                let bit = found.trailing_zeros() as usize - shift;
                found &= found - 1;
                visit(P2::new(self.x_of(first_column + bit), y));
            }
        }
    }

    /// Whether any material dot lies inside the circle (a rapid's collision test, §5.8).
    pub(crate) fn any_inside(&self, centre: P2, radius: f64) -> bool {
        let limit = radius * radius * (1.0 + DISC_SLACK);
        self.rows_near(centre, radius).any(|row| {
            let (start, end) = self.disc_span(centre, limit, row);
            start <= end
                && self.masks(row, start as usize, end as usize).any(|(index, mask)| self.bits[index] & mask != 0)
        })
    }

    /// Material dots left.
    #[cfg(test)]
    pub(crate) fn count(&self) -> u64 {
        self.bits.iter().map(|w| u64::from(w.count_ones())).sum()
    }
}

/// The x-interval of row `y` within `radius` of segment [a, b] (a convex capsule).
fn capsule_row(a: P2, b: P2, radius: f64, y: f64) -> Option<(f64, f64)> {
    let mut span: Option<(f64, f64)> = None;
    let mut add = |x0: f64, x1: f64| {
        span = Some(span.map_or((x0, x1), |(l, h)| (l.min(x0), h.max(x1))));
    };
    for end in [a, b] {
        let dy = y - end.y;
        if dy.abs() <= radius {
            let half = (radius * radius - dy * dy).sqrt();
            add(end.x - half, end.x + half);
        }
    }
    let d = b - a;
    let length = d.norm();
    if length > 0.0 {
        let normal = P2::new(-d.y, d.x) / length * radius;
        let corners = [a + normal, b + normal, b - normal, a - normal];
        for index in 0..4 {
            let (p, q) = (corners[index], corners[(index + 1) % 4]);
            if (p.y - y) * (q.y - y) <= 0.0 && p.y != q.y {
                let x = p.x + (y - p.y) / (q.y - p.y) * (q.x - p.x);
                add(x, x);
            } else if p.y == y && q.y == y {
                add(p.x.min(q.x), p.x.max(q.x));
            }
        }
    }
    span
}

/// The contact dots of one sample, split by side (§5.3.2 "front dot if u ≥ −(Δs/2 + g)").
#[derive(Debug, Default)]
pub(crate) struct Contacts {
    pub front: Vec<f64>,
    pub back: Vec<f64>,
    /// Contact angles of the removed dots, degrees (projected: ±acos(ℓ/R)), when kept.
    pub angles: Vec<f64>,
    /// Keep `angles` (for the scatter plot).
    pub keep_angles: bool,
    pub(crate) bins: Bins,
}

/// Per-bin smallest and largest lateral offset, reused between samples.
#[derive(Debug, Default)]
pub(crate) struct Bins {
    low: Vec<f64>,
    high: Vec<f64>,
    stamp: Vec<u32>,
    epoch: u32,
}

impl Contacts {
    /// Records a removed dot at `dot` for a tool at `station` that moved `step` since the last
    /// removal.
    #[inline]
    pub(crate) fn record(&mut self, dot: P2, station: &Station, radius: f64, step: f64, cell: f64) {
        let d = dot - station.centre;
        let forward = station.tangent;
        let lateral = d.x * forward.y - d.y * forward.x;
        let along = d.x * forward.x + d.y * forward.y;
        let front = along >= -(0.5 * step + cell);
        if front {
            self.front.push(lateral);
        } else {
            self.back.push(lateral);
        }
        if self.keep_angles {
            let angle = (lateral / radius).clamp(-1.0, 1.0).acos().to_degrees();
            self.angles.push(if front { angle } else { -angle });
        }
    }

    /// Whether any dot was removed.
    pub(crate) fn touched(&self) -> bool {
        !self.front.is_empty() || !self.back.is_empty()
    }

    /// The arcs rebuilt from the dots (§5.3.2 steps 1–5): clusters of lateral offsets split at
    /// gaps wider than τ = max(2g, 14g²/Δs), widened by g/2, turned into arcs.
    ///
    /// The offsets are binned τ wide instead of sorted: two offsets in one bin are never more
    /// than τ apart, and the gap between neighbouring bins is taken from their exact extremes,
    /// so the clusters are the same as after sorting.
    pub(crate) fn arcs(&mut self, radius: f64, cell: f64, step: f64) -> Vec<Arc> {
        let gap = (2.0 * cell).max(14.0 * cell * cell / step.max(cell));
        let count = ((2.0 * radius + 2.0 * cell) / gap).ceil() as usize + 1;
        let mut arcs = Vec::new();
        for front in [true, false] {
            let values = if front { &self.front } else { &self.back };
            if values.is_empty() {
                continue;
            }
            let bins = &mut self.bins;
            if bins.stamp.len() < count {
                *bins = Bins { low: vec![0.0; count], high: vec![0.0; count], stamp: vec![0; count], epoch: 0 };
            }
            bins.epoch = bins.epoch.wrapping_add(1);
            if bins.epoch == 0 {
                bins.stamp.iter_mut().for_each(|s| *s = 0);
                bins.epoch = 1;
            }
            let epoch = bins.epoch;
            for &value in values {
                let index = (((value + radius + cell) / gap).floor().max(0.0) as usize).min(count - 1);
                if bins.stamp[index] == epoch {
                    bins.low[index] = bins.low[index].min(value);
                    bins.high[index] = bins.high[index].max(value);
                } else {
                    bins.stamp[index] = epoch;
                    bins.low[index] = value;
                    bins.high[index] = value;
                }
            }
            let close = |low: f64, high: f64, arcs: &mut Vec<Arc>| {
                let low = (low - 0.5 * cell).max(-radius);
                let high = (high + 0.5 * cell).min(radius);
                let (a, b) = (
                    (high / radius).clamp(-1.0, 1.0).acos().to_degrees(),
                    (low / radius).clamp(-1.0, 1.0).acos().to_degrees(),
                );
                arcs.push(if front { Arc { from: a, to: b } } else { Arc { from: -b, to: -a } });
            };
            let mut cluster: Option<(f64, f64)> = None;
            for index in 0..count {
                if bins.stamp[index] != epoch {
                    continue;
                }
                let (low, high) = (bins.low[index], bins.high[index]);
                cluster = match cluster {
                    Some((start, end)) if low - end > gap => {
                        close(start, end, &mut arcs);
                        Some((low, high))
                    }
                    Some((start, end)) => Some((start, end.max(high))),
                    None => Some((low, high)),
                };
            }
            if let Some((start, end)) = cluster {
                close(start, end, &mut arcs);
            }
        }
        normalise(arcs)
    }

    /// Empties the buffers for the next sample.
    pub(crate) fn clear(&mut self) {
        self.front.clear();
        self.back.clear();
        self.angles.clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engagement::outline::Outline;
    use crate::engagement::segments::Shape;
    use crate::engagement::stock::Cut;

    fn block(x0: f64, y0: f64, x1: f64, y1: f64) -> Region {
        let rings = vec![vec![P2::new(x0, y0), P2::new(x1, y0), P2::new(x1, y1), P2::new(x0, y1)]];
        Region { base: Base::Polygons(Outline::new(rings, 1.0)), cuts: Vec::new() }
    }

    #[test]
    fn rasterising_a_block_counts_its_dots() {
        let grid = DotGrid::new(&block(0.0, 0.0, 2.0, 1.0), P2::new(-1.0, -1.0), 0.1, 40, 30);
        // Dot centres at −0.95, −0.85, ...: 20 columns × 10 rows fall inside.
        assert_eq!(grid.count(), 200);
    }

    #[test]
    fn crescent_removal_equals_full_disc_removal() {
        let region = block(0.0, -3.0, 10.0, 3.0);
        let mut fast = DotGrid::new(&region, P2::new(-2.0, -4.0), 0.05, 300, 160);
        let mut slow = fast.clone();
        let radius = 2.0;
        let mut previous: Option<P2> = None;
        for step in 0..40 {
            let centre = P2::new(-1.0 + 0.23 * f64::from(step), 0.3 + 0.01 * f64::from(step));
            let (mut a, mut b) = (0, 0);
            fast.remove(centre, previous, radius, &mut |_| a += 1);
            slow.remove(centre, None, radius, &mut |_| b += 1);
            assert_eq!(a, b, "step {step}");
            previous = Some(centre);
        }
        assert_eq!(fast.count(), slow.count());
        assert!(fast.count() > 0);
    }

    /// The sorted form of §5.3.2's clustering, for comparison with the binned one.
    fn sorted_clusters(values: &[f64], gap: f64) -> Vec<(f64, f64)> {
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let mut clusters: Vec<(f64, f64)> = Vec::new();
        for v in sorted {
            match clusters.last_mut() {
                Some(last) if v - last.1 <= gap => last.1 = v,
                _ => clusters.push((v, v)),
            }
        }
        clusters
    }

    #[test]
    fn binned_clusters_equal_sorted_clusters() {
        let (radius, cell, step): (f64, f64, f64) = (5.0, 0.05, 0.2);
        let gap = (2.0 * cell).max(14.0 * cell * cell / step);
        let mut state = 12345_u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1_u64 << 53) as f64
        };
        let mut contacts = Contacts::default();
        let mut splits = 0;
        for _ in 0..200 {
            contacts.clear();
            let n = 1 + (next() * 60.0) as usize;
            for _ in 0..n {
                // Clumps with gaps near τ.
                let spread = if next() < 0.5 { 1.0 } else { 0.3 };
                let value = (next() * 10.0 - 5.0) * spread;
                contacts.front.push(value.clamp(-radius, radius));
            }
            let clusters = sorted_clusters(&contacts.front, gap);
            splits += clusters.len() - 1;
            let expected: Vec<Arc> = normalise(
                clusters
                    .iter()
                    .map(|(low, high)| {
                        let low = (low - 0.5 * cell).max(-radius);
                        let high = (high + 0.5 * cell).min(radius);
                        Arc { from: (high / radius).acos().to_degrees(), to: (low / radius).acos().to_degrees() }
                    })
                    .collect::<Vec<_>>(),
            );
            assert_eq!(contacts.arcs(radius, cell, step), expected);
        }
        assert!(splits > 50, "the data should exercise the gap rule");
    }

    #[test]
    fn earlier_cut_clears_a_channel() {
        let mut region = block(0.0, 0.0, 10.0, 10.0);
        region.cuts.push(Cut::new(vec![Shape::Line { from: P2::new(-1.0, 5.0), to: P2::new(11.0, 5.0) }], 1.0));
        let grid = DotGrid::new(&region, P2::new(0.0, 0.0), 0.1, 100, 100);
        // Rows with centres at 4.05 … 5.95 (within 1 of y = 5, strictly) are cleared: 20 rows.
        assert_eq!(grid.count(), 100 * 80);
    }
}
