//! The target curve P as the segmentation sees it (docs/spec/segment.md §1.2, §2.8, §2.9): points by an
//! internal parameter u, arc length both ways, the deviation of a chord from the curve, the
//! smallest radius of curvature on a stretch, and the corners where the path must be split (E11).
//!
//! u is the arc length itself for circular arcs and polylines, the ellipse angle t for ellipses
//! and the knot parameter for NURBS; evaluating there and converting only chord ends keeps the
//! arc-length inversion out of the inner loops.

use super::arclength::{ArcLengthTable, NODES, Speed, WEIGHTS};
use super::cubic;
use super::numeric::{minimise, small_sin_cos};
use super::nurbs::{CubicStretch, Nurbs};
use super::radius::SpanMinima;
use crate::error::ErrorCode;
use crate::error::SolverError;
use crate::geometry::{Segment, Vec3, distance_to_segment};
use std::cell::Cell;

/// Sub-intervals sampled before the deviation is refined (docs/spec/segment.md §2.9).
const DEVIATION_SAMPLES: usize = 32;

/// Below this fraction of a threshold the refinement of the best sample cannot change a
/// "does the chord fit" answer on a smooth curve (it raises the sampled maximum by about
/// 1/1000 of the deviation), so it is skipped.
const REFINE_FRACTION: f64 = 0.9;

/// Most parabolic steps when refining a deviation.
const PARABOLIC_STEPS: usize = 6;

/// Most radius samples on one stretch.
const MAX_RADIUS_SAMPLES: usize = 4096;

/// A circular arc in a plane parallel to XY: P(s) = c + r·(cos φ, sin φ, 0), φ = φ0 + σ·s/r.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Arc {
    pub centre: Vec3,
    pub radius: f64,
    pub start: f64,
    /// +1 counter-clockwise, −1 clockwise.
    pub sense: f64,
    /// Swept angle, rad (> 0).
    pub sweep: f64,
}

/// An elliptic arc: P(t) = c + R(ψ)·(a cos t, b sin t, 0), t = t0 + σ·u, u ∈ [0, sweep].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ellipse {
    pub centre: Vec3,
    pub semi_axes: [f64; 2],
    /// sin and cos of the rotation ψ (computed once: every point needs them).
    pub rotation_sin_cos: (f64, f64),
    pub start: f64,
    pub sense: f64,
    pub sweep: f64,
    pub table: ArcLengthTable,
    /// The sines and cosines of angles the segmentation asks for again and again.
    pub angles: AngleMemo,
}

/// sin and cos of an ellipse's angle at the parameter where they were last taken, `f64::sin_cos`'s
/// values: a chord's end is the next chord's start, and an arc-length panel's start is that of
/// the next hundred lookups, so a chord's mean angle and a panel's nodes are turned from there by
/// a small angle ([`small_sin_cos`]) instead of reducing the whole angle again. What is
/// remembered never changes a value: it is the value a miss computes.
#[derive(Debug, Clone)]
pub(crate) struct AngleMemo {
    /// At the last point asked for (a chord's end, the next one's start).
    point: Cell<(f64, f64, f64)>,
    /// At the start of the last arc-length panel.
    panel: Cell<(f64, f64, f64)>,
}

/// Two ellipses are the same whatever they remember.
impl PartialEq for AngleMemo {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Default for AngleMemo {
    fn default() -> Self {
        // NaN is no parameter: the first lookup computes.
        Self { point: Cell::new((f64::NAN, 0.0, 1.0)), panel: Cell::new((f64::NAN, 0.0, 1.0)) }
    }
}

/// A polyline taken as the true curve: P(s) runs along its edges.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Polyline {
    pub vertices: Vec<Vec3>,
    /// Arc length at each vertex.
    pub stations: Vec<f64>,
    /// The edge found last: the segmentation walks along the polyline, so the next lookup is
    /// nearly always on it or the next edge (no binary search over every vertex).
    pub last_edge: std::cell::Cell<usize>,
}

/// A NURBS curve with its arc-length table and its spans' smallest radii.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Spline {
    pub nurbs: Nurbs,
    pub table: ArcLengthTable,
    pub radius_minima: SpanMinima,
}

/// One of the supported curves.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Shape {
    Arc(Arc),
    Ellipse(Ellipse),
    Polyline(Polyline),
    Spline(Spline),
}

/// |dP/dt| of an ellipse with semi-axes a, b at angle t: √(a² sin² t + b² cos² t). Not by
/// `hypot`, whose guard against overflow cost a quarter of an ellipse's segmentation: the
/// semi-axes are at most `MAX_COORDINATE` (1e5 mm), far from it.
pub(crate) fn ellipse_speed([a, b]: [f64; 2], t: f64) -> f64 {
    let (sin, cos) = t.sin_cos();
    ((a * sin).powi(2) + (b * cos).powi(2)).sqrt()
}

impl Ellipse {
    fn angle(&self, u: f64) -> f64 {
        self.start + self.sense * u
    }

    /// sin and cos of the angle at `u`, remembered in `slot` (see [`AngleMemo`]).
    fn sin_cos_at(&self, u: f64, slot: &Cell<(f64, f64, f64)>) -> (f64, f64) {
        let (at, sin, cos) = slot.get();
        if at == u {
            return (sin, cos);
        }
        let (sin, cos) = self.angle(u).sin_cos();
        slot.set((u, sin, cos));
        (sin, cos)
    }

