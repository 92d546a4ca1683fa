//! Corner loops (docs/spec/contour.md §3.5): the arc loop (claim 4, §3.5.1, L1–L3), the triangle and
//! parallelogram loops (claim 5, §3.5.2–3.5.3, L4–L5) and the sizing rules of §3.5.4.
//!
//! Every loop leaves the corner point P along d1, turns by 2π − ψ against the corner's own turn
//! and comes back to P along d2, so the tool passes P twice in straight lines.

use std::f64::consts::TAU;

use super::element::{Element, ElementKind};
use super::job::LoopConfig;
use super::request::LoopStyle;
use crate::planar::{Vec2, right_normal};

/// A loop at one corner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoopShape {
    /// `arc`, `triangle` or `parallelogram`.
    pub style: LoopStyle,
    /// Leg length L: |PA| = |PB|, mm.
    pub leg: f64,
    /// Arc radius ρ (arc loops).
    pub radius: Option<f64>,
    /// A = P + L·d1, the end of the exit leg.
    pub exit_end: Vec2,
    /// B = P − L·d2, the start of the entry leg.
    pub entry_start: Vec2,
    /// C, the arc centre (arc loops).
    pub centre: Option<Vec2>,
    /// M = P + L·d1 − L·d2, the far corner (parallelogram loops).
    pub far_corner: Option<Vec2>,
    /// Signed sweep of the arc, radians (arc loops): −σ(2π − ψ).
    pub sweep: Option<f64>,
}

impl LoopShape {
    /// The arc loop of radius `radius` at corner point `p` (L1–L3).
    pub fn arc(p: &Vec2, d1: &Vec2, d2: &Vec2, sigma: f64, radius: f64) -> Self {
        let psi = turn_size(d1, d2);
        let leg = radius * (0.5 * psi).tan();
        let exit_end = p + leg * d1;
        Self {
            style: LoopStyle::Arc,
            leg,
            radius: Some(radius),
            exit_end,
            entry_start: p - leg * d2,
            centre: Some(exit_end + radius * sigma * right_normal(d1)),
            far_corner: None,
            sweep: Some(-sigma * (TAU - psi)),
        }
    }

    /// The triangle loop with legs `leg` (L4).
    pub fn triangle(p: &Vec2, d1: &Vec2, d2: &Vec2, leg: f64) -> Self {
        Self {
            style: LoopStyle::Triangle,
            leg,
            radius: None,
            exit_end: p + leg * d1,
            entry_start: p - leg * d2,
            centre: None,
            far_corner: None,
            sweep: None,
        }
    }

    /// The parallelogram loop with legs `leg` (L5).
    pub fn parallelogram(p: &Vec2, d1: &Vec2, d2: &Vec2, leg: f64) -> Self {
        Self {
            style: LoopStyle::Parallelogram,
            leg,
            radius: None,
            exit_end: p + leg * d1,
            entry_start: p - leg * d2,
            centre: None,
            far_corner: Some(p + leg * d1 - leg * d2),
            sweep: None,
        }
    }

    /// The same style, `factor` times the size.
    #[must_use]
    pub fn scaled(&self, p: &Vec2, d1: &Vec2, d2: &Vec2, sigma: f64, factor: f64) -> Self {
        match self.style {
            LoopStyle::Arc => Self::arc(p, d1, d2, sigma, self.radius.unwrap_or(0.0) * factor),
            LoopStyle::Triangle => Self::triangle(p, d1, d2, self.leg * factor),
            LoopStyle::Parallelogram | LoopStyle::None => Self::parallelogram(p, d1, d2, self.leg * factor),
        }
    }

    /// Exit, loop and entry elements from P back to P.
    pub fn elements(&self, p: &Vec2) -> Vec<Element> {
        let line = |start: Vec2, end: Vec2, kind| Element::Line { start, end, kind };
        let mut elements = vec![line(*p, self.exit_end, ElementKind::Exit)];
        match (self.style, self.centre, self.sweep, self.far_corner) {
            (LoopStyle::Arc, Some(centre), Some(sweep), _) => elements.push(Element::Arc {
                start: self.exit_end,
                end: self.entry_start,
                centre,
                radius: self.radius.unwrap_or(0.0),
                sweep,
                kind: ElementKind::Loop,
            }),
            (LoopStyle::Parallelogram, _, _, Some(far)) => {
                elements.push(line(self.exit_end, far, ElementKind::Loop));
                elements.push(line(far, self.entry_start, ElementKind::Loop));
            }
            _ => elements.push(line(self.exit_end, self.entry_start, ElementKind::Loop)),
        }
        elements.push(line(self.entry_start, *p, ElementKind::Entry));
        elements
    }

    /// Extra path length of the loop (exit + loop + entry).
    pub fn length(&self) -> f64 {
        let middle = match (self.radius, self.sweep, self.far_corner) {
            (Some(radius), Some(sweep), _) => radius * sweep.abs(),
            (_, _, Some(far)) => (far - self.exit_end).norm() + (self.entry_start - far).norm(),
            _ => (self.entry_start - self.exit_end).norm(),
        };
        2.0 * self.leg + middle
    }
}

