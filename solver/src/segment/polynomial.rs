//! Polynomials of low degree and their real roots on an interval, for the exact extrema of a plain
//! B-spline span (docs/spec/segment.md §2.9a: "curvature bounds ... of a NURBS span" and exact chord
//! deviations): the roots of the derivative split the interval into pieces where the polynomial
//! is monotone, and each piece whose ends differ in sign holds one root, found by Newton steps
//! kept inside the bracket (bisection where a step leaves it); first, the signs of the Bernstein
//! coefficients on the interval settle the common cases of no root and of one. No sampling, so
//! no root between samples is missed.

/// Highest degree handled (the radius of curvature of a cubic span leads to degree 7).
pub(crate) const MAX_DEGREE: usize = 8;

/// Most Newton or bisection steps for one root (bisection alone narrows the bracket to 2⁻¹⁰⁰).
const ROOT_STEPS: usize = 100;
/// A root is found when a Newton step moves it less than this fraction of its bracket: its
/// function's extrema sit at such roots, and a function is flat at its extremum, so the value
/// there is then exact to about the square of it.
const ROOT_WIDTH: f64 = 1e-12;

/// Σ c_k·x^k, lowest power first, of degree at most [`MAX_DEGREE`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Polynomial {
    coefficients: [f64; MAX_DEGREE + 1],
    /// Index of the highest non-zero coefficient (0 for a constant, also for zero).
    degree: usize,
}

/// Real roots in increasing order, at most [`MAX_DEGREE`] of them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Roots {
    values: [f64; MAX_DEGREE],
    count: usize,
}

impl Roots {
    fn push(&mut self, x: f64) {
        // A root at a piece's shared end is found from both sides: keep it once.
        if self.count > 0 && self.values[self.count - 1] == x {
            return;
        }
        if self.count < MAX_DEGREE {
            self.values[self.count] = x;
            self.count += 1;
        }
    }

    pub(crate) fn as_slice(&self) -> &[f64] {
        &self.values[..self.count]
    }
}

impl Polynomial {
    /// The polynomial with these coefficients (lowest power first; at most `MAX_DEGREE + 1`,
    /// the rest ignored).
    pub(crate) fn new(coefficients: &[f64]) -> Self {
        let mut all = [0.0; MAX_DEGREE + 1];
        for (slot, &c) in all.iter_mut().zip(coefficients) {
            *slot = c;
        }
        let degree = all.iter().rposition(|&c| c != 0.0).unwrap_or(0);
        Self { coefficients: all, degree }
    }

    pub(crate) fn value(&self, x: f64) -> f64 {
        self.coefficients[..=self.degree].iter().rev().fold(0.0, |sum, &c| sum * x + c)
    }

    pub(crate) fn derivative(&self) -> Self {
        let mut derivative = [0.0; MAX_DEGREE + 1];
        for k in 1..=self.degree {
            derivative[k - 1] = k as f64 * self.coefficients[k];
        }
        Self::new(&derivative)
    }

    /// The real roots in [lo, hi] (a root of even multiplicity, where the sign does not change,
    /// may be missed; callers take the extrema of a function at roots of its derivative and at
    /// the interval's ends, where such a double root is a flat turn, not an extremum). None for
    /// the zero polynomial.
    pub(crate) fn roots_in(&self, lo: f64, hi: f64) -> Roots {
        let mut roots = Roots { values: [0.0; MAX_DEGREE], count: 0 };
        if lo.is_nan() || hi.is_nan() || lo > hi || self.degree == 0 {
            return roots;
        }
        if self.degree == 1 {
            let root = -self.coefficients[0] / self.coefficients[1];
            if root >= lo && root <= hi {
                roots.push(root);
            }
            return roots;
        }
        if self.degree == 2 {
            let [c, b, a] = [self.coefficients[0], self.coefficients[1], self.coefficients[2]];
            let mut found = [f64::NAN; 2];
            for (slot, root) in found.iter_mut().zip(quadratic_roots(a, b, c)) {
                *slot = root;
            }
            let (first, second) = (found[0], found[1]);
            for root in [first.min(second), first.max(second)] {
                if root >= lo && root <= hi {
                    roots.push(root);
                }
            }
            return roots;
        }
        let slope = self.derivative();
        // Most spans' turning polynomials have no root or one on the interval, which the signs
        // of their Bernstein coefficients show without finding the derivative's roots.
        match self.bernstein_sign_changes(lo, hi) {
            Some(0) => return roots,
            Some(1) => {
                roots.push(self.root_between(&slope, lo, hi, self.value(lo)));
                return roots;
            }
            _ => {}
        }
        let turns = slope.roots_in(lo, hi);
        let mut left = lo;
        let mut value_left = self.value(lo);
        for &right in turns.as_slice().iter().chain(std::iter::once(&hi)) {
            let value_right = self.value(right);
            if value_left == 0.0 {
                roots.push(left);
            } else if value_left.signum() != value_right.signum() && value_right != 0.0 {
                roots.push(self.root_between(&slope, left, right, value_left));
            }
            (left, value_left) = (right, value_right);
        }
        if value_left == 0.0 {
            roots.push(left);
        }
        roots
    }

