//! The software depth buffer (docs/spec/predict.md §3.5, §3.6, §3.9–3.11, §6.2): an orthographic
//! N × N view of the lower hemisphere M, the swept volumes and the stock along v̂, evaluated
//! analytically per pixel. From below (v̂ = +Z) or from a rotated or zoomed view (§3.10).
//!
//! The image is processed in 16 × 16 pixel tiles; a tile whose box misses the stock, lies off the
//! disc of M or above the ball centre is skipped whole, and the capsule candidates are pruned per
//! tile, so only the pixels where M is in the material pay for capsule tests.

use std::collections::HashMap;

use super::scene::{SampleState, Scene, TileLists};
use crate::geometry::Vec3;
use crate::stock::{Region, StockModel};

/// Pixels per tile side.
const TILE: usize = 16;
/// Tiles per group side (groups share a candidate pool).
const GROUP: usize = 4;
/// Pixels per side of the blocks a tile crossed by the stock's surface is placed by.
const BLOCK: usize = 8;

/// The window: square of side `window` in the image plane of the scene's frame, centred at
/// `centre` (image-plane coordinates relative to the ball centre), N × N pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Window {
    pub(crate) centre: [f64; 2],
    pub(crate) side: f64,
    pub(crate) pixels: usize,
    /// Weight pixels by 1/|n·v̂| (their true area) for the centroid.
    pub(crate) area_weighted: bool,
}

/// What one rendering shows.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Image {
    /// Pixels of the cutting region K.
    pub(crate) cut_pixels: usize,
    /// Pixels of the finished region S (all regions).
    pub(crate) finished_pixels: usize,
    /// Disjoint regions of S.
    pub(crate) regions: usize,
    /// Some pixel of S lies in the outermost ring of M's disc (§5 E5).
    pub(crate) rim: bool,
    /// Generation point C (world) of the largest region of S.
    pub(crate) point: Option<Vec3>,
    /// Distance of the centroid from the view axis through O, mm (for the tip test, §5 E7).
    pub(crate) centroid_offset: f64,
    /// Pixel size, mm.
    pub(crate) pixel: f64,
    /// Sum over K of −ê_r (world), for the rotated view direction (§3.10 a).
    pub(crate) cut_inward: Vec3,
    /// Image-plane bounding box of K: [x_lo, y_lo, x_hi, y_hi].
    pub(crate) cut_box: Option<[f64; 4]>,
    /// Some surviving pixel was hidden by T1 only through a tie (§5 E11).
    pub(crate) retraced: bool,
}

/// A pixel of S: its indices, image-plane coordinates and centroid weight.
#[derive(Debug, Clone, Copy)]
struct Finished {
    i: usize,
    j: usize,
    x: f64,
    y: f64,
    weight: f64,
}

/// A tile of the image kept for testing: its pixel columns `i0..i1` and rows `j0..j1`, its place
/// relative to the stock and its frame box.
#[derive(Debug, Clone, Copy)]
struct KeptTile {
    i0: usize,
    i1: usize,
    j0: usize,
    j1: usize,
    region: Region,
    lo: Vec3,
    hi: Vec3,
}

/// One rendering's scene, stock and window, with the pixel size.
struct Renderer<'a> {
    scene: &'a Scene,
    stock: &'a StockModel,
    window: &'a Window,
    pixel: f64,
}