/// ψ = |φ|, the size of the turn from d1 to d2.
fn turn_size(d1: &Vec2, d2: &Vec2) -> f64 {
    crate::planar::turn_angle(d1, d2).abs()
}

/// The loop the sizing rules give at a corner of turn ψ (§3.5.4), with the reason when they
/// forced a change of style (`W_LOOP_FALLBACK`).
pub(crate) fn sized(
    config: &LoopConfig,
    p: &Vec2,
    d1: &Vec2,
    d2: &Vec2,
    sigma: f64,
) -> Option<(LoopShape, Option<String>)> {
    let psi = turn_size(d1, d2);
    let clamp_leg = |leg: f64| leg.clamp(config.min_leg, config.max_leg);
    match config.style {
        LoopStyle::None => None,
        LoopStyle::Triangle => {
            let leg = clamp_leg(config.leg);
            (leg > 0.0).then(|| (LoopShape::triangle(p, d1, d2, leg), None))
        }
        LoopStyle::Parallelogram => {
            let leg = clamp_leg(config.leg);
            (leg > 0.0).then(|| (LoopShape::parallelogram(p, d1, d2, leg), None))
        }
        LoopStyle::Arc => {
            let tan_half = (0.5 * psi).tan();
            if !(tan_half > 0.0 && tan_half.is_finite()) {
                return None;
            }
            let mut radius = config.radius;
            let mut leg = radius * tan_half;
            if leg > config.max_leg {
                leg = config.max_leg;
                radius = leg / tan_half;
            } else if leg < config.min_leg {
                leg = config.min_leg;
                radius = leg / tan_half;
            }
            if (config.min_radius..=config.max_radius).contains(&radius) {
                return Some((LoopShape::arc(p, d1, d2, sigma, radius), None));
            }
            let mut fallback_leg = clamp_leg(leg);
            if fallback_leg <= 0.0 {
                fallback_leg = clamp_leg(config.leg);
            }
            (fallback_leg > 0.0).then(|| {
                (
                    LoopShape::parallelogram(p, d1, d2, fallback_leg),
                    Some(format!(
                        "arc radius {radius:.4} mm outside [{:.4} mm, {:.4} mm]: parallelogram with leg {fallback_leg:.4} mm",
                        config.min_radius, config.max_radius
                    )),
                )
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;
    use std::f64::consts::PI;

    #[test]
    fn arc_loop_of_case_c1_corner_1() {
        let p = Vec2::new(21.0, -1.0);
        let shape = LoopShape::arc(&p, &Vec2::x(), &Vec2::y(), 1.0, 1.0);
        assert_abs_diff_eq!(shape.leg, 1.0, epsilon = 1e-15);
        assert_abs_diff_eq!(shape.exit_end, Vec2::new(22.0, -1.0), epsilon = 1e-15);
        assert_abs_diff_eq!(shape.centre.unwrap(), Vec2::new(22.0, -2.0), epsilon = 1e-15);
        assert_abs_diff_eq!(shape.entry_start, Vec2::new(21.0, -2.0), epsilon = 1e-15);
        assert_abs_diff_eq!(shape.sweep.unwrap(), -1.5 * PI, epsilon = 1e-15);
        assert_abs_diff_eq!(shape.length(), 2.0 + 1.5 * PI, epsilon = 1e-14);
        // The arc really ends at B: the centre is ρ from both A and B.
        let centre = shape.centre.unwrap();
        assert_abs_diff_eq!((shape.entry_start - centre).norm(), 1.0, epsilon = 1e-15);
    }

    #[test]
    fn sizing_clamps_the_legs_and_falls_back() {
        let config = LoopConfig {
            style: LoopStyle::Arc,
            radius: 1.0,
            leg: 1.0,
            min_leg: 0.0,
            max_leg: 10.0,
            min_radius: 0.1,
            max_radius: 5.0,
            min_turn: 10f64.to_radians(),
        };
        let p = Vec2::zeros();
        // α = 5°: L = ρ cot(α/2) = 22.9 > 10, so ρ shrinks to 10·tan(2.5°) = 0.4366.
        let psi = 175f64.to_radians();
        let d2 = Vec2::new(psi.cos(), psi.sin());
        let (shape, fallback) = sized(&config, &p, &Vec2::x(), &d2, 1.0).unwrap();
        assert!(fallback.is_none());
        assert_abs_diff_eq!(shape.leg, 10.0, epsilon = 1e-12);
        assert_abs_diff_eq!(shape.radius.unwrap(), 10.0 * 2.5f64.to_radians().tan(), epsilon = 1e-12);
        // A tiny max_leg pushes ρ below its minimum: parallelogram.
        let tight = LoopConfig { max_leg: 0.5, ..config };
        let (shape, fallback) = sized(&tight, &p, &Vec2::x(), &d2, 1.0).unwrap();
        assert_eq!(shape.style, LoopStyle::Parallelogram);
        assert!(fallback.is_some());
        assert_abs_diff_eq!(shape.leg, 0.5);
    }
}
