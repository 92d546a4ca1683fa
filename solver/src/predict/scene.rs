//! What one prediction position sees (docs/spec/predict.md §3.5, §6.1–6.2): the nearby swept
//! volumes split into T1 (motion before s₀ − n_g·f_t) and T2 (after s₀ + n_g·f_t) as capsules in
//! a view frame, per-tile candidate lists, and the point test every method shares: is a point of
//! M in the stock, and is it behind a swept volume along the view direction?

use nalgebra::Matrix3;

use super::capsule::{BoxProbe, Capsule};
use super::passes::{PathModel, Stamps};
use crate::geometry::Vec3;
use crate::stock::{Region, StockModel};

/// Which swept volumes a capsule belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Side {
    /// T1: before the prediction position.
    Before,
    /// T2: after it.
    After,
}

/// A piece of nearby motion in world coordinates.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Piece {
    pub(crate) a: Vec3,
    pub(crate) b: Vec3,
    pub(crate) side: Side,
}

/// Per-thread scratch buffers.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    pub(crate) stamps: Stamps,
    pub(crate) indices: Vec<u32>,
}

/// Which motion one prediction position needs.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Query {
    /// Ball centre O.
    pub(crate) centre: Vec3,
    /// Global arclength of O.
    pub(crate) sigma: f64,
    /// Half-width of the excluded gap, n_g·f_t.
    pub(crate) gap: f64,
    /// Ball radius R.
    pub(crate) radius: f64,
    /// xy search reach (and 3-D reach for `any_view`).
    pub(crate) reach: f64,
    /// Keep every piece within `reach` in 3-D (tilted views) instead of those that can hide
    /// the lower hemisphere from below.
    pub(crate) any_view: bool,
    /// From below: an upper bound of the stock's top within R of the centre in xy (∞ for none).
    /// Only points of the stock are ever tested, so pieces that can hide or tie only points
    /// above it are left out (fewer capsules to build and filter, the same answers).
    pub(crate) stock_top: f64,
    pub(crate) order: PieceOrder,
}

/// The order of the gathered pieces.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum PieceOrder {
    /// Path order (neighbourhoods compared pass by pass).
    Path,
    /// By their segments' lowest points, ties in path order: a scene seen from below keeps its
    /// capsules in this order, so only the pieces clipped at the gap can be out of place.
    Height,
}

/// Collects the motion near the ball minus the gap (σ − gap, σ + gap), as pieces that can hide
/// part of the lower hemisphere below the stock's top seen from below, or for tilted views every
/// piece within `reach` in 3-D.
///
/// From below, a capsule hides or ties a point q (entry ≤ q.z + ε) only if its axis's lowest
/// point is below q.z + R + ε and its axis passes within R of q in xy. A point of the lower
/// hemisphere in the stock has q.z < min(O.z, top) and so lies within ρ = √(R² − (O.z − top)²)
/// of O in xy (R when top ≥ O.z). So a piece is kept when its lowest point is below
/// min(O.z, top) + R and its xy distance below R + ρ (both with a slack of 10⁻⁶·R for ε and
/// rounding), at most 2R = `reach`.
pub(crate) fn gather(path: &PathModel, query: &Query, scratch: &mut Scratch, out: &mut Vec<Piece>) {
    let Query { centre, sigma, gap, radius, reach, any_view, order, stock_top } = *query;
    let centre = &centre;
    let (lowest_limit, reach) =
        if any_view { (f64::INFINITY, reach) } else { limits_below(centre, radius, reach, stock_top) };
    out.clear();
    scratch.indices.clear();
    match order {
        PieceOrder::Path => path.near_in_order(centre, reach, &mut scratch.stamps, &mut scratch.indices),
        PieceOrder::Height => path.near_by_height(centre, reach, &mut scratch.stamps, &mut scratch.indices),
    }
    out.reserve(scratch.indices.len());
    for &index in &scratch.indices {
        let segment = &path.segments[index as usize];
        let (a, b) = path.ends(index as usize);
        let (start, end) = (segment.sigma, segment.sigma + segment.length);
        let point = |s: f64| {
            if segment.length > 0.0 { a + ((s - start) / segment.length).clamp(0.0, 1.0) * (b - a) } else { a }
        };
        let mut push = |p: Vec3, q: Vec3, side: Side| {
            let keep = if any_view {
                crate::geometry::distance_to_segment(centre, &p, &q) < reach
            } else {
                p.z.min(q.z) - radius < lowest_limit && distance_xy(centre, &p, &q) < reach
            };
            if keep {
                out.push(Piece { a: p, b: q, side });
            }
        };
        if start < sigma - gap || (segment.length == 0.0 && start <= sigma - gap) {
            push(a, point(end.min(sigma - gap)), Side::Before);
        }
        if end > sigma + gap || (segment.length == 0.0 && start >= sigma + gap) {
            push(point(start.max(sigma + gap)), b, Side::After);
        }
    }
}

