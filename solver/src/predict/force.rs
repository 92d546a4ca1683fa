//! Engagement of the cutting edge and the mechanistic cutting force over one revolution
//! (docs/spec/predict.md §3.7, S3).
//!
//! The edge is discretised into N_θ elements (θ_k = (k + ½)Δθ) and the revolution into N_t
//! rotation steps. Flute j at contact angle θ sits at azimuth
//! φ_j(ψ, θ) = Φ₀ + s_rot·(ψ − ψ_lag(θ)) + 2πj/N_f, so every ring of elements visits the same N_t
//! azimuths; the engagement is tested once per (θ_k, azimuth) with the exact point test
//! (q ∈ W and q not hidden by T1, the reference of case D) and reused for all flutes and steps.
//! Only elements on the front of the ball (ê_r·û > 0) can cut (h = f_t·max(0, ê_r·û)); the
//! edge-force terms act only where h > 0. The force on the tool is
//! dF = −(dF_t ê_v + dF_r ê_r + dF_a ê_θ) with dF_· = (K_·c h + K_·e)·R·Δθ.

use serde::{Deserialize, Serialize};

use super::scene::{Cover, Scene, Side, TileLists};
use crate::error::SolverError;
use crate::geometry::Vec3;
use crate::stock::{Region, StockModel};
use crate::validate::finite;

/// Rings per engagement tile.
const TILE_RINGS: usize = 6;
/// Azimuth steps per engagement tile.
const TILE_STEPS: usize = 12;
/// Tiles per group (rings × steps) sharing a candidate pool.
const GROUP_RINGS: usize = 2;
const GROUP_STEPS: usize = 3;

/// Specific cutting forces of the tool/material pair (docs/spec/predict.md §1.2 I5, §3.7).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CuttingCoefficients {
    /// K_tc, tangential, N/mm².
    pub ktc: f64,
    /// K_rc, radial, N/mm².
    pub krc: f64,
    /// K_ac, axial, N/mm².
    pub kac: f64,
    /// K_te, tangential edge force, N/mm (default 0).
    #[serde(default)]
    pub kte: f64,
    /// K_re, radial edge force, N/mm (default 0).
    #[serde(default)]
    pub kre: f64,
    /// K_ae, axial edge force, N/mm (default 0).
    #[serde(default)]
    pub kae: f64,
}

impl CuttingCoefficients {
    /// Checks that every coefficient is finite, naming it under `field`.
    pub(crate) fn validate(&self, field: &str) -> Result<(), SolverError> {
        for (name, value) in [
            ("ktc", self.ktc),
            ("krc", self.krc),
            ("kac", self.kac),
            ("kte", self.kte),
            ("kre", self.kre),
            ("kae", self.kae),
        ] {
            finite(&format!("{field}.{name}"), value)?;
        }
        Ok(())
    }
}

/// One engagement tile: a block of rings × azimuth steps with the box of its unit vectors.
#[derive(Debug, Clone, Copy)]
struct Tile {
    rings: (usize, usize),
    steps: (usize, usize),
    lo: Vec3,
    hi: Vec3,
    /// Index of its group in [`EdgeGrid::group_boxes`].
    group: usize,
}

/// The edge discretisation for one spindle sense.
#[derive(Debug, Clone)]
pub(crate) struct EdgeGrid {
    pub(crate) rings: usize,
    pub(crate) steps: usize,
    pub(crate) flutes: usize,
    /// s_rot.
    sign: f64,
    /// Per ring: (sin θ, cos θ).
    ring_angle: Vec<(f64, f64)>,
    /// Per ring and step: (cos φ, sin φ).
    azimuth: Vec<(f64, f64)>,
    tiles: Vec<Tile>,
    /// Per group of GROUP_RINGS × GROUP_STEPS tiles, the box of its unit vectors: a group whose
    /// box misses the stock spares its tiles the classification.
    group_boxes: Vec<(Vec3, Vec3)>,
}

