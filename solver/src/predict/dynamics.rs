//! Tool-tip deflection over one revolution from the cutting force (docs/spec/predict.md §3.8, S4):
//! steady-state forced response D_m = G(mΩ)·F_m per spindle harmonic, with G static, modal or a
//! measured compliance table; the FFT route for whole histories, and a precomputed periodic
//! impulse response so one prediction needs D only at the generation instant (O(N_t)).

use nalgebra::Complex;

use crate::tool::{FrfPoint, Mode, Stiffness};

/// Compliance of one direction.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Compliance {
    /// 1/k at every frequency.
    Static(f64),
    /// Sum of modes.
    Modal(Vec<Mode>),
    /// Measured table.
    Table(Vec<FrfPoint>),
}

impl Compliance {
    /// The X and Y compliances of a tool's stiffness.
    pub(crate) fn pair(stiffness: &Stiffness) -> (Self, Self) {
        match stiffness {
            Stiffness::Static { x, y } => (Self::Static(*x), Self::Static(*y)),
            Stiffness::Modal { x, y } => (Self::Modal(x.clone()), Self::Modal(y.clone())),
            Stiffness::Frf { x, y } => (Self::Table(x.clone()), Self::Table(y.clone())),
        }
    }

    /// G(ω) in mm/N, and whether ω lies outside a measured table (§5 E21: 0 above it, the first
    /// row below it).
    pub(crate) fn at(&self, omega: f64) -> (Complex<f64>, bool) {
        match self {
            Self::Static(k) => (Complex::new(1.0 / k, 0.0), false),
            Self::Modal(modes) => (modal(modes, omega), false),
            Self::Table(rows) => {
                let frequency = omega / std::f64::consts::TAU;
                let (first, last) = (rows[0], rows[rows.len() - 1]);
                if frequency > last.frequency_hz {
                    return (Complex::new(0.0, 0.0), true);
                }
                if frequency <= first.frequency_hz {
                    return (Complex::new(first.real, first.imag), frequency < first.frequency_hz);
                }
                let upper = rows.partition_point(|r| r.frequency_hz < frequency);
                let (a, b) = (rows[upper - 1], rows[upper]);
                let t = (frequency - a.frequency_hz) / (b.frequency_hz - a.frequency_hz);
                (Complex::new(a.real + t * (b.real - a.real), a.imag + t * (b.imag - a.imag)), false)
            }
        }
    }
}

fn modal(modes: &[Mode], omega: f64) -> Complex<f64> {
    modes
        .iter()
        .map(|m| {
            let ratio = omega / (std::f64::consts::TAU * m.frequency_hz);
            Complex::new(1.0 / m.stiffness, 0.0) / Complex::new(1.0 - ratio * ratio, 2.0 * m.damping_ratio * ratio)
        })
        .sum()
}

/// Periodic impulse response h over one revolution of N steps: D = h ⊛ F (circular), which is
/// D_m = G(mΩ)·F_m with G(−ω) = conj G(ω). Returns h and whether some harmonic was outside a
/// measured table.
pub(crate) fn kernel(compliance: &Compliance, spindle_rpm: f64, steps: usize) -> (Vec<f64>, bool) {
    let omega = std::f64::consts::TAU * spindle_rpm / 60.0;
    let half = steps / 2;
    let mut outside = false;
    let gains: Vec<Complex<f64>> = (0..=half)
        .map(|m| {
            let (g, out) = compliance.at(m as f64 * omega);
            outside |= out && m > 0;
            g
        })
        .collect();
    let table: Vec<(f64, f64)> =
        (0..steps).map(|k| (std::f64::consts::TAU * k as f64 / steps as f64).sin_cos()).collect();
    let n = steps as f64;
    let kernel = (0..steps)
        .map(|t| {
            let mut sum = gains[0].re;
            for (m, g) in gains.iter().enumerate().skip(1) {
                let (s, c) = table[(m * t) % steps];
                let term = g.re * c - g.im * s;
                if 2 * m == steps {
                    sum += if t % 2 == 0 { g.re } else { -g.re };
                } else {
                    sum += 2.0 * term;
                }
            }
            sum / n
        })
        .collect();
    (kernel, outside)
}

/// D at step `m` from the force component `axis`: Σ_n h[(m − n) mod N]·F[n].
fn convolve_at(kernel: &[f64], force: &[[f64; 3]], axis: usize, m: usize) -> f64 {
    let steps = kernel.len();
    force
        .iter()
        .enumerate()
        .filter(|(_, f)| f[axis] != 0.0)
        .map(|(n, f)| kernel[(m + steps - n) % steps] * f[axis])
        .sum()
}

/// Deflection (D_x, D_y) at rotation angle `psi` (radians), interpolated linearly between steps.
pub(crate) fn deflection_at(kernels: &(Vec<f64>, Vec<f64>), force: &[[f64; 3]], psi: f64) -> [f64; 2] {
    let steps = force.len();
    let position = psi.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU * steps as f64;
    let m0 = (position.floor() as usize).min(steps - 1);
    let m1 = (m0 + 1) % steps;
    let t = position - m0 as f64;
    let value = |kernel: &[f64], axis: usize| {
        (1.0 - t) * convolve_at(kernel, force, axis, m0) + t * convolve_at(kernel, force, axis, m1)
    };
    [value(&kernels.0, 0), value(&kernels.1, 1)]
}

/// The whole deflection history (D_x, D_y) over one revolution.
pub(crate) fn deflection_history(kernels: &(Vec<f64>, Vec<f64>), force: &[[f64; 3]]) -> Vec<[f64; 2]> {
    (0..force.len()).map(|m| [convolve_at(&kernels.0, force, 0, m), convolve_at(&kernels.1, force, 1, m)]).collect()
}

