//! kerf's `exact` centre path (docs/spec/deburr.md §2.9, the swept-sphere characteristic circle):
//! centres whose swept envelope, not one ball section, meets the true surfaces W apart.
//!
//! The ball moving along the centre path cuts the envelope of its positions; its characteristic
//! circle lies in the plane normal to the *path* tangent, which tilts away from the ridge's normal
//! plane VP wherever the path is not parallel to the ridge, so neighbouring balls cut past one
//! ball's section. The wanted band edges are known curves, though: at every ridge point P the
//! single-section construction ([`Construction::exact`]) gives G1 on the true cylinder and G2 on
//! the true wall, in VP, with equal legs and W apart. As P runs round the ridge they trace two
//! edge curves Γ1 and Γ2. The swept chamfer ends exactly on them when every ball reaches both
//! curves without crossing them: when each centre is at distance D from Γ1 and from Γ2 (as
//! curves, not from the points of its own P). The coupling through the path tangent then
//! disappears: at the point where a ball touches Γ1 the distance has a minimum, so that point
//! lies on the ball's characteristic circle, whatever the path tangent is. Each centre is
//! therefore solved on its own: kept in its VP (so P stays the ridge point nearest to it) and
//! moved by Newton steps until both distances are D.
//!
//! The edge curves are sampled at nodes spread along the ridge and interpolated (cubic Hermite);
//! the centres are solved at the nodes, and between them the centre is the patent's closed-form
//! centre plus the interpolated correction, which is smooth and small.

use super::centre::Construction;
use super::profile::Profile;
use crate::geometry::Vec3;

/// Node spacing along the hole profile, as a fraction of min(R2, D): fine enough that the
/// interpolated path is within about 1e-5 mm of a full solve between nodes.
const NODE_SPACING: f64 = 1.0 / 24.0;
/// Fewest nodes on one profile segment (the one-sided derivatives at its ends need three).
const MIN_SEGMENT_NODES: usize = 4;
/// Most nodes on a loop; beyond it the spacing grows.
const MAX_NODES: usize = 16_384;

/// The exact centre path of one job.
#[derive(Debug, Clone)]
pub(crate) struct EnvelopePath {
    /// Per segment: its first node and node count (its end is the next segment's first node).
    segments: Vec<(usize, usize)>,
    /// Per node: the exact centre minus the patent's tangent-line centre.
    corrections: Vec<Vec3>,
    /// Per node: the target band edges G1 and G2, samples of the edge curves.
    edges: [Vec<Vec3>; 2],
    /// Largest |distance of a node centre from an edge curve − D|, mm: 0 up to rounding where
    /// a placement giving W exists.
    pub residual: f64,
    /// Where that residual is: segment and parameter.
    pub residual_at: (usize, f64),
    /// Nodes where the true section curves admit no single-section band edges, so the tangent-line
    /// edges were used as the target there.
    pub approximate_edges: usize,
    /// Largest distance by which the swept volume falls short of an edge curve's node, mm: where
    /// an edge curve bends towards the balls more tightly than radius D, a ball reaching it
    /// would cut past it nearby, so the balls only bridge the bend and the chamfer there is
    /// narrower than W (the closest to W without cutting past W anywhere).
    pub shortfall: f64,
    /// Where that shortfall is: segment and parameter.
    pub shortfall_at: (usize, f64),
}

/// Most Newton steps of one centre; typical ones converge in 3–5.
const MAX_NEWTON_STEPS: usize = 40;

