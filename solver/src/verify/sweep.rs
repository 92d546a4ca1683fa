//! A body of the assembly swept along a straight move, cut by a vertical ray (docs/spec/verify.md
//! §4 Sweeping): the lowest and highest z the swept body reaches on the ray.
//!
//! With the tip at p(t) = a + t·(b − a), the body reaches down to z(t) + lower(dist(t)) and up to
//! z(t) + upper(dist(t)) on the ray, where dist(t) is the horizontal distance from the ray to the
//! axis. dist is convex in t, `lower` convex and non-decreasing, `upper` concave and
//! non-increasing, so the first is convex and the second concave in t: each has one extremum,
//! found in closed form for horizontal and vertical moves, for the flat parts (a linear function:
//! at an end of the interval) and for spheres (a capsule), by golden-section search for a bull
//! nose's torus.

use super::assembly::{Body, Shape};
use super::dexel::Interval;

/// Golden-section steps: the bracket shrinks to 0.618⁶⁰ ≈ 3·10⁻¹³ of the move.
const GOLDEN_STEPS: usize = 60;
/// A move shorter than this horizontally (mm) is taken as vertical.
const VERTICAL: f64 = 1e-12;

/// A straight move of the tip, with what every ray query of it shares.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segment {
    pub from: [f64; 3],
    pub to: [f64; 3],
    /// Horizontal direction (b − a)_xy and its squared length.
    ux: f64,
    uy: f64,
    uu: f64,
    /// 1 / uu, the rise b_z − a_z and |b − a|², for the capsule of a sloping move.
    inverse_uu: f64,
    vz: f64,
    vv: f64,
    /// Whether the move slopes (neither horizontal nor vertical).
    sloping: bool,
}

impl Segment {
    pub fn new(from: [f64; 3], to: [f64; 3]) -> Self {
        let (ux, uy, vz) = (to[0] - from[0], to[1] - from[1], to[2] - from[2]);
        let uu = ux * ux + uy * uy;
        let sloping = uu >= VERTICAL && from[2] != to[2];
        Self { from, to, ux, uy, uu, inverse_uu: 1.0 / uu, vz, vv: uu + vz * vz, sloping }
    }

    /// The xy rectangle a body of `radius` sweeps.
    pub fn reach(&self, radius: f64) -> ([f64; 2], [f64; 2]) {
        (
            [self.from[0].min(self.to[0]) - radius, self.from[1].min(self.to[1]) - radius],
            [self.from[0].max(self.to[0]) + radius, self.from[1].max(self.to[1]) + radius],
        )
    }

    /// The lowest tip height along the move.
    pub fn low_z(&self) -> f64 {
        self.from[2].min(self.to[2])
    }

    /// The interval of x on the row of rays at `y` within `radius` of the move horizontally
    /// (the footprint of a body of that radius), if any. Rays outside it are out of reach;
    /// the interval is widened by a rounding margin, so [`Self::lowest`] still decides each ray.
    pub fn row(&self, radius: f64, y: f64) -> Option<[f64; 2]> {
        let (ax, ay) = (self.from[0], self.from[1]);
        let mut low = f64::INFINITY;
        let mut high = f64::NEG_INFINITY;
        let mut disc = |cx: f64, cy: f64| {
            let room = radius * radius - (y - cy) * (y - cy);
            if room >= 0.0 {
                let half = room.sqrt();
                low = low.min(cx - half);
                high = high.max(cx + half);
            }
        };
        disc(ax, ay);
        disc(self.to[0], self.to[1]);
        if self.uu >= VERTICAL {
            // The strip between the end discs: 0 ≤ (p − a)·u ≤ |u|² and |(p − a) × u| ≤ r·|u|,
            // each a slab that meets the row in an interval of x (or all or none of it).
            let dy = y - ay;
            let slab = |slope: f64, offset: f64, from: f64, to: f64| -> Option<[f64; 2]> {
                // from ≤ offset + slope·(x − ax) ≤ to
                if slope == 0.0 {
                    return (from <= offset && offset <= to).then_some([f64::NEG_INFINITY, f64::INFINITY]);
                }
                let (p, q) = (ax + (from - offset) / slope, ax + (to - offset) / slope);
                Some([p.min(q), p.max(q)])
            };
            let across = radius * self.uu.sqrt();
            if let (Some(along), Some(side)) =
                (slab(self.ux, dy * self.uy, 0.0, self.uu), slab(-self.uy, self.ux * dy, -across, across))
            {
                let (from, to) = (along[0].max(side[0]), along[1].min(side[1]));
                if from <= to {
                    low = low.min(from);
                    high = high.max(to);
                }
            }
        }
        let margin = 1e-9 * (1.0 + low.abs().max(high.abs()));
        (low <= high).then_some([low - margin, high + margin])
    }

