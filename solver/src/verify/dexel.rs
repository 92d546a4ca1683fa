//! The z-dexel field (docs/spec/verify.md §3 Stock model): a regular grid of vertical rays, each
//! holding the material on it as sorted, disjoint intervals of z; removing an interval from a ray
//! and measuring how much of one lies in the material.

use smallvec::SmallVec;

/// An interval of z on a ray, `[low, high]` with `low < high`, mm.
pub(crate) type Interval = [f64; 2];

/// The material on one ray: sorted, disjoint intervals (most rays hold one).
pub(crate) type Ray = SmallVec<[Interval; 1]>;

/// Bytes one ray takes in memory (its inline interval; a ray with more spills to the heap).
pub(crate) const RAY_BYTES: u64 = std::mem::size_of::<Ray>() as u64;

/// The grid of rays: ray `(i, j)` is the vertical line through
/// `(origin.x + (i + ½)·spacing, origin.y + (j + ½)·spacing)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Grid {
    pub origin: [f64; 2],
    pub spacing: f64,
    pub nx: usize,
    pub ny: usize,
}

impl Grid {
    /// The grid covering the rectangle `[lo, hi]` at `spacing`.
    pub fn covering(lo: [f64; 2], hi: [f64; 2], spacing: f64) -> Self {
        let count = |k: usize| (((hi[k] - lo[k]) / spacing).ceil().max(1.0)) as usize;
        Self { origin: lo, spacing, nx: count(0), ny: count(1) }
    }

    /// The number of rays the rectangle `[lo, hi]` needs at `spacing` (as a float: a refused
    /// request may ask for more than `usize` holds).
    pub fn rays_for(lo: [f64; 2], hi: [f64; 2], spacing: f64) -> f64 {
        let count = |k: usize| ((hi[k] - lo[k]) / spacing).ceil().max(1.0);
        count(0) * count(1)
    }

    pub fn len(&self) -> usize {
        self.nx * self.ny
    }

    pub fn x(&self, i: usize) -> f64 {
        self.origin[0] + (i as f64 + 0.5) * self.spacing
    }

    pub fn y(&self, j: usize) -> f64 {
        self.origin[1] + (j as f64 + 0.5) * self.spacing
    }

    /// The cell area each ray stands for, mm².
    pub fn cell_area(&self) -> f64 {
        self.spacing * self.spacing
    }

    /// The columns whose rays lie in `[low, high]` of x (`axis` 0) or y (1), empty when none.
    pub fn span(&self, axis: usize, low: f64, high: f64) -> std::ops::Range<usize> {
        let count = if axis == 0 { self.nx } else { self.ny };
        let first = ((low - self.origin[axis]) / self.spacing - 0.5).ceil().max(0.0);
        let last = ((high - self.origin[axis]) / self.spacing - 0.5).floor();
        if last.is_nan() || last < first {
            return 0..0;
        }
        (first as usize).min(count)..((last as usize).saturating_add(1)).min(count)
    }
}

/// Rows of rays in one strip: the unit a verification is split into for several workers, and
/// the grouping every sum over rays follows, so that a split cut adds the same numbers in the
/// same order as one process (docs/spec/verify.md §5).
pub(crate) const STRIP_ROWS: usize = 32;

impl Grid {
    /// The number of strips of [`STRIP_ROWS`] rows.
    pub fn strips(&self) -> usize {
        self.ny.div_ceil(STRIP_ROWS)
    }

    /// The rows of strips `strips`.
    pub fn strip_rows(&self, strips: std::ops::Range<usize>) -> std::ops::Range<usize> {
        (strips.start * STRIP_ROWS).min(self.ny)..(strips.end * STRIP_ROWS).min(self.ny)
    }
}

/// The material of a solid on the rows `rows` of the grid (all of them but in a part of a split
/// cut), ray `(i, j)` at `rays[(j − rows.start)·nx + i]`.
#[derive(Debug, Clone)]
pub(crate) struct Field {
    pub grid: Grid,
    pub rows: std::ops::Range<usize>,
    pub rays: Vec<Ray>,
}

impl Field {
    /// The field of `rays` over every row of `grid`.
    pub fn new(grid: Grid, rays: Vec<Ray>) -> Self {
        Self { grid, rows: 0..grid.ny, rays }
    }

