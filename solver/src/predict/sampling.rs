//! The resolution-free surface-sampling method (docs/spec/predict.md §6.6): a point q of M
//! survives iff it is in W and hidden by neither T1 nor T2; the generation point is the
//! area-weighted mean of the surviving surface, projected radially onto M.
//!
//! M is parametrised by sphere zones about an axis ŵ (the feed direction): a = (q − O)·ŵ and
//! the angle α around ŵ. In these coordinates the area element is exactly R·dα·da (Archimedes),
//! so uniform samples carry equal weights and the tip needs no special care. When the path runs
//! straight through the gap [s₀ − g, s₀ + g], the balls at both gap ends hide everything with
//! |a| ≥ g/2, so only that band is sampled; otherwise the whole zone range is.
//!
//! Rows (fixed a) are sampled at spacing Δ (the pixel size 2R/N) along α, then every run of
//! surviving samples has both ends located by bisection to Δ/256, and each row's run is
//! integrated in closed form. Runs overlapping in α on neighbouring rows form one region; the
//! largest region is the representative one (§5 E8).

use super::scene::{SampleState, Scene, TileLists};
use crate::geometry::Vec3;
use crate::stock::{Region, StockModel};

/// Samples per α tile. (Tile and block sizes only trade candidate-list work against point-test
/// work: the lists are conservative, so the answer does not depend on them. 16 × 8 did the least
/// of both on the bench's raster, where a straight pass has 8 rows: one block.)
const TILE: usize = 16;
/// Rows per tile block.
const ROW_BLOCK: usize = 8;
/// Bisection steps at each run end.
const BISECTIONS: u32 = 8;
/// Fewest rows across the band.
const MIN_ROWS: usize = 8;

/// Where and how to sample.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Band {
    /// Zone axis ŵ (unit).
    pub(crate) axis: Vec3,
    /// Range of a = (q − O)·ŵ, mm.
    pub(crate) a_lo: f64,
    pub(crate) a_hi: f64,
    /// Row spacing upper bound, mm.
    pub(crate) row_spacing: f64,
    /// Sample spacing along α, mm.
    pub(crate) spacing: f64,
}

/// The finished surface found by sampling.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Surface {
    /// Generation point C (world), if any surface survives.
    pub(crate) point: Option<Vec3>,
    /// Samples in the cutting region K (strict), in the band.
    pub(crate) cut_samples: usize,
    /// Surviving samples.
    pub(crate) finished_samples: usize,
    /// Area of the representative region, mm².
    pub(crate) area: f64,
    /// Number of disjoint regions.
    pub(crate) regions: usize,
    /// Some sample was hidden by T1 only through a tie (retraced pass, §5 E11).
    pub(crate) retraced: bool,
}

/// A run of surviving samples on one row, with refined ends.
#[derive(Debug, Clone, Copy)]
struct Run {
    row: usize,
    start: f64,
    end: f64,
}

/// A tile of samples: its box (frame), place relative to the stock, and its members (the range
/// of samples on each row of the block).
struct TileBox {
    lo: Vec3,
    hi: Vec3,
    region: Region,
    members: [(usize, usize); ROW_BLOCK],
}

/// One row of the band.
#[derive(Debug, Clone, Copy)]
struct Row {
    a: f64,
    rho: f64,
    alpha_lo: f64,
    step: f64,
    count: usize,
    full_circle: bool,
}

impl Row {
    /// α of sample `i`, at the middle of its step.
    fn alpha(&self, i: usize) -> f64 {
        self.alpha_lo + (i as f64 + 0.5) * self.step
    }
}

/// The zone frame: ŵ, the lowest direction d0 normal to it and d1 = ŵ × d0.
#[derive(Debug, Clone, Copy)]
struct Zone {
    w: Vec3,
    d0: Vec3,
    d1: Vec3,
    /// sin of ŵ's angle from the vertical.
    tilt: f64,
}

impl Zone {
    /// The frame about `w` (unit).
    fn new(w: Vec3) -> Self {
        // d0: the lowest direction in the plane normal to ŵ; d1 completes the frame.
        let down = Vec3::new(0.0, 0.0, -1.0);
        let mut d0 = down - down.dot(&w) * w;
        if d0.norm() < 1e-9 {
            d0 = Vec3::x() - w.x * w;
        }
        let d0 = d0.normalize();
        let d1 = w.cross(&d0);
        let tilt = (1.0 - w.z * w.z).max(0.0).sqrt();
        Self { w, d0, d1, tilt }
    }