    /// The lowest z `body` reaches on the ray through `(x, y)` along the move, if it reaches the
    /// ray: the first end of [`Self::cut`], without its top.
    #[inline(always)]
    pub fn lowest(&self, body: &Body, x: f64, y: f64) -> Option<f64> {
        if self.sloping && body.is_round() {
            return self.capsule_low(body.radius, x - self.from[0], y - self.from[1]);
        }
        self.lowest_otherwise(body, x, y)
    }

    /// [`Self::lowest`] of a body that does not sweep a capsule, or of a move that does not slope.
    #[inline(never)]
    fn lowest_otherwise(&self, body: &Body, x: f64, y: f64) -> Option<f64> {
        let (px, py) = (x - self.from[0], y - self.from[1]);
        let reach = body.radius;
        let (z0, z1) = (self.from[2], self.to[2]);
        if self.uu < VERTICAL {
            let d = (px * px + py * py).sqrt();
            return (d <= reach).then(|| z0.min(z1) + body.lower(d));
        }
        let pu = px * self.ux + py * self.uy;
        let pp = px * px + py * py;
        let closest = pu / self.uu;
        let least = pp - pu * closest;
        let room = reach * reach - least;
        if room < 0.0 {
            return None;
        }
        let half = (room / self.uu).sqrt();
        let (t_in, t_out) = ((closest - half).max(0.0), (closest + half).min(1.0));
        if t_in > t_out {
            return None;
        }
        let distance = |t: f64| (self.uu * t * t - 2.0 * pu * t + pp).max(0.0).sqrt();
        let height = |t: f64| z0 + t * (z1 - z0);
        if z0 == z1 {
            return Some(z0 + body.lower(distance(closest.clamp(t_in, t_out))));
        }
        Some(match body.shape {
            Shape::Cylinder { base } => height(t_in).min(height(t_out)) + base,
            Shape::Rounded { corner: 0.0 } => height(t_in).min(height(t_out)),
            _ => golden(t_in, t_out, |t| height(t) + body.lower(distance(t))),
        })
    }

    /// The interval of the ray through `(x, y)` that `body` sweeps, if it reaches the ray.
    pub fn cut(&self, body: &Body, x: f64, y: f64) -> Option<Interval> {
        let low = self.lowest(body, x, y)?;
        let (px, py) = (x - self.from[0], y - self.from[1]);
        let (z0, z1) = (self.from[2], self.to[2]);
        if self.uu < VERTICAL {
            let d = (px * px + py * py).sqrt();
            return Some([low, z0.max(z1) + body.upper(d)]);
        }
        let pu = px * self.ux + py * self.uy;
        let pp = px * px + py * py;
        let closest = pu / self.uu;
        let room = (body.radius * body.radius - (pp - pu * closest)).max(0.0);
        if z0 == z1 {
            let half = (room / self.uu).sqrt();
            let t = closest.clamp((closest - half).max(0.0), (closest + half).min(1.0));
            let d = (self.uu * t * t - 2.0 * pu * t + pp).max(0.0).sqrt();
            return Some([low, z0 + body.upper(d)]);
        }
        let high = match body.shape {
            Shape::Sphere => self.capsule_high(body.radius, px, py).unwrap_or(low),
            Shape::Rounded { .. } | Shape::Cylinder { .. } => {
                let half = (room / self.uu).sqrt();
                let t_in = (closest - half).clamp(0.0, 1.0);
                let t_out = (closest + half).min(1.0).max(t_in);
                (z0 + t_in * (z1 - z0)).max(z0 + t_out * (z1 - z0)) + body.top
            }
        };
        Some([low, high])
    }