    fn point(&self, u: f64) -> Vec3 {
        let (sin_t, cos_t) = self.sin_cos_at(u, &self.angles.point);
        let (x, y) = (self.semi_axes[0] * cos_t, self.semi_axes[1] * sin_t);
        let (sin, cos) = self.rotation_sin_cos;
        self.centre + Vec3::new(cos * x - sin * y, sin * x + cos * y, 0.0)
    }

    /// |dP/du|.
    fn speed(&self, u: f64) -> f64 {
        ellipse_speed(self.semi_axes, self.angle(u))
    }

    /// The chord from `ua` to `ub ≥ ua` (at most a quarter turn apart) measured in closed form:
    /// the affine image of a circle, its farthest point is at the mean angle t_m; with the half
    /// angle δ = (ub − ua)/2, dev = 2·sin²(δ/2)·ab/v(t_m) for v = (a² sin² t + b² cos² t)^½.
    /// The angles at t_m are those at `ua` (remembered: the previous chord's end) turned by δ.
    fn chord(&self, ua: f64, ub: f64) -> EllipseChord<'_> {
        let [a, b] = self.semi_axes;
        let half = 0.5 * (ub - ua);
        let (sin_a, cos_a) = self.sin_cos_at(ua, &self.angles.point);
        let (sin_quarter, cos_quarter) = small_sin_cos(0.5 * half);
        let half_sin = 2.0 * sin_quarter * cos_quarter;
        let half_cos = 1.0 - 2.0 * sin_quarter * sin_quarter;
        let turn = self.sense * half_sin;
        let (sin, cos) = (sin_a * half_cos + cos_a * turn, cos_a * half_cos - sin_a * turn);
        let speed = ((a * sin).powi(2) + (b * cos).powi(2)).sqrt();
        let deviation = 2.0 * sin_quarter * sin_quarter * a * b / speed;
        EllipseChord { ellipse: self, half_sin, sin, cos, speed, deviation }
    }

    /// The deviation of the chord from `ua` to `ub` ([`Ellipse::chord`]), with its rate per unit
    /// of u as `ub` moves (worked out when asked, [`EllipseChord::rate`]; dv/dt = (a² − b²)·sin t·cos t/v).
    fn deviation_with_rate(&self, ua: f64, ub: f64) -> (f64, DeviationRate<'_>) {
        let chord = self.chord(ua, ub);
        (chord.deviation, DeviationRate::Ellipse(chord))
    }

    /// Radius of curvature at t: (a² sin² t + b² cos² t)^{3/2} / (a·b).
    fn radius(&self, t: f64) -> f64 {
        let [a, b] = self.semi_axes;
        ellipse_speed(self.semi_axes, t).powi(3) / (a * b)
    }
}

impl Speed for Ellipse {
    fn speed(&self, u: f64) -> f64 {
        Ellipse::speed(self, u)
    }

    /// The five nodes' angles by turning the middle's sine and cosine by the nodes' offsets,
    /// which come in ± pairs, and the middle's by turning the panel's start (remembered: the
    /// table's node, the start of the next lookups too); the turns are small angles
    /// ([`small_sin_cos`]), no whole angle is reduced but the start (an ellipse's arc length
    /// costs its trigonometry).
    fn panel(&self, a: f64, b: f64) -> f64 {
        let [semi_a, semi_b] = self.semi_axes;
        let speed = |sin: f64, cos: f64| ((semi_a * sin).powi(2) + (semi_b * cos).powi(2)).sqrt();
        let half = 0.5 * (b - a);
        let (sin_a, cos_a) = self.sin_cos_at(a, &self.angles.panel);
        let (turn_sin, turn_cos) = small_sin_cos(self.sense * half);
        let (sin, cos) = (sin_a * turn_cos + cos_a * turn_sin, cos_a * turn_cos - sin_a * turn_sin);
        let mut sum = WEIGHTS[2] * speed(sin, cos);
        for k in [3, 4] {
            let (turn_sin, turn_cos) = small_sin_cos(self.sense * half * NODES[k]);
            let ahead = speed(sin * turn_cos + cos * turn_sin, cos * turn_cos - sin * turn_sin);
            let behind = speed(sin * turn_cos - cos * turn_sin, cos * turn_cos + sin * turn_sin);
            sum += WEIGHTS[k] * (ahead + behind);
        }
        sum * half
    }
}

/// The rate of a chord's deviation per unit of u as its end moves ([`Shape::deviation_with_rate`]),
/// worked out when asked: the chord search's last trial, which confirms the chord, needs the
/// deviation alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum DeviationRate<'a> {
    /// An ellipse chord of up to a quarter turn, in closed form.
    Ellipse(EllipseChord<'a>),
    /// A plain cubic B-spline's chord: the rate per unit of the span's parameter, times `per_u`.
    Spline { inputs: cubic::RateInputs<'a>, per_u: f64 },
}

impl DeviationRate<'_> {
    /// The rate per unit of u; `None` where the chord is straight (the rate has no direction).
    pub(crate) fn per_u(&self) -> Option<f64> {
        match self {
            Self::Ellipse(chord) => Some(chord.rate()),
            Self::Spline { inputs, per_u } => Some(inputs.rate()? * per_u),
        }
    }
}