    /// Where ray `(i, j)` is in `rays`.
    #[inline(always)]
    pub fn index(&self, i: usize, j: usize) -> usize {
        (j - self.rows.start) * self.grid.nx + i
    }

    /// The column and row of the ray at `index` in `rays`.
    pub fn ray_at(&self, index: usize) -> (usize, usize) {
        (index % self.grid.nx, self.rows.start + index / self.grid.nx)
    }

    /// `rows` within the field's.
    pub fn within(&self, rows: std::ops::Range<usize>) -> std::ops::Range<usize> {
        rows.start.max(self.rows.start)..rows.end.min(self.rows.end)
    }

    /// The strips the field's rows make up.
    pub fn strips(&self) -> std::ops::Range<usize> {
        self.rows.start / STRIP_ROWS..self.rows.end.div_ceil(STRIP_ROWS)
    }

    /// The total length of material on the rays of each of the field's strips, in order, each
    /// summed ray by ray in row order.
    pub fn strip_lengths(&self) -> Vec<f64> {
        self.strips()
            .map(|strip| {
                let rows = self.within(self.grid.strip_rows(strip..strip + 1));
                let rays = &self.rays[self.index(0, rows.start)..self.index(0, rows.end)];
                rays.iter().map(|ray| length(ray)).sum::<f64>()
            })
            .collect()
    }

    /// The total length of material on every ray times the cell area, mm³: [`volume`] of its
    /// [`Field::strip_lengths`].
    #[cfg(test)]
    pub fn volume(&self) -> f64 {
        volume(&self.strip_lengths(), self.grid.cell_area())
    }
}

/// The volume of strips holding `lengths` of material on their rays of `area` each: their sum in
/// strip order times the area.
pub(crate) fn volume(lengths: &[f64], area: f64) -> f64 {
    lengths.iter().fold(0.0, |sum, length| sum + length) * area
}

/// Rays on a side of a tile of [`Tops`].
const TILE: usize = 32;

/// An upper bound of the highest material over square tiles of the grid's rays: a body whose
/// lowest point over a tile is at or above it cannot meet anything there, so its rays are not
/// visited. Material is only ever removed, so a bound once true stays true; a tile whose rays
/// were cut is marked and its bound is tightened (rescanned) only when a check needs it.
#[derive(Debug, Clone)]
pub(crate) struct Tops {
    columns: usize,
    bounds: Vec<f64>,
    stale: Vec<bool>,
}

impl Tops {
    pub fn new(field: &Field) -> Self {
        let grid = field.grid;
        let (columns, rows) = (grid.nx.div_ceil(TILE), grid.ny.div_ceil(TILE));
        let mut tops =
            Self { columns, bounds: vec![f64::NEG_INFINITY; columns * rows], stale: vec![false; columns * rows] };
        for j in field.rows.clone() {
            for i in 0..grid.nx {
                let bound = &mut tops.bounds[(j / TILE) * columns + i / TILE];
                *bound = bound.max(top(&field.rays[field.index(i, j)]));
            }
        }
        tops
    }

    /// Marks the tile of ray `(i, j)` as cut.
    pub fn cut(&mut self, i: usize, j: usize) {
        self.stale[(j / TILE) * self.columns + i / TILE] = true;
    }

    /// Whether some ray of `columns` × `rows` (rows of the field) may hold material above
    /// `floor`: the tiles they cover are checked, stale ones rescanned.
    pub fn above(
        &mut self,
        field: &Field,
        columns: std::ops::Range<usize>,
        rows: std::ops::Range<usize>,
        floor: f64,
    ) -> bool {
        if columns.is_empty() || rows.is_empty() {
            return false;
        }
        let grid = field.grid;
        for tj in rows.start / TILE..=(rows.end - 1) / TILE {
            for ti in columns.start / TILE..=(columns.end - 1) / TILE {
                let tile = tj * self.columns + ti;
                if self.bounds[tile] <= floor {
                    continue;
                }
                if self.stale[tile] {
                    let mut bound = f64::NEG_INFINITY;
                    for j in field.within(tj * TILE..((tj + 1) * TILE).min(grid.ny)) {
                        for ray in
                            &field.rays[field.index(ti * TILE, j)..field.index(((ti + 1) * TILE).min(grid.nx), j)]
                        {
                            bound = bound.max(top(ray));
                        }
                    }
                    self.bounds[tile] = bound;
                    self.stale[tile] = false;
                    if bound <= floor {
                        continue;
                    }
                }
                return true;
            }
        }
        false
    }
}