    /// Where the ray at `(px, py)` from the start enters the capsule of `radius` round the
    /// segment of centres `radius` above the tip (the lowest point of a ball's or sphere's
    /// sweep), for a sloping move.
    ///
    /// The lowest point of the ball over the ray is c_z(t) − √(r² − dist(t)²), convex in t; over
    /// all t it is where the ray enters the infinite cylinder round the centres' line, at the
    /// lower root σ (height above the start's centre) of |(p + σẑ) × v|² = r²|v|² (v the move,
    /// u its horizontal part): |u|²σ² − 2 v_z (p·u) σ + |v|²(|p|² − r²) − (p·u)² = 0, whose
    /// discriminant over 4 is |v|²·w with w = |u|²(r² − |p|²) + (p·u)², |u|² times r² less the
    /// squared distance from the ray to the move's line. Where that point's foot on the line is
    /// within the move (0 ≤ p·u + σ v_z ≤ |v|²) it is the answer; before the start (after the
    /// end) the least over the move is at the start (end), on its sphere, which then reaches the
    /// ray exactly when the move's reach does.
    #[inline(always)]
    fn capsule_low(&self, radius: f64, px: f64, py: f64) -> Option<f64> {
        let pu = px * self.ux + py * self.uy;
        let pp = px * px + py * py;
        let r2 = radius * radius;
        let w = self.uu * (r2 - pp) + pu * pu;
        if w < 0.0 {
            return None;
        }
        let sigma = (self.vz * pu - (self.vv * w).sqrt()) * self.inverse_uu;
        let foot = pu + sigma * self.vz;
        if foot >= 0.0 && foot <= self.vv {
            return Some(self.from[2] + radius + sigma);
        }
        let (z, d2) = if foot < 0.0 { (self.from[2], pp) } else { (self.to[2], pp - 2.0 * pu + self.uu) };
        (d2 <= r2).then(|| z + radius - (r2 - d2).sqrt())
    }

    /// A lower bound of [`Self::lowest`] of a round `body` (a ball end or a sphere) along this
    /// move, for a move that is not vertical: cheaper than the lowest point itself (no square
    /// root), so that the rays a move cannot lower are passed over before it is computed.
    pub fn low_bound(&self, body: &Body) -> Option<LowBound> {
        if !body.is_round() || self.uu < VERTICAL {
            return None;
        }
        let radius = body.radius;
        // The rounding of the lowest point as computed: the relative rounding of the heights, and
        // the square root of the rounding of w in `capsule_low` (at most 4ε·|u|²(r² + 2|p|²) with
        // |p| ≤ r + |u|), which its division by |u|² turns into at most 2√3·√ε·√(|v|²/|u|²)·(r + |u|)
        // ≈ 4·10⁻⁸·√(|v|²/|u|²)·(r + |u|), and a grazing end sphere's √(r² − d²) (√ε·r): the margin
        // is over twenty times the largest.
        let length = self.uu.sqrt();
        let margin = 1e-6
            * (1.0
                + radius
                + self.from[2].abs()
                + self.to[2].abs()
                + (self.vv * self.inverse_uu).sqrt() * (radius + length));
        Some(LowBound {
            from: self.from,
            ux: self.ux,
            uy: self.uy,
            vz: self.vz,
            inverse_uu: self.inverse_uu,
            radius,
            half_curvature: 0.5 / radius,
            margin,
        })
    }