/// An ellipse chord as [`Ellipse::deviation_with_rate`] measured it: its half angle, the sine and
/// cosine of its mean angle, the speed there and its deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct EllipseChord<'a> {
    ellipse: &'a Ellipse,
    /// sin of the half angle δ.
    half_sin: f64,
    sin: f64,
    cos: f64,
    speed: f64,
    deviation: f64,
}

impl EllipseChord<'_> {
    /// d dev/d ub: the half angle and the mean angle (through the sense of the parameter) move by ½.
    fn rate(&self) -> f64 {
        let Self { ellipse, half_sin, sin, cos, speed, deviation } = *self;
        let [a, b] = ellipse.semi_axes;
        let speed_rate = (a * a - b * b) * sin * cos / speed * 0.5 * ellipse.sense;
        0.5 * half_sin * a * b / speed - deviation * speed_rate / speed
    }
}

impl Spline {
    pub(crate) fn new(nurbs: Nurbs, table: ArcLengthTable) -> Self {
        let radius_minima = SpanMinima::new(&nurbs);
        Self { nurbs, table, radius_minima }
    }

    fn speed(&self, u: f64) -> f64 {
        self.nurbs.speed(u)
    }

    /// [`Spline::exact_deviation`] of a chord from `ua` to `ub > ua`, with its rate of change per
    /// unit of u as `ub` moves ([`cubic::deviation_with_rate`]); `None` where that is `None`.
    pub(crate) fn deviation_with_rate(&self, ua: f64, ub: f64) -> Option<(f64, DeviationRate<'_>)> {
        let (stretch, per_u) = self.nurbs.cubic_stretch(ua, ub)?;
        let (deviation, inputs) = match stretch {
            CubicStretch::Inside(piece) => cubic::deviation_with_rate(&piece)?,
            CubicStretch::AcrossKnot(first, second) => {
                cubic::deviation_across_knot_with_rate(&first, &second, &self.nurbs.point(ua), &self.nurbs.point(ub))?
            }
        };
        Some((deviation, DeviationRate::Spline { inputs, per_u }))
    }

    /// The exact deviation of a chord of a plain B-spline of degree ≤ 3 inside one knot span
    /// ([`cubic::deviation`]) or across one knot ([`cubic::deviation_across_knot`]); `None`
    /// elsewhere.
    fn exact_deviation(&self, ua: f64, ub: f64) -> Option<f64> {
        let (lo, hi) = (ua.min(ub), ua.max(ub));
        match self.nurbs.cubic_stretch(lo, hi)?.0 {
            CubicStretch::Inside(piece) => cubic::deviation(&piece),
            CubicStretch::AcrossKnot(first, second) => {
                cubic::deviation_across_knot(&first, &second, &self.nurbs.point(lo), &self.nurbs.point(hi))
            }
        }
    }
}

impl Polyline {
    /// Index of the edge holding arc length `s`: the last station at or before `s` (the last
    /// edge beyond the end). Gallops from the previous answer and bisects inside the bracket
    /// found, so nearby lookups (a chord's ends, a radius's three points) cost a few steps
    /// instead of a search of the whole list.
    pub(crate) fn edge(&self, s: f64) -> usize {
        let stations = &self.stations;
        let last_edge = self.vertices.len().saturating_sub(2);
        let hint = self.last_edge.get().min(stations.len().saturating_sub(1));
        // Invariant: stations[..below] <= s and stations[above..] > s.
        let (mut below, mut above) = (0, stations.len());
        let mut step = 1;
        if stations.get(hint).is_some_and(|&x| x <= s) {
            below = hint;
            while below + step < stations.len() {
                if stations[below + step] > s {
                    above = below + step;
                    break;
                }
                below += step;
                step *= 2;
            }
        } else {
            above = hint;
            while above >= step {
                if stations[above - step] <= s {
                    below = above - step;
                    break;
                }
                above -= step;
                step *= 2;
            }
        }
        let at_or_before = below + stations[below..above].partition_point(|&x| x <= s);
        let k = at_or_before.saturating_sub(1).min(last_edge);
        self.last_edge.set(k);
        k
    }

    fn point(&self, s: f64) -> Vec3 {
        self.point_on(self.edge(s), s)
    }

    /// The farthest vertex strictly between arc lengths `ua` and `ub` from the chord joining
    /// their points (docs/spec/segment.md §2.9: a polyline's deviation is exact).
    pub(crate) fn deviation(&self, ua: f64, ub: f64) -> f64 {
        let (lo, hi) = (ua.min(ub), ua.max(ub));
        // lo's edge from the hint (the search keeps a chord's start and moves its end);
        // hi's edge forward from it over the chord's few vertices, so that the end's
        // lookup neither searches the whole list nor moves the hint away from the start.
        let k = self.edge(lo);
        let mut k_hi = k;
        while k_hi + 2 < self.vertices.len() && self.stations[k_hi + 1] <= hi {
            k_hi += 1;
        }
        let (k_a, k_b) = if ua <= ub { (k, k_hi) } else { (k_hi, k) };
        let (a, b) = (self.point_on(k_a, ua), self.point_on(k_b, ub));
        // The first vertex strictly after lo: the end of lo's edge.
        let first = if self.stations[k] <= lo && self.stations.get(k + 1).is_some_and(|&x| x > lo) {
            k + 1
        } else {
            self.stations.partition_point(|&x| x <= lo)
        };
        // The vertices strictly inside, then their distances in a plain loop over them
        // against the chord's vector computed once (the search measures a chord's dozen
        // vertices several times per block).
        let mut end = first;
        while end < self.stations.len() && self.stations[end] < hi {
            end += 1;
        }
        let chord = Segment::new(a, b);
        let inside = self.vertices.get(first..end).unwrap_or_default();
        inside.iter().map(|vertex| chord.distance_squared(vertex)).fold(0.0_f64, f64::max).sqrt()
    }