impl EdgeGrid {
    /// Builds the grid; `lag(θ)` is ψ_lag in radians, `flute_zero` is Φ₀.
    pub(crate) fn new(
        rings: usize,
        steps: usize,
        flutes: usize,
        sign: f64,
        flute_zero: f64,
        lag: impl Fn(f64) -> f64,
    ) -> Self {
        let d_theta = std::f64::consts::FRAC_PI_2 / rings as f64;
        let ring_angle: Vec<(f64, f64)> = (0..rings).map(|k| ((k as f64 + 0.5) * d_theta).sin_cos()).collect();
        let mut azimuth = Vec::with_capacity(rings * steps);
        for k in 0..rings {
            let theta = (k as f64 + 0.5) * d_theta;
            let base = flute_zero - sign * lag(theta);
            for i in 0..steps {
                let phi = base + sign * std::f64::consts::TAU * i as f64 / steps as f64;
                let (s, c) = phi.sin_cos();
                azimuth.push((c, s));
            }
        }
        let mut grid =
            Self { rings, steps, flutes, sign, ring_angle, azimuth, tiles: Vec::new(), group_boxes: Vec::new() };
        let group_columns = steps.div_ceil(GROUP_STEPS * TILE_STEPS);
        let group_count = rings.div_ceil(GROUP_RINGS * TILE_RINGS) * group_columns;
        grid.group_boxes = vec![(Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)); group_count];
        for k0 in (0..rings).step_by(TILE_RINGS) {
            for i0 in (0..steps).step_by(TILE_STEPS) {
                let rings = (k0, (k0 + TILE_RINGS).min(grid.rings));
                let steps = (i0, (i0 + TILE_STEPS).min(grid.steps));
                let mut lo = Vec3::repeat(f64::INFINITY);
                let mut hi = Vec3::repeat(f64::NEG_INFINITY);
                for k in rings.0..rings.1 {
                    for i in steps.0..steps.1 {
                        let u = grid.unit(k, i);
                        lo = lo.inf(&u);
                        hi = hi.sup(&u);
                    }
                }
                let group = k0 / (GROUP_RINGS * TILE_RINGS) * group_columns + i0 / (GROUP_STEPS * TILE_STEPS);
                let group_box = &mut grid.group_boxes[group];
                *group_box = (group_box.0.inf(&lo), group_box.1.sup(&hi));
                grid.tiles.push(Tile { rings, steps, lo, hi, group });
            }
        }
        grid
    }

    /// ê_r of element (k, i).
    #[inline]
    fn unit(&self, k: usize, i: usize) -> Vec3 {
        let (s, c) = self.ring_angle[k];
        let (cp, sp) = self.azimuth[k * self.steps + i];
        Vec3::new(s * cp, s * sp, -c)
    }
}

/// The engagement at one position and the resulting force history.
#[derive(Debug, Clone, Default)]
pub(crate) struct Engagement {
    /// Engaged elements (in W, not hidden by T1, on the front).
    pub(crate) cut_elements: usize,
    /// F(ψ_m) on the tool, N; empty without coefficients.
    pub(crate) force: Vec<[f64; 3]>,
}

/// Tests every front element against W and T1 and, with coefficients, sums the forces.
/// `scene` must use the machine frame.
pub(crate) fn engage(
    grid: &EdgeGrid,
    scene: &Scene,
    stock: &StockModel,
    feed_direction: &Vec3,
    tooth_feed: f64,
    coefficients: Option<&CuttingCoefficients>,
) -> Engagement {
    let radius = scene.radius;
    let mut engagement = Engagement {
        cut_elements: 0,
        force: if coefficients.is_some() { vec![[0.0; 3]; grid.steps] } else { Vec::new() },
    };
    let d_theta = std::f64::consts::FRAC_PI_2 / grid.rings as f64;
    let engager = Engager {
        grid,
        scene,
        stock,
        u: feed_direction,
        tooth_feed,
        coefficients,
        width: radius * d_theta,
        flute_shift: grid.steps / grid.flutes,
    };
    // Tiles on the front of the ball that meet the stock, then the capsules near all of them.
    let (mut kept, union_lo, union_hi) = engager.kept_tiles();
    if kept.is_empty() {
        return engagement;
    }
    let mut pool = TileLists::default();
    scene.candidates(&union_lo, &union_hi, false, None, &mut pool);
    // A middle level: groups of neighbouring tiles share a narrower pool.
    let mut groups: std::collections::BTreeMap<(usize, usize), (Vec3, Vec3)> = std::collections::BTreeMap::new();
    for (tile, _, lo, hi) in &kept {
        let entry =
            groups.entry(group_of(tile)).or_insert((Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)));
        entry.0 = entry.0.inf(lo);
        entry.1 = entry.1.sup(hi);
    }
    kept.sort_by_key(|(tile, ..)| group_of(tile));
    let mut group_pool = TileLists::default();
    let mut current_group = None;
    let mut lists = TileLists::default();
    let mut hide_hint = 0usize;
    for (tile, region, lo, hi) in kept {
        let key = group_of(tile);
        if current_group != Some(key) {
            let (group_lo, group_hi) = groups[&key];
            scene.candidates(&group_lo, &group_hi, false, Some(&pool), &mut group_pool);
            current_group = Some(key);
        }
        scene.candidates(&lo, &hi, false, Some(&group_pool), &mut lists);
        // A tile that one T1 capsule hides whole engages nothing (the same answer as testing each
        // element, without the stock and capsule tests).
        if scene.hides_box(&lo, &hi, &lists.before, &mut hide_hint) {
            continue;
        }
        engager.engage_tile(tile, region, &lists, &mut engagement);
    }
    engagement
}

/// The group of neighbouring tiles `tile` belongs to (groups share a candidate pool).
fn group_of(tile: &Tile) -> (usize, usize) {
    (tile.rings.0 / (GROUP_RINGS * TILE_RINGS), tile.steps.0 / (GROUP_STEPS * TILE_STEPS))
}