impl EnvelopePath {
    /// Samples the edge curves and solves the centre at every node.
    pub fn solve(construction: &Construction, profile: &Profile) -> Self {
        let spacing = profile.radius.min(construction.ball_radius) * NODE_SPACING;
        let lengths: Vec<f64> = profile.segments.iter().map(|s| s.length(profile.radius)).collect();
        let total: f64 = lengths.iter().sum();
        let spacing = spacing.max(total / MAX_NODES as f64);
        let mut segments = Vec::with_capacity(lengths.len());
        let mut count_so_far = 0;
        for length in &lengths {
            let count = ((length / spacing).ceil() as usize).max(MIN_SEGMENT_NODES);
            segments.push((count_so_far, count));
            count_so_far += count;
        }
        let mut path = Self {
            segments,
            corrections: Vec::with_capacity(count_so_far),
            edges: [Vec::new(), Vec::new()],
            residual: 0.0,
            residual_at: (0, 0.0),
            approximate_edges: 0,
            shortfall: 0.0,
            shortfall_at: (0, 0.0),
        };
        let mut edges = [Vec::with_capacity(count_so_far), Vec::with_capacity(count_so_far)];
        let mut starts = Vec::with_capacity(count_so_far);
        let mut ridges = Vec::with_capacity(count_so_far);
        for (segment, &(_, count)) in profile.segments.iter().zip(&path.segments) {
            for j in 0..count {
                let point = segment.point(profile.radius, j as f64 / count as f64);
                let ridge = construction.tangent(&point);
                let (start, g1, g2) = construction.exact(profile, &ridge).unwrap_or_else(|| {
                    path.approximate_edges += 1;
                    let (g1, g2) = ridge.band_edges(construction.half_width);
                    (ridge.centre, g1, g2)
                });
                edges[0].push(g1);
                edges[1].push(g2);
                starts.push(start);
                ridges.push(ridge);
            }
        }
        for (index, (start, ridge)) in starts.iter().zip(&ridges).enumerate() {
            let (centre, miss) =
                path.touching_centre(&edges, construction.ball_radius, *start, ridge.plane_basis(), index);
            if miss > path.residual {
                path.residual = miss;
                path.residual_at = path.node_place(index);
            }
            path.corrections.push(centre - ridge.centre);
        }
        let centres: Vec<Vec3> = ridges.iter().zip(&path.corrections).map(|(r, c)| r.centre + c).collect();
        for (index, hint) in (0..centres.len()).zip(0..) {
            for side in &edges {
                let mut hint = hint;
                let (distance, _) = path.nearest(&centres, &side[index], &mut hint);
                if distance - construction.ball_radius > path.shortfall {
                    path.shortfall = distance - construction.ball_radius;
                    path.shortfall_at = path.node_place(index);
                }
            }
        }
        path.edges = edges;
        path
    }

    /// The centre in the plane through `start` spanned by `plane` that is at distance `ball`
    /// from both edge curves (node values `edges`), by Newton from `start` (moving the centre by
    /// Δ changes its distance from a curve by n·Δ, n the unit vector from the curve's nearest
    /// point, as that point is a minimum). Returns the centre with the smallest miss found and
    /// that miss; `hint` is a node near the answer.
    fn touching_centre(
        &self,
        edges: &[Vec<Vec3>; 2],
        ball: f64,
        start: Vec3,
        plane: (Vec3, Vec3),
        hint: usize,
    ) -> (Vec3, f64) {
        let converged = 1e-13 * ball.max(1.0);
        let mut hints = [hint; 2];
        let mut centre = start;
        let mut best = (start, f64::INFINITY);
        for _ in 0..MAX_NEWTON_STEPS {
            let mut normals = [Vec3::zeros(); 2];
            let mut misses = [0.0; 2];
            for side in 0..2 {
                let (distance, nearest) = self.nearest(&edges[side], &centre, &mut hints[side]);
                misses[side] = ball - distance;
                normals[side] = (centre - nearest) / distance;
            }
            let miss = misses[0].abs().max(misses[1].abs());
            if miss < best.1 {
                best = (centre, miss);
            } else if miss > 2.0 * best.1 {
                // Diverging (no placement gives both distances): keep the closest found.
                break;
            }
            if miss < converged {
                break;
            }
            centre += plane_step(&normals, &misses, plane);
        }
        best
    }

    /// The exact centre at parameter `s` of segment `segment`: the patent's centre plus the
    /// interpolated correction.
    pub fn centre(&self, construction: &Construction, profile: &Profile, segment: usize, s: f64) -> Vec3 {
        let point = profile.segments[segment].point(profile.radius, s);
        let (_, count) = self.segments[segment];
        let scaled = s.clamp(0.0, 1.0) * count as f64;
        let local = (scaled.floor() as usize).min(count - 1);
        let [start, start_slope, end, end_slope] = self.interval(&self.corrections, segment, local);
        let (correction, _, _) = hermite(&[start, start_slope, end, end_slope], scaled - local as f64);
        construction.tangent_centre(&point) + correction
    }

    fn node_count(&self) -> usize {
        self.segments.iter().map(|(_, count)| count).sum()
    }

    /// Segment and parameter of a node.
    fn node_place(&self, index: usize) -> (usize, f64) {
        let segment = self.segments.iter().rposition(|(first, _)| *first <= index).unwrap_or(0);
        let (first, count) = self.segments[segment];
        (segment, (index - first) as f64 / count as f64)
    }

