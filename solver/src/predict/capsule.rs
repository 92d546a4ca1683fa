//! Swept volume of a ball end mill on one straight segment (a capsule) and where a ray along the
//! view direction first enters it: the closed forms of docs/spec/predict.md §3.5 and §6.3.
//!
//! Everything here works in a view frame whose +z is the view direction v̂ (from the material
//! toward the tool): a ray through a point (x, y) travels along +z, and the capsule's "entry
//! depth" at (x, y) is the smallest z at which it is inside the capsule. For the view from below
//! the frame is the machine frame, and the entry depth equals the lowest point of the tool
//! (ball and shank) over (x, y), so the same test serves the depth buffer and the point test of
//! the surface-sampling method (§6.6, 3-axis with a vertical shank).

use nalgebra::Matrix3;

use crate::geometry::Vec3;

/// A capsule of radius R about the segment AB, in view-frame coordinates.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Capsule {
    a: Vec3,
    b: Vec3,
    /// Unit axis A→B (zero for a point).
    axis: Vec3,
    length: f64,
    /// xy part of B − A and the inverse of its squared length (0 for a vertical segment).
    ab_xy: (f64, f64),
    inverse_xy: f64,
    /// 1 − axis_z²: the cylinder term's quadratic coefficient, and its inverse (0 for a segment
    /// along the view).
    denom: f64,
    inverse_denom: f64,
    /// Unit xy direction of the axis and its rise per unit of xy length (zeros for a segment along
    /// the view), for [`Self::cylinder_at_or_above`].
    unit_xy: (f64, f64),
    slope: f64,
    /// Lowest z of the axis segment.
    pub(crate) min_z: f64,
}

impl Capsule {
    pub(crate) fn new(a: Vec3, b: Vec3) -> Self {
        let ab = b - a;
        let length = ab.norm();
        let axis = if length > 0.0 { ab / length } else { Vec3::zeros() };
        let denom = 1.0 - axis.z * axis.z;
        let denom = if length > 0.0 && denom > 1e-12 { denom } else { 0.0 };
        let length_xy2 = ab.x * ab.x + ab.y * ab.y;
        let inverse_cos_tilt = if denom > 0.0 { 1.0 / denom.sqrt() } else { 0.0 };
        Self {
            a,
            b,
            axis,
            length,
            ab_xy: (ab.x, ab.y),
            inverse_xy: if length_xy2 > 0.0 { 1.0 / length_xy2 } else { 0.0 },
            denom,
            inverse_denom: if denom > 0.0 { 1.0 / denom } else { 0.0 },
            unit_xy: (axis.x * inverse_cos_tilt, axis.y * inverse_cos_tilt),
            slope: axis.z * inverse_cos_tilt,
            min_z: a.z.min(b.z),
        }
    }

    /// This capsule in another frame (`rotation` applied to both ends).
    pub(crate) fn in_frame(&self, rotation: &Matrix3<f64>) -> Self {
        Self::new(rotation * self.a, rotation * self.b)
    }

    /// The smallest z at which the ray along +z through (x, y) is inside the capsule of squared
    /// radius `r2`, if the ray meets it.
    #[inline]
    pub(crate) fn entry_z(&self, x: f64, y: f64, r2: f64) -> Option<f64> {
        self.entry_z_up_to(x, y, r2, f64::INFINITY)
    }

    /// [`Self::entry_z`], or `None` early when the capsule's lowest point over (x, y) is
    /// certainly at or above `top`: every point of the capsule over (x, y) is within R of an
    /// axis point c with c.z ≥ min_z and an xy distance ≥ d (the distance to the axis's
    /// projection), so its z ≥ min_z − √(R² − d²). Always inlined: it is the body of the point
    /// test's inner loop.
    #[inline(always)]
    pub(crate) fn entry_z_up_to(&self, x: f64, y: f64, r2: f64, top: f64) -> Option<f64> {
        // Beyond R of the axis in xy the ray misses everything.
        let (abx, aby) = self.ab_xy;
        let (apx, apy) = (x - self.a.x, y - self.a.y);
        let t = ((apx * abx + apy * aby) * self.inverse_xy).clamp(0.0, 1.0);
        let (dx, dy) = (apx - t * abx, apy - t * aby);
        let d2 = dx * dx + dy * dy;
        if d2 > r2 {
            return None;
        }
        let rise = self.min_z - top;
        if rise > 0.0 && rise * rise >= r2 - d2 {
            return None;
        }
        if self.denom > 0.0 {
            // The end spheres lie inside the infinite cylinder: when the ray enters that cylinder
            // within the segment's span, this is the capsule's entry.
            let along = apx * self.axis.x + apy * self.axis.y;
            let half_b = -along * self.axis.z;
            let c = apx * apx + apy * apy - along * along - r2;
            let disc = half_b * half_b - self.denom * c;
            if disc >= 0.0 {
                let t = (-half_b - disc.sqrt()) * self.inverse_denom;
                let foot = along + t * self.axis.z;
                if (0.0..=self.length).contains(&foot) {
                    return Some(self.a.z + t);
                }
            }
        }
        let mut best = f64::INFINITY;
        for end in [&self.a, &self.b] {
            let (dx, dy) = (x - end.x, y - end.y);
            let d2 = dx * dx + dy * dy;
            if d2 <= r2 {
                best = best.min(end.z - (r2 - d2).sqrt());
            }
        }
        best.is_finite().then_some(best)
    }