/// From below: the bound a piece's lowest point less R must stay under, and the xy reach (see
/// [`gather`]).
fn limits_below(centre: &Vec3, radius: f64, reach: f64, stock_top: f64) -> (f64, f64) {
    let slack = 1e-6 * radius;
    let below = stock_top - centre.z;
    if below >= 0.0 {
        return (centre.z, reach.min(2.0 * radius));
    }
    let rho = (radius * radius - below * below).max(0.0).sqrt();
    (centre.z.min(stock_top + slack), reach.min(radius + rho + slack))
}

fn distance_xy(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let flat = |v: &Vec3| Vec3::new(v.x, v.y, 0.0);
    crate::geometry::distance_to_segment(&flat(p), &flat(a), &flat(b))
}

/// The pieces as capsules in a view frame centred on the ball centre O.
#[derive(Debug, Clone)]
pub(crate) struct Scene {
    pub(crate) radius: f64,
    pub(crate) r2: f64,
    /// Depth tolerance ε (§3.5).
    pub(crate) eps: f64,
    pub(crate) centre: Vec3,
    /// World → frame (rows ê₁, ê₂, v̂).
    pub(crate) rotation: Matrix3<f64>,
    pub(crate) before: Vec<Capsule>,
    pub(crate) after: Vec<Capsule>,
}

/// The capsules sorted by lowest axis point: the box filter and the point test stop at the first
/// capsule too high to matter. Which capsule hides a point never depends on the order, only how
/// soon a scan finds it. Pieces gathered in [`PieceOrder::Height`] come sorted but for the few
/// clipped at the gap, which the run-adaptive stable sort merges in about linear time. (Sorting
/// integer keys, not the 128-byte capsules.)
fn by_lowest_point(capsules: Vec<Capsule>) -> Vec<Capsule> {
    if capsules.is_sorted_by(|p, q| p.min_z <= q.min_z) {
        return capsules;
    }
    let mut keys: Vec<(u64, u32)> =
        capsules.iter().enumerate().map(|(i, c)| (total_order_key(c.min_z), i as u32)).collect();
    keys.sort();
    keys.into_iter().map(|(_, i)| capsules[i as usize]).collect()
}

/// An unsigned integer in the order of [`f64::total_cmp`] (integer keys sort faster than a float
/// comparator).
fn total_order_key(value: f64) -> u64 {
    let bits = value.to_bits();
    if bits >> 63 == 1 { !bits } else { bits | 1 << 63 }
}

/// Whether a ray has entered a swept volume by the time it reaches a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Cover {
    /// Not entered.
    Open,
    /// Entered within ±ε: a tie (retraced motion, §5 E11).
    Tie,
    /// Entered more than ε before.
    Hidden,
}

/// Candidate capsules of one tile.
#[derive(Debug, Default, Clone)]
pub(crate) struct TileLists {
    pub(crate) region: Option<Region>,
    pub(crate) before: Vec<u32>,
    pub(crate) after: Vec<u32>,
}

impl Scene {
    pub(crate) fn new(pieces: &[Piece], centre: Vec3, rotation: Matrix3<f64>, radius: f64) -> Self {
        let before_count = pieces.iter().filter(|p| p.side == Side::Before).count();
        let mut before = Vec::with_capacity(before_count);
        let mut after = Vec::with_capacity(pieces.len() - before_count);
        // The machine frame (the common case) needs no product: 1·x + 0·y + 0·z is x (up to the
        // sign of a zero).
        let machine = rotation == Matrix3::identity();
        let to_frame = |p: &Vec3| if machine { p - centre } else { rotation * (p - centre) };
        for piece in pieces {
            let capsule = Capsule::new(to_frame(&piece.a), to_frame(&piece.b));
            match piece.side {
                Side::Before => before.push(capsule),
                Side::After => after.push(capsule),
            }
        }
        Self {
            radius,
            r2: radius * radius,
            eps: 1e-9 * radius,
            centre,
            rotation,
            before: by_lowest_point(before),
            after: by_lowest_point(after),
        }
    }