    /// The cubic Hermite data (end values and end slopes in the interval's own parameter) of
    /// interval `local` of `segment`, for node `values`. Slopes are central differences inside a
    /// segment and one-sided at its ends: at a junction the profile's curvature jumps, and with
    /// it the centre path's speed.
    fn interval(&self, values: &[Vec3], segment: usize, local: usize) -> [Vec3; 4] {
        let (first, count) = self.segments[segment];
        let total = values.len();
        let at = |j: usize| values[(first + j) % total];
        let slope = |j: usize| {
            if j == 0 {
                0.5 * (-3.0 * at(0) + 4.0 * at(1) - at(2))
            } else if j == count {
                0.5 * (3.0 * at(count) - 4.0 * at(count - 1) + at(count - 2))
            } else {
                0.5 * (at(j + 1) - at(j - 1))
            }
        };
        [at(local), slope(local), at(local + 1), slope(local + 1)]
    }

    /// Distance from `point` to the curve through the node values `curve`, and its nearest
    /// point. `hint` is a node near the answer; it is moved to the nearest node.
    fn nearest(&self, curve: &[Vec3], point: &Vec3, hint: &mut usize) -> (f64, Vec3) {
        let total = self.node_count();
        let distance = |index: usize| (curve[index] - point).norm_squared();
        // The distance along a smooth curve is unimodal near its minimum: walk downhill.
        let mut index = *hint;
        while distance((index + 1) % total) < distance(index) {
            index = (index + 1) % total;
        }
        while distance((index + total - 1) % total) < distance(index) {
            index = (index + total - 1) % total;
        }
        *hint = index;
        let mut best = (distance(index).sqrt(), curve[index]);
        for (interval, start) in [(index, 0.0), ((index + total - 1) % total, 1.0)] {
            let (segment, _) = self.node_place(interval);
            let local = interval - self.segments[segment].0;
            let data = self.interval(curve, segment, local);
            let (near, candidate) = nearest_on_cubic(&data, point, start);
            if near < best.0 {
                best = (near, candidate);
            }
        }
        best
    }
}

/// The step within VP (basis `plane`) that changes the distances along `normals` by `misses`
/// (n·Δ = miss for both). Solved with a tiny
/// Levenberg damping, so a singular case (both normals alike) takes the least-squares step.
fn plane_step(normals: &[Vec3; 2], misses: &[f64; 2], plane: (Vec3, Vec3)) -> Vec3 {
    let (a, b) = plane;
    let rows = [(normals[0].dot(&a), normals[0].dot(&b)), (normals[1].dot(&a), normals[1].dot(&b))];
    // Normal equations (JᵀJ + μI)x = Jᵀr.
    let (aa, ab, bb) = (
        rows[0].0 * rows[0].0 + rows[1].0 * rows[1].0,
        rows[0].0 * rows[0].1 + rows[1].0 * rows[1].1,
        rows[0].1 * rows[0].1 + rows[1].1 * rows[1].1,
    );
    let damping = 1e-12 * (aa + bb);
    let (ra, rb) = (rows[0].0 * misses[0] + rows[1].0 * misses[1], rows[0].1 * misses[0] + rows[1].1 * misses[1]);
    let (aa, bb) = (aa + damping, bb + damping);
    let determinant = aa * bb - ab * ab;
    if determinant <= 0.0 || !determinant.is_finite() {
        return Vec3::zeros();
    }
    let x = (bb * ra - ab * rb) / determinant;
    let y = (aa * rb - ab * ra) / determinant;
    x * a + y * b
}

/// Value, first and second derivative of the cubic Hermite `[p0, m0, p1, m1]` at `t` ∈ [0, 1].
fn hermite(data: &[Vec3; 4], t: f64) -> (Vec3, Vec3, Vec3) {
    let [p0, m0, p1, m1] = data;
    let (t2, t3) = (t * t, t * t * t);
    let value =
        (2.0 * t3 - 3.0 * t2 + 1.0) * p0 + (t3 - 2.0 * t2 + t) * m0 + (3.0 * t2 - 2.0 * t3) * p1 + (t3 - t2) * m1;
    let first = (6.0 * t2 - 6.0 * t) * p0
        + (3.0 * t2 - 4.0 * t + 1.0) * m0
        + (6.0 * t - 6.0 * t2) * p1
        + (3.0 * t2 - 2.0 * t) * m1;
    let second = (12.0 * t - 6.0) * p0 + (6.0 * t - 4.0) * m0 + (6.0 - 12.0 * t) * p1 + (6.0 * t - 2.0) * m1;
    (value, first, second)
}