    /// The sign changes of the polynomial's Bernstein coefficients on [lo, hi], which bound its
    /// roots there and share their parity (variation diminishing: none, no root; one, exactly
    /// one); `None` when a coefficient is within rounding of zero, where the count may be off.
    fn bernstein_sign_changes(&self, lo: f64, hi: f64) -> Option<usize> {
        let n = self.degree;
        // Every quantity below is a sum of terms no larger than Σ|a_k|·r^k (r the interval's
        // reach from 0), so it is exact to about n²·ε of that: a coefficient within 1e-12 of it
        // may have the wrong sign.
        let reach = lo.abs() + (hi - lo);
        let magnitude = self.coefficients[..=n].iter().rev().fold(0.0, |sum, c| sum * reach + c.abs());
        // p(lo + w·s) by Taylor shifts (repeated synthetic division), then scaled by w^k.
        let mut shifted = self.coefficients;
        for k in 0..n {
            for j in (k..n).rev() {
                shifted[j] += lo * shifted[j + 1];
            }
        }
        let width = hi - lo;
        let mut power = 1.0;
        for c in &mut shifted[..=n] {
            *c *= power;
            power *= width;
        }
        // b_i = Σ_{j ≤ i} C(i, j)/C(n, j)·c_j.
        let mut bernstein = [0.0; MAX_DEGREE + 1];
        for (i, value) in bernstein.iter_mut().enumerate().take(n + 1) {
            let mut sum = 0.0;
            let mut ratio = 1.0; // C(i, j)/C(n, j), from j = 0
            for (j, &c) in shifted[..=i].iter().enumerate() {
                sum += ratio * c;
                ratio *= (i - j) as f64 / (n - j) as f64;
            }
            *value = sum;
        }
        let margin = 1e-12 * magnitude;
        if !(margin.is_finite() && margin > 0.0) || bernstein[..=n].iter().any(|b| b.abs() <= margin) {
            return None;
        }
        Some(bernstein[..=n].windows(2).filter(|pair| pair[0].signum() != pair[1].signum()).count())
    }

    /// The root of the polynomial on [left, right], where its sign changes once.
    fn root_between(&self, slope: &Self, left: f64, right: f64, value_left: f64) -> f64 {
        bracketed_root(&|x| self.value(x), &|x| slope.value(x), left, right, value_left, ROOT_WIDTH)
    }
}

/// The real roots of a·x² + b·x + c (none, one or two, in no order); a linear equation when
/// a = 0.
pub(crate) fn quadratic_roots(a: f64, b: f64, c: f64) -> impl Iterator<Item = f64> {
    let mut roots = [f64::NAN; 2];
    if a == 0.0 {
        if b != 0.0 {
            roots[0] = -c / b;
        }
    } else {
        let discriminant = b * b - 4.0 * a * c;
        if discriminant >= 0.0 {
            // The form without cancellation: q = −(b + sign(b)·√D)/2, roots q/a and c/q.
            let q = -0.5 * (b + b.signum() * discriminant.sqrt());
            roots[0] = q / a;
            if q != 0.0 {
                roots[1] = c / q;
            }
        }
    }
    roots.into_iter().filter(|x| x.is_finite())
}