    /// The point at arc length `s` on edge `k` (the edge holding `s`).
    fn point_on(&self, k: usize, s: f64) -> Vec3 {
        let (Some(a), Some(b), Some(&s0), Some(&s1)) =
            (self.vertices.get(k), self.vertices.get(k + 1), self.stations.get(k), self.stations.get(k + 1))
        else {
            return self.vertices.first().copied().unwrap_or_else(Vec3::zeros);
        };
        let fraction = ((s - s0) / (s1 - s0)).clamp(0.0, 1.0);
        a + (b - a) * fraction
    }
}

/// The maximum of a smooth `f` near the middle of three samples `x` (increasing) with values
/// `y` (the middle one the largest): successive parabolic interpolation, kept inside the
/// bracket, until a step gains less than 1e-13 of the value or the `rounding` of the distances;
/// Brent's method when the parabola has no peak inside the bracket or converges slowly.
fn refine_maximum(f: &impl Fn(f64) -> f64, x: [f64; 3], y: [f64; 3], tol: f64, rounding: f64) -> f64 {
    let ([mut a, mut b, mut c], [mut fa, mut fb, mut fc]) = (x, y);
    // A smooth maximum is found to 1e-13 in three or four steps (superlinear convergence from
    // a bracket of 1/16 of the chord); beyond that the values' rounding only moves the vertex.
    for _ in 0..PARABOLIC_STEPS {
        let (left, right) = (b - a, b - c);
        let numerator = left * left * (fb - fc) - right * right * (fb - fa);
        let denominator = left * (fb - fc) - right * (fb - fa);
        let vertex = b - 0.5 * numerator / denominator;
        if denominator == 0.0 || !(vertex > a && vertex < c) {
            // Not a peak the parabola sees (flat, or rounding): search the bracket.
            let (_, negative) = minimise(|u| -f(u), a, c, tol);
            return fb.max(-negative);
        }
        if (vertex - b).abs() <= tol {
            return fb.max(f(vertex));
        }
        let value = f(vertex);
        if (value - fb).abs() <= 1e-13 * fb + rounding {
            return fb.max(value);
        }
        if value >= fb {
            if vertex < b {
                (c, fc) = (b, fb);
            } else {
                (a, fa) = (b, fb);
            }
            (b, fb) = (vertex, value);
        } else if vertex < b {
            (a, fa) = (vertex, value);
        } else {
            (c, fc) = (vertex, value);
        }
    }
    // Slow convergence (a kink, e.g. a curvature jump at a knot): finish on the bracket.
    let (_, negative) = minimise(|u| -f(u), a, c, tol);
    fb.max(-negative)
}

/// Most steps bracketing, and then bisecting, the tip of a hairpin at a chord end
/// (`end_overshoot`).
const OVERSHOOT_STEPS: usize = 64;

/// Sub-intervals per knot span in [`Shape::fast_deviation`].
const SPAN_SAMPLES: usize = 4;
/// Most knot spans one fast deviation samples; beyond, the reference sampling is used.
const MAX_FAST_SPANS: usize = 8;

/// The fast deviation of a NURBS chord (see [`Shape::fast_deviation`]); `None` when the chord
/// crosses more than [`MAX_FAST_SPANS`] knot spans.
fn spline_deviation(spline: &Spline, ua: f64, ub: f64, limit: f64) -> Option<f64> {
    let (lo, hi) = (ua.min(ub), ua.max(ub));
    let mut breaks = [0.0_f64; MAX_FAST_SPANS + 1];
    breaks[0] = lo;
    let mut count = 1;
    for knot in spline.nurbs.distinct_knots_between(lo, hi) {
        if count == MAX_FAST_SPANS {
            return None;
        }
        breaks[count] = knot;
        count += 1;
    }
    breaks[count] = hi;
    let (a, b) = (spline.nurbs.point(ua), spline.nurbs.point(ub));
    let hint = std::cell::Cell::new(0);
    let distance = |u: f64| distance_to_segment(&spline.nurbs.point_near(u, &hint), &a, &b);
    const CAPACITY: usize = MAX_FAST_SPANS * SPAN_SAMPLES + 1;
    let (mut at, mut value) = ([0.0_f64; CAPACITY], [0.0_f64; CAPACITY]);
    at[0] = lo;
    let mut n = 1;
    let mut best = 0;
    for piece in breaks[..=count].windows(2) {
        let step = (piece[1] - piece[0]) / SPAN_SAMPLES as f64;
        for j in 1..=SPAN_SAMPLES {
            let u = if j == SPAN_SAMPLES { piece[1] } else { piece[0] + step * j as f64 };
            let d = if u == hi { 0.0 } else { distance(u) };
            if d > limit {
                return Some(d);
            }
            (at[n], value[n]) = (u, d);
            if d > value[best] {
                best = n;
            }
            n += 1;
        }
    }
    let overshoot = end_overshoot(spline, ua, ub, at[1] - at[0], &distance);
    if best == 0 || (limit.is_finite() && value[best] < REFINE_FRACTION * limit) {
        return Some(value[best].max(overshoot));
    }
    let tol = 1e-9 * (hi - lo) + 4.0 * f64::EPSILON * lo.abs().max(hi.abs());
    let rounding = 8.0 * f64::EPSILON * a.amax().max(b.amax());
    let refined = refine_maximum(
        &distance,
        [at[best - 1], at[best], at[best + 1]],
        [value[best - 1], value[best], value[best + 1]],
        tol,
        rounding,
    );
    Some(refined.max(overshoot))
}