    /// The point of M (relative to the ball centre) at α on `row`.
    fn point(&self, row: &Row, alpha: f64) -> Vec3 {
        row.a * self.w + row.rho * (alpha.cos() * self.d0 + alpha.sin() * self.d1)
    }
}

/// Sample counts over the whole band.
#[derive(Debug, Default)]
struct Tally {
    cut_samples: usize,
    finished_samples: usize,
    retraced: bool,
}

/// Samples the band around the ball centre of `scene` (whose frame must be the machine frame).
pub(crate) fn sample(scene: &Scene, stock: &StockModel, band: &Band) -> Surface {
    let radius = scene.radius;
    let zone = Zone::new(band.axis);
    let a_lo = band.a_lo.max(-radius);
    let a_hi = band.a_hi.min(radius);
    let span = a_hi - a_lo;
    let empty = Surface { point: None, cut_samples: 0, finished_samples: 0, area: 0.0, regions: 0, retraced: false };
    if span <= 0.0 {
        return empty;
    }
    let row_count = ((span / band.row_spacing).ceil() as usize).max(MIN_ROWS);
    let row_height = span / row_count as f64;
    let rows: Vec<Row> =
        (0..row_count).map(|j| row(&zone, band, radius, a_lo + (j as f64 + 0.5) * row_height)).collect();

    let mut runs: Vec<Run> = Vec::new();
    let mut tally = Tally::default();
    let sampler = Sampler { scene, stock, band, zone };
    for block_start in (0..rows.len()).step_by(ROW_BLOCK) {
        let block = &rows[block_start..(block_start + ROW_BLOCK).min(rows.len())];
        sampler.sample_block(block, block_start, &mut tally, &mut runs);
    }
    let Tally { cut_samples, finished_samples, retraced } = tally;
    if runs.is_empty() {
        return Surface { cut_samples, retraced, ..empty };
    }
    let (area, mean, regions) = largest_region(&runs, &rows, &zone, radius * row_height);
    let point = if mean.norm() > 1e-12 * radius {
        Some(scene.centre + radius * mean.normalize())
    } else {
        Some(scene.centre - radius * Vec3::z())
    };
    Surface { point, cut_samples, finished_samples, area, regions, retraced }
}

/// The row at zone height `a`: its α range on the lower hemisphere and its samples there.
fn row(zone: &Zone, band: &Band, radius: f64, a: f64) -> Row {
    let (w, tilt) = (zone.w, zone.tilt);
    let rho = (radius * radius - a * a).max(0.0).sqrt();
    // Lower hemisphere: a·w_z − ρ·tilt·cos α ≤ 0.
    let (lo, hi, full) = if tilt < 1e-12 || rho <= 0.0 {
        if a * w.z <= 0.0 { (-std::f64::consts::PI, std::f64::consts::PI, true) } else { (0.0, 0.0, false) }
    } else {
        let c = a * w.z / (rho * tilt);
        if c > 1.0 {
            (0.0, 0.0, false)
        } else if c < -1.0 {
            (-std::f64::consts::PI, std::f64::consts::PI, true)
        } else {
            let limit = c.acos();
            (-limit, limit, false)
        }
    };
    let count = if hi > lo && rho > 0.0 { ((hi - lo) * rho / band.spacing).ceil().max(1.0) as usize } else { 0 };
    Row { a, rho, alpha_lo: lo, step: if count > 0 { (hi - lo) / count as f64 } else { 0.0 }, count, full_circle: full }
}

/// What the samples of one band are tested against, and where they are.
struct Sampler<'a> {
    scene: &'a Scene,
    stock: &'a StockModel,
    band: &'a Band,
    zone: Zone,
}