/// The root of `g` on [left, right], whose ends' values differ in sign (or one is zero) and
/// whose sign changes once between them: Newton steps kept inside the bracket, bisection where
/// a step leaves it, until a step moves less than `width` of the bracket. Inlined: the chord
/// search finds a hump's peak with it for every chord it measures.
#[inline]
pub(crate) fn bracketed_root(
    g: &impl Fn(f64) -> f64,
    slope: &impl Fn(f64) -> f64,
    left: f64,
    right: f64,
    g_left: f64,
    width: f64,
) -> f64 {
    let rising = g_left < 0.0;
    let (mut lo, mut hi) = (left, right);
    let mut x = 0.5 * (lo + hi);
    for _ in 0..ROOT_STEPS {
        let value = g(x);
        if value == 0.0 {
            return x;
        }
        if (value < 0.0) == rising {
            lo = x;
        } else {
            hi = x;
        }
        let step = value / slope(x);
        if step.abs() <= width * (right - left) {
            return x; // converged: a smaller step could round onto a bracket end
        }
        let newton = x - step;
        x = if newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        if hi - lo <= width * (right - left) {
            return x;
        }
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    impl Polynomial {
        /// p · q (degrees adding up to at most [`MAX_DEGREE`]; higher terms are dropped).
        fn times(&self, other: &Self) -> Self {
            let mut product = [0.0; MAX_DEGREE + 1];
            for (i, &a) in self.coefficients[..=self.degree].iter().enumerate() {
                for (j, &b) in other.coefficients[..=other.degree].iter().enumerate() {
                    if i + j <= MAX_DEGREE {
                        product[i + j] += a * b;
                    }
                }
            }
            Self::new(&product)
        }
    }

    /// The polynomial with these roots (leading coefficient `scale`).
    fn with_roots(roots: &[f64], scale: f64) -> Polynomial {
        roots.iter().fold(Polynomial::new(&[scale]), |p, &r| p.times(&Polynomial::new(&[-r, 1.0])))
    }

    #[test]
    fn bernstein_signs_count_the_roots_they_can() {
        // No root, one root, three roots (the signs may only bound them), a root at an end.
        let none = with_roots(&[2.0, 3.0, -1.0, 1.5, -0.5], 2.0);
        assert_eq!(none.bernstein_sign_changes(0.0, 1.0), Some(0));
        let one = with_roots(&[0.3, 2.0, 3.0, -1.0], -1.0);
        assert_eq!(one.bernstein_sign_changes(0.0, 1.0), Some(1));
        assert_eq!(one.roots_in(0.0, 1.0).as_slice().len(), 1);
        assert!((one.roots_in(0.0, 1.0).as_slice()[0] - 0.3).abs() < 1e-14);
        let three = with_roots(&[0.2, 0.5, 0.7, 4.0], 1.0);
        assert!(three.bernstein_sign_changes(0.0, 1.0).is_some_and(|changes| changes >= 3));
        assert_eq!(three.roots_in(0.0, 1.0).as_slice().len(), 3);
        let at_end = with_roots(&[0.0, 2.0, 3.0], 1.0);
        assert_eq!(at_end.bernstein_sign_changes(0.0, 1.0), None);
        // Shifted away from 0: the same polynomial moved by 10, on [10, 11].
        let moved = with_roots(&[10.3, 12.0, 13.0, 9.0], -1.0);
        assert_eq!(moved.bernstein_sign_changes(10.0, 11.0), Some(1));
        assert!((moved.roots_in(10.0, 11.0).as_slice()[0] - 10.3).abs() < 1e-12);
    }

    #[test]
    fn finds_every_simple_root_in_the_interval() {
        let cases: [&[f64]; 5] = [
            &[0.3],
            &[0.1, 0.7],
            &[-2.0, 0.25, 0.5, 0.75, 3.0],
            &[0.01, 0.011, 0.5, 0.98, 0.99],
            &[0.05, 0.15, 0.3, 0.45, 0.6, 0.75, 0.9],
        ];
        for roots in cases {
            for scale in [1e-6, 1.0, 1e6] {
                let found = with_roots(roots, scale).roots_in(0.0, 1.0);
                let inside: Vec<f64> = roots.iter().copied().filter(|r| (0.0..=1.0).contains(r)).collect();
                assert_eq!(found.as_slice().len(), inside.len(), "{roots:?} × {scale}: {:?}", found.as_slice());
                for (got, want) in found.as_slice().iter().zip(&inside) {
                    assert!((got - want).abs() < 1e-12, "{roots:?} × {scale}: {got} vs {want}");
                }
            }
        }
    }

    #[test]
    fn roots_at_the_ends_count_once() {
        let found = with_roots(&[0.0, 0.5, 1.0], 2.0).roots_in(0.0, 1.0);
        assert_eq!(found.as_slice().len(), 3);
        for (got, want) in found.as_slice().iter().zip([0.0, 0.5, 1.0]) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }

    #[test]
    fn constants_and_lines() {
        assert!(Polynomial::new(&[0.0]).roots_in(0.0, 1.0).as_slice().is_empty());
        assert!(Polynomial::new(&[2.0, 0.0, 0.0]).roots_in(0.0, 1.0).as_slice().is_empty());
        assert_eq!(Polynomial::new(&[-1.0, 4.0]).roots_in(0.0, 1.0).as_slice(), &[0.25]);
        assert!(Polynomial::new(&[-1.0, 4.0]).roots_in(0.5, 1.0).as_slice().is_empty());
    }

    #[test]
    fn algebra_matches_evaluation() {
        let p = Polynomial::new(&[1.0, -2.0, 0.5]);
        let q = Polynomial::new(&[0.25, 3.0]);
        for x in [-1.5, 0.0, 0.3, 2.0] {
            assert!((p.times(&q).value(x) - p.value(x) * q.value(x)).abs() < 1e-12);
            assert!((p.derivative().value(x) - (-2.0 + x)).abs() < 1e-12);
        }
    }
}
