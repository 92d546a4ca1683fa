//! Arc-feed correction of the chip thickness (docs/spec/engagement.md §11 item 6): on a curved path the
//! cutting edge meets the material at a distance ρ(θ) from the path's centre, not r_path, so
//! it advances f_z·ρ/r_path per tooth there: (r_path + R)/r_path on the outside of the turn,
//! (r_path − R)/r_path on the inside, and the chip is h = f_z·c(θ)·sin θ with c = ρ/r_path.

use super::arcs::Arc;
use super::phase;
use super::segments::{Route, Shape, Station};

/// Tooth on an arc end counts as inside, degrees (closed arcs, as in `teeth`).
const END_TOLERANCE: f64 = 1e-9;

/// The edge-feed factor of one sample on an arc of the path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ArcFeed {
    /// R / r_path.
    ratio: f64,
    /// +1 when the path turns left (ccw: the right of travel, θ = 0°, is outside the turn),
    /// −1 when it turns right.
    side: f64,
}

impl ArcFeed {
    /// The factor at `station`, `None` on a straight piece.
    pub(crate) fn at(route: &Route, station: &Station, tool_radius: f64) -> Option<Self> {
        match route.pieces.get(station.piece)?.shape {
            Shape::Arc { radius, sweep, .. } if radius > 0.0 => {
                Some(Self { ratio: tool_radius / radius, side: sweep.signum() })
            }
            _ => None,
        }
    }

    /// The factor of a tool `ratio` = R/r_path times the path's radius, turning left (`side`
    /// +1) or right (−1).
    #[cfg(test)]
    pub(crate) fn new(ratio: f64, side: f64) -> Self {
        Self { ratio, side }
    }

    /// c(θ) = ρ(θ)/r_path = √(1 + q² ± 2q·cos θ), q = R/r_path, θ in degrees.
    pub(crate) fn factor(&self, theta: f64) -> f64 {
        let q = self.ratio;
        (1.0 + q * q + 2.0 * self.side * q * theta.to_radians().cos()).max(0.0).sqrt()
    }

    /// The largest c(θ) anywhere on the circle: (r_path + R)/r_path.
    pub(crate) fn largest_factor(&self) -> f64 {
        1.0 + self.ratio
    }

    /// The smallest c(θ) anywhere on the circle: |r_path − R|/r_path.
    pub(crate) fn smallest_factor(&self) -> f64 {
        (1.0 - self.ratio).abs()
    }

    /// c(θ)·max(0, sin θ) on the arcs, 0 off them.
    fn ratio_at(&self, arcs: &[Arc], theta: f64) -> f64 {
        if arcs.iter().any(|a| a.contains(theta, END_TOLERANCE)) {
            self.factor(theta) * theta.to_radians().sin().max(0.0)
        } else {
            0.0
        }
    }

    /// H_k/f_z: the largest summed c(θ)·sin θ of k teeth over the phase (§5.6 with the factor).
    pub(crate) fn tooth_sum(&self, arcs: &[Arc], flutes: u32) -> f64 {
        let ends: Vec<f64> = arcs.iter().flat_map(|a| [a.from, a.to]).chain([0.0, 180.0]).collect();
        phase::peak(flutes, &ends, |theta| self.ratio_at(arcs, theta))
    }

    /// The thickest chip over the arcs, per f_z (the feed plan's basis `tooth`).
    pub(crate) fn peak_ratio(&self, arcs: &[Arc]) -> f64 {
        // One tooth: the phase peak of a single tooth is the largest value on the arcs.
        self.tooth_sum(arcs, 1)
    }

    /// Mean of c(θ)·sin θ over the engaged angles (the mean chip thickness per f_z).
    pub(crate) fn mean_ratio(&self, arcs: &[Arc]) -> f64 {
        let total: f64 = arcs.iter().map(Arc::span).sum();
        if total <= 0.0 {
            return 0.0;
        }
        // Midpoint rule on 0.1° pieces: the integrand is smooth on each arc but for the kink
        // of max(0, ·) at 0°/180°, which costs at most a piece's width squared.
        let mut integral = 0.0;
        for arc in arcs {
            let pieces = (arc.span() / 0.1).ceil().max(1.0);
            let width = arc.span() / pieces;
            for i in 0..pieces as usize {
                let theta = arc.from + width * (i as f64 + 0.5);
                integral += self.factor(theta) * theta.to_radians().sin().max(0.0) * width;
            }
        }
        integral / total
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outside_and_inside_of_the_turn() {
        // r_path = 20, R = 5, turning left: θ = 0° is outside ((20 + 5)/20), 180° inside.
        let feed = ArcFeed { ratio: 0.25, side: 1.0 };
        assert!((feed.factor(0.0) - 1.25).abs() < 1e-12);
        assert!((feed.factor(180.0) - 0.75).abs() < 1e-12);
        assert!((feed.factor(90.0) - (1.0_f64 + 0.0625).sqrt()).abs() < 1e-12);
        let right = ArcFeed { ratio: 0.25, side: -1.0 };
        assert!((right.factor(0.0) - 0.75).abs() < 1e-12);
    }

    #[test]
    fn thin_side_cut_scales_by_the_edge_feed() {
        // A thin cut on the outside of a left turn: every contact angle is near 0°, so the
        // chip is about (r + R)/r times the straight one.
        let feed = ArcFeed { ratio: 0.25, side: 1.0 };
        let arcs = [Arc { from: 0.0, to: 5.0 }];
        let straight = 5.0_f64.to_radians().sin();
        let ratio = feed.peak_ratio(&arcs) / straight;
        assert!((ratio - feed.factor(5.0)).abs() < 1e-9 && (ratio - 1.25).abs() < 0.001, "{ratio}");
        assert!((feed.mean_ratio(&arcs) / (straight / 2.0) - 1.25).abs() < 0.002);
    }
}
