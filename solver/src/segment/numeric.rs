//! Bracketed one-dimensional solvers for the segmentation (docs/spec/segment.md §2.9, §7 "Numerics"): Brent's
//! minimiser (golden section with parabolic steps) for the chord deviation and Brent's root
//! finder, kept on the side of the root where the function is not positive (the greedy chord's
//! "last point that still fits").

/// Largest iteration count of every loop here (docs/spec/segment.md §4, E14: iteration cap 200).
pub(crate) const ITERATION_CAP: usize = 200;

/// Minimises `f` on `[lo, hi]` to a position tolerance `tol` (absolute, > 0). Returns the best
/// position and value found. Brent (1973), `fmin`: golden section safeguarded parabolic steps.
pub(crate) fn minimise(f: impl Fn(f64) -> f64, lo: f64, hi: f64, tol: f64) -> (f64, f64) {
    const GOLDEN: f64 = 0.381_966_011_250_105_1; // (3 − √5)/2
    let (mut a, mut b) = (lo.min(hi), lo.max(hi));
    let mut x = a + GOLDEN * (b - a);
    let (mut w, mut v) = (x, x);
    let mut fx = f(x);
    let (mut fw, mut fv) = (fx, fx);
    let (mut d, mut e) = (0.0_f64, 0.0_f64);
    for _ in 0..ITERATION_CAP {
        let middle = 0.5 * (a + b);
        let tol1 = f64::EPSILON.sqrt() * x.abs() * 1e-4 + tol / 3.0;
        let tol2 = 2.0 * tol1;
        if (x - middle).abs() <= tol2 - 0.5 * (b - a) {
            break;
        }
        let mut golden_step = true;
        if e.abs() > tol1 {
            // Parabola through (v, fv), (w, fw), (x, fx).
            let r = (x - w) * (fx - fv);
            let mut q = (x - v) * (fx - fw);
            let mut p = (x - v) * q - (x - w) * r;
            q = 2.0 * (q - r);
            if q > 0.0 {
                p = -p;
            }
            q = q.abs();
            let previous = e;
            e = d;
            if p.abs() < (0.5 * q * previous).abs() && p > q * (a - x) && p < q * (b - x) {
                d = p / q;
                let u = x + d;
                if u - a < tol2 || b - u < tol2 {
                    d = if middle >= x { tol1 } else { -tol1 };
                }
                golden_step = false;
            }
        }
        if golden_step {
            e = if x >= middle { a - x } else { b - x };
            d = GOLDEN * e;
        }
        let u = if d.abs() >= tol1 {
            x + d
        } else if d > 0.0 {
            x + tol1
        } else {
            x - tol1
        };
        let fu = f(u);
        if fu <= fx {
            if u >= x {
                a = x;
            } else {
                b = x;
            }
            (v, fv, w, fw, x, fx) = (w, fw, x, fx, u, fu);
        } else {
            if u < x {
                a = u;
            } else {
                b = u;
            }
            if fu <= fw || w == x {
                (v, fv, w, fw) = (w, fw, u, fu);
            } else if fu <= fv || v == x || v == w {
                (v, fv) = (u, fu);
            }
        }
    }
    (x, fx)
}

/// The last point that still fits: given `lo` with `g(lo) ≤ 0` and `hi` with `g(hi) > 0`,
/// returns a point `x` with `g(x) ≤ 0` within `tol` (absolute, > 0) of a sign change of `g`
/// between them. Brent (1973), `zeroin`, with the answer taken on the non-positive side. `None`
/// when the iteration cap is reached (E14) or `g` stops being a number.
pub(crate) fn last_fitting(g: impl Fn(f64) -> f64, lo: f64, g_lo: f64, hi: f64, g_hi: f64, tol: f64) -> Option<f64> {
    let (mut a, mut fa, mut b, mut fb) = (lo, g_lo, hi, g_hi);
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for _ in 0..ITERATION_CAP {
        if (fb > 0.0) == (fc > 0.0) {
            (c, fc) = (a, fa);
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            (a, fa) = (b, fb);
            (b, fb) = (c, fc);
            (c, fc) = (a, fa);
        }
        let tol1 = 2.0 * f64::EPSILON * b.abs() + 0.5 * tol;
        let half = 0.5 * (c - b);
        if half.abs() <= tol1 || fb == 0.0 {
            return Some(if fb <= 0.0 { b } else { c });
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            let s = fb / fa;
            let (mut p, mut q);
            if a == c {
                p = 2.0 * half * s;
                q = 1.0 - s;
            } else {
                let qa = fa / fc;
                let r = fb / fc;
                p = s * (2.0 * half * qa * (qa - r) - (b - a) * (r - 1.0));
                q = (qa - 1.0) * (r - 1.0) * (s - 1.0);
            }
            if p > 0.0 {
                q = -q;
            } else {
                p = -p;
            }
            if 2.0 * p < (3.0 * half * q - (tol1 * q).abs()).min((e * q).abs()) {
                e = d;
                d = p / q;
            } else {
                d = half;
                e = d;
            }
        } else {
            d = half;
            e = d;
        }
        (a, fa) = (b, fb);
        b += if d.abs() > tol1 { d } else { tol1.copysign(half) };
        fb = g(b);
        if fb.is_nan() {
            return None;
        }
    }
    None
}

