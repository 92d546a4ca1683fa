//! Arc length of a parametric curve and its inverse (docs/spec/segment.md §2.9 "Curve types"): composite
//! 5-point Gauss–Legendre quadrature on adaptively halved panels, inverted by safeguarded
//! Newton iteration.

use crate::error::ErrorCode;
use std::cell::Cell;

use crate::error::SolverError;

/// 5-point Gauss–Legendre nodes on [−1, 1].
pub(crate) const NODES: [f64; 5] =
    [-0.906_179_845_938_664, -0.538_469_310_105_683_1, 0.0, 0.538_469_310_105_683_1, 0.906_179_845_938_664];
/// Their weights.
pub(crate) const WEIGHTS: [f64; 5] = [
    0.236_926_885_056_189_1,
    0.478_628_670_499_366_5,
    0.568_888_888_888_888_9,
    0.478_628_670_499_366_5,
    0.236_926_885_056_189_1,
];

/// Deepest halving of a panel.
const MAX_DEPTH: u32 = 16;

/// Most panels one curve may use (memory bound: 16 bytes each).
pub(crate) const MAX_PANELS: usize = 2_000_000;

/// ∫ speed over [a, b] by one 5-point Gauss–Legendre panel.
pub(crate) fn gauss_panel(speed: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (centre, half) = (0.5 * (a + b), 0.5 * (b - a));
    let mut sum = 0.0;
    for (node, weight) in NODES.iter().zip(WEIGHTS) {
        sum += weight * speed(centre + half * node);
    }
    sum * half
}

/// The integrand of an arc-length table, |dC/du|, and its integral over one panel: a curve of
/// polynomial pieces finds the piece once per panel, not once per node (the chord search takes
/// an arc length at every command point and window end).
pub(crate) trait Speed {
    fn speed(&self, u: f64) -> f64;

    /// ∫ speed over [a, b] by one 5-point Gauss–Legendre panel.
    fn panel(&self, a: f64, b: f64) -> f64 {
        gauss_panel(|u| self.speed(u), a, b)
    }
}

impl<F: Fn(f64) -> f64> Speed for F {
    fn speed(&self, u: f64) -> f64 {
        self(u)
    }
}

/// Panel boundaries `u[k]` with the arc length `s[k]` from the start to each.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ArcLengthTable {
    u: Vec<f64>,
    s: Vec<f64>,
    /// The panel found last: the segmentation walks along the curve, so the next lookup is
    /// nearly always in it or the next one (no binary search over the whole table).
    last_panel: Cell<usize>,
}

impl ArcLengthTable {
    /// Tabulates ∫ speed du over the increasing `breaks` (at least two; the curve's knots or
    /// other places where the speed is not smooth), each interval cut into `panels_per_break`
    /// equal panels and each panel halved until one more halving changes its length by less than
    /// 1e-14 mm + 1e-13 of it.
    ///
    /// # Errors
    /// `E_TOO_MANY_POINTS` (at `field`) past [`MAX_PANELS`].
    pub(crate) fn build(
        speed: &impl Speed,
        breaks: &[f64],
        panels_per_break: usize,
        field: &str,
    ) -> Result<Self, SolverError> {
        let mut table =
            Self { u: vec![breaks.first().copied().unwrap_or(0.0)], s: vec![0.0], last_panel: Cell::new(0) };
        for pair in breaks.windows(2) {
            let (start, end) = (pair[0], pair[1]);
            for k in 0..panels_per_break {
                let a = start + (end - start) * k as f64 / panels_per_break as f64;
                let b = if k + 1 == panels_per_break {
                    end
                } else {
                    start + (end - start) * (k + 1) as f64 / panels_per_break as f64
                };
                let whole = speed.panel(a, b);
                table.refine(speed, a, b, whole, 0, field)?;
            }
        }
        Ok(table)
    }