/// The largest distance from the chord `a`–`b` near an end where the curve runs back along the
/// chord (it went past that end and turned: a hairpin between two samples, which the property
/// tests found on a rational curve, a 0.009 mm overshoot the samples saw as a few micrometres).
/// The tip is where the curve turns along the chord: bracketed by steps back from the end
/// (from `width`, doubling) to where the curve still heads for the end, then bisected; the
/// distance is refined between the tip's mirror and the end. 0 where the curve leaves `a` and
/// reaches `b` heading along the chord.
fn end_overshoot(spline: &Spline, ua: f64, ub: f64, width: f64, distance: &impl Fn(f64) -> f64) -> f64 {
    let (a, b) = (spline.nurbs.point(ua), spline.nurbs.point(ub));
    let chord = b - a;
    let travel = (ub - ua).signum();
    let tol = 1e-9 * (ub - ua).abs() + 4.0 * f64::EPSILON * ua.abs().max(ub.abs());
    // The curve's motion along the chord, travelling from ua to ub.
    let heading = |u: f64| (spline.nurbs.derivatives(u)[1] * travel).dot(&chord);
    let mut largest = 0.0_f64;
    for (end, inward) in [(ua, travel), (ub, -travel)] {
        // Leaving a it must head for b, and arriving at b it must come from a's side: moving
        // back along the chord at either end, it is beyond that end on one side of its tip.
        let away = |u: f64| heading(u) < 0.0;
        if !away(end) {
            continue;
        }
        let reach = (ub - ua).abs();
        let (mut inner, mut outer, mut step) = (end, end, width.abs().min(reach));
        let mut bracketed = false;
        for _ in 0..OVERSHOOT_STEPS {
            outer = end + inward * step;
            if !away(outer) {
                bracketed = true;
                break;
            }
            inner = outer;
            if step >= reach {
                break;
            }
            step = (2.0 * step).min(reach);
        }
        if !bracketed {
            continue; // runs back all the way: the samples see it
        }
        for _ in 0..OVERSHOOT_STEPS {
            let middle = 0.5 * (inner + outer);
            if (outer - inner).abs() <= tol || middle == inner || middle == outer {
                break;
            }
            if away(middle) {
                inner = middle;
            } else {
                outer = middle;
            }
        }
        let tip = 0.5 * (inner + outer);
        let mirror = tip + (tip - end);
        let (_, negative) = minimise(|u| -distance(u), end.min(mirror), end.max(mirror), tol);
        largest = largest.max(-negative).max(distance(tip));
    }
    largest
}

/// Radius of the circle through three points, in any dimension (docs/spec/segment.md §2.8); infinite when
/// they are collinear: |u×v| ≤ 1e-15·longest side², plus the rounding of coordinates of this
/// size (points interpolated far from the origin are collinear only to that).
pub(crate) fn circumradius(p0: &Vec3, pm: &Vec3, p1: &Vec3) -> f64 {
    let (u, v, w) = (pm - p0, p1 - p0, p1 - pm);
    let twice_area = u.cross(&v).norm();
    let longest = u.norm().max(v.norm()).max(w.norm());
    let size = p0.amax().max(pm.amax()).max(p1.amax());
    if twice_area <= 1e-15 * longest * longest + 16.0 * f64::EPSILON * size * longest {
        return f64::INFINITY;
    }
    u.norm() * v.norm() * w.norm() / (2.0 * twice_area)
}

impl Shape {
    /// Parameter range.
    pub(crate) fn domain(&self) -> (f64, f64) {
        match self {
            Self::Arc(arc) => (0.0, arc.radius * arc.sweep),
            Self::Ellipse(ellipse) => (0.0, ellipse.sweep),
            Self::Polyline(line) => (0.0, line.stations.last().copied().unwrap_or(0.0)),
            Self::Spline(spline) => spline.nurbs.domain(),
        }
    }

    /// The range of the radius of curvature of the whole circle or ellipse the curve lies on
    /// (the ellipse's b²/a at the ends of its major axis, a²/b at the minor): bounds that hold
    /// for any part of it. `None` for polylines and NURBS, which may be straight.
    pub(crate) fn radius_bounds(&self) -> Option<(f64, f64)> {
        match self {
            Self::Arc(arc) => Some((arc.radius, arc.radius)),
            Self::Ellipse(ellipse) => {
                let [a, b] = ellipse.semi_axes;
                let (major, minor) = (a.max(b), a.min(b));
                Some((minor * minor / major, major * major / minor))
            }
            Self::Polyline(_) | Self::Spline(_) => None,
        }
    }