/// sin x and cos x without the library's argument reduction, for the small angles of chords and
/// arc-length panels (an ellipse's segmentation cost its trigonometry): the Taylor polynomials,
/// to x⁸ below 1/32, to x¹⁴ below 1/4 and to x¹⁸ up to π/4 (the first term left out is under
/// 1e-19 of the value in each), within an ulp or two of `f64::sin_cos`, which takes over beyond.
#[inline]
pub(crate) fn small_sin_cos(x: f64) -> (f64, f64) {
    let x2 = x * x;
    if x.abs() <= 1.0 / 32.0 {
        let sin = x + x * x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 - x2 / 5040.0));
        let cos = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 / 40_320.0)));
        return (sin, cos);
    }
    if x.abs() <= 0.25 {
        let sin = x + x
            * x2
            * (-1.0 / 6.0
                + x2 * (1.0 / 120.0
                    + x2 * (-1.0 / 5040.0
                        + x2 * (1.0 / 362_880.0 + x2 * (-1.0 / 39_916_800.0 + x2 / 6_227_020_800.0)))));
        let cos = 1.0
            + x2 * (-0.5
                + x2 * (1.0 / 24.0
                    + x2 * (-1.0 / 720.0
                        + x2 * (1.0 / 40_320.0
                            + x2 * (-1.0 / 3_628_800.0 + x2 * (1.0 / 479_001_600.0 - x2 / 87_178_291_200.0))))));
        return (sin, cos);
    }
    if x.abs() > std::f64::consts::FRAC_PI_4 {
        return x.sin_cos();
    }
    // 1/k! for the odd and even powers, highest first.
    const SIN: [f64; 8] = [
        1.0 / 355_687_428_096_000.0,
        -1.0 / 1_307_674_368_000.0,
        1.0 / 6_227_020_800.0,
        -1.0 / 39_916_800.0,
        1.0 / 362_880.0,
        -1.0 / 5040.0,
        1.0 / 120.0,
        -1.0 / 6.0,
    ];
    const COS: [f64; 9] = [
        -1.0 / 6_402_373_705_728_000.0,
        1.0 / 20_922_789_888_000.0,
        -1.0 / 87_178_291_200.0,
        1.0 / 479_001_600.0,
        -1.0 / 3_628_800.0,
        1.0 / 40_320.0,
        -1.0 / 720.0,
        1.0 / 24.0,
        -0.5,
    ];
    let sin = x + x * x2 * SIN.iter().fold(0.0, |sum, &c| sum * x2 + c);
    let cos = 1.0 + x2 * COS.iter().fold(0.0, |sum, &c| sum * x2 + c);
    (sin, cos)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_abs_diff_eq;

    #[test]
    fn minimise_finds_a_smooth_minimum() {
        let (x, fx) = minimise(|x| (x - 0.3).powi(2), 0.0, 1.0, 1e-10);
        assert_abs_diff_eq!(x, 0.3, epsilon = 1e-9);
        assert_abs_diff_eq!(fx, 0.0, epsilon = 1e-18);
    }

    #[test]
    fn last_fitting_stays_on_the_fitting_side() {
        let g = |x: f64| x * x - 2.0;
        let x = last_fitting(g, 0.0, g(0.0), 2.0, g(2.0), 1e-13).unwrap();
        assert!(g(x) <= 0.0);
        assert_abs_diff_eq!(x, std::f64::consts::SQRT_2, epsilon = 1e-12);
        // Reversed orientation (hi below lo) works too.
        let h = |x: f64| 1.0 - x;
        let y = last_fitting(h, 3.0, h(3.0), 0.5, h(0.5), 1e-13).unwrap();
        assert!(h(y) <= 0.0);
        assert_abs_diff_eq!(y, 1.0, epsilon = 1e-12);
    }

    #[test]
    fn last_fitting_gives_up_on_nan() {
        assert!(last_fitting(|_| f64::NAN, 0.0, -1.0, 1.0, 1.0, 1e-12).is_none());
    }

    #[test]
    fn small_sin_cos_is_the_library_s_within_two_ulps() {
        let ulps = |a: f64, b: f64| (a - b).abs() / f64::EPSILON / b.abs().max(f64::MIN_POSITIVE);
        for k in -20_000..=20_000 {
            // Up to π/4 and past it, densely near 0 and near the tiers' ends.
            for x in
                [f64::from(k) * 4e-5, f64::from(k) * 1e-9, 1.0 / 32.0 + f64::from(k) * 1e-8, 0.25 + f64::from(k) * 1e-8]
            {
                let (sin, cos) = small_sin_cos(x);
                let (library_sin, library_cos) = x.sin_cos();
                assert!(ulps(sin, library_sin) <= 2.0 || sin == library_sin, "sin {x}: {sin} vs {library_sin}");
                assert!(ulps(cos, library_cos) <= 2.0, "cos {x}: {cos} vs {library_cos}");
            }
        }
    }
}