    /// The same capsules seen in the view frame `rotation`, for a scene in the machine frame (the
    /// capsules as [`Self::new`] would build them from the same pieces). A turn about the vertical
    /// keeps every height, so the capsules keep their order and need no new sort.
    pub(crate) fn in_frame(&self, rotation: Matrix3<f64>) -> Self {
        debug_assert_eq!(self.rotation, Matrix3::identity());
        let turn = |capsules: &[Capsule]| by_lowest_point(capsules.iter().map(|c| c.in_frame(&rotation)).collect());
        Self {
            radius: self.radius,
            r2: self.r2,
            eps: self.eps,
            centre: self.centre,
            rotation,
            before: turn(&self.before),
            after: turn(&self.after),
        }
    }

    /// World point of a frame point.
    pub(crate) fn world(&self, frame: &Vec3) -> Vec3 {
        self.centre + self.rotation.transpose() * frame
    }

    /// Where the frame box `[lo, hi]` lies relative to the stock.
    pub(crate) fn region(&self, stock: &StockModel, lo: &Vec3, hi: &Vec3) -> Region {
        let (world_lo, world_hi) = self.world_box(lo, hi);
        stock.classify(&world_lo, &world_hi, self.eps)
    }

    /// Fills `lists` with the capsules that may hide a point of the frame box `[lo, hi]`, taken
    /// from `pool` (or from all capsules); `want_after` skips T2 when only K is needed. The
    /// region is left to the caller. The capsules are sorted by `min_z` and pools list them in
    /// index order, so the scan stops at the first capsule above the box (all later ones are).
    pub(crate) fn candidates(
        &self,
        lo: &Vec3,
        hi: &Vec3,
        want_after: bool,
        pool: Option<&TileLists>,
        lists: &mut TileLists,
    ) {
        lists.before.clear();
        lists.after.clear();
        let probe = BoxProbe::new(lo, hi);
        let (r, tie) = (self.radius, self.eps);
        let pick = |capsules: &[Capsule], from: Option<&[u32]>, out: &mut Vec<u32>| match from {
            Some(indices) => {
                debug_assert!(indices.is_sorted());
                for &i in indices {
                    let capsule = &capsules[i as usize];
                    if capsule.above(&probe, r, tie) {
                        break;
                    }
                    if capsule.may_cover(&probe, r, tie) {
                        out.push(i);
                    }
                }
            }
            None => {
                let end = capsules.partition_point(|c| !c.above(&probe, r, tie));
                for (i, capsule) in capsules[..end].iter().enumerate() {
                    if capsule.may_cover(&probe, r, tie) {
                        out.push(i as u32);
                    }
                }
            }
        };
        pick(&self.before, pool.map(|p| p.before.as_slice()), &mut lists.before);
        if want_after {
            pick(&self.after, pool.map(|p| p.after.as_slice()), &mut lists.after);
        }
    }

    /// World bounding box of a frame box. Rounding is monotone, so [`Self::world`] reaches each
    /// world coordinate's extremes over the box at the corner taking, per frame axis, the low or
    /// the high end as that axis's back-rotation coefficient is ≥ 0 or not (the same bits as
    /// trying all 8 corners): 2 corners for the machine frame, at most 6 for any other.
    pub(crate) fn world_box(&self, lo: &Vec3, hi: &Vec3) -> (Vec3, Vec3) {
        let back = self.rotation.transpose();
        let corner = |row: usize, low: bool| {
            let pick = |column: usize| if (back[(row, column)] >= 0.0) == low { lo[column] } else { hi[column] };
            Vec3::new(pick(0), pick(1), pick(2))
        };
        let extreme = |low: bool| {
            let mut extreme = Vec3::zeros();
            let mut last: Option<(Vec3, Vec3)> = None;
            for row in 0..3 {
                let c = corner(row, low);
                let w = match last {
                    Some((previous, w)) if previous == c => w,
                    _ => self.world(&c),
                };
                extreme[row] = w[row];
                last = Some((c, w));
            }
            extreme
        };
        (extreme(true), extreme(false))
    }