    /// Where the ray at `(px, py)` from the start leaves that capsule (the highest point of a
    /// sphere's sweep): the upper root, or the end sphere beyond which its foot falls.
    fn capsule_high(&self, radius: f64, px: f64, py: f64) -> Option<f64> {
        let pu = px * self.ux + py * self.uy;
        let pp = px * px + py * py;
        let r2 = radius * radius;
        let w = self.uu * (r2 - pp) + pu * pu;
        if w < 0.0 {
            return None;
        }
        let sigma = (self.vz * pu + (self.vv * w).sqrt()) * self.inverse_uu;
        let foot = pu + sigma * self.vz;
        if foot >= 0.0 && foot <= self.vv {
            return Some(self.from[2] + radius + sigma);
        }
        let (z, d2) = if foot < 0.0 { (self.from[2], pp) } else { (self.to[2], pp - 2.0 * pu + self.uu) };
        (d2 <= r2).then(|| z + radius + (r2 - d2).sqrt())
    }
}

/// [`Segment::low_bound`]: a ball of radius r is above the paraboloid of its tip,
/// r − √(r² − d²) ≥ d²/(2r), so the lowest point of its sweep over a ray is at least the least of
/// z(t) + dist(t)²/(2r) over the whole move, a quadratic in t whose least is in closed form; that
/// less a margin for the rounding of both.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LowBound {
    from: [f64; 3],
    ux: f64,
    uy: f64,
    vz: f64,
    inverse_uu: f64,
    radius: f64,
    /// 1 / (2r).
    half_curvature: f64,
    margin: f64,
}

impl LowBound {
    /// The bound on the ray through `(x, y)`.
    #[inline(always)]
    pub fn at(&self, x: f64, y: f64) -> f64 {
        let (px, py) = (x - self.from[0], y - self.from[1]);
        // d/dt [t·v_z + |p − t·u|²/(2r)] = 0 at t = (p·u − r·v_z)/|u|².
        let t = ((px * self.ux + py * self.uy - self.radius * self.vz) * self.inverse_uu).clamp(0.0, 1.0);
        let (dx, dy) = (px - t * self.ux, py - t * self.uy);
        self.from[2] + t * self.vz + (dx * dx + dy * dy) * self.half_curvature - self.margin
    }
}

/// The least value of the convex `f` on `[a, b]`.
fn golden(mut a: f64, mut b: f64, f: impl Fn(f64) -> f64) -> f64 {
    const INVERSE_PHI: f64 = 0.618_033_988_749_894_9;
    let ends = f(a).min(f(b));
    let mut c = b - INVERSE_PHI * (b - a);
    let mut d = a + INVERSE_PHI * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..GOLDEN_STEPS {
        if b - a <= 1e-15 {
            break;
        }
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - INVERSE_PHI * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + INVERSE_PHI * (b - a);
            fd = f(d);
        }
    }
    ends.min(fc).min(fd)
}

#[cfg(test)]
mod tests {
    use proptest::prelude::prop;

    use super::super::assembly::{Body, Member, Shape};
    use super::*;

    fn ball(radius: f64) -> Body {
        Body { member: Member::Cutter, shape: Shape::Rounded { corner: radius }, radius, top: 20.0 }
    }

    /// The sampled extremes of the swept body on the ray, for comparison.
    fn sampled(segment: &Segment, body: &Body, x: f64, y: f64) -> Option<Interval> {
        let mut result: Option<Interval> = None;
        for k in 0..=200_000 {
            let t = f64::from(k) / 200_000.0;
            let p: Vec<f64> = (0..3).map(|i| segment.from[i] + t * (segment.to[i] - segment.from[i])).collect();
            let d = ((x - p[0]).powi(2) + (y - p[1]).powi(2)).sqrt();
            if d <= body.radius {
                let (low, high) = (p[2] + body.lower(d), p[2] + body.upper(d));
                result = Some(result.map_or([low, high], |[a, b]| [a.min(low), b.max(high)]));
            }
        }
        result
    }

