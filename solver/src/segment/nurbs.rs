//! NURBS curves of degree 1–5 (docs/spec/segment.md §1.2 "Prior art uses NURBS", §2.9 "Curve types"):
//! knot-vector and weight validation, points and the first two derivatives by the basis-function
//! algorithms A2.1–A2.3 of Piegl & Tiller, *The NURBS Book*, in homogeneous coordinates.

use std::cell::Cell;

use crate::error::SolverError;

use super::arclength::{Speed, gauss_panel};
use super::radius::radius_from;
use crate::geometry::Vec3;
use crate::validate::finite;

/// Highest supported degree.
pub const MAX_DEGREE: usize = 5;
/// Most control points accepted.
pub const MAX_CONTROL_POINTS: usize = 100_000;

const SLOTS: usize = MAX_DEGREE + 1;

/// A validated clamped NURBS curve.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Nurbs {
    degree: usize,
    knots: Vec<f64>,
    /// Control points times their weight, and the weight: (w·x, w·y, w·z, w).
    weighted: Vec<[f64; 4]>,
    /// The knot span found last: a chord search evaluates near it again and again, so the
    /// binary search over all knots is skipped when it or the next span holds the parameter.
    last_span: Cell<usize>,
    /// Each knot span `degree + k` as a polynomial in its local parameter (see [`SpanPolynomial`]).
    polynomials: Vec<SpanPolynomial>,
    /// The one weight of every control point when all are equal: the curve is a polynomial
    /// (a plain B-spline) on each span, not a ratio of two.
    common_weight: Option<f64>,
}

/// A stretch [lo, hi] inside one knot span of a polynomial curve of degree ≤ 3, in the span's
/// power form: P(t) = origin + Σ coefficients[k]·t^k with t = (u − u_i)/h. Borrows the span's
/// coefficients (the chord search builds one or two pieces for every deviation it measures).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CubicPiece<'a> {
    pub coefficients: &'a [Vec3; 4],
    /// Local parameters of lo and hi.
    pub t_lo: f64,
    pub t_hi: f64,
}

/// A chord's stretch of a plain cubic curve by the knot spans it lies in (see
/// [`Nurbs::cubic_stretch`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum CubicStretch<'a> {
    Inside(CubicPiece<'a>),
    /// From the chord's start to the knot, and from the knot to its end.
    AcrossKnot(CubicPiece<'a>, CubicPiece<'a>),
}

/// One knot span [u_i, u_i+1) of the curve in power form: the homogeneous curve relative to
/// the span's first point O, (w·(x − O), w), as polynomials in t = (u − u_i)/h. Evaluating it
/// by Horner's rule costs a few multiply-adds instead of the basis-function recurrences (the
/// chord search evaluates the curve some fifty times per block); relative coordinates keep the
/// rounding at the span's size, not the curve's. Points only: derivatives keep the basis
/// functions (exact zeros at cusps).
#[derive(Debug, Clone, PartialEq)]
struct SpanPolynomial {
    origin: Vec3,
    start: f64,
    /// 1/h (0 for an empty span, never evaluated).
    inverse_width: f64,
    /// Coefficients of t⁰…t^p of (w·(x − O_x), w·(y − O_y), w·(z − O_z), w).
    coefficients: [[f64; 4]; SLOTS],
    /// For a plain B-spline (one common weight): coefficients of t⁰…t^(2p−2) of |dP/dt|², so the
    /// arc-length integrand is one square root of a polynomial; empty (all zero) otherwise.
    speed_squared: [f64; 2 * MAX_DEGREE - 1],
    /// 2p − 1, the coefficients of `speed_squared` that may be non-zero.
    speed_terms: usize,
    /// For a plain B-spline: the coefficients of P − O itself (the homogeneous ones divided by
    /// the common weight once, not at every chord the search measures); zero otherwise.
    plain: [Vec3; SLOTS],
}

impl SpanPolynomial {
    /// |dC/du| at local parameter t of a plain B-spline's span, from its squared-speed polynomial.
    fn plain_speed(&self, t: f64) -> f64 {
        // Loops of fixed length the compiler unrolls: the cubic's five coefficients (nearly every
        // curve sent), else all of them, the ones above degree 2p − 2 being zero (leading zeros
        // leave Horner's sum exactly as it was, so both give the same bits).
        let horner = |coefficients: &[f64]| coefficients.iter().rev().fold(0.0, |sum, c| sum * t + c);
        let squared =
            if self.speed_terms == 5 { horner(&self.speed_squared[..5]) } else { horner(&self.speed_squared) };
        squared.max(0.0).sqrt() * self.inverse_width
    }
}