/// In-place discrete Fourier transform (forward: e^{−2πimn/N}; inverse without the 1/N):
/// radix-2 for powers of two, direct otherwise.
pub fn dft(data: &mut [Complex<f64>], inverse: bool) {
    let n = data.len();
    if n <= 1 {
        return;
    }
    let sign = if inverse { 1.0 } else { -1.0 };
    if !n.is_power_of_two() {
        let input = data.to_vec();
        for (m, out) in data.iter_mut().enumerate() {
            *out = input
                .iter()
                .enumerate()
                .map(|(k, x)| {
                    let angle = sign * std::f64::consts::TAU * ((m * k) % n) as f64 / n as f64;
                    x * Complex::new(angle.cos(), angle.sin())
                })
                .sum();
        }
        return;
    }
    let bits = n.trailing_zeros();
    for i in 0..n {
        let j = i.reverse_bits() >> (usize::BITS - bits);
        if j > i {
            data.swap(i, j);
        }
    }
    let mut length = 2;
    while length <= n {
        let angle = sign * std::f64::consts::TAU / length as f64;
        let step = Complex::new(angle.cos(), angle.sin());
        for chunk in data.chunks_mut(length) {
            let mut twiddle = Complex::new(1.0, 0.0);
            let (low, high) = chunk.split_at_mut(length / 2);
            for (a, b) in low.iter_mut().zip(high.iter_mut()) {
                let t = *b * twiddle;
                *b = *a - t;
                *a += t;
                twiddle *= step;
            }
        }
        length *= 2;
    }
}

/// Steady-state deflection (mm) over one revolution of a periodic force (N) sampled at equal
/// rotation steps, through a tool tip with `modes` (§3.8): D = IDFT(G(mΩ)·DFT(F)).
pub fn steady_state_deflection(force: &[f64], spindle_rpm: f64, modes: &[Mode]) -> Vec<f64> {
    let n = force.len();
    let mut spectrum: Vec<Complex<f64>> = force.iter().map(|f| Complex::new(*f, 0.0)).collect();
    dft(&mut spectrum, false);
    let omega = std::f64::consts::TAU * spindle_rpm / 60.0;
    for (m, bin) in spectrum.iter_mut().enumerate() {
        // Bins above N/2 are the negative harmonics: G(−ω) = conj G(ω).
        let harmonic = if 2 * m <= n { m as f64 } else { m as f64 - n as f64 };
        let g = modal(modes, harmonic.abs() * omega);
        let g = if harmonic < 0.0 { g.conj() } else { g };
        let g = if 2 * m == n { Complex::new(g.re, 0.0) } else { g };
        *bin *= g;
    }
    dft(&mut spectrum, true);
    spectrum.iter().map(|c| c.re / n as f64).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radix_two_and_direct_transforms_agree() {
        let signal: Vec<Complex<f64>> =
            (0..16).map(|k| Complex::new((k as f64 * 0.7).sin(), (k as f64 * 0.3).cos())).collect();
        let mut fast = signal.clone();
        dft(&mut fast, false);
        for (m, value) in fast.iter().enumerate() {
            let direct: Complex<f64> = signal
                .iter()
                .enumerate()
                .map(|(k, x)| {
                    let angle = -std::f64::consts::TAU * (m * k) as f64 / 16.0;
                    x * Complex::new(angle.cos(), angle.sin())
                })
                .sum();
            assert!((value - direct).norm() < 1e-12);
        }
        dft(&mut fast, true);
        for (a, b) in fast.iter().zip(&signal) {
            assert!((a / 16.0 - b).norm() < 1e-12);
        }
    }

    #[test]
    fn kernel_convolution_equals_the_spectral_route() {
        let modes = [Mode { stiffness: 5000.0, frequency_hz: 1370.0, damping_ratio: 0.05 }];
        let steps = 90;
        let force: Vec<[f64; 3]> = (0..steps)
            .map(|k| {
                let x = (k as f64 * 0.37).sin().max(0.0) * 40.0;
                [x, 0.5 * x, 0.0]
            })
            .collect();
        let spectral = steady_state_deflection(&force.iter().map(|f| f[0]).collect::<Vec<_>>(), 6000.0, &modes);
        let compliance = Compliance::Modal(modes.to_vec());
        let (h, outside) = kernel(&compliance, 6000.0, steps);
        assert!(!outside);
        let history = deflection_history(&(h.clone(), h), &force);
        for (a, b) in history.iter().zip(&spectral) {
            assert!((a[0] - b).abs() < 1e-12, "{} vs {b}", a[0]);
        }
        // A static compliance is a pure scaling.
        let (h, _) = kernel(&Compliance::Static(2000.0), 6000.0, steps);
        let history = deflection_history(&(h.clone(), h), &force);
        for (a, f) in history.iter().zip(&force) {
            assert!((a[0] - f[0] / 2000.0).abs() < 1e-12);
        }
    }

    #[test]
    fn table_compliance_interpolates_and_flags_the_band() {
        let table = Compliance::Table(vec![
            FrfPoint { frequency_hz: 0.0, real: 2e-4, imag: 0.0 },
            FrfPoint { frequency_hz: 1000.0, real: 0.0, imag: -1e-3 },
        ]);
        let (g, out) = table.at(std::f64::consts::TAU * 500.0);
        assert!((g.re - 1e-4).abs() < 1e-15 && (g.im + 5e-4).abs() < 1e-15 && !out);
        let (g, out) = table.at(std::f64::consts::TAU * 2000.0);
        assert!(g.norm() == 0.0 && out);
    }
}