    /// The first point in (u_a, u_b] where the curve may turn without bending (a polyline's
    /// vertex, a NURBS knot where it is only C⁰), if any: a chord that fits up to it and no
    /// further must end there exactly, or the next chord starts a rounding's width short of it
    /// and cannot get past (with a chord error of 0 on straight pieces).
    pub(crate) fn kink_between(&self, ua: f64, ub: f64) -> Option<f64> {
        match self {
            Self::Arc(_) | Self::Ellipse(_) => None,
            Self::Polyline(line) => {
                let next = line.edge(ua) + 1;
                line.stations.get(next).copied().filter(|&s| s > ua && s <= ub)
            }
            Self::Spline(spline) => spline.nurbs.first_kink_in(ua, ub),
        }
    }

    /// Arc length, mm.
    pub(crate) fn length(&self) -> f64 {
        match self {
            Self::Arc(_) | Self::Polyline(_) => self.domain().1,
            Self::Ellipse(ellipse) => ellipse.table.length(),
            Self::Spline(spline) => spline.table.length(),
        }
    }

    /// P(u).
    pub(crate) fn point(&self, u: f64) -> Vec3 {
        match self {
            Self::Arc(arc) => {
                let angle = arc.start + arc.sense * u / arc.radius;
                arc.centre + arc.radius * Vec3::new(angle.cos(), angle.sin(), 0.0)
            }
            Self::Ellipse(ellipse) => ellipse.point(u),
            Self::Polyline(line) => line.point(u),
            Self::Spline(spline) => spline.nurbs.point(u),
        }
    }

    /// |dP/du|: 1 where u is the arc length.
    pub(crate) fn speed(&self, u: f64) -> f64 {
        match self {
            Self::Arc(_) | Self::Polyline(_) => 1.0,
            Self::Ellipse(ellipse) => ellipse.speed(u),
            Self::Spline(spline) => spline.speed(u),
        }
    }

    /// Arc length from the start to parameter `u`.
    pub(crate) fn s_at(&self, u: f64) -> f64 {
        match self {
            Self::Arc(_) | Self::Polyline(_) => u,
            Self::Ellipse(ellipse) => ellipse.table.s_at(ellipse, u),
            Self::Spline(spline) => spline.table.s_at(&spline.nurbs, u),
        }
    }

    /// Parameter at arc length `s`.
    pub(crate) fn u_at(&self, s: f64) -> f64 {
        match self {
            Self::Arc(_) | Self::Polyline(_) => s.clamp(0.0, self.domain().1),
            Self::Ellipse(ellipse) => ellipse.table.u_at(ellipse, s),
            Self::Spline(spline) => spline.table.u_at(&spline.nurbs, s),
        }
    }

    /// dev(u_a, u_b): the largest distance of the curve between the two parameters from the
    /// segment joining their points (docs/spec/segment.md §2.9). Exact for arcs (the sagitta) and polylines
    /// (the farthest vertex); otherwise 32 samples refined by Brent's method on the two
    /// sub-intervals around the best.
    pub(crate) fn deviation(&self, ua: f64, ub: f64) -> f64 {
        match self {
            Self::Arc(arc) => {
                let quarter = (ub - ua).abs() / (4.0 * arc.radius);
                2.0 * arc.radius * quarter.sin().powi(2)
            }
            Self::Polyline(line) => line.deviation(ua, ub),
            Self::Ellipse(_) | Self::Spline(_) => self.sampled_deviation(ua, ub, None),
        }
    }

    /// dev(u_a, u_b) where only "is it above `limit`" matters: the sampling stops at the first
    /// sample above it, and the refinement is skipped well below it.
    pub(crate) fn deviation_against(&self, ua: f64, ub: f64, limit: f64) -> f64 {
        match self {
            Self::Ellipse(_) | Self::Spline(_) => self.sampled_deviation(ua, ub, Some(limit)),
            Self::Arc(_) | Self::Polyline(_) => self.deviation(ua, ub),
        }
    }

    /// dev(u_a, u_b) for the fast search (docs/spec/segment.md §2.9a), where only values near `limit`
    /// need to be exact: closed forms for arcs and ellipses, the farthest vertex of a
    /// polyline, the exact value inside one span or across one knot of a plain B-spline of degree
    /// ≤ 3, and for other
    /// NURBS four sub-intervals per knot span refined around the best sample (a smooth span
    /// bends one way over a chord cut to its curvature, so its distance from the chord has one
    /// hump per span). Stops at the first sample above `limit`; skips the
    /// refinement well below it (an infinite `limit` gives the refined maximum). The flag says
    /// whether the value is exact (a closed form, a polyline's vertices, cubic spans), so that
    /// the chord needs no check.
    pub(crate) fn fast_deviation(&self, ua: f64, ub: f64, limit: f64) -> (f64, bool) {
        match self {
            Self::Arc(_) | Self::Polyline(_) => (self.deviation(ua, ub), true),
            Self::Ellipse(ellipse) if (ub - ua).abs() <= std::f64::consts::FRAC_PI_2 => {
                (ellipse.chord(ua.min(ub), ua.max(ub)).deviation, true)
            }
            Self::Ellipse(_) => (self.sampled_deviation(ua, ub, Some(limit)), false),
            Self::Spline(spline) => match spline.exact_deviation(ua, ub) {
                Some(exact) => (exact, true),
                None => {
                    let sampled = spline_deviation(spline, ua, ub, limit)
                        .unwrap_or_else(|| self.sampled_deviation(ua, ub, Some(limit)));
                    (sampled, false)
                }
            },
        }
    }