impl Sampler<'_> {
    /// Tests the samples of one block of rows tile by tile, counting them in `tally`, and adds the
    /// block's runs of finished samples, their ends refined, to `runs`.
    fn sample_block(&self, block: &[Row], block_start: usize, tally: &mut Tally, runs: &mut Vec<Run>) {
        let Self { scene, stock, zone, .. } = self;
        // Tiles: the same α window across the block's rows.
        let alpha_min = block.iter().map(|r| r.alpha_lo).fold(f64::INFINITY, f64::min);
        let alpha_max = block.iter().map(|r| r.alpha_lo + r.step * r.count as f64).fold(f64::NEG_INFINITY, f64::max);
        let step_min = block.iter().filter(|r| r.count > 0).map(|r| r.step).fold(f64::INFINITY, f64::min);
        if !step_min.is_finite() || alpha_max <= alpha_min {
            return;
        }
        let tile_width = step_min * TILE as f64;
        let tile_count = ((alpha_max - alpha_min) / tile_width).ceil().max(1.0) as usize;
        let mut row_states: Vec<Vec<SampleState>> = block.iter().map(|r| vec![SampleState::Air; r.count]).collect();
        let mut tile_of: Vec<Vec<usize>> = block.iter().map(|r| vec![0; r.count]).collect();
        let (boxes, union_lo, union_hi) = self.tile_boxes(block, alpha_min, tile_width, tile_count);
        let mut pool = TileLists::default();
        if union_lo.x.is_finite() {
            scene.candidates(&union_lo, &union_hi, true, None, &mut pool);
        }
        let mut tile_lists: Vec<TileLists> = Vec::with_capacity(tile_count);
        let mut hide_hint = 0usize;
        for (tile, entry) in boxes.into_iter().enumerate() {
            let Some(TileBox { lo, hi, region, members }) = entry else {
                tile_lists.push(TileLists::default());
                continue;
            };
            let mut lists = TileLists::default();
            scene.candidates(&lo, &hi, true, Some(&pool), &mut lists);
            lists.region = Some(region);
            // A tile that one T1 capsule hides whole has no cut or finished sample: every sample
            // would test CutBefore (or Air outside the stock), which the rest treats alike.
            let hidden = scene.hides_box(&lo, &hi, &lists.before, &mut hide_hint);
            let mut hints = [0usize; 2];
            for (r, (row, &(first, last))) in block.iter().zip(&members).enumerate() {
                for i in first..last {
                    tile_of[r][i] = tile;
                    if hidden {
                        row_states[r][i] = SampleState::CutBefore;
                        continue;
                    }
                    let test = scene.test(stock, &lists, &zone.point(row, row.alpha(i)), &mut hints);
                    row_states[r][i] = test.state;
                    if test.cut {
                        tally.cut_samples += 1;
                    }
                    if test.state == SampleState::Finished {
                        tally.finished_samples += 1;
                        if !test.cut {
                            tally.retraced = true;
                        }
                    }
                }
            }
            tile_lists.push(lists);
        }
        for (r, row) in block.iter().enumerate() {
            let states = &row_states[r];
            let row_index = block_start + r;
            let mut i = 0;
            while i < row.count {
                if states[i] != SampleState::Finished {
                    i += 1;
                    continue;
                }
                let first = i;
                while i < row.count && states[i] == SampleState::Finished {
                    i += 1;
                }
                let last = i - 1;
                let refine = |inside: usize, outside_alpha: f64| -> f64 {
                    let lists = &tile_lists[tile_of[r][inside]];
                    let mut hints = [0usize; 2];
                    let (mut good, mut bad) = (row.alpha(inside), outside_alpha);
                    for _ in 0..BISECTIONS {
                        let mid = 0.5 * (good + bad);
                        let q = zone.point(row, mid);
                        if scene.test(stock, lists, &q, &mut hints).state == SampleState::Finished {
                            good = mid;
                        } else {
                            bad = mid;
                        }
                    }
                    0.5 * (good + bad)
                };
                let start = if first == 0 { row.alpha_lo } else { refine(first, row.alpha(first - 1)) };
                let end = if last + 1 == row.count {
                    row.alpha_lo + row.step * row.count as f64
                } else {
                    refine(last, row.alpha(last + 1))
                };
                runs.push(Run { row: row_index, start, end });
            }
        }
    }

    /// The boxes of a block's tiles that may hold cut samples (`None` for the others), with their
    /// place relative to the stock, and the box around all of them.
    ///
    /// A box needs only each row's first and last sample: the samples between lie on the arc
    /// joining them, within its sagitta of their chord. The samples themselves are computed only in
    /// the tiles that are tested.
    fn tile_boxes(
        &self,
        block: &[Row],
        alpha_min: f64,
        tile_width: f64,
        tile_count: usize,
    ) -> (Vec<Option<TileBox>>, Vec3, Vec3) {
        let Self { scene, stock, band, zone } = self;
        let mut boxes: Vec<Option<TileBox>> = Vec::with_capacity(tile_count);
        let mut union_lo = Vec3::repeat(f64::INFINITY);
        let mut union_hi = Vec3::repeat(f64::NEG_INFINITY);
        for tile in 0..tile_count {
            let (t_lo, t_hi) = (alpha_min + tile as f64 * tile_width, alpha_min + (tile + 1) as f64 * tile_width);
            let mut lo = Vec3::repeat(f64::INFINITY);
            let mut hi = Vec3::repeat(f64::NEG_INFINITY);
            let mut members = [(0, 0); ROW_BLOCK];
            for (r, row) in block.iter().enumerate() {
                if row.count == 0 {
                    continue;
                }
                let first = (((t_lo - row.alpha_lo) / row.step).ceil().max(0.0)) as usize;
                let last = (((t_hi - row.alpha_lo) / row.step).ceil().max(0.0) as usize).min(row.count);
                if first >= last {
                    continue;
                }
                members[r] = (first, last);
                let (alpha_first, alpha_last) = (row.alpha(first), row.alpha(last - 1));
                let sagitta = Vec3::repeat(row.rho * (1.0 - (0.5 * (alpha_last - alpha_first)).cos()));
                let (p, q) = (zone.point(row, alpha_first), zone.point(row, alpha_last));
                lo = lo.inf(&(p.inf(&q) - sagitta));
                hi = hi.sup(&(p.sup(&q) + sagitta));
            }
            // Bisection points lie within one step of a sample.
            let margin = Vec3::repeat(band.spacing * 1.01 + scene.eps);
            let (lo, hi) = (lo - margin, hi + margin);
            if members.iter().all(|(first, last)| first == last) || lo.z > 0.0 {
                boxes.push(None);
                continue;
            }
            let region = scene.region(stock, &lo, &hi);
            if region == Region::Outside {
                boxes.push(None);
                continue;
            }
            union_lo = union_lo.inf(&lo);
            union_hi = union_hi.sup(&hi);
            boxes.push(Some(TileBox { lo, hi, region, members }));
        }
        (boxes, union_lo, union_hi)
    }
}

