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
}

impl Segment {
    pub fn new(from: [f64; 3], to: [f64; 3]) -> Self {
        let (ux, uy) = (to[0] - from[0], to[1] - from[1]);
        Self { from, to, ux, uy, uu: ux * ux + uy * uy }
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

    /// The interval of the ray through `(x, y)` that `body` sweeps, if it reaches the ray.
    pub fn cut(&self, body: &Body, x: f64, y: f64) -> Option<Interval> {
        let (px, py) = (x - self.from[0], y - self.from[1]);
        let reach = body.radius;
        let (z0, z1) = (self.from[2], self.to[2]);
        if self.uu < VERTICAL {
            let d = (px * px + py * py).sqrt();
            return (d <= reach).then(|| [z0.min(z1) + body.lower(d), z0.max(z1) + body.upper(d)]);
        }
        // dist²(t) = uu·t² − 2·pu·t + pp ≤ reach² on [t_in, t_out].
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
            let d = distance(closest.clamp(t_in, t_out));
            return Some([z0 + body.lower(d), z0 + body.upper(d)]);
        }
        let ends = [height(t_in), height(t_out)];
        let low = match body.shape {
            Shape::Cylinder { base } => ends[0].min(ends[1]) + base,
            Shape::Rounded { corner: 0.0 } => ends[0].min(ends[1]),
            Shape::Rounded { corner } if corner == body.radius => self.capsule(body.radius, x, y)?[0],
            Shape::Sphere => self.capsule(body.radius, x, y)?[0],
            Shape::Rounded { .. } => golden(t_in, t_out, |t| height(t) + body.lower(distance(t))),
        };
        let high = match body.shape {
            Shape::Sphere => self.capsule(body.radius, x, y)?[1],
            Shape::Rounded { .. } | Shape::Cylinder { .. } => ends[0].max(ends[1]) + body.top,
        };
        Some([low, high])
    }

    /// Where the ray through `(x, y)` enters and leaves the capsule of `radius` round the
    /// segment of centres `radius` above the tip: the lowest point of a ball's sweep (and both
    /// ends of a sphere's). The capsule is the two end spheres and the cylinder between them;
    /// the cylinder counts where the point's projection falls on the segment (elsewhere its
    /// surface lies inside an end sphere).
    fn capsule(&self, radius: f64, x: f64, y: f64) -> Option<Interval> {
        let mut low = f64::INFINITY;
        let mut high = f64::NEG_INFINITY;
        let r2 = radius * radius;
        for centre in [self.from, self.to] {
            let d2 = (x - centre[0]).powi(2) + (y - centre[1]).powi(2);
            if d2 <= r2 {
                let half = (r2 - d2).sqrt();
                low = low.min(centre[2] + radius - half);
                high = high.max(centre[2] + radius + half);
            }
        }
        // Points P = (x, y, s) at `radius` from the axis line C0 + t·v: |(q + s·ẑ) × v|² = r²·|v|²
        // with q = (x, y, 0) − C0.
        let v = [self.ux, self.uy, self.to[2] - self.from[2]];
        let vv = self.uu + v[2] * v[2];
        let q = [x - self.from[0], y - self.from[1], -(self.from[2] + radius)];
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