/// A tile kept for testing: its place relative to the stock and its box (machine frame,
/// relative to the ball centre).
type KeptTile<'a> = (&'a Tile, Region, Vec3, Vec3);

/// What one engagement tests the cutting edge against, and the force model's constants.
struct Engager<'a> {
    grid: &'a EdgeGrid,
    scene: &'a Scene,
    stock: &'a StockModel,
    /// Feed direction û.
    u: &'a Vec3,
    tooth_feed: f64,
    coefficients: Option<&'a CuttingCoefficients>,
    /// Edge element width R·Δθ, mm.
    width: f64,
    /// ψ steps between neighbouring flutes.
    flute_shift: usize,
}

impl<'a> Engager<'a> {
    /// The tiles on the front of the ball (ê_r·û > 0 somewhere) that meet the stock, in grid
    /// order, and the box around all of them.
    fn kept_tiles(&self) -> (Vec<KeptTile<'a>>, Vec3, Vec3) {
        let (grid, scene, stock, u) = (self.grid, self.scene, self.stock, self.u);
        let radius = scene.radius;
        let mut kept: Vec<KeptTile<'a>> = Vec::new();
        let mut union_lo = Vec3::repeat(f64::INFINITY);
        let mut union_hi = Vec3::repeat(f64::NEG_INFINITY);
        let mut group_outside: Vec<Option<bool>> = vec![None; grid.group_boxes.len()];
        for tile in &grid.tiles {
            // Upper bound of ê_r·û over the tile.
            let front: f64 = (0..3).map(|c| (u[c] * tile.lo[c]).max(u[c] * tile.hi[c])).sum();
            if front <= 0.0 {
                continue;
            }
            let outside = *group_outside[tile.group].get_or_insert_with(|| {
                let (lo, hi) = grid.group_boxes[tile.group];
                let (lo, hi) = (radius * lo - Vec3::repeat(scene.eps), radius * hi + Vec3::repeat(scene.eps));
                scene.region(stock, &lo, &hi) == Region::Outside
            });
            if outside {
                continue;
            }
            let lo = radius * tile.lo - Vec3::repeat(scene.eps);
            let hi = radius * tile.hi + Vec3::repeat(scene.eps);
            let region = scene.region(stock, &lo, &hi);
            if region == Region::Outside {
                continue;
            }
            union_lo = union_lo.inf(&lo);
            union_hi = union_hi.sup(&hi);
            kept.push((tile, region, lo, hi));
        }
        (kept, union_lo, union_hi)
    }

    /// Tests the front elements of one tile against W and T1 (`lists`), counting the engaged
    /// ones and, with coefficients, adding their forces to each flute's ψ steps.
    fn engage_tile(&self, tile: &Tile, region: Region, lists: &TileLists, engagement: &mut Engagement) {
        let (grid, scene, stock, u) = (self.grid, self.scene, self.stock, self.u);
        let (radius, tooth_feed, width, flute_shift) = (scene.radius, self.tooth_feed, self.width, self.flute_shift);
        let mut hint = 0usize;
        for k in tile.rings.0..tile.rings.1 {
            let (sin_t, cos_t) = grid.ring_angle[k];
            for i in tile.steps.0..tile.steps.1 {
                let e_r = grid.unit(k, i);
                let along = e_r.dot(u);
                if along <= 0.0 {
                    continue;
                }
                let q = radius * e_r;
                if (region == Region::Mixed && scene.hidden_at_hint(&q, &lists.before, hint))
                    || !scene.in_stock(stock, region, &q)
                    || scene.cover(&q, Side::Before, &lists.before, &mut hint) != Cover::Open
                {
                    continue;
                }
                engagement.cut_elements += 1;
                let Some(cutting) = self.coefficients else {
                    continue;
                };
                let h = tooth_feed * along;
                let (cp, sp) = grid.azimuth[k * grid.steps + i];
                let e_theta = Vec3::new(cos_t * cp, cos_t * sp, sin_t);
                let e_v = grid.sign * Vec3::new(-sp, cp, 0.0);
                let tangential = (cutting.ktc * h + cutting.kte) * width;
                let radial = (cutting.krc * h + cutting.kre) * width;
                let axial = (cutting.kac * h + cutting.kae) * width;
                let d_force = -(tangential * e_v + radial * e_r + axial * e_theta);
                // Flute j is at this azimuth when ψ index m = i − s_rot·j·N_t/N_f.
                for j in 0..grid.flutes {
                    let shift = (j * flute_shift) % grid.steps;
                    let m =
                        if grid.sign < 0.0 { (i + shift) % grid.steps } else { (i + grid.steps - shift) % grid.steps };
                    let slot = &mut engagement.force[m];
                    slot[0] += d_force.x;
                    slot[1] += d_force.y;
                    slot[2] += d_force.z;
                }
            }
        }
    }
}