/// Nearest point of the cubic to `point` on t ∈ [0, 1] by Newton from `start`: distance and point.
fn nearest_on_cubic(data: &[Vec3; 4], point: &Vec3, start: f64) -> (f64, Vec3) {
    let mut t = start;
    for _ in 0..12 {
        let (value, first, second) = hermite(data, t);
        let offset = value - point;
        let slope = offset.dot(&first);
        let curvature = first.norm_squared() + offset.dot(&second);
        if curvature <= 0.0 {
            break;
        }
        let next = (t - slope / curvature).clamp(0.0, 1.0);
        let moved = (next - t).abs();
        t = next;
        if moved < 1e-15 {
            break;
        }
    }
    let (value, _, _) = hermite(data, t);
    ((value - point).norm(), value)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    fn construction(r1: f64, ball: f64, width: f64) -> Construction {
        Construction {
            cylinder_radius: r1,
            inner: false,
            half_width: width / 2.0,
            ball_radius: ball,
            centre_to_chord: (ball * ball - width * width / 4.0).sqrt(),
        }
    }

    #[test]
    fn hermite_reproduces_a_cubic() {
        // p(t) = (t³, t², t): slopes in t at 0 and 1.
        let data = [Vec3::zeros(), Vec3::new(0.0, 0.0, 1.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(3.0, 2.0, 1.0)];
        let (value, first, second) = hermite(&data, 0.5);
        assert_abs_diff_eq!(value, Vec3::new(0.125, 0.25, 0.5), epsilon = 1e-15);
        assert_abs_diff_eq!(first, Vec3::new(0.75, 1.0, 1.0), epsilon = 1e-15);
        assert_abs_diff_eq!(second, Vec3::new(3.0, 2.0, 0.0), epsilon = 1e-15);
    }

    #[test]
    fn centres_touch_both_edge_curves() {
        // Tube R10, hole r8 (geometry 3).
        let construction = construction(10.0, 3.0, 0.5 * std::f64::consts::SQRT_2);
        let profile = Profile::round(8.0, 0.0, 0.0);
        let path = EnvelopePath::solve(&construction, &profile);
        assert_eq!(path.approximate_edges, 0);
        assert!(path.residual < 1e-10, "residual {}", path.residual);
        // The swept volume reaches the edge curves everywhere (to the node path's resolution).
        assert!(path.shortfall < 2e-3, "shortfall {}", path.shortfall);
        for (s, tilted) in [(0.0, false), (0.13, true), (0.55, true), (0.8, false)] {
            let ridge = construction.tangent(&profile.segments[0].point(8.0, s));
            let (single, _, _) = construction.exact(&profile, &ridge).unwrap();
            let swept = path.centre(&construction, &profile, 0, s);
            // Between nodes the interpolated correction is as good as a full solve there.
            let (solved, miss) = path.touching_centre(&path.edges, 3.0, swept, ridge.plane_basis(), 0);
            assert!(miss < 1e-10, "miss {miss}");
            assert_abs_diff_eq!(swept, solved, epsilon = 1e-5);
            // Where the path tilts against the ridge the single-section centre is off the swept
            // one by far more (at φ = 0°, 90°, 180°, 270° they are parallel by symmetry).
            if tilted {
                assert!((single - swept).norm() > 1e-3, "at {s}: {}", (single - swept).norm());
            }
            // The exact centre stays in VP: P is still the ridge point nearest to it.
            let tangent = ridge.cylinder_normal.cross(&ridge.wall_normal).normalize();
            assert_abs_diff_eq!((swept - ridge.target).dot(&tangent), 0.0, epsilon = 1e-6);
        }
    }

    #[test]
    fn a_too_tight_ridge_is_bridged_not_overcut() {
        // Tube R10, hole r8 off centre by 0.3, ball 4, Q 1 (geometry 4): near φ = 0 the
        // edge curves bend more tightly than the ball can follow.
        let construction = construction(10.0, 4.0, std::f64::consts::SQRT_2);
        let profile = Profile::round(8.0, 0.3, 0.0);
        let path = EnvelopePath::solve(&construction, &profile);
        assert!(path.residual < 1e-10, "every centre still touches both curves: {}", path.residual);
        assert!(path.shortfall > 0.1, "shortfall {}", path.shortfall);
        let (_, s) = path.shortfall_at;
        assert!(!(0.05..=0.95).contains(&s), "the tight bend is at φ = 0, not s = {s}");
    }
}