/// Joins the runs into regions (runs overlapping in α on neighbouring rows, and across ±π on
/// full rows) and integrates each in closed form, each run's row weighing `weight` (R × row
/// height). Returns the largest region's area and area-weighted mean point (relative to the
/// ball centre), and the number of regions.
fn largest_region(runs: &[Run], rows: &[Row], zone: &Zone, weight: f64) -> (f64, Vec3, usize) {
    let (w, d0, d1) = (zone.w, zone.d0, zone.d1);
    let mut parent: Vec<usize> = (0..runs.len()).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    let union = |parent: &mut Vec<usize>, x: usize, y: usize| {
        let (rx, ry) = (find(parent, x), find(parent, y));
        if rx != ry {
            parent[rx.max(ry)] = rx.min(ry);
        }
    };
    let pi = std::f64::consts::PI;
    for i in 0..runs.len() {
        for j in i + 1..runs.len() {
            let (p, q) = (runs[i], runs[j]);
            if q.row > p.row + 1 {
                break;
            }
            let same_row_wrap = q.row == p.row
                && rows[p.row].full_circle
                && ((p.start <= -pi + 1e-12 && q.end >= pi - 1e-12) || (q.start <= -pi + 1e-12 && p.end >= pi - 1e-12));
            let neighbours = q.row == p.row + 1 && p.start < q.end && q.start < p.end;
            if same_row_wrap || neighbours {
                union(&mut parent, i, j);
            }
        }
    }
    let mut area_of: Vec<f64> = vec![0.0; runs.len()];
    let mut sum_of: Vec<Vec3> = vec![Vec3::zeros(); runs.len()];
    for (index, run) in runs.iter().enumerate() {
        let row = &rows[run.row];
        let root = find(&mut parent, index);
        let width = run.end - run.start;
        area_of[root] += weight * width;
        sum_of[root] += weight
            * (width * row.a * w
                + row.rho * ((run.end.sin() - run.start.sin()) * d0 + (run.start.cos() - run.end.cos()) * d1));
    }
    let regions = (0..runs.len()).filter(|&i| find(&mut parent, i) == i).count();
    let best = (0..runs.len())
        .filter(|&i| parent[i] == i)
        .max_by(|&x, &y| area_of[x].total_cmp(&area_of[y]).then(y.cmp(&x)))
        .unwrap_or(0);
    let area = area_of[best];
    let mean = sum_of[best] / area.max(f64::MIN_POSITIVE);
    (area, mean, regions)
}