    /// The exact deviation of the chord from `ua` to `ub > ua` with its rate per unit of u as
    /// `ub` moves, where both have closed forms: chords of a plain cubic B-spline inside one span
    /// or across one knot ([`Spline::deviation_with_rate`]) and ellipse chords of up to a quarter
    /// turn; `None` elsewhere (the chord search then brackets).
    pub(crate) fn deviation_with_rate(&self, ua: f64, ub: f64) -> Option<(f64, DeviationRate<'_>)> {
        match self {
            Self::Spline(spline) => spline.deviation_with_rate(ua, ub),
            Self::Ellipse(ellipse) if ub > ua && ub - ua <= std::f64::consts::FRAC_PI_2 => {
                Some(ellipse.deviation_with_rate(ua, ub))
            }
            _ => None,
        }
    }

    /// The reference deviation (32 samples, refined) of a chord the fast search found, where
    /// [`Shape::fast_deviation`] only samples: it catches a hump between the fast samples, and
    /// the answer reports it as the chord's deviation. The exact value of a cubic span's chord;
    /// `None` where the fast value is exact and cheap.
    pub(crate) fn checked_deviation(&self, ua: f64, ub: f64) -> Option<f64> {
        match self {
            Self::Arc(_) | Self::Polyline(_) => None,
            Self::Ellipse(_) if (ub - ua).abs() <= std::f64::consts::FRAC_PI_2 => None,
            Self::Ellipse(_) => Some(self.sampled_deviation(ua, ub, None)),
            Self::Spline(spline) => {
                Some(spline.exact_deviation(ua, ub).unwrap_or_else(|| self.sampled_deviation(ua, ub, None)))
            }
        }
    }

    fn sampled_deviation(&self, ua: f64, ub: f64, threshold: Option<f64>) -> f64 {
        let (a, b) = (self.point(ua), self.point(ub));
        let hint = std::cell::Cell::new(0);
        let distance = |u: f64| {
            let p = match self {
                Self::Spline(spline) => spline.nurbs.point_near(u, &hint),
                _ => self.point(u),
            };
            distance_to_segment(&p, &a, &b)
        };
        let step = (ub - ua) / DEVIATION_SAMPLES as f64;
        let mut samples = [0.0_f64; DEVIATION_SAMPLES + 1];
        let mut best_index = 0;
        for j in 1..DEVIATION_SAMPLES {
            samples[j] = distance(ua + step * j as f64);
            if threshold.is_some_and(|limit| samples[j] > limit) {
                return samples[j];
            }
            if samples[j] > samples[best_index] {
                best_index = j;
            }
        }
        let overshoot = match self {
            Self::Spline(spline) => end_overshoot(spline, ua, ub, step, &distance),
            _ => 0.0,
        };
        let best = samples[best_index];
        if best_index == 0 || threshold.is_some_and(|limit| best < REFINE_FRACTION * limit) {
            return best.max(overshoot);
        }
        let at = |j: usize| ua + step * j as f64;
        let tol = 1e-9 * (ub - ua).abs() + 4.0 * f64::EPSILON * ua.abs().max(ub.abs());
        // Distances are computed from coordinates of this size: their rounding is the floor.
        let rounding = 8.0 * f64::EPSILON * a.amax().max(b.amax());
        let refined = refine_maximum(
            &distance,
            [at(best_index - 1), at(best_index), at(best_index + 1)],
            [samples[best_index - 1], best, samples[best_index + 1]],
            tol,
            rounding,
        );
        refined.max(overshoot)
    }

    /// The smallest radius of curvature on [u_a, u_b] (mm; infinite where straight), and where it
    /// is. Analytic for arcs and ellipses, sampled from the derivatives and refined for NURBS;
    /// for polylines the circumradius of P(s − L/2), P(s), P(s + L/2) at steps of L/4 with
    /// `scale` = L (the block length), which measures the bend at the scale of the chords and
    /// not the noise of the points.
    pub(crate) fn min_radius(&self, ua: f64, ub: f64, scale: f64) -> (f64, f64) {
        let (lo, hi) = (ua.min(ub), ua.max(ub));
        match self {
            Self::Arc(arc) => (arc.radius, lo),
            Self::Ellipse(ellipse) => {
                // r(t) is monotone between multiples of π/2: check the ends and those.
                let mut best = (ellipse.radius(ellipse.angle(lo)), lo);
                let end = ellipse.radius(ellipse.angle(hi));
                if end < best.0 {
                    best = (end, hi);
                }
                let quarter = std::f64::consts::FRAC_PI_2;
                let (t_lo, t_hi) = {
                    let (x, y) = (ellipse.angle(lo), ellipse.angle(hi));
                    (x.min(y), x.max(y))
                };
                let mut k = (t_lo / quarter).ceil();
                while k * quarter <= t_hi {
                    let t = k * quarter;
                    let radius = ellipse.radius(t);
                    if radius < best.0 {
                        best = (radius, (t - ellipse.start) * ellipse.sense);
                    }
                    k += 1.0;
                }
                best
            }
            Self::Polyline(line) => {
                let half = 0.5 * scale;
                if hi - lo <= scale {
                    let middle = 0.5 * (lo + hi);
                    let radius = circumradius(&line.point(lo), &line.point(middle), &line.point(hi));
                    return (radius, middle);
                }
                let count = (((hi - lo) / (0.25 * scale)).ceil() as usize).clamp(1, MAX_RADIUS_SAMPLES);
                let step = (hi - lo - scale) / count as f64;
                let mut best = (f64::INFINITY, lo + half);
                // The three points move forward along the polyline with the samples: each keeps
                // its edge and steps on from it, instead of a lookup per point.
                let first_edge = line.edge(lo);
                let mut edges = [first_edge; 3];
                let mut point_at = |which: usize, s: f64| {
                    let edge = &mut edges[which];
                    while *edge + 2 < line.vertices.len() && line.stations[*edge + 1] <= s {
                        *edge += 1;
                    }
                    line.point_on(*edge, s)
                };
                for j in 0..=count {
                    let s = lo + half + step * j as f64;
                    let radius = circumradius(&point_at(0, s - half), &point_at(1, s), &point_at(2, s + half));
                    if radius < best.0 {
                        best = (radius, s);
                    }
                }
                best
            }
            Self::Spline(spline) => spline.radius_minima.smallest(&spline.nurbs, lo, hi),
        }
    }