    /// How the frame point `q` is covered by the listed capsules of one side (`list` in index
    /// order); `hint` is the list position that covered the previous point (tried first). Kept
    /// out of line: one tight loop for every caller (inlined into the pixel and sample loops it
    /// cost more instructions).
    #[inline(never)]
    pub(crate) fn cover(&self, q: &Vec3, side: Side, list: &[u32], hint: &mut usize) -> Cover {
        debug_assert!(list.is_sorted());
        let capsules = match side {
            Side::Before => &self.before,
            Side::After => &self.after,
        };
        let mut state = Cover::Open;
        let start = (*hint).min(list.len());
        // From the hint to the end, then the start of the list; each part is sorted by `min_z`,
        // so its scan stops at the first capsule too high to reach q.
        for (offset, part) in [(start, &list[start..]), (0, &list[..start])] {
            for (k, &index) in part.iter().enumerate() {
                match self.capsule_cover(&capsules[index as usize], q) {
                    None => break,
                    Some(Cover::Hidden) => {
                        *hint = offset + k;
                        return Cover::Hidden;
                    }
                    Some(Cover::Tie) => state = Cover::Tie,
                    Some(Cover::Open) => {}
                }
            }
        }
        state
    }

    /// How one capsule covers the frame point `q`; `None` when its axis lies too high to reach q
    /// (so does every later capsule of a list sorted by `min_z`). Always inlined: it is the
    /// inner loop of every point test.
    #[inline(always)]
    fn capsule_cover(&self, capsule: &Capsule, q: &Vec3) -> Option<Cover> {
        if capsule.min_z - self.radius > q.z + self.eps {
            return None;
        }
        // Capsules whose lowest point over q lies more than 2ε above it are skipped before the
        // square root (neither hidden nor a tie, so the same answer): most by the bound of their
        // infinite cylinder, the rest by the bounds in `entry_z_up_to`.
        let top = q.z + 2.0 * self.eps;
        if capsule.cylinder_at_or_above(q.x, q.y, self.r2, top) {
            return Some(Cover::Open);
        }
        Some(self.cover_by_entry(capsule.entry_z_up_to(q.x, q.y, self.r2, top), q))
    }

    /// How a ray that enters a capsule at `entry` (if at all) covers `q`.
    #[inline(always)]
    fn cover_by_entry(&self, entry: Option<f64>, q: &Vec3) -> Cover {
        match entry {
            Some(entry) if entry < q.z - self.eps => Cover::Hidden,
            Some(entry) if entry <= q.z + self.eps => Cover::Tie,
            _ => Cover::Open,
        }
    }

    /// Whether the T1 capsule at position `hint` of `list` hides `q`: the first test of
    /// [`Self::cover`] on its own. Neighbouring points are nearly always hidden by the same
    /// capsule, so where the tile meets the stock's surface callers ask this before the costlier
    /// point-in-stock test (a point it hides is cut before or not in the stock, which every
    /// caller treats alike).
    #[inline]
    pub(crate) fn hidden_at_hint(&self, q: &Vec3, list: &[u32], hint: usize) -> bool {
        // Without the cylinder's bound of the scan: the capsule that hid the previous point
        // nearly always hides this one too.
        list.get(hint).is_some_and(|&index| {
            let entry = self.before[index as usize].entry_z_up_to(q.x, q.y, self.r2, q.z + 2.0 * self.eps);
            self.cover_by_entry(entry, q) == Cover::Hidden
        })
    }

