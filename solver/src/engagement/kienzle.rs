//! The integral of Kienzle's chip-thickness term over the tool circle (docs/spec/engagement.md §11
//! item 4): F_t = k_c1.1·b·h^(1−m_c) with h = f_z·sin θ, so every force, torque and power of a
//! tooth is a multiple of max(0, sin θ)^(1−m_c) and every mean over the tooth phase a multiple of
//! its integral over the engaged arcs. The law's values themselves, [`crate::material::Kienzle`],
//! belong to the work material.

/// Cells of the table over [0, π/2]: the interpolation error is below 1e-10 of the integral.
const CELLS: usize = 2048;
/// Below this many cells from 0 the integral is computed directly (sin^a is not smooth at 0).
const DIRECT_CELLS: f64 = 4.0;

/// Nodes and weights of the n-point Gauss–Legendre rule on [−1, 1] (Newton on P_n).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    let mut rule = Vec::with_capacity(n);
    let order = n as f64;
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (order + 0.5)).cos();
        let mut derivative = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let k = k as f64;
                let p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            derivative = order * (x * p1 - p0) / (x * x - 1.0);
            let delta = p1 / derivative;
            x -= delta;
            if delta.abs() < 1e-15 {
                break;
            }
        }
        rule.push((x, 2.0 / ((1.0 - x * x) * derivative * derivative)));
    }
    rule
}

/// S(x) = ∫₀^x max(0, sin t)^a dt over the whole real line (a = 1 − m_c), from a table over
/// [0, π/2] with cubic Hermite interpolation (the slope sin^a is known exactly) and a direct
/// quadrature next to 0, where sin^a has no bounded derivatives.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SinPower {
    exponent: f64,
    cell: f64,
    /// S at the nodes i·cell, i = 0..=CELLS.
    values: Vec<f64>,
    /// sin^a at the nodes.
    slopes: Vec<f64>,
    rule: Vec<(f64, f64)>,
}

impl SinPower {
    pub(crate) fn new(exponent: f64) -> Self {
        let cell = std::f64::consts::FRAC_PI_2 / CELLS as f64;
        let rule = gauss_legendre(16);
        let mut table = Self { exponent, cell, values: Vec::with_capacity(CELLS + 1), slopes: Vec::new(), rule };
        let mut total = 0.0;
        table.values.push(0.0);
        table.slopes = (0..=CELLS).map(|i| (i as f64 * cell).sin().powf(exponent)).collect();
        for i in 0..CELLS {
            total += if i == 0 { table.direct(cell) } else { table.gauss(i as f64 * cell, (i + 1) as f64 * cell) };
            table.values.push(total);
        }
        table
    }

    /// The exponent a.
    pub(crate) fn exponent(&self) -> f64 {
        self.exponent
    }

    /// max(0, sin θ)^a, θ in radians.
    pub(crate) fn integrand(&self, theta: f64) -> f64 {
        let s = theta.sin();
        if s <= 0.0 { 0.0 } else { s.powf(self.exponent) }
    }

    fn gauss(&self, from: f64, to: f64) -> f64 {
        let (middle, half) = (0.5 * (from + to), 0.5 * (to - from));
        half * self.rule.iter().map(|(x, w)| w * (middle + half * x).sin().powf(self.exponent)).sum::<f64>()
    }

    /// ∫₀^x sin^a by t = x·u²: the integrand 2xu·sin^a(xu²) is smooth enough for Gauss.
    fn direct(&self, x: f64) -> f64 {
        if x <= 0.0 {
            return 0.0;
        }
        // Nodes on [0, 1].
        self.rule
            .iter()
            .map(|(node, w)| {
                let u = 0.5 * (node + 1.0);
                0.5 * w * 2.0 * x * u * (x * u * u).sin().powf(self.exponent)
            })
            .sum()
    }

    /// ∫₀^x sin^a for x in [0, π/2].
    fn quarter(&self, x: f64) -> f64 {
        let position = x / self.cell;
        if position < DIRECT_CELLS {
            return self.direct(x);
        }
        let index = (position.floor() as usize).min(CELLS - 1);
        let t = position - index as f64;
        let (y0, y1) = (self.values[index], self.values[index + 1]);
        let (d0, d1) = (self.slopes[index] * self.cell, self.slopes[index + 1] * self.cell);
        let (t2, t3) = (t * t, t * t * t);
        (2.0 * t3 - 3.0 * t2 + 1.0) * y0 + (t3 - 2.0 * t2 + t) * d0 + (-2.0 * t3 + 3.0 * t2) * y1 + (t3 - t2) * d1
    }

    /// ∫₀^π sin^a.
    pub(crate) fn half_turn(&self) -> f64 {
        2.0 * self.values[CELLS]
    }

    /// S(x) = ∫₀^x max(0, sin t)^a dt for any real x (radians).
    pub(crate) fn cumulative(&self, x: f64) -> f64 {
        let turns = (x / std::f64::consts::TAU).floor();
        let r = x - turns * std::f64::consts::TAU;
        let within = if r <= std::f64::consts::FRAC_PI_2 {
            self.quarter(r.max(0.0))
        } else if r < std::f64::consts::PI {
            self.half_turn() - self.quarter(std::f64::consts::PI - r)
        } else {
            self.half_turn()
        };
        turns * self.half_turn() + within
    }

    /// ∫ over [from, to] (radians, from ≤ to) of max(0, sin)^a.
    pub(crate) fn between(&self, from: f64, to: f64) -> f64 {
        (self.cumulative(to) - self.cumulative(from)).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Composite midpoint rule with u² substitution at both ends, independent of the table.
    fn reference(a: f64, from: f64, to: f64) -> f64 {
        let n = 200_000;
        let h = (to - from) / n as f64;
        (0..n).map(|i| (from + (i as f64 + 0.5) * h).sin().max(0.0).powf(a) * h).sum()
    }

    #[test]
    fn gauss_rule_integrates_polynomials() {
        let rule = gauss_legendre(16);
        let sum: f64 = rule.iter().map(|(x, w)| w * x.powi(30)).sum();
        assert!((sum - 2.0 / 31.0).abs() < 1e-13, "{sum}");
        assert!((rule.iter().map(|(_, w)| w).sum::<f64>() - 2.0).abs() < 1e-13);
    }

    #[test]
    fn matches_a_plain_quadrature() {
        for a in [0.6, 0.75, 0.85, 1.0] {
            let table = SinPower::new(a);
            for (from, to) in [(0.0, PI), (0.0, 1e-3), (0.1, 0.2), (1.0, 2.9), (-1.0, 0.5), (3.0, 7.0)] {
                let got = table.between(from, to);
                let want = reference(a, from, to);
                assert!((got - want).abs() < 1e-7 * want.max(1e-3), "a {a} [{from}, {to}]: {got} vs {want}");
            }
        }
        // a = 1: ∫₀^π sin = 2.
        assert!((SinPower::new(1.0).half_turn() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn whole_turns_add_one_half_turn_each() {
        let table = SinPower::new(0.75);
        let once = table.between(0.3, 0.3 + 2.0 * PI);
        assert!((once - table.half_turn()).abs() < 1e-12);
        assert!((table.between(-9.0, 9.0) - table.between(-9.0, 0.0) - table.between(0.0, 9.0)).abs() < 1e-12);
    }
}