    fn refine(
        &mut self,
        speed: &impl Speed,
        a: f64,
        b: f64,
        whole: f64,
        depth: u32,
        field: &str,
    ) -> Result<(), SolverError> {
        let middle = 0.5 * (a + b);
        let (left, right) = (speed.panel(a, middle), speed.panel(middle, b));
        let converged = (left + right - whole).abs() <= 1e-14 + 1e-13 * whole.abs();
        if converged || depth >= MAX_DEPTH || middle <= a || middle >= b {
            if self.u.len() + 2 > MAX_PANELS {
                return Err(SolverError::new(
                    ErrorCode::TooManyPoints,
                    format!("the curve needs more than {MAX_PANELS} arc-length panels; simplify it"),
                )
                .at(field));
            }
            let base = self.s.last().copied().unwrap_or(0.0);
            self.u.push(middle);
            self.s.push(base + left);
            self.u.push(b);
            self.s.push(base + left + right);
            return Ok(());
        }
        self.refine(speed, a, middle, left, depth + 1, field)?;
        self.refine(speed, middle, b, right, depth + 1, field)
    }

    /// Total arc length, mm.
    pub(crate) fn length(&self) -> f64 {
        self.s.last().copied().unwrap_or(0.0)
    }

    /// Index of the panel holding parameter `u`.
    fn panel_of_u(&self, u: f64) -> usize {
        self.panel_of(&self.u, u)
    }

    /// Index k of the panel with `stations[k] ≤ x < stations[k + 1]` (the last panel at and
    /// past the end, the first before the start), trying the last panel found and the next.
    fn panel_of(&self, stations: &[f64], x: f64) -> usize {
        let last_panel = stations.len().saturating_sub(2);
        let hint = self.last_panel.get();
        for k in [hint, hint + 1] {
            if k <= last_panel && k + 1 < stations.len() && stations[k] <= x && x < stations[k + 1] {
                self.last_panel.set(k);
                return k;
            }
        }
        let k = stations.partition_point(|&v| v <= x).saturating_sub(1).min(last_panel);
        self.last_panel.set(k);
        k
    }

    /// Arc length from the start to parameter `u`.
    pub(crate) fn s_at(&self, speed: &impl Speed, u: f64) -> f64 {
        let k = self.panel_of_u(u);
        match (self.u.get(k), self.s.get(k)) {
            (Some(&u0), Some(&s0)) if u > u0 => s0 + speed.panel(u0, u),
            (_, Some(&s0)) => s0,
            _ => 0.0,
        }
    }

    /// Parameter at arc length `s` (clamped to the curve).
    pub(crate) fn u_at(&self, speed: &impl Speed, s: f64) -> f64 {
        let k = self.panel_of(&self.s, s);
        let (Some(&u0), Some(&u1), Some(&s0), Some(&s1)) =
            (self.u.get(k), self.u.get(k + 1), self.s.get(k), self.s.get(k + 1))
        else {
            return self.u.first().copied().unwrap_or(0.0);
        };
        if s <= s0 {
            return u0;
        }
        if s >= s1 {
            return u1;
        }
        let target = s - s0;
        // Newton on σ(u) = ∫_{u0}^{u} speed − target, kept inside the bracket by bisection.
        let (mut lo, mut hi) = (u0, u1);
        let mut u = u0 + (u1 - u0) * target / (s1 - s0);
        for _ in 0..super::numeric::ITERATION_CAP {
            let residual = speed.panel(u0, u) - target;
            if residual > 0.0 {
                hi = u;
            } else {
                lo = u;
            }
            if residual.abs() <= 1e-15 * (1.0 + s.abs()) || hi - lo <= f64::EPSILON * u.abs() {
                return u;
            }
            let slope = speed.speed(u);
            let newton = u - residual / slope;
            u = if slope > 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        }
        u
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn quarter_ellipse_length_matches_the_reference() {
        let (a, b) = (100.0_f64, 50.0_f64);
        let speed = |t: f64| (a * a * t.sin().powi(2) + b * b * t.cos().powi(2)).sqrt();
        let table = ArcLengthTable::build(&speed, &[0.0, std::f64::consts::FRAC_PI_2], 16, "curve").unwrap();
        assert_relative_eq!(table.length(), 121.105_602_756_846_01, max_relative = 1e-13);
        let t = table.u_at(&speed, 60.0);
        assert_relative_eq!(table.s_at(&speed, t), 60.0, max_relative = 1e-14);
    }
}