    /// Whether the ray along +z through (x, y) enters the infinite cylinder about the axis (of
    /// squared radius `r2`) at or above `top`, or misses it: then it enters the capsule, which
    /// lies inside, no lower. The cylinder is entered at the axis's height over the foot of
    /// (x, y) on its line less √(r2 − n²)/cos φ (n the xy distance to the line, φ the axis's
    /// tilt, cos² φ = denom), compared squared: no square root. Never true for a segment along
    /// the view (unit_xy and slope zero, so the squared term is 0). Always inlined: it settles
    /// most capsules of the point test's inner loop (the neighbouring pass's capsules over an
    /// open point), before [`Self::entry_z_up_to`].
    #[inline(always)]
    pub(crate) fn cylinder_at_or_above(&self, x: f64, y: f64, r2: f64, top: f64) -> bool {
        let (apx, apy) = (x - self.a.x, y - self.a.y);
        let (ux, uy) = self.unit_xy;
        let (along, across) = (apx * ux + apy * uy, apy * ux - apx * uy);
        let depth2 = r2 - across * across;
        let rise = self.a.z + along * self.slope - top;
        depth2 < 0.0 || (rise >= 0.0 && rise * rise * self.denom >= depth2)
    }

    /// Squared distance from `p` to the axis segment.
    #[inline]
    pub(crate) fn distance_squared(&self, p: &Vec3) -> f64 {
        let ap = p - self.a;
        let t = ap.dot(&self.axis).clamp(0.0, self.length);
        (ap - t * self.axis).norm_squared()
    }

    /// Whether the ray through `q` (along +z) has entered the capsule by the time it reaches `q`
    /// (within `tie`).
    #[cfg(test)]
    pub(crate) fn covers(&self, q: &Vec3, r: f64, r2: f64, tie: f64) -> bool {
        if self.min_z - r > q.z + tie {
            return false;
        }
        self.entry_z(q.x, q.y, r2).is_some_and(|z| z <= q.z + tie)
    }

    /// Conservative test: can the capsule cover any point of the box `[lo, hi]` (bounding circle
    /// of its xy rectangle and its top)?
    #[cfg(test)]
    pub(crate) fn may_cover_box(&self, lo: &Vec3, hi: &Vec3, r: f64, tie: f64) -> bool {
        self.may_cover(&BoxProbe::new(lo, hi), r, tie)
    }

    /// Whether the capsule's axis lies more than R (+ `tie`) above the top of the probed box, so
    /// that it covers no point of it. Monotone in `min_z`: over capsules sorted by `min_z`, once
    /// one is above, all later ones are.
    #[inline]
    pub(crate) fn above(&self, probe: &BoxProbe, r: f64, tie: f64) -> bool {
        self.min_z - probe.top - tie > r
    }

    /// [`Self::may_cover_box`] with the box's centre and half-diagonal computed once per box.
    #[inline]
    pub(crate) fn may_cover(&self, probe: &BoxProbe, r: f64, tie: f64) -> bool {
        let rise = self.min_z - probe.top - tie;
        if rise > r {
            return false;
        }
        let (abx, aby) = self.ab_xy;
        let (apx, apy) = (probe.cx - self.a.x, probe.cy - self.a.y);
        let t = ((apx * abx + apy * aby) * self.inverse_xy).clamp(0.0, 1.0);
        let (dx, dy) = (apx - t * abx, apy - t * aby);
        let distance = ((dx * dx + dy * dy).sqrt() - probe.half_diagonal).max(0.0);
        if distance >= r {
            return false;
        }
        // Lowest point over the box: min_z − √(r² − distance²) ≤ top.
        rise <= 0.0 || rise * rise <= r * r - distance * distance
    }

    /// xy distance from (x, y) to the axis segment's projection.
    #[cfg(test)]
    pub(crate) fn distance_xy(&self, x: f64, y: f64) -> f64 {
        distance_2d(x, y, &self.a, &self.b)
    }
}

/// What the box filter needs of a box: its xy centre, the half-diagonal of its xy rectangle and
/// its top.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BoxProbe {
    cx: f64,
    cy: f64,
    half_diagonal: f64,
    top: f64,
}

impl BoxProbe {
    pub(crate) fn new(lo: &Vec3, hi: &Vec3) -> Self {
        let (width, height) = (hi.x - lo.x, hi.y - lo.y);
        Self {
            cx: 0.5 * (lo.x + hi.x),
            cy: 0.5 * (lo.y + hi.y),
            half_diagonal: 0.5 * (width * width + height * height).sqrt(),
            top: hi.z,
        }
    }
}