    /// Whether one listed T1 capsule hides every point of the frame box `[lo, hi]`: the box lies
    /// in the capsule shrunk by 2ε. A capsule is convex, so that holds when the box's 8 corners
    /// lie within R − 2ε of the axis (checked after two cheaper tests of the box's centre: within
    /// R − 2ε is needed, within R − 2ε − half the diagonal is enough). Then every point q of the
    /// box has q − 2ε·ẑ inside the capsule, so the ray enters it more than ε before q and
    /// [`Self::cover`] would answer `Hidden` for each (the capsule passes the conservative box
    /// filter, so it is in the list). `hint` is the list position that hid the previous box
    /// (tried first).
    pub(crate) fn hides_box(&self, lo: &Vec3, hi: &Vec3, list: &[u32], hint: &mut usize) -> bool {
        let centre = 0.5 * (lo + hi);
        let inner = self.radius - 2.0 * self.eps;
        let inner2 = inner * inner;
        let sure = (inner - 0.5 * (hi - lo).norm()).max(0.0);
        let sure2 = sure * sure;
        let corners = [0, 1, 2, 3, 4, 5, 6, 7].map(|corner: usize| {
            Vec3::new(
                if corner & 1 == 0 { lo.x } else { hi.x },
                if corner & 2 == 0 { lo.y } else { hi.y },
                if corner & 4 == 0 { lo.z } else { hi.z },
            )
        });
        let start = (*hint).min(list.len());
        let (tail, head) = list.split_at(start);
        for (position, &index) in head.iter().enumerate().map(|(k, i)| (k + start, i)).chain(tail.iter().enumerate()) {
            let capsule = &self.before[index as usize];
            let to_centre = capsule.distance_squared(&centre);
            if to_centre > inner2 {
                continue;
            }
            if (sure > 0.0 && to_centre <= sure2) || corners.iter().all(|c| capsule.distance_squared(c) <= inner2) {
                *hint = position;
                return true;
            }
        }
        false
    }

    /// In the stock, given the tile's region.
    pub(crate) fn in_stock(&self, stock: &StockModel, region: Region, frame: &Vec3) -> bool {
        match region {
            Region::Outside => false,
            Region::Inside => true,
            Region::Mixed => stock.contains(&self.world(frame), self.eps),
        }
    }
}

/// The state of one sample of M.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SampleState {
    /// Not in the stock (or not on the lower hemisphere).
    Air,
    /// Hidden by T1: cut before (or not in the stock: a point T1 hides needs no stock test, and
    /// every caller treats both alike).
    CutBefore,
    /// In the cutting region K, hidden by T2: cut again later.
    CutAfter,
    /// In K and not hidden by T2: finished surface S.
    Finished,
}

/// Full point test of a frame point `q` on M: stock, T1 (a tie counts as hidden for K but the
/// surface is credited to the later of two identical passes, §5 E11) and T2.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PointTest {
    pub(crate) state: SampleState,
    /// In K with the strict rule (a tie with T1 hides).
    pub(crate) cut: bool,
}

impl Scene {
    pub(crate) fn test(&self, stock: &StockModel, lists: &TileLists, q: &Vec3, hints: &mut [usize; 2]) -> PointTest {
        match lists.region {
            Some(region) => self.test_in(stock, region, lists, q, hints),
            None => PointTest { state: SampleState::Air, cut: false },
        }
    }