    /// Break points of [u_a, u_b] into pieces small enough for [`Shape::min_radius`] to sample
    /// well: NURBS knot spans, polyline pieces of 1000 `scale` (at most 10 000 of them), else
    /// the whole range.
    pub(crate) fn radius_pieces(&self, ua: f64, ub: f64, scale: f64) -> Vec<f64> {
        let mut out = vec![ua];
        match self {
            Self::Spline(spline) => {
                out.extend(spline.nurbs.breaks().iter().map(|(knot, _)| *knot).filter(|&knot| knot > ua && knot < ub))
            }
            Self::Polyline(_) => {
                // At most 10 000 pieces, whatever the scale.
                let piece = (1000.0 * scale).max((ub - ua) / 10_000.0);
                let count = ((ub - ua) / piece).ceil();
                if count > 1.0 && count.is_finite() {
                    for k in 1..count as usize {
                        out.push(ua + piece * k as f64);
                    }
                }
            }
            Self::Arc(_) | Self::Ellipse(_) => {}
        }
        out.push(ub);
        out
    }

    /// Parameters of the interior corners, where the direction turns by more than `corner`
    /// radians (E11): polyline vertices, and NURBS knots of multiplicity ≥ the degree or where
    /// the curve stops (cusps).
    pub(crate) fn corners(&self, corner: f64) -> Vec<f64> {
        // Whether the direction turns by more than `corner`: by the cosine, with acos only
        // within 1e-9 of the threshold's, where the two could round differently (a polyline of
        // 100 000 points spent a tenth of its solve in acos).
        let threshold = corner.cos();
        let turns = |before: Vec3, after: Vec3| {
            let (nb, na) = (before.norm(), after.norm());
            if nb == 0.0 || na == 0.0 {
                return false;
            }
            let cosine = (before.dot(&after) / (nb * na)).clamp(-1.0, 1.0);
            if (cosine - threshold).abs() > 1e-9 {
                return cosine < threshold;
            }
            cosine.acos() > corner
        };
        match self {
            Self::Arc(_) | Self::Ellipse(_) => Vec::new(),
            Self::Polyline(line) => line
                .vertices
                .windows(3)
                .zip(line.stations.iter().skip(1))
                .filter(|(three, _)| turns(three[1] - three[0], three[2] - three[1]))
                .map(|(_, &station)| station)
                .collect(),
            Self::Spline(spline) => {
                let degree = spline.nurbs.degree();
                let breaks = spline.nurbs.breaks();
                let (start, end) = spline.nurbs.domain();
                let mean_speed = spline.table.length() / (end - start);
                let mut out = Vec::new();
                for window in breaks.windows(3) {
                    let (before, (knot, multiplicity), after) = (window[0].0, window[1], window[2].0);
                    // A tangent may break where the curve is only C0 (multiplicity ≥ degree) or
                    // where it stops (a cusp from `degree` coincident control points).
                    let speed = spline.nurbs.plain_speed_at_knot(knot).unwrap_or_else(|| spline.speed(knot));
                    let stops = speed <= 1e-9 * mean_speed;
                    if multiplicity < degree && !stops {
                        continue;
                    }
                    // Directions just before and after; at a cusp the curve moves only with
                    // the square of the step, so grow it until the moves stand above rounding.
                    let here = spline.nurbs.point(knot);
                    let noise = 1e-11 * here.amax().max(1.0);
                    let room = (knot - before).min(after - knot);
                    let (mut incoming, mut outgoing) = (Vec3::zeros(), Vec3::zeros());
                    for fraction in [1e-7, 1e-5, 1e-3] {
                        let delta = fraction * room;
                        incoming = here - spline.nurbs.point(knot - delta);
                        outgoing = spline.nurbs.point(knot + delta) - here;
                        if incoming.norm() > noise && outgoing.norm() > noise {
                            break;
                        }
                    }
                    if turns(incoming, outgoing) {
                        out.push(knot);
                    }
                }
                out
            }
        }
    }
}

/// Checks that a curve has a usable length.
pub(crate) fn require_length(shape: &Shape, field: &str) -> Result<f64, SolverError> {
    let length = shape.length();
    if length.is_nan() || length <= 1e-9 || !length.is_finite() {
        return Err(SolverError::new(
            ErrorCode::DegenerateCurve,
            format!("the curve has no length ({length:e} mm): nothing to segment"),
        )
        .at(field));
    }
    Ok(length)
}

#[cfg(test)]
mod tests;