/// Distance in the xy plane from (x, y) to the projection of the segment ab.
#[cfg(test)]
fn distance_2d(x: f64, y: f64, a: &Vec3, b: &Vec3) -> f64 {
    let (abx, aby) = (b.x - a.x, b.y - a.y);
    let (apx, apy) = (x - a.x, y - a.y);
    let length2 = abx * abx + aby * aby;
    let t = if length2 > 0.0 { ((apx * abx + apy * aby) / length2).clamp(0.0, 1.0) } else { 0.0 };
    let (dx, dy) = (apx - t * abx, apy - t * aby);
    (dx * dx + dy * dy).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::distance_to_segment;

    /// Brute force: march z upward until the point is within R of the segment.
    fn brute_entry(a: &Vec3, b: &Vec3, x: f64, y: f64, r: f64) -> Option<f64> {
        let mut z = a.z.min(b.z) - r - 1.0;
        let top = a.z.max(b.z) + r + 1.0;
        let step = 1e-4;
        while z < top {
            if distance_to_segment(&Vec3::new(x, y, z), a, b) <= r {
                return Some(z);
            }
            z += step;
        }
        None
    }

    /// Axis segments for the entry tests: tilted, vertical, a point, level, and a short one
    /// sloping down.
    fn test_segments() -> [(Vec3, Vec3); 5] {
        [
            (Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 1.0, 2.0)),
            (Vec3::new(1.0, 1.0, 1.0), Vec3::new(1.0, 1.0, 4.0)),
            (Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 0.0)),
            (Vec3::new(-1.0, 2.0, 3.0), Vec3::new(3.0, -2.0, 3.0)),
            (Vec3::new(0.5, -0.5, 1.0), Vec3::new(1.0, 0.0, 0.8)),
        ]
    }

    /// A 25 × 25 grid of ray positions (x, y) around the segments.
    fn probe_grid() -> impl Iterator<Item = (f64, f64)> {
        (0..25).flat_map(|i| (0..25).map(move |j| (-3.0 + 0.41 * f64::from(i), -4.0 + 0.43 * f64::from(j))))
    }

    #[test]
    fn capsule_entry_matches_brute_force() {
        let r = 2.0;
        for &(a, b) in &test_segments()[..4] {
            let capsule = Capsule::new(a, b);
            for (x, y) in probe_grid() {
                let exact = capsule.entry_z(x, y, r * r);
                let brute = brute_entry(&a, &b, x, y, r);
                match (exact, brute) {
                    (Some(e), Some(f)) => assert!((e - f).abs() < 2e-4, "{e} vs {f}"),
                    (None, None) => {}
                    (e, f) => {
                        // Grazing rays may differ by the brute-force step.
                        let d = capsule.distance_xy(x, y);
                        assert!((d - r).abs() < 1e-3, "{e:?} vs {f:?} at distance {d}");
                    }
                }
            }
        }
    }

    /// The early exits of `entry_z_up_to` (the lowest-point bound) and the cylinder's bound give
    /// up only where the entry is at or above `top`; otherwise `entry_z_up_to` is the entry.
    #[test]
    fn early_exits_agree_with_entry() {
        let r = 2.0;
        let mut cylinder_decided = 0;
        for (a, b) in test_segments() {
            let capsule = Capsule::new(a, b);
            for (x, y) in probe_grid() {
                let entry = capsule.entry_z(x, y, r * r);
                for k in 0..40 {
                    let top = -3.0 + 0.2 * f64::from(k);
                    if capsule.cylinder_at_or_above(x, y, r * r, top) {
                        cylinder_decided += 1;
                        assert!(entry.is_none_or(|f| f >= top), "{entry:?} < {top} at ({x}, {y})");
                    }
                    match (capsule.entry_z_up_to(x, y, r * r, top), entry) {
                        (Some(e), Some(f)) => assert_eq!(e, f),
                        (None, Some(f)) => assert!(f >= top, "{f} < {top} at ({x}, {y})"),
                        (None, None) => {}
                        (Some(e), None) => panic!("{e} without an entry at ({x}, {y})"),
                    }
                }
            }
        }
        assert!(cylinder_decided > 1000, "{cylinder_decided}");
    }

    #[test]
    fn box_test_is_conservative() {
        let r = 1.5;
        let capsule = Capsule::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(3.0, 0.5, -0.5));
        for i in 0..12 {
            for j in 0..12 {
                for k in 0..6 {
                    let lo = Vec3::new(-2.0 + 0.5 * f64::from(i), -3.0 + 0.5 * f64::from(j), -2.5 + 0.5 * f64::from(k));
                    let hi = lo + Vec3::new(0.4, 0.3, 0.2);
                    if capsule.may_cover_box(&lo, &hi, r, 0.0) {
                        continue;
                    }
                    for s in 0..5 {
                        for t in 0..5 {
                            for u in 0..3 {
                                let q = lo + Vec3::new(0.1 * f64::from(s), 0.075 * f64::from(t), 0.1 * f64::from(u));
                                assert!(!capsule.covers(&q, r, r * r, 0.0), "{q:?}");
                            }
                        }
                    }
                }
            }
        }
    }
}