impl Renderer<'_> {
    /// Image-plane coordinate of the centre of pixel `k` on the axis whose window centre is `c`.
    fn coordinate(&self, k: usize, c: f64) -> f64 {
        c + (k as f64 + 0.5 - self.window.pixels as f64 / 2.0) * self.pixel
    }

    /// The frame box of M over the pixels i0..i1 × j0..j1, if any of them is on its disc.
    fn pixel_box(&self, (i0, i1): (usize, usize), (j0, j1): (usize, usize)) -> Option<(Vec3, Vec3)> {
        let (scene, window) = (self.scene, self.window);
        let (radius, r2) = (scene.radius, scene.r2);
        let (x_lo, x_hi) = (self.coordinate(i0, window.centre[0]), self.coordinate(i1 - 1, window.centre[0]));
        let (y_lo, y_hi) = (self.coordinate(j0, window.centre[1]), self.coordinate(j1 - 1, window.centre[1]));
        let nearest_x = 0.0_f64.clamp(x_lo, x_hi);
        let nearest_y = 0.0_f64.clamp(y_lo, y_hi);
        let rho_min = nearest_x.hypot(nearest_y);
        if rho_min > radius {
            return None;
        }
        let rho_max = (x_lo.abs().max(x_hi.abs())).hypot(y_lo.abs().max(y_hi.abs())).min(radius);
        let lo = Vec3::new(x_lo, y_lo, -(r2 - rho_min * rho_min).max(0.0).sqrt()) - Vec3::repeat(scene.eps);
        let hi = Vec3::new(x_hi, y_hi, -(r2 - rho_max * rho_max).max(0.0).sqrt()) + Vec3::repeat(scene.eps);
        Some((lo, hi))
    }

    /// The tiles on M's disc, below the ball centre and meeting the stock, in row-major order,
    /// and the box around all of them (empty when there are none).
    fn kept_tiles(&self, tiles: usize) -> (Vec<KeptTile>, Vec3, Vec3) {
        let (scene, n) = (self.scene, self.window.pixels);
        let mut kept: Vec<KeptTile> = Vec::new();
        let mut union_lo = Vec3::repeat(f64::INFINITY);
        let mut union_hi = Vec3::repeat(f64::NEG_INFINITY);
        for tile_j in 0..tiles {
            for tile_i in 0..tiles {
                let (i0, i1) = (tile_i * TILE, ((tile_i + 1) * TILE).min(n));
                let (j0, j1) = (tile_j * TILE, ((tile_j + 1) * TILE).min(n));
                let Some((lo, hi)) = self.pixel_box((i0, i1), (j0, j1)) else {
                    continue;
                };
                let (world_lo, _) = scene.world_box(&lo, &hi);
                if world_lo.z > scene.centre.z {
                    continue;
                }
                let region = scene.region(self.stock, &lo, &hi);
                if region == Region::Outside {
                    continue;
                }
                union_lo = union_lo.inf(&lo);
                union_hi = union_hi.sup(&hi);
                kept.push(KeptTile { i0, i1, j0, j1, region, lo, hi });
            }
        }
        (kept, union_lo, union_hi)
    }

    /// Where the stock's surface crosses a tile, its BLOCK × BLOCK blocks one by one: those one
    /// T1 capsule hides whole are skipped (their pixels would all be cut before), and only the
    /// pixels of blocks the surface crosses pay for the point-in-stock test. `None`: no pixel of
    /// the block needs a test.
    fn block_regions(
        &self,
        tile: &KeptTile,
        lists: &TileLists,
        hide_hint: &mut usize,
    ) -> [[Option<Region>; TILE / BLOCK]; TILE / BLOCK] {
        let KeptTile { i0, i1, j0, j1, region, .. } = *tile;
        let scene = self.scene;
        let mut block_regions = [[None; TILE / BLOCK]; TILE / BLOCK];
        for (b_j, regions) in block_regions.iter_mut().enumerate() {
            for (b_i, block_region) in regions.iter_mut().enumerate() {
                let (bi0, bj0) = (i0 + b_i * BLOCK, j0 + b_j * BLOCK);
                let columns = (bi0, (bi0 + BLOCK).min(i1));
                let rows = (bj0, (bj0 + BLOCK).min(j1));
                if columns.0 >= columns.1 || rows.0 >= rows.1 {
                    continue;
                }
                let Some((lo, hi)) = self.pixel_box(columns, rows) else {
                    continue;
                };
                let placed = if region == Region::Mixed { scene.region(self.stock, &lo, &hi) } else { region };
                if placed != Region::Outside && !scene.hides_box(&lo, &hi, &lists.before, hide_hint) {
                    *block_region = Some(placed);
                }
            }
        }
        block_regions
    }

    /// Tests the pixels of one tile against `lists`, adding the cut ones to `image` and the
    /// finished ones to `finished`.
    fn render_tile(
        &self,
        tile: &KeptTile,
        lists: &TileLists,
        hide_hint: &mut usize,
        image: &mut Image,
        finished: &mut Vec<Finished>,
    ) {
        let (scene, window) = (self.scene, self.window);
        let (radius, r2) = (scene.radius, scene.r2);
        let back = scene.rotation.transpose();
        let rim_radius = radius - self.pixel;
        let KeptTile { i0, i1, j0, j1, .. } = *tile;
        let block_regions = self.block_regions(tile, lists, hide_hint);
        let mut hints = [0usize; 2];
        for j in j0..j1 {
            let y = self.coordinate(j, window.centre[1]);
            for i in i0..i1 {
                let Some(block_region) = block_regions[(j - j0) / BLOCK][(i - i0) / BLOCK] else {
                    continue;
                };
                let x = self.coordinate(i, window.centre[0]);
                let rho2 = x * x + y * y;
                if rho2 > r2 {
                    continue;
                }
                let z = -(r2 - rho2).sqrt();
                let q = Vec3::new(x, y, z);
                let offset = back * q;
                // Only the lower hemisphere is M (§3.5).
                if offset.z > 0.0 {
                    continue;
                }
                let test = scene.test_in(self.stock, block_region, lists, &q, &mut hints);
                if test.cut {
                    image.cut_pixels += 1;
                    image.cut_inward -= offset / radius;
                    let b = image.cut_box.get_or_insert([x, y, x, y]);
                    *b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
                }
                if test.state == SampleState::Finished {
                    if !test.cut {
                        image.retraced = true;
                    }
                    if rho2.sqrt() > rim_radius {
                        image.rim = true;
                    }
                    let weight = if window.area_weighted { radius / (-z).max(1e-3 * radius) } else { 1.0 };
                    finished.push(Finished { i, j, x, y, weight });
                }
            }
        }
    }
}