    /// [`Self::test`] for a point whose place relative to the stock is `region` (a part of the
    /// tile's box). Always inlined into the callers' pixel and sample loops.
    #[inline(always)]
    pub(crate) fn test_in(
        &self,
        stock: &StockModel,
        region: Region,
        lists: &TileLists,
        q: &Vec3,
        hints: &mut [usize; 2],
    ) -> PointTest {
        let cut_before = PointTest { state: SampleState::CutBefore, cut: false };
        if region == Region::Mixed && self.hidden_at_hint(q, &lists.before, hints[0]) {
            return cut_before;
        }
        if !self.in_stock(stock, region, q) {
            return PointTest { state: SampleState::Air, cut: false };
        }
        let before = self.cover(q, Side::Before, &lists.before, &mut hints[0]);
        if before == Cover::Hidden {
            return cut_before;
        }
        let after = self.cover(q, Side::After, &lists.after, &mut hints[1]);
        PointTest {
            state: if after == Cover::Open { SampleState::Finished } else { SampleState::CutAfter },
            cut: before == Cover::Open,
        }
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// Random pieces near the origin on both sides (some repeated heights, some vertical or
    /// degenerate).
    fn pieces() -> impl Strategy<Value = Vec<Piece>> {
        let point = || (-12.0..12.0_f64, -12.0..12.0_f64, prop_oneof![-8.0..8.0_f64, Just(-1.0)]);
        prop::collection::vec((point(), point(), any::<bool>(), 0..4u8), 0..60).prop_map(|raw| {
            raw.into_iter()
                .map(|((ax, ay, az), (bx, by, bz), before, kind)| {
                    let a = Vec3::new(ax, ay, az);
                    let b = match kind {
                        0 => a,
                        1 => Vec3::new(ax, ay, bz),
                        _ => Vec3::new(bx, by, bz),
                    };
                    Piece { a, b, side: if before { Side::Before } else { Side::After } }
                })
                .collect()
        })
    }

    fn frame_box() -> impl Strategy<Value = (Vec3, Vec3)> {
        (-8.0..8.0_f64, -8.0..8.0_f64, -8.0..4.0_f64, 0.0..3.0_f64, 0.0..3.0_f64, 0.0..2.0_f64)
            .prop_map(|(x, y, z, w, h, d)| (Vec3::new(x, y, z), Vec3::new(x + w, y + h, z + d)))
    }

    /// The filter over every capsule, without the early stop.
    fn brute(capsules: &[Capsule], from: &[u32], lo: &Vec3, hi: &Vec3, r: f64, tie: f64) -> Vec<u32> {
        from.iter().copied().filter(|&i| capsules[i as usize].may_cover_box(lo, hi, r, tie)).collect()
    }

    /// The point test over every listed capsule, without the early stop.
    fn brute_cover(scene: &Scene, q: &Vec3, capsules: &[Capsule], list: &[u32]) -> Cover {
        let mut state = Cover::Open;
        for &i in list {
            if let Some(entry) = capsules[i as usize].entry_z(q.x, q.y, scene.r2) {
                if entry < q.z - scene.eps {
                    return Cover::Hidden;
                }
                if entry <= q.z + scene.eps {
                    state = Cover::Tie;
                }
            }
        }
        state
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, .. ProptestConfig::default() })]

        /// The world box from the extreme corners is the box of all 8 corners, bit for bit, for
        /// the machine frame, turns about the vertical and tilted frames.
        #[test]
        fn world_box_matches_all_corners(
            turn in -4.0..4.0_f64,
            tilt in prop_oneof![Just(0.0), -1.5..1.5_f64],
            machine in any::<bool>(),
            (lo, hi) in frame_box(),
        ) {
            let rotation = if machine {
                Matrix3::identity()
            } else {
                *nalgebra::Rotation3::from_euler_angles(tilt, 0.0, turn).matrix()
            };
            let scene = Scene::new(&[], Vec3::new(3.25, -1.5, 0.75), rotation, 5.0);
            let mut world_lo = Vec3::repeat(f64::INFINITY);
            let mut world_hi = Vec3::repeat(f64::NEG_INFINITY);
            for corner in 0..8 {
                let c = Vec3::new(
                    if corner & 1 == 0 { lo.x } else { hi.x },
                    if corner & 2 == 0 { lo.y } else { hi.y },
                    if corner & 4 == 0 { lo.z } else { hi.z },
                );
                world_lo = world_lo.inf(&scene.world(&c));
                world_hi = world_hi.sup(&scene.world(&c));
            }
            prop_assert_eq!(scene.world_box(&lo, &hi), (world_lo, world_hi));
        }

        /// A piece that the stock's top leaves out of a scene seen from below hides and ties no
        /// point of the lower hemisphere under that top.
        #[test]
        fn pieces_left_out_hide_nothing_in_the_stock(
            pieces in pieces(),
            top in -6.0..1.0_f64,
            directions in prop::collection::vec((-3.2..3.2_f64, 0.0..3.0_f64), 40),
        ) {
            let (centre, radius) = (Vec3::new(1.0, -2.0, 0.5), 5.0);
            let (lowest_limit, reach) = limits_below(&centre, radius, 2.0 * radius, top);
            let scene = Scene::new(&pieces, centre, Matrix3::identity(), radius);
            for piece in &pieces {
                let kept = piece.a.z.min(piece.b.z) - radius < lowest_limit
                    && distance_xy(&centre, &piece.a, &piece.b) < reach;
                if kept {
                    continue;
                }
                let capsule = Capsule::new(piece.a - centre, piece.b - centre);
                for &(azimuth, depth) in &directions {
                    // A point of the lower hemisphere (frame), up to 3 below the top.
                    let z = ((top - centre.z).min(0.0) - depth).max(-radius);
                    let rho = (radius * radius - z * z).sqrt();
                    let q = Vec3::new(rho * azimuth.cos(), rho * azimuth.sin(), z);
                    if q.z + centre.z >= top {
                        continue;
                    }
                    let entry = capsule.entry_z(q.x, q.y, scene.r2);
                    prop_assert!(entry.is_none_or(|e| e > q.z + scene.eps), "{entry:?} over {q:?}");
                }
            }
        }

        /// Every point of a box that one T1 capsule hides whole is hidden by the point test.
        #[test]
        fn hidden_boxes_hide_their_points(
            pieces in pieces(),
            (lo, size) in frame_box(),
            shrink in 0.05..1.0_f64,
            inside in (0.0..1.0_f64, 0.0..1.0_f64, 0.0..1.0_f64),
        ) {
            let scene = Scene::new(&pieces, Vec3::new(1.0, -2.0, 0.5), Matrix3::identity(), 5.0);
            let hi = lo + shrink * (size - lo);
            let mut lists = TileLists::default();
            scene.candidates(&lo, &hi, false, None, &mut lists);
            let mut hint = 0;
            if scene.hides_box(&lo, &hi, &lists.before, &mut hint) {
                let all: Vec<u32> = (0..scene.before.len() as u32).collect();
                for k in 0..9 {
                    let q = if k == 8 {
                        lo + (hi - lo).component_mul(&Vec3::new(inside.0, inside.1, inside.2))
                    } else {
                        Vec3::new(
                            if k & 1 == 0 { lo.x } else { hi.x },
                            if k & 2 == 0 { lo.y } else { hi.y },
                            if k & 4 == 0 { lo.z } else { hi.z },
                        )
                    };
                    prop_assert_eq!(brute_cover(&scene, &q, &scene.before, &all), Cover::Hidden);
                }
            }
        }

        /// The sorted capsules with the early stop give exactly the candidates of the full scan,
        /// from all capsules and from a pool, and the same point test answers.
        #[test]
        fn candidates_match_brute_force(pieces in pieces(), outer in frame_box(), inner in frame_box(), hint in 0..40usize) {
            let scene = Scene::new(&pieces, Vec3::new(1.0, -2.0, 0.5), Matrix3::identity(), 5.0);
            prop_assert!(scene.before.is_sorted_by(|p, q| p.min_z <= q.min_z));
            prop_assert!(scene.after.is_sorted_by(|p, q| p.min_z <= q.min_z));
            let (r, tie) = (scene.radius, scene.eps);
            let all_before: Vec<u32> = (0..scene.before.len() as u32).collect();
            let all_after: Vec<u32> = (0..scene.after.len() as u32).collect();
            // A pool for a box holding both boxes, then the inner box from it.
            let (pool_lo, pool_hi) = (outer.0.inf(&inner.0), outer.1.sup(&inner.1));
            let mut pool = TileLists::default();
            scene.candidates(&pool_lo, &pool_hi, true, None, &mut pool);
            prop_assert_eq!(&pool.before, &brute(&scene.before, &all_before, &pool_lo, &pool_hi, r, tie));
            prop_assert_eq!(&pool.after, &brute(&scene.after, &all_after, &pool_lo, &pool_hi, r, tie));
            let mut lists = TileLists::default();
            scene.candidates(&inner.0, &inner.1, true, Some(&pool), &mut lists);
            prop_assert_eq!(&lists.before, &brute(&scene.before, &pool.before, &inner.0, &inner.1, r, tie));
            prop_assert_eq!(&lists.after, &brute(&scene.after, &pool.after, &inner.0, &inner.1, r, tie));
            // Point tests at the inner box's corners and centre, from any starting hint.
            for k in 0..9 {
                let q = if k == 8 {
                    0.5 * (inner.0 + inner.1)
                } else {
                    Vec3::new(
                        if k & 1 == 0 { inner.0.x } else { inner.1.x },
                        if k & 2 == 0 { inner.0.y } else { inner.1.y },
                        if k & 4 == 0 { inner.0.z } else { inner.1.z },
                    )
                };
                for (side, capsules, list) in
                    [(Side::Before, &scene.before, &all_before), (Side::After, &scene.after, &all_after)]
                {
                    let mut h = hint;
                    prop_assert_eq!(scene.cover(&q, side, list, &mut h), brute_cover(&scene, &q, capsules, list));
                }
            }
        }
    }
}