impl Speed for Nurbs {
    fn speed(&self, u: f64) -> f64 {
        Nurbs::speed(self, u)
    }

    /// On a plain B-spline the span is found once for the five nodes, which lie inside one span
    /// when the panel does (the table's panels end at knots); each node's value is the one
    /// [`Nurbs::speed`] gives, bit for bit.
    fn panel(&self, a: f64, b: f64) -> f64 {
        if self.common_weight.is_none() {
            return gauss_panel(|u| Nurbs::speed(self, u), a, b);
        }
        let polynomial = &self.polynomials[self.span(0.5 * (a + b)) - self.degree];
        gauss_panel(
            |u| {
                let t = (u - polynomial.start) * polynomial.inverse_width;
                if t > 0.0 && t < 1.0 { polynomial.plain_speed(t) } else { Nurbs::speed(self, u) }
            },
            a,
            b,
        )
    }
}

impl Nurbs {
    /// Builds and validates a curve. `knots` defaults to the clamped uniform vector on [0, 1],
    /// `weights` to 1 (a plain B-spline). Field paths start with `field` (e.g. `curve`).
    ///
    /// # Errors
    /// `E_INPUT` for a bad degree, too few or too many control points, a knot vector of the wrong
    /// length, decreasing, not clamped (first and last knot each `degree + 1` times) or with an
    /// interior knot repeated more than `degree` times (the curve would break apart), and for
    /// weights that are not positive.
    pub(crate) fn new(
        degree: usize,
        points: &[Vec3],
        knots: Option<&[f64]>,
        weights: Option<&[f64]>,
        field: &str,
    ) -> Result<Self, SolverError> {
        if !(1..=MAX_DEGREE).contains(&degree) {
            return Err(SolverError::input(
                format!("{field}.degree"),
                format!("degree must be 1 to {MAX_DEGREE} (got {degree})"),
            ));
        }
        let count = points.len();
        if count < degree + 1 {
            return Err(SolverError::input(
                format!("{field}.control_points"),
                format!("a degree-{degree} curve needs at least {} control points (got {count})", degree + 1),
            ));
        }
        if count > MAX_CONTROL_POINTS {
            return Err(SolverError::input(
                format!("{field}.control_points"),
                format!("at most {MAX_CONTROL_POINTS} control points are accepted (got {count})"),
            ));
        }
        let knots = match knots {
            Some(given) => validate_knots(given, degree, count, field)?,
            None => clamped_uniform(degree, count),
        };
        let weights: Vec<f64> = match weights {
            Some(given) => {
                if given.len() != count {
                    return Err(SolverError::input(
                        format!("{field}.weights"),
                        format!("weights must have one entry per control point ({count}), got {}", given.len()),
                    ));
                }
                for (index, &weight) in given.iter().enumerate() {
                    let path = format!("{field}.weights[{index}]");
                    if finite(&path, weight)? <= 0.0 {
                        return Err(SolverError::input(path, format!("weights must be greater than 0 (got {weight})")));
                    }
                }
                given.to_vec()
            }
            None => vec![1.0; count],
        };
        let common_weight = weights.iter().all(|&w| w == weights[0]).then_some(weights[0]);
        let weighted = points.iter().zip(&weights).map(|(p, &w)| [w * p.x, w * p.y, w * p.z, w]).collect();
        let mut curve =
            Self { degree, knots, weighted, last_span: Cell::new(degree), polynomials: Vec::new(), common_weight };
        curve.polynomials = (degree..count).map(|span| curve.span_polynomial(span)).collect();
        Ok(curve)
    }

    /// Parameter range [u_p, u_n].
    pub(crate) fn domain(&self) -> (f64, f64) {
        let n = self.weighted.len();
        (self.knots[self.degree], self.knots[n])
    }

    /// The distinct knots inside the domain, ends included, with their multiplicity.
    pub(crate) fn breaks(&self) -> Vec<(f64, usize)> {
        let (start, end) = self.domain();
        let mut out: Vec<(f64, usize)> = Vec::new();
        for &knot in &self.knots {
            if knot < start || knot > end {
                continue;
            }
            match out.last_mut() {
                Some((value, multiplicity)) if *value == knot => *multiplicity += 1,
                _ => out.push((knot, 1)),
            }
        }
        out
    }