    /// The capsule met as the union of its two end spheres and the cylinder between them, each
    /// root kept where its foot falls on the move: the reference the closed form is held to.
    fn capsule_by_parts(segment: &Segment, radius: f64, x: f64, y: f64) -> Option<Interval> {
        let mut low = f64::INFINITY;
        let mut high = f64::NEG_INFINITY;
        let r2 = radius * radius;
        for centre in [segment.from, segment.to] {
            let d2 = (x - centre[0]).powi(2) + (y - centre[1]).powi(2);
            if d2 <= r2 {
                let half = (r2 - d2).sqrt();
                low = low.min(centre[2] + radius - half);
                high = high.max(centre[2] + radius + half);
            }
        }
        let v = [segment.ux, segment.uy, segment.to[2] - segment.from[2]];
        let vv = segment.uu + v[2] * v[2];
        let q = [x - segment.from[0], y - segment.from[1], -(segment.from[2] + radius)];
        let a = [q[1] * v[2] - q[2] * v[1], q[2] * v[0] - q[0] * v[2], q[0] * v[1] - q[1] * v[0]];
        let b = [-v[1], v[0], 0.0];
        let bb = b[0] * b[0] + b[1] * b[1];
        let ab = a[0] * b[0] + a[1] * b[1];
        let aa = a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
        let discriminant = ab * ab - bb * (aa - r2 * vv);
        if discriminant >= 0.0 {
            let root = discriminant.sqrt();
            for s in [(-ab - root) / bb, (-ab + root) / bb] {
                let t = (q[0] * v[0] + q[1] * v[1] + (q[2] + s) * v[2]) / vv;
                if (0.0..=1.0).contains(&t) {
                    low = low.min(s);
                    high = high.max(s);
                }
            }
        }
        (low <= high).then_some([low, high])
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(256))]

        #[test]
        fn the_closed_form_capsule_is_the_union_of_its_parts(
            from in proptest::array::uniform3(-5.0..5.0f64),
            to in proptest::array::uniform3(-5.0..5.0f64),
            x in -9.0..9.0f64,
            y in -9.0..9.0f64,
            radius in 0.2..4.0f64,
        ) {
            let segment = Segment::new(from, to);
            proptest::prop_assume!(segment.uu >= VERTICAL && from[2] != to[2]);
            let sphere = Body { member: Member::Cutter, shape: Shape::Sphere, radius, top: 2.0 * radius };
            let parts = capsule_by_parts(&segment, radius, x, y);
            let closed = segment.cut(&sphere, x, y);
            let ball = segment.lowest(&ball(radius), x, y);
            match (parts, closed) {
                (Some(p), Some(c)) => {
                    proptest::prop_assert!((p[0] - c[0]).abs() < 1e-6 && (p[1] - c[1]).abs() < 1e-6, "{p:?} {c:?}");
                    proptest::prop_assert_eq!(ball, Some(c[0]));
                }
                (None, None) => proptest::prop_assert_eq!(ball, None),
                // Only a ray grazing the capsule (within rounding) may be taken by one and not the other.
                (p, c) => {
                    let [low, high] = p.or(c).unwrap();
                    proptest::prop_assert!(high - low < 1e-6, "{p:?} {c:?}");
                }
            }
        }

        #[test]
        fn every_ray_a_body_reaches_is_in_its_row(
            from in proptest::array::uniform3(-5.0..5.0f64),
            to in proptest::array::uniform3(-5.0..5.0f64),
            along in prop::bool::ANY,
            x in -9.0..9.0f64,
            y in -9.0..9.0f64,
            radius in 0.2..4.0f64,
        ) {
            // Moves along an axis too, where a slab of the strip is a whole row or none.
            let to = if along { [to[0], from[1], to[2]] } else { to };
            let segment = Segment::new(from, to);
            for body in [ball(radius), Body { member: Member::Cutter, shape: Shape::Rounded { corner: 0.0 }, radius, top: 9.0 }] {
                if segment.lowest(&body, x, y).is_some() {
                    let row = segment.row(radius, y);
                    proptest::prop_assert!(row.is_some_and(|[a, b]| a <= x && x <= b), "{row:?} {x}");
                }
            }
            let swapped = Segment::new([from[1], from[0], from[2]], [to[1], to[0], to[2]]);
            if swapped.lowest(&ball(radius), y, x).is_some() {
                proptest::prop_assert!(swapped.row(radius, x).is_some_and(|[a, b]| a <= y && y <= b));
            }
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(2048))]

        #[test]
        fn the_low_bound_is_below_the_lowest_point(
            from in proptest::array::uniform3(-5.0..5.0f64),
            to in proptest::array::uniform3(-5.0..5.0f64),
            kind in 0..4usize,
            along in 0.0..1.0f64,
            angle in 0.0..std::f64::consts::TAU,
            inside in prop::sample::select(vec![0.0, 1e-15, 1e-12, 1e-9, 1e-6, 1e-3, 0.1, 0.5, 0.9, -1e-12]),
            shift in prop::sample::select(vec![0.0, 0.3, 250.0, -4000.0]),
            radius in 0.05..6.0f64,
        ) {
            // Sloping, level, steep (nearly vertical) and long moves, away from the origin too.
            let to = match kind {
                0 => to,
                1 => [to[0], to[1], from[2]],
                2 => [from[0] + 1e-5 * to[0], from[1] + 1e-5 * to[1], to[2]],
                _ => [from[0] + 40.0 * to[0], from[1] + 40.0 * to[1], to[2]],
            };
            let (from, to) = (from.map(|c| c + shift), to.map(|c| c + shift));
            let segment = Segment::new(from, to);
            // A ray at distance r·(1 − inside) from a point of the move: on the edge of its reach
            // and just inside or outside, where the roots round the most.
            let (x, y) = (
                from[0] + along * (to[0] - from[0]) + radius * (1.0 - inside) * angle.cos(),
                from[1] + along * (to[1] - from[1]) + radius * (1.0 - inside) * angle.sin(),
            );
            for body in [ball(radius), Body { member: Member::Cutter, shape: Shape::Sphere, radius, top: 2.0 * radius }] {
                let Some(bound) = segment.low_bound(&body) else {
                    proptest::prop_assert!(segment.uu < VERTICAL);
                    continue;
                };
                if let Some(low) = segment.lowest(&body, x, y) {
                    proptest::prop_assert!(bound.at(x, y) <= low, "{} > {low}", bound.at(x, y));
                }
            }
        }
    }

    #[test]
    fn sweeps_match_sampling() {
        let bodies = [
            ball(3.0),
            Body { member: Member::Cutter, shape: Shape::Rounded { corner: 0.0 }, radius: 5.0, top: 20.0 },
            Body { member: Member::Cutter, shape: Shape::Rounded { corner: 1.0 }, radius: 4.0, top: 20.0 },
            Body { member: Member::Cutter, shape: Shape::Sphere, radius: 2.0, top: 4.0 },
        ];
        let segments = [
            Segment::new([0.0, 0.0, 0.0], [10.0, 0.0, 0.0]),
            Segment::new([0.0, 0.0, 0.0], [10.0, 3.0, -4.0]),
            Segment::new([1.0, 1.0, 5.0], [1.0, 1.0, -2.0]),
            Segment::new([0.0, 0.0, -1.0], [2.0, 1.0, 3.0]),
        ];
        for body in &bodies {
            for segment in &segments {
                for (x, y) in [(0.5, 0.2), (5.0, 2.9), (9.0, -1.0), (1.5, 1.0), (12.5, 1.0), (-3.0, 0.0)] {
                    let exact = segment.cut(body, x, y);
                    let approx = sampled(segment, body, x, y);
                    match (exact, approx) {
                        (Some(e), Some(s)) => {
                            assert!((e[0] - s[0]).abs() < 1e-3 && (e[1] - s[1]).abs() < 1e-3, "{e:?} {s:?}")
                        }
                        (None, None) => {}
                        (e, s) => assert!(e.is_some() && s.is_none(), "{body:?} {segment:?} {x} {y}: {e:?} {s:?}"),
                    }
                }
            }
        }
    }
}