/// The total length of the intervals of `ray`.
pub(crate) fn length(ray: &[Interval]) -> f64 {
    ray.iter().map(|[low, high]| high - low).sum()
}

/// The highest z of material on `ray`, −∞ when it is empty.
pub(crate) fn top(ray: &[Interval]) -> f64 {
    ray.last().map_or(f64::NEG_INFINITY, |interval| interval[1])
}

/// Removes `cut` from `ray`, pushing each removed piece to `removed`.
pub(crate) fn subtract(ray: &mut Ray, cut: Interval, removed: &mut Vec<Interval>) {
    let [low, high] = cut;
    if low.partial_cmp(&high) != Some(std::cmp::Ordering::Less)
        || ray.last().is_none_or(|last| last[1] <= low)
        || ray[0][0] >= high
    {
        return;
    }
    let mut kept = Ray::new();
    for &[a, b] in ray.iter() {
        if b <= low || a >= high {
            kept.push([a, b]);
            continue;
        }
        removed.push([a.max(low), b.min(high)]);
        if a < low {
            kept.push([a, low]);
        }
        if b > high {
            kept.push([high, b]);
        }
    }
    *ray = kept;
}

/// The length of `probe` inside the intervals of `ray`, and the lowest z of that overlap.
pub(crate) fn overlap(ray: &[Interval], probe: Interval) -> Option<(f64, f64)> {
    let mut total = 0.0;
    let mut lowest = f64::INFINITY;
    for &[a, b] in ray {
        let (from, to) = (a.max(probe[0]), b.min(probe[1]));
        if to > from {
            total += to - from;
            lowest = lowest.min(from);
        }
    }
    (total > 0.0).then_some((total, lowest))
}

/// The pieces of `ray` outside the intervals of `other` grown by `margin` at both ends.
pub(crate) fn outside(ray: &[Interval], other: &[Interval], margin: f64, pieces: &mut Vec<Interval>) {
    for &interval in ray {
        let mut rest: Ray = smallvec::smallvec![interval];
        for &[a, b] in other {
            let mut scratch = Vec::new();
            subtract(&mut rest, [a - margin, b + margin], &mut scratch);
        }
        pieces.extend(rest);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn subtract_splits_and_reports() {
        let mut ray: Ray = smallvec::smallvec![[0.0, 10.0], [20.0, 30.0]];
        let mut removed = Vec::new();
        subtract(&mut ray, [5.0, 25.0], &mut removed);
        assert_eq!(ray.as_slice(), &[[0.0, 5.0], [25.0, 30.0]]);
        assert_eq!(removed, vec![[5.0, 10.0], [20.0, 25.0]]);
        removed.clear();
        subtract(&mut ray, [1.0, 2.0], &mut removed);
        assert_eq!(ray.as_slice(), &[[0.0, 1.0], [2.0, 5.0], [25.0, 30.0]]);
        assert_eq!(length(&ray), 9.0);
        assert_eq!(overlap(&ray, [0.5, 3.0]), Some((1.5, 0.5)));
        let mut pieces = Vec::new();
        outside(&ray, &[[0.0, 4.0]], 0.5, &mut pieces);
        assert_eq!(pieces, vec![[4.5, 5.0], [25.0, 30.0]]);
    }

    #[test]
    fn spans_cover_the_rays_in_range() {
        let grid = Grid::covering([0.0, 0.0], [10.0, 5.0], 1.0);
        assert_eq!((grid.nx, grid.ny), (10, 5));
        assert_eq!(grid.span(0, 0.4, 2.6), 0..3);
        assert!(grid.span(0, 0.6, 1.4).is_empty());
        assert_eq!(grid.span(1, -5.0, 100.0), 0..5);
        assert_eq!(grid.span(0, 20.0, 30.0), 10..10);
    }
}