    /// The first knot in (lo, hi] where the curve is only C⁰ (multiplicity ≥ degree, so its
    /// tangent may turn there), if any.
    pub(crate) fn first_kink_in(&self, lo: f64, hi: f64) -> Option<f64> {
        let end = self.domain().1;
        let mut i = self.knots.partition_point(|&k| k <= lo);
        while i < self.knots.len() && self.knots[i] <= hi && self.knots[i] < end {
            let knot = self.knots[i];
            let repeats = self.knots[i..].iter().take_while(|&&k| k == knot).count();
            if repeats >= self.degree {
                return Some(knot);
            }
            i += repeats;
        }
        None
    }

    /// The distinct knots strictly between `lo` and `hi`, increasing.
    pub(crate) fn distinct_knots_between(&self, lo: f64, hi: f64) -> impl Iterator<Item = f64> + '_ {
        let (start, end) = self.domain();
        // The first knot above lo follows lo's span (found from the hint, not by a search).
        let from = if lo >= start && lo < end { self.span(lo) + 1 } else { self.knots.partition_point(|&k| k <= lo) };
        let to = from + self.knots[from..].iter().take_while(|&&k| k < hi).count();
        let inside = &self.knots[from..to];
        inside.iter().enumerate().filter(move |&(i, k)| i == 0 || inside[i - 1] != *k).map(|(_, &k)| k)
    }

    /// Degree p.
    pub(crate) fn degree(&self) -> usize {
        self.degree
    }

    /// The knot spans' indices for [`Nurbs::span`] and [`Nurbs::derivatives_in`]: p to n − 1
    /// (some may be empty).
    pub(crate) fn spans(&self) -> std::ops::Range<usize> {
        self.degree..self.weighted.len()
    }

    /// The parameter range [u_i, u_i+1] of knot span `span`.
    pub(crate) fn span_range(&self, span: usize) -> (f64, f64) {
        (self.knots[span], self.knots[span + 1])
    }

    /// Knot span index i with u_i ≤ u < u_{i+1} (A2.1), the last non-empty span at the end.
    #[inline]
    pub(crate) fn span(&self, u: f64) -> usize {
        // The span found last holds u nearly always (the search evaluates near it again and
        // again): one bracket test, inlined into the callers (a million and a half of them per
        // solve on the chord bench), before the ends' cases and the search.
        let last = self.last_span.get();
        if let (Some(&lo), Some(&hi)) = (self.knots.get(last), self.knots.get(last + 1))
            && lo <= u
            && u < hi
            && last < self.weighted.len()
        {
            return last;
        }
        self.span_searched(u)
    }

    /// [`Nurbs::span`] past the last span's bracket test.
    #[cold]
    fn span_searched(&self, u: f64) -> usize {
        let n = self.weighted.len();
        let last = self.last_span.get();
        let (start, end) = self.domain();
        if u >= end {
            // Last span with a non-zero length.
            let mut i = n - 1;
            while i > self.degree && self.knots[i] >= end {
                i -= 1;
            }
            return i;
        }
        if u <= start {
            let mut i = self.degree;
            while i + 1 < n && self.knots[i + 1] <= start {
                i += 1;
            }
            return i;
        }
        if last + 1 < n && self.knots[last + 1] <= u && u < self.knots[last + 2] {
            self.last_span.set(last + 1);
            return last + 1;
        }
        // The span before: a chord that starts before the knot the last lookup crossed.
        if last > self.degree && last <= n && self.knots[last - 1] <= u && u < self.knots[last] {
            self.last_span.set(last - 1);
            return last - 1;
        }
        // First index with knot > u, minus one.
        let span = self.knots[..=n].partition_point(|&k| k <= u) - 1;
        self.last_span.set(span);
        span
    }

    /// The curve point at `u`.
    pub(crate) fn point(&self, u: f64) -> Vec3 {
        self.point_in(self.span(u), u)
    }

    /// The curve point at `u`, with `hint` a span index near it (updated to u's span): cheap
    /// for the increasing parameters of a sampling loop.
    pub(crate) fn point_near(&self, u: f64, hint: &std::cell::Cell<usize>) -> Vec3 {
        let n = self.weighted.len();
        let guess = hint.get();
        let span = if guess >= self.degree
            && guess < n
            && self.knots[guess] <= u
            && (u < self.knots[guess + 1] || (guess == n - 1 && u <= self.knots[n]))
        {
            guess
        } else if guess + 1 >= self.degree && guess + 1 < n && self.knots[guess + 1] <= u && u < self.knots[guess + 2] {
            guess + 1
        } else {
            self.span(u)
        };
        hint.set(span);
        self.point_in(span, u)
    }

    /// [lo, hi] of a polynomial curve of degree ≤ 3 as the stretches of the knot spans it lies
    /// in: one (its end may be the span's closing knot), or two when it crosses one knot; `None`
    /// for other curves and for stretches over more knots.
    /// With the stretch, dt/du of the span holding `hi` (the rate of a chord end moving there).
    pub(crate) fn cubic_stretch(&self, lo: f64, hi: f64) -> Option<(CubicStretch<'_>, f64)> {
        if !self.is_plain_cubic() || lo >= hi || lo.is_nan() || hi.is_nan() {
            return None;
        }
        let per_u = |span: usize| self.polynomials[span - self.degree].inverse_width;
        let span = self.span(lo);
        let knot = self.knots[span + 1];
        if hi <= knot {
            return Some((CubicStretch::Inside(self.piece_in(span, lo, hi)?), per_u(span)));
        }
        // The next non-empty span (a repeated knot leaves empty ones between).
        let mut next = span + 1;
        while next < self.weighted.len() && self.knots[next + 1] <= knot {
            next += 1;
        }
        if next >= self.weighted.len() || hi > self.knots[next + 1] {
            return None;
        }
        Some((CubicStretch::AcrossKnot(self.piece_in(span, lo, knot)?, self.piece_in(next, knot, hi)?), per_u(next)))
    }

    /// [lo, hi] inside knot span `span` of a plain cubic curve as a [`CubicPiece`].
    fn piece_in(&self, span: usize, lo: f64, hi: f64) -> Option<CubicPiece<'_>> {
        let polynomial = &self.polynomials[span - self.degree];
        let coefficients = polynomial.plain.first_chunk()?;
        let local = |u: f64| (u - polynomial.start) * polynomial.inverse_width;
        Some(CubicPiece { coefficients, t_lo: local(lo), t_hi: local(hi) })
    }

    /// The radius of curvature at `u` strictly inside a knot span of a plain cubic curve, from the
    /// span's power form: |P′|³/|P′ × P″| in the span's own parameter (the scale cancels), without
    /// the homogeneous division of [`Nurbs::derivatives_in`]; `None` at a knot (whose one-sided
    /// values may differ) and on other curves. The smallest radius of a stretch evaluates this at
    /// every chord's ends in mode `guarantee`.
    pub(crate) fn plain_radius_inside(&self, u: f64) -> Option<f64> {
        if !self.is_plain_cubic() {
            return None;
        }
        let polynomial = &self.polynomials[self.span(u) - self.degree];
        let t = (u - polynomial.start) * polynomial.inverse_width;
        if !(t > 0.0 && t < 1.0) {
            return None;
        }
        let [_, a1, a2, a3, ..] = polynomial.plain;
        let first = a1 + t * (2.0 * a2 + 3.0 * a3 * t);
        let second = 2.0 * a2 + 6.0 * a3 * t;
        Some(radius_from(&first, &second))
    }

    /// The span starting at knot `u` of a plain cubic curve; `None` off a knot and on other curves.
    fn plain_cubic_span_from_knot(&self, u: f64) -> Option<usize> {
        if !self.is_plain_cubic() {
            return None;
        }
        let span = self.span(u);
        (self.knots[span] == u).then_some(span)
    }

    /// The radius of curvature at interior knot `u` of a plain cubic curve, the smaller of its
    /// one-sided values, from the power forms of the spans on either side (at the left one's
    /// t = 1 and the right one's t = 0); `None` off a knot, on other curves, and where the curve
    /// nearly stops there: the basis functions give the exact zero of a cusp, the power forms only
    /// a rounding of it (radius_at then takes them; a curve has one knot per span, and their
    /// radii by the basis functions cost a twentieth of the chord bench's B-spline solve).
    pub(crate) fn plain_radius_at_knot(&self, u: f64) -> Option<f64> {
        let right = self.plain_cubic_span_from_knot(u)?;
        let n = self.weighted.len();
        let left = self.knots[..=n].partition_point(|&k| k < u).saturating_sub(1).clamp(self.degree, n - 1);
        let radius = |span: usize, t: f64| {
            let [first, second] = self.plain_derivatives_moving(span, t)?;
            Some(radius_from(&first, &second))
        };
        let from_right = radius(right, 0.0)?;
        if left == right {
            return Some(from_right);
        }
        Some(from_right.min(radius(left, 1.0)?))
    }

    /// |dC/du| just after knot `u` of a plain cubic curve from the power form of the span it
    /// starts; `None` as for [`Nurbs::plain_radius_at_knot`] (off a knot, other curves, a near
    /// stop).
    pub(crate) fn plain_speed_at_knot(&self, u: f64) -> Option<f64> {
        let span = self.plain_cubic_span_from_knot(u)?;
        let [first, _] = self.plain_derivatives_moving(span, 0.0)?;
        Some(first.norm() * self.polynomials[span - self.degree].inverse_width)
    }

    /// P′ and P″ in the parameter of non-empty span `span` of a plain cubic curve at its local t,
    /// when |P′| stands clear of the power form's rounding (above 1e-6 of its coefficients'
    /// size); `None` for an empty span and a near stop.
    fn plain_derivatives_moving(&self, span: usize, t: f64) -> Option<[Vec3; 2]> {
        let polynomial = &self.polynomials[span - self.degree];
        if polynomial.inverse_width == 0.0 {
            return None;
        }
        let [_, a1, a2, a3, ..] = polynomial.plain;
        let first = a1 + t * (2.0 * a2 + 3.0 * a3 * t);
        let size = a1.norm() + 2.0 * a2.norm() + 3.0 * a3.norm();
        (first.norm() > 1e-6 * size).then(|| [first, 2.0 * a2 + 6.0 * a3 * t])
    }

    /// Whether every span is a polynomial of degree ≤ 3 (a plain B-spline: one common weight),
    /// whose radius of curvature turns where a polynomial has its roots (`radius`).
    pub(crate) fn is_plain_cubic(&self) -> bool {
        self.common_weight.is_some() && self.degree <= 3
    }

    /// The power-form coefficients a₀…a₃ of knot span `span` of a plain cubic curve, in the
    /// span's own parameter t ∈ [0, 1] and relative to its first point; `None` for other curves.
    pub(crate) fn plain_span_form(&self, span: usize) -> Option<[Vec3; 4]> {
        if !self.is_plain_cubic() {
            return None;
        }
        let [a0, a1, a2, a3, ..] = self.polynomials[span - self.degree].plain;
        Some([a0, a1, a2, a3])
    }

    fn point_in(&self, span: usize, u: f64) -> Vec3 {
        let polynomial = &self.polynomials[span - self.degree];
        let t = (u - polynomial.start) * polynomial.inverse_width;
        let mut sum = polynomial.coefficients[self.degree];
        for coefficient in polynomial.coefficients[..self.degree].iter().rev() {
            for (total, c) in sum.iter_mut().zip(coefficient) {
                *total = *total * t + c;
            }
        }
        polynomial.origin + Vec3::new(sum[0], sum[1], sum[2]) / sum[3]
    }

    /// The homogeneous curve (relative to O) at `u` in `span` by the basis functions (A2.2).
    fn homogeneous_by_basis(&self, span: usize, u: f64, origin: &Vec3) -> [f64; 4] {
        let basis = self.basis(span, u);
        let mut sum = [0.0; 4];
        for (j, value) in basis.iter().take(self.degree + 1).enumerate() {
            let [wx, wy, wz, w] = self.weighted[span - self.degree + j];
            let relative = [wx - w * origin.x, wy - w * origin.y, wz - w * origin.z, w];
            for (total, coordinate) in sum.iter_mut().zip(relative) {
                *total += value * coordinate;
            }
        }
        sum
    }

    /// The power form of knot span `span`: the homogeneous curve interpolated at p + 1 equally
    /// spaced local parameters (exact: it is a polynomial of degree p there), converted from
    /// Newton's divided differences to monomial coefficients.
    fn span_polynomial(&self, span: usize) -> SpanPolynomial {
        let p = self.degree;
        let (start, end) = (self.knots[span], self.knots[span + 1]);
        let mut coefficients = [[0.0; 4]; SLOTS];
        if end <= start {
            return SpanPolynomial {
                origin: Vec3::zeros(),
                start,
                inverse_width: 0.0,
                coefficients,
                speed_squared: [0.0; 2 * MAX_DEGREE - 1],
                speed_terms: 2 * p - 1,
                plain: [Vec3::zeros(); SLOTS],
            };
        }
        let origin = {
            let h = self.homogeneous_by_basis(span, start, &Vec3::zeros());
            Vec3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3])
        };
        // Fixed arrays, not vectors: a curve of 7 000 spans built two allocations per span.
        let mut nodes = [0.0; SLOTS];
        let mut table = [[0.0; 4]; SLOTS];
        for j in 0..=p {
            let t = j as f64 / p as f64;
            let u = if t >= 1.0 { end } else { start + (end - start) * t };
            (nodes[j], table[j]) = (t, self.homogeneous_by_basis(span, u, &origin));
        }
        // Divided differences in place: table[k] = f[t_0..t_k].
        for level in 1..=p {
            for k in (level..=p).rev() {
                let width = nodes[k] - nodes[k - level];
                let below = table[k - 1];
                for (value, lower) in table[k].iter_mut().zip(below) {
                    *value = (*value - lower) / width;
                }
            }
        }
        // Newton form to powers of t: c ← c·(t − t_k) + f[t_0..t_k], from the highest term.
        for k in (0..=p).rev() {
            for power in (1..=p).rev() {
                let lower = coefficients[power - 1];
                for (value, low) in coefficients[power].iter_mut().zip(lower) {
                    *value = low - nodes[k] * *value;
                }
            }
            for (value, difference) in coefficients[0].iter_mut().zip(table[k]) {
                *value = difference - nodes[k] * *value;
            }
        }
        let mut speed_squared = [0.0; 2 * MAX_DEGREE - 1];
        if let Some(weight) = self.common_weight {
            // dP/dt = Σ k·a_k·t^(k−1); its square by convolution of the coefficient vectors.
            let derivative =
                |k: usize| Vec3::new(coefficients[k][0], coefficients[k][1], coefficients[k][2]) * (k as f64 / weight);
            for i in 1..=p {
                for j in 1..=p {
                    speed_squared[i + j - 2] += derivative(i).dot(&derivative(j));
                }
            }
        }
        let mut plain = [Vec3::zeros(); SLOTS];
        if let Some(weight) = self.common_weight {
            for (vector, h) in plain.iter_mut().zip(&coefficients) {
                *vector = Vec3::new(h[0], h[1], h[2]) / weight;
            }
        }
        SpanPolynomial {
            origin,
            start,
            inverse_width: 1.0 / (end - start),
            coefficients,
            speed_squared,
            speed_terms: 2 * p - 1,
            plain,
        }
    }

    /// Point, first and second derivative with respect to u (the right-hand limits at a knot).
    pub(crate) fn derivatives(&self, u: f64) -> [Vec3; 3] {
        self.derivatives_in(self.span(u), u)
    }

    /// The left-hand limits of [`Nurbs::derivatives`] when `u` is an interior knot, where the
    /// curvature may jump (a degree-2 curve is only C1 there); `None` elsewhere.
    pub(crate) fn derivatives_from_left(&self, u: f64) -> Option<[Vec3; 3]> {
        let right = self.span(u);
        if self.knots[right] != u {
            return None; // not a knot: one-sided limits agree (this is the common case)
        }
        let n = self.weighted.len();
        let left = self.knots[..=n].partition_point(|&k| k < u).saturating_sub(1).clamp(self.degree, n - 1);
        (left != right).then(|| self.derivatives_in(left, u))
    }

    /// Non-zero basis functions N_{span−p..span, p}(u) (A2.2).
    fn basis(&self, span: usize, u: f64) -> [f64; SLOTS] {
        let p = self.degree;
        let knots = &self.knots;
        let mut values = [0.0; SLOTS];
        let (mut left, mut right) = ([0.0; SLOTS], [0.0; SLOTS]);
        values[0] = 1.0;
        for j in 1..=p {
            left[j] = u - knots[span + 1 - j];
            right[j] = knots[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                let temp = values[r] / (right[r + 1] + left[j - r]);
                values[r] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            values[j] = saved;
        }
        values
    }

    /// Point and first two derivatives with respect to u in `span`: from the power form inside
    /// the span, by the basis functions (A2.3) at its ends: at a cusp of coincident control
    /// points (always at a knot) those give exactly zero, which the corner and radius logic
    /// rely on, while the power form leaves rounding there.
    pub(crate) fn derivatives_in(&self, span: usize, u: f64) -> [Vec3; 3] {
        let polynomial = &self.polynomials[span - self.degree];
        let scale = polynomial.inverse_width;
        let t = (u - polynomial.start) * scale;
        if !(t > 0.0 && t < 1.0) {
            return self.derivatives_by_basis(span, u);
        }
        // Horner for the value and the first two derivatives in t.
        let mut value = polynomial.coefficients[self.degree];
        let (mut first, mut second) = ([0.0_f64; 4], [0.0_f64; 4]);
        for coefficient in polynomial.coefficients[..self.degree].iter().rev() {
            for axis in 0..4 {
                second[axis] = second[axis] * t + first[axis];
                first[axis] = first[axis] * t + value[axis];
                value[axis] = value[axis] * t + coefficient[axis];
            }
        }
        let vector = |h: &[f64; 4], factor: f64| Vec3::new(h[0], h[1], h[2]) * factor;
        let curvature_scale = 2.0 * scale * scale;
        let (a0, a1, a2) = (vector(&value, 1.0), vector(&first, scale), vector(&second, curvature_scale));
        let (w0, w1, w2) = (value[3], first[3] * scale, second[3] * curvature_scale);
        let relative = a0 / w0;
        let first = (a1 - w1 * relative) / w0;
        let second = (a2 - 2.0 * w1 * first - w2 * relative) / w0;
        [polynomial.origin + relative, first, second]
    }

    /// |dC/du| (the right-hand limit at a knot): the arc-length integrand, from the span's
    /// squared-speed polynomial on a plain B-spline, else from the power form without the
    /// second derivative [`Nurbs::derivatives_in`] also carries.
    pub(crate) fn speed(&self, u: f64) -> f64 {
        let span = self.span(u);
        let polynomial = &self.polynomials[span - self.degree];
        let scale = polynomial.inverse_width;
        let t = (u - polynomial.start) * scale;
        if !(t > 0.0 && t < 1.0) {
            return self.derivatives_by_basis(span, u)[1].norm();
        }
        if self.common_weight.is_some() {
            return polynomial.plain_speed(t);
        }
        let mut value = polynomial.coefficients[self.degree];
        let mut first = [0.0_f64; 4];
        for coefficient in polynomial.coefficients[..self.degree].iter().rev() {
            for axis in 0..4 {
                first[axis] = first[axis] * t + value[axis];
                value[axis] = value[axis] * t + coefficient[axis];
            }
        }
        // (a/w)' = (a' − w'·a/w)/w, in u: d/du = scale·d/dt.
        let relative = Vec3::new(value[0], value[1], value[2]) / value[3];
        let first_t = Vec3::new(first[0], first[1], first[2]) - first[3] * relative;
        (first_t * (scale / value[3])).norm()
    }

    /// Point and first two derivatives by the basis functions (A2.3).
    fn derivatives_by_basis(&self, span: usize, u: f64) -> [Vec3; 3] {
        let ders = self.basis_derivatives(span, u);
        let mut homogeneous = [[0.0_f64; 4]; 3];
        for (order, row) in ders.iter().enumerate() {
            for (j, value) in row.iter().take(self.degree + 1).enumerate() {
                let control = &self.weighted[span - self.degree + j];
                for (total, coordinate) in homogeneous[order].iter_mut().zip(control) {
                    *total += value * coordinate;
                }
            }
        }
        let vector = |h: &[f64; 4]| Vec3::new(h[0], h[1], h[2]);
        let (a0, a1, a2) = (vector(&homogeneous[0]), vector(&homogeneous[1]), vector(&homogeneous[2]));
        let (w0, w1, w2) = (homogeneous[0][3], homogeneous[1][3], homogeneous[2][3]);
        let point = a0 / w0;
        let first = (a1 - w1 * point) / w0;
        let second = (a2 - 2.0 * w1 * first - w2 * point) / w0;
        [point, first, second]
    }

    /// Basis functions and their first two derivatives (A2.3); rows are the derivative order.
    fn basis_derivatives(&self, span: usize, u: f64) -> [[f64; SLOTS]; 3] {
        let p = self.degree;
        let knots = &self.knots;
        let mut ndu = [[0.0_f64; SLOTS]; SLOTS];
        let (mut left, mut right) = ([0.0; SLOTS], [0.0; SLOTS]);
        ndu[0][0] = 1.0;
        for j in 1..=p {
            left[j] = u - knots[span + 1 - j];
            right[j] = knots[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = ndu[r][j - 1] / ndu[j][r];
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        let mut ders = [[0.0_f64; SLOTS]; 3];
        for j in 0..=p {
            ders[0][j] = ndu[j][p];
        }
        let orders = p.min(2);
        let (p_i, n_i) = (p as isize, orders as isize);
        for r in 0..=p_i {
            let mut a = [[0.0_f64; SLOTS]; 2];
            let (mut s1, mut s2) = (0_usize, 1_usize);
            a[0][0] = 1.0;
            for k in 1..=n_i {
                let mut d = 0.0;
                let rk = r - k;
                let pk = p_i - k;
                let idx = |x: isize| x as usize;
                if r >= k {
                    a[s2][0] = a[s1][0] / ndu[idx(pk + 1)][idx(rk)];
                    d = a[s2][0] * ndu[idx(rk)][idx(pk)];
                }
                let j1 = if rk >= -1 { 1 } else { -rk };
                let j2 = if r - 1 <= pk { k - 1 } else { p_i - r };
                for j in j1..=j2 {
                    a[s2][idx(j)] = (a[s1][idx(j)] - a[s1][idx(j - 1)]) / ndu[idx(pk + 1)][idx(rk + j)];
                    d += a[s2][idx(j)] * ndu[idx(rk + j)][idx(pk)];
                }
                if r <= pk {
                    a[s2][idx(k)] = -a[s1][idx(k - 1)] / ndu[idx(pk + 1)][idx(r)];
                    d += a[s2][idx(k)] * ndu[idx(r)][idx(pk)];
                }
                ders[idx(k)][idx(r)] = d;
                std::mem::swap(&mut s1, &mut s2);
            }
        }
        let mut factor = p as f64;
        for (k, row) in ders.iter_mut().enumerate().skip(1).take(orders) {
            for value in row.iter_mut().take(p + 1) {
                *value *= factor;
            }
            factor *= (p - k) as f64;
        }
        ders
    }
}

/// The clamped uniform knot vector on [0, 1] for `count` control points.
fn clamped_uniform(degree: usize, count: usize) -> Vec<f64> {
    let interior = count - degree - 1;
    let mut knots = vec![0.0; degree + 1];
    for k in 1..=interior {
        knots.push(k as f64 / (interior + 1) as f64);
    }
    knots.extend(std::iter::repeat_n(1.0, degree + 1));
    knots
}

fn validate_knots(knots: &[f64], degree: usize, count: usize, field: &str) -> Result<Vec<f64>, SolverError> {
    let path = format!("{field}.knots");
    let expected = count + degree + 1;
    if knots.len() != expected {
        return Err(SolverError::input(
            path,
            format!(
                "a degree-{degree} curve with {count} control points needs {expected} knots \
                 (control points + degree + 1), got {}",
                knots.len()
            ),
        ));
    }
    for (index, &knot) in knots.iter().enumerate() {
        if !knot.is_finite() {
            finite(&format!("{path}[{index}]"), knot)?;
        }
        if index > 0 && knot < knots[index - 1] {
            return Err(SolverError::input(
                format!("{path}[{index}]"),
                format!("knots must not decrease: {knot} follows {}", knots[index - 1]),
            ));
        }
    }
    let (first, last) = (knots[0], knots[expected - 1]);
    for index in 1..=degree {
        if knots[index] != first {
            return Err(SolverError::input(
                format!("{path}[{index}]"),
                format!("the knot vector must be clamped: the first {} knots must be equal", degree + 1),
            ));
        }
        let back = expected - 1 - index;
        if knots[back] != last {
            return Err(SolverError::input(
                format!("{path}[{back}]"),
                format!("the knot vector must be clamped: the last {} knots must be equal", degree + 1),
            ));
        }
    }
    if last <= first {
        return Err(SolverError::input(
            path,
            "the knot vector spans no parameter range: its first and last knot are equal",
        ));
    }
    // The ends appear exactly degree + 1 times, interior knots at most degree times: more and
    // the curve would not start at its first control point, or would fall apart.
    if knots[degree + 1] == first {
        return Err(SolverError::input(
            format!("{path}[{}]", degree + 1),
            format!("the first knot may appear at most {} times", degree + 1),
        ));
    }
    if knots[count - 1] == last {
        return Err(SolverError::input(
            format!("{path}[{}]", count - 1),
            format!("the last knot may appear at most {} times", degree + 1),
        ));
    }
    let mut run = 0;
    for index in degree + 1..count {
        run = if index > degree + 1 && knots[index] == knots[index - 1] { run + 1 } else { 1 };
        if run > degree {
            return Err(SolverError::input(
                format!("{path}[{index}]"),
                format!(
                    "interior knot {} is repeated {run} times; at most the degree ({degree}) is allowed",
                    knots[index]
                ),
            ));
        }
    }
    Ok(knots.to_vec())
}

#[cfg(test)]
mod tests;