/// Renders the scene through `window`.
pub(crate) fn render(scene: &Scene, stock: &StockModel, window: &Window) -> Image {
    let n = window.pixels;
    let pixel = window.side / n as f64;
    let r2 = scene.r2;
    let renderer = Renderer { scene, stock, window, pixel };
    let mut image = Image {
        cut_pixels: 0,
        finished_pixels: 0,
        regions: 0,
        rim: false,
        point: None,
        centroid_offset: 0.0,
        pixel,
        cut_inward: Vec3::zeros(),
        cut_box: None,
        retraced: false,
    };
    let mut finished: Vec<Finished> = Vec::new();
    // Tiles on M's disc, below the ball centre and meeting the stock; then the capsules near
    // all of them.
    let tiles = n.div_ceil(TILE);
    let (kept, union_lo, union_hi) = renderer.kept_tiles(tiles);
    let mut pool = TileLists::default();
    if !kept.is_empty() {
        scene.candidates(&union_lo, &union_hi, true, None, &mut pool);
    }
    // A middle level: GROUP × GROUP neighbouring tiles share a narrower pool (the tiles keep
    // their row-major order, which the sums and the region tie-break depend on).
    let groups = tiles.div_ceil(GROUP);
    let group_of = |i0: usize, j0: usize| (j0 / TILE / GROUP) * groups + i0 / TILE / GROUP;
    let mut group_boxes: Vec<Option<(Vec3, Vec3)>> = vec![None; groups * groups];
    for tile in &kept {
        let entry = group_boxes[group_of(tile.i0, tile.j0)].get_or_insert((tile.lo, tile.hi));
        *entry = (entry.0.inf(&tile.lo), entry.1.sup(&tile.hi));
    }
    let group_pools: Vec<TileLists> = group_boxes
        .iter()
        .map(|entry| {
            let mut lists = TileLists::default();
            if let Some((lo, hi)) = entry {
                scene.candidates(lo, hi, true, Some(&pool), &mut lists);
            }
            lists
        })
        .collect();
    let mut lists = TileLists::default();
    let mut hide_hint = 0usize;
    for tile in &kept {
        scene.candidates(&tile.lo, &tile.hi, true, Some(&group_pools[group_of(tile.i0, tile.j0)]), &mut lists);
        lists.region = Some(tile.region);
        // A tile that one T1 capsule hides whole has no cut or finished pixel.
        if scene.hides_box(&tile.lo, &tile.hi, &lists.before, &mut hide_hint) {
            continue;
        }
        renderer.render_tile(tile, &lists, &mut hide_hint, &mut image, &mut finished);
    }
    image.finished_pixels = finished.len();
    if finished.is_empty() {
        return image;
    }
    let (regions, x, y) = largest_region(&finished);
    image.regions = regions;
    let rho2 = (x * x + y * y).min(r2);
    let z = -(r2 - rho2).sqrt();
    image.centroid_offset = rho2.sqrt();
    image.point = Some(scene.world(&Vec3::new(x, y, z)));
    image
}

/// Regions of S: 4-connected pixel components; the largest is the representative (§5 E8).
/// Returns the number of regions and the weighted centroid of the largest in the image plane.
fn largest_region(finished: &[Finished]) -> (usize, f64, f64) {
    let index: HashMap<(usize, usize), usize> = finished.iter().enumerate().map(|(k, f)| ((f.i, f.j), k)).collect();
    let mut parent: Vec<usize> = (0..finished.len()).collect();
    fn find(parent: &mut [usize], mut x: usize) -> usize {
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }
    for (k, f) in finished.iter().enumerate() {
        for neighbour in [(f.i + 1, f.j), (f.i, f.j + 1)] {
            if let Some(&other) = index.get(&neighbour) {
                let (a, b) = (find(&mut parent, k), find(&mut parent, other));
                if a != b {
                    parent[a.max(b)] = a.min(b);
                }
            }
        }
    }
    let mut weight_of = vec![0.0; finished.len()];
    let mut count_of = vec![0usize; finished.len()];
    let mut sum_of = vec![[0.0; 2]; finished.len()];
    for (k, f) in finished.iter().enumerate() {
        let root = find(&mut parent, k);
        count_of[root] += 1;
        weight_of[root] += f.weight;
        sum_of[root][0] += f.weight * f.x;
        sum_of[root][1] += f.weight * f.y;
    }
    let regions = (0..finished.len()).filter(|&k| parent[k] == k).count();
    let best = (0..finished.len())
        .filter(|&k| parent[k] == k)
        .max_by(|&a, &b| count_of[a].cmp(&count_of[b]).then(b.cmp(&a)))
        .unwrap_or(0);
    (regions, sum_of[best][0] / weight_of[best], sum_of[best][1] / weight_of[best])
}
