//! Property tests of the segmentation (docs/spec/segment.md §2.9): on random circles, ellipses,
//! NURBS curves and 3-D polylines, at random feeds, block times and margins,
//!
//! * every block except the remainder at a span end is at least margin × feed × block time long
//!   (with the conservative `minimum` radius estimate and with the whole-curve rule),
//! * every chord's deviation from the true curve is at most its window's chord error, checked by
//!   dense sampling with the test's own curve evaluators,
//! * every command point lies on the curve, the first and last at its ends,
//! * on circles the on-surface chord is k_f·F·T_b/60000 (docs/spec/segment.md §7),
//! * the fast search (docs/spec/segment.md §2.9a) gives at most 0.5 % (and at least one block) more than
//!   the reference greedy of §2.9 on random NURBS of degrees 1–5, rational or plain (one weight:
//!   the Newton search of cubic chords), in 2-D and 3-D,
//! * in mode `guarantee` (§2.9a) no block but the last (or one ending at a corner) is shorter
//!   than margin × feed × block time, on the same random NURBS.

use kerf_solver::segment::{self, CommandPoint, SegmentRequest, SegmentSolution};
use proptest::prelude::*;
use serde_json::{Value, json};

/// Slack on chord errors and lengths (the greedy search brackets to 1e-12 mm).
const SLACK: f64 = 1e-9;

type Point = [f64; 3];

fn sub(a: &Point, b: &Point) -> Point {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: &Point, b: &Point) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn norm(a: &Point) -> f64 {
    dot(a, a).sqrt()
}

fn to_point(p: &CommandPoint) -> Point {
    let p = p.as_slice();
    [p[0], p[1], p.get(2).copied().unwrap_or(0.0)]
}

fn segment_distance(p: &Point, a: &Point, b: &Point) -> f64 {
    let ab = sub(b, a);
    let ap = sub(p, a);
    let length_squared = dot(&ab, &ab);
    let t = if length_squared == 0.0 { 0.0 } else { (dot(&ap, &ab) / length_squared).clamp(0.0, 1.0) };
    norm(&sub(&ap, &[ab[0] * t, ab[1] * t, ab[2] * t]))
}

/// The test's own curve: a parametric function on [0, 1].
trait Reference {
    fn at(&self, t: f64) -> Point;
}

struct Ellipse {
    centre: Point,
    a: f64,
    b: f64,
    rotation: f64,
    start: f64,
    sweep: f64,
}

impl Reference for Ellipse {
    fn at(&self, t: f64) -> Point {
        let angle = self.start + self.sweep * t;
        let (x, y) = (self.a * angle.cos(), self.b * angle.sin());
        let (sin, cos) = self.rotation.sin_cos();
        [self.centre[0] + cos * x - sin * y, self.centre[1] + sin * x + cos * y, self.centre[2]]
    }
}

/// NURBS by the Cox–de Boor recursion in homogeneous coordinates, clamped uniform knots.
struct Spline {
    degree: usize,
    control: Vec<Point>,
    weights: Vec<f64>,
    knots: Vec<f64>,
}

impl Spline {
    fn new(degree: usize, control: Vec<Point>, weights: Vec<f64>) -> Self {
        let n = control.len();
        let mut knots = vec![0.0; degree + 1];
        for k in 1..n - degree {
            knots.push(k as f64 / (n - degree) as f64);
        }
        knots.extend(std::iter::repeat_n(1.0, degree + 1));
        Self { degree, control, weights, knots }
    }

    fn basis(&self, i: usize, p: usize, u: f64) -> f64 {
        let k = &self.knots;
        if p == 0 {
            let last = u >= 1.0 && k[i + 1] == 1.0 && k[i] < 1.0;
            return if (k[i] <= u && u < k[i + 1]) || last { 1.0 } else { 0.0 };
        }
        let mut value = 0.0;
        if k[i + p] > k[i] {
            value += (u - k[i]) / (k[i + p] - k[i]) * self.basis(i, p - 1, u);
        }
        if k[i + p + 1] > k[i + 1] {
            value += (k[i + p + 1] - u) / (k[i + p + 1] - k[i + 1]) * self.basis(i + 1, p - 1, u);
        }
        value
    }
}

impl Reference for Spline {
    fn at(&self, u: f64) -> Point {
        let mut sum = [0.0; 4];
        for (i, (p, w)) in self.control.iter().zip(&self.weights).enumerate() {
            let n = self.basis(i, self.degree, u) * w;
            if n == 0.0 {
                continue;
            }
            for axis in 0..3 {
                sum[axis] += n * p[axis];
            }
            sum[3] += n;
        }
        [sum[0] / sum[3], sum[1] / sum[3], sum[2] / sum[3]]
    }
}

/// Dense samples of a reference curve with their cumulative chord length.
struct Dense {
    t: Vec<f64>,
    points: Vec<Point>,
    s: Vec<f64>,
}

impl Dense {
    fn new(curve: &dyn Reference, count: usize) -> Self {
        let t: Vec<f64> = (0..=count).map(|j| j as f64 / count as f64).collect();
        let points: Vec<Point> = t.iter().map(|&t| curve.at(t)).collect();
        let mut s = vec![0.0];
        for pair in points.windows(2) {
            s.push(s.last().unwrap() + norm(&sub(&pair[1], &pair[0])));
        }
        Self { t, points, s }
    }

    /// The samples within 1 mm of arc length of `s_hint` about as near `point` as the nearest
    /// (within two sample spacings), the nearest of each run of neighbours: where the curve comes
    /// back near itself (a hairpin) one on each branch, of which the caller keeps the one the
    /// point is on.
    fn candidates(&self, point: &Point, s_hint: f64) -> Vec<usize> {
        let lo = self.s.partition_point(|&s| s < s_hint - 1.0);
        let hi = self.s.partition_point(|&s| s <= s_hint + 1.0).min(self.s.len());
        let distance = |index: usize| norm(&sub(&self.points[index], point));
        let nearest = (lo..hi).min_by(|&a, &b| distance(a).total_cmp(&distance(b))).unwrap();
        let last = self.s.len() - 1;
        let spacing = self.s[(nearest + 1).min(last)] - self.s[nearest.saturating_sub(1)];
        // The nearest sample of each run of neighbouring ones: one per branch.
        let mut runs: Vec<usize> = Vec::new();
        let mut previous: Option<usize> = None;
        for index in (lo..hi).filter(|&index| distance(index) <= distance(nearest) + spacing) {
            match runs.last_mut() {
                Some(best) if previous == Some(index - 1) => {
                    if distance(index) < distance(*best) {
                        *best = index;
                    }
                }
                _ => runs.push(index),
            }
            previous = Some(index);
        }
        runs
    }
}

/// Distance of `point` from the curve near sample `index` (golden-section on the neighbouring
/// parameter interval).
fn distance_to_curve(curve: &dyn Reference, dense: &Dense, index: usize, point: &Point) -> f64 {
    let lo = dense.t[index.saturating_sub(1)];
    let hi = dense.t[(index + 1).min(dense.t.len() - 1)];
    let f = |t: f64| norm(&sub(&curve.at(t), point));
    let (mut a, mut b) = (lo, hi);
    let ratio = (5f64.sqrt() - 1.0) / 2.0;
    for _ in 0..100 {
        let (c, d) = (b - ratio * (b - a), a + ratio * (b - a));
        if f(c) < f(d) {
            b = d;
        } else {
            a = c;
        }
    }
    f(0.5 * (a + b)).min(f(lo)).min(f(hi))
}

/// The chord error of the window each block starts in.
fn block_chord_errors(answer: &SegmentSolution) -> Vec<f64> {
    answer.s[..answer.s.len() - 1]
        .iter()
        .map(|&s| {
            let index = answer.windows.partition_point(|w| w.s_start <= s + 1e-9).saturating_sub(1);
            answer.windows[index].chord_error
        })
        .collect()
}

/// Checks the three invariants against a reference curve; `span_end` says whether block i ends a
/// span (so may be a short remainder).
fn check(answer: &SegmentSolution, curve: &dyn Reference, samples: usize, min_block: Option<f64>) {
    let dense = Dense::new(curve, samples);
    let points: Vec<Point> = answer.points.iter().map(to_point).collect();
    let first = points.first().unwrap();
    let last = points.last().unwrap();
    assert!(norm(&sub(first, &curve.at(0.0))) <= 1e-9, "first point off the start");
    assert!(norm(&sub(last, &curve.at(1.0))) <= 1e-9, "last point off the end");
    let indices: Vec<usize> = points
        .iter()
        .zip(&answer.s)
        .map(|(p, &s)| {
            let candidates = dense.candidates(p, s * dense.s.last().unwrap() / answer.curve_length);
            if let [only] = candidates[..] {
                return only;
            }
            let on_curve = |index: usize| distance_to_curve(curve, &dense, index, p);
            candidates.into_iter().map(|index| (on_curve(index), index)).min_by(|a, b| a.0.total_cmp(&b.0)).unwrap().1
        })
        .collect();
    for (point, &index) in points.iter().zip(&indices) {
        let distance = distance_to_curve(curve, &dense, index, point);
        assert!(distance <= 1e-8, "point {point:?} is {distance} off the curve");
    }
    let allowed = block_chord_errors(answer);
    for (block, pair) in indices.windows(2).enumerate() {
        let (a, b) = (&points[block], &points[block + 1]);
        // Samples strictly between the ones nearest the ends lie inside the chord's stretch.
        let worst = (pair[0] + 1..pair[1]).map(|j| segment_distance(&dense.points[j], a, b)).fold(0.0, f64::max);
        assert!(
            worst <= allowed[block] + SLACK,
            "block {block}: deviation {worst} over its chord error {}",
            allowed[block]
        );
    }
    if let Some(min_block) = min_block {
        let count = points.len() - 1;
        let short: Vec<(usize, f64)> = points
            .windows(2)
            .enumerate()
            .map(|(i, pair)| (i, norm(&sub(&pair[1], &pair[0]))))
            .filter(|&(_, length)| length < min_block * (1.0 - SLACK))
            .collect();
        // Only span-end remainders may be short: the answer counts them apart.
        assert_eq!(answer.stats.short_blocks, 0, "short blocks {short:?} of {count}");
        if let Some(&(index, _)) = short.iter().find(|&&(i, _)| i + 1 != count) {
            // A short block that is not the last must end at a corner; smooth curves have none.
            panic!("block {index} of {count} is short and not the last");
        }
    }
}

fn solve_feasible(request: Value) -> Option<SegmentSolution> {
    feasible_request(request).map(|(_, answer)| answer)
}

/// The request (its feed lowered until feasible, at most three times by 4) and its answer.
fn feasible_request(mut request: Value) -> Option<(SegmentRequest, SegmentSolution)> {
    for _ in 0..4 {
        let parsed: SegmentRequest = serde_json::from_value(request.clone()).unwrap();
        match segment::solve(&parsed, None) {
            Ok(answer) => return Some((parsed, answer)),
            Err(error) if error.code().as_str() == "E_INFEASIBLE_FEED_FOR_RADIUS" => {
                assert!(error.message().contains("largest feasible feed"));
                assert_eq!(error.field(), Some("feed"));
                let feed = request["feed"].as_f64().unwrap();
                request["feed"] = json!(feed / 4.0);
            }
            Err(error) => panic!("{}: {}", error.code().as_str(), error.message()),
        }
    }
    None
}

fn target_chord(answer: &SegmentSolution) -> f64 {
    answer.margin * answer.feed * answer.block_time_ms / 60_000.0
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, .. ProptestConfig::default() })]

    #[test]
    fn circles_cut_on_the_surface(
        radius in 2.0_f64..200.0,
        centre in prop::array::uniform3(-100.0_f64..100.0),
        start_deg in -360.0_f64..360.0,
        clockwise in any::<bool>(),
        feed in 2000.0_f64..20_000.0,
        block_time_ms in 1.0_f64..8.0,
        margin in 1.0_f64..1.3,
    ) {
        let request = json!({
            "curve": {"kind": "circle", "centre": centre, "radius": radius, "start_deg": start_deg,
                      "direction": if clockwise { "cw" } else { "ccw" }},
            "feed": feed, "block_time_ms": block_time_ms, "margin": margin
        });
        let Some(answer) = solve_feasible(request) else { return Ok(()); };
        let sweep = if clockwise { -std::f64::consts::TAU } else { std::f64::consts::TAU };
        let curve = Ellipse { centre, a: radius, b: radius, rotation: 0.0, start: start_deg.to_radians(), sweep };
        for p in &answer.points {
            let p = to_point(p);
            prop_assert!((norm(&sub(&p, &centre)) - radius).abs() <= 1e-9);
        }
        let target = target_chord(&answer);
        let lengths: Vec<f64> = answer.points.windows(2).map(|w| norm(&sub(&to_point(&w[1]), &to_point(&w[0])))).collect();
        // The greedy search accepts 1e-12 mm over C_ep: that lengthens the chord by eps/(2·C_ep).
        let slack = target * 1e-12 / answer.chord_error + 1e-9 * target.max(1.0);
        for length in &lengths[..lengths.len() - 1] {
            prop_assert!((length - target).abs() <= slack, "{length} vs {target}");
        }
        let samples = ((answer.curve_length / (0.02 * target)).ceil() as usize).clamp(2000, 200_000);
        check(&answer, &curve, samples, Some(target));
    }

    #[test]
    fn ellipses_keep_every_block_long_enough(
        a in 5.0_f64..200.0,
        ratio in 0.2_f64..1.0,
        centre in prop::array::uniform3(-100.0_f64..100.0),
        rotation_deg in -180.0_f64..180.0,
        start_deg in -360.0_f64..360.0,
        sweep_deg in 10.0_f64..360.0,
        clockwise in any::<bool>(),
        feed in 2000.0_f64..15_000.0,
        block_time_ms in 1.0_f64..6.0,
        margin in 1.0_f64..1.2,
        min_chord_error in prop::option::of(0.0_f64..0.003),
        whole_curve in any::<bool>(),
    ) {
        let b = a * ratio;
        let end_deg = if clockwise { start_deg - sweep_deg } else { start_deg + sweep_deg };
        let mut request = json!({
            "curve": {"kind": "ellipse", "centre": centre, "semi_axes": [a, b], "start_deg": start_deg,
                      "end_deg": end_deg, "rotation_deg": rotation_deg,
                      "direction": if clockwise { "cw" } else { "ccw" }},
            "feed": feed, "block_time_ms": block_time_ms, "margin": margin,
            "min_chord_error": min_chord_error.unwrap_or(0.0)
        });
        if whole_curve {
            request["mode"] = json!("curve");
        } else {
            request["radius_estimate"] = json!("minimum");
        }
        let Some(answer) = solve_feasible(request) else { return Ok(()); };
        let sweep = if clockwise { -sweep_deg } else { sweep_deg }.to_radians();
        let curve = Ellipse { centre, a, b, rotation: rotation_deg.to_radians(), start: start_deg.to_radians(), sweep };
        let target = target_chord(&answer);
        let samples = ((answer.curve_length / (0.02 * target)).ceil() as usize).clamp(2000, 200_000);
        check(&answer, &curve, samples, Some(target));
    }

    #[test]
    fn nurbs_keep_every_block_long_enough(
        degree in 2_usize..=5,
        heights in prop::collection::vec((-6.0_f64..6.0, -3.0_f64..3.0, 0.5_f64..2.0), 6..14),
        feed in 2000.0_f64..12_000.0,
        block_time_ms in 1.0_f64..4.0,
        margin in 1.0_f64..1.2,
        whole_curve in any::<bool>(),
    ) {
        let control: Vec<Point> = heights.iter().enumerate().map(|(i, (y, z, _))| [10.0 * i as f64, *y, *z]).collect();
        let weights: Vec<f64> = heights.iter().map(|(_, _, w)| *w).collect();
        let mut request = json!({
            "curve": {"kind": "bspline", "degree": degree, "control_points": control, "weights": weights},
            "feed": feed, "block_time_ms": block_time_ms, "margin": margin
        });
        if whole_curve {
            request["mode"] = json!("curve");
        } else {
            request["radius_estimate"] = json!("minimum");
        }
        let Some(answer) = solve_feasible(request) else { return Ok(()); };
        let curve = Spline::new(degree, control, weights);
        let target = target_chord(&answer);
        let samples = ((answer.curve_length / (0.1 * target)).ceil() as usize).clamp(4000, 40_000);
        // The smallest radius of a NURBS is sampled: allow 1e-6 of the target chord.
        check(&answer, &curve, samples, Some(target * (1.0 - 1e-6)));
    }

    #[test]
    fn three_point_windows_stay_within_their_chord_errors(
        degree in 2_usize..=5,
        heights in prop::collection::vec(-6.0_f64..6.0, 6..14),
        feed in 2000.0_f64..12_000.0,
        block_time_ms in 1.0_f64..4.0,
        window in 1.0_f64..20.0,
        min_chord_error in 0.0_f64..0.002,
        margin in 1.0_f64..1.3,
    ) {
        let control: Vec<Point> = heights.iter().enumerate().map(|(i, y)| [10.0 * i as f64, *y, 0.0]).collect();
        let request = json!({
            "curve": {"kind": "bspline", "degree": degree, "control_points": control},
            "feed": feed, "block_time_ms": block_time_ms, "window": window, "min_chord_error": min_chord_error,
            "margin": margin
        });
        let Some(answer) = solve_feasible(request) else { return Ok(()); };
        let curve = Spline::new(degree, control, vec![1.0; heights.len()]);
        let target = target_chord(&answer);
        let samples = ((answer.curve_length / (0.1 * target)).ceil() as usize).clamp(4000, 40_000);
        check(&answer, &curve, samples, None);
        // The answer's own count agrees with the block lengths.
        let short = answer.points.windows(2).take(answer.stats.blocks - 1)
            .filter(|w| norm(&sub(&to_point(&w[1]), &to_point(&w[0]))) < answer.stats.block_length * (1.0 - SLACK))
            .count();
        prop_assert_eq!(short, answer.stats.short_blocks);
        // The 3-point radius is held within 1.1 times the smallest radius in its window, so a
        // margin of √1.1 (with a little room for the first chord of a window, which may reach past
        // it) keeps every block at least feed × block time long.
        if margin >= 1.08 {
            prop_assert_eq!(answer.stats.short_blocks, 0, "margin {}", margin);
        }
    }

    #[test]
    fn dense_helix_polylines_are_cut_on_their_edges(
        radius in 5.0_f64..30.0,
        pitch in 0.0_f64..10.0,
        turns in 0.3_f64..1.5,
        points_per_chord in 10.0_f64..30.0,
        feed in 3000.0_f64..10_000.0,
        block_time_ms in 2.0_f64..4.0,
        margin in 1.02_f64..1.2,
    ) {
        // Dense: at least 10 points per target chord (sparser polylines get W_SPARSE_POLYLINE).
        let target = margin * feed * block_time_ms / 60_000.0;
        let length = std::f64::consts::TAU * turns * radius;
        let count = (length / target * points_per_chord).ceil() as usize;
        let vertices: Vec<Point> = (0..=count)
            .map(|j| {
                let t = std::f64::consts::TAU * turns * j as f64 / count as f64;
                [radius * t.cos(), radius * t.sin(), pitch * t / std::f64::consts::TAU]
            })
            .collect();
        let request = json!({
            "curve": {"kind": "polyline", "points": vertices},
            "feed": feed, "block_time_ms": block_time_ms, "margin": margin, "radius_estimate": "minimum"
        });
        let Some(answer) = solve_feasible(request) else { return Ok(()); };
        prop_assert_eq!(answer.points[0].dimension(), 3);
        prop_assert!(answer.warnings.iter().all(|w| w.code != "W_SPARSE_POLYLINE"));
        let allowed = block_chord_errors(&answer);
        let points: Vec<Point> = answer.points.iter().map(to_point).collect();
        let mut stations = vec![0.0];
        for pair in vertices.windows(2) {
            stations.push(stations.last().unwrap() + norm(&sub(&pair[1], &pair[0])));
        }
        // Each point on the polyline edge at its arc length.
        for (p, &s) in points.iter().zip(&answer.s) {
            let edge = stations.partition_point(|&x| x <= s).saturating_sub(1).min(vertices.len() - 2);
            let distance = (edge.saturating_sub(1)..(edge + 2).min(vertices.len() - 1))
                .map(|e| segment_distance(p, &vertices[e], &vertices[e + 1]))
                .fold(f64::INFINITY, f64::min);
            prop_assert!(distance <= 1e-9, "{:?} is {} off the polyline", p, distance);
        }
        prop_assert!(norm(&sub(&points[0], &vertices[0])) <= 1e-12);
        prop_assert!(norm(&sub(points.last().unwrap(), vertices.last().unwrap())) <= 1e-9);
        // Each chord within its chord error of the vertices it spans.
        for (block, pair) in points.windows(2).enumerate() {
            let (s0, s1) = (answer.s[block], answer.s[block + 1]);
            let lo = stations.partition_point(|&s| s <= s0);
            let hi = stations.partition_point(|&s| s < s1);
            let worst = (lo..hi)
                .map(|j| segment_distance(&vertices[j], &pair[0], &pair[1]))
                .fold(0.0, f64::max);
            prop_assert!(worst <= allowed[block] + SLACK, "block {} deviation {} over {}", block, worst, allowed[block]);
        }
        // Dense points and a little margin: no block starves the control.
        prop_assert_eq!(answer.stats.short_blocks, 0);
    }

    #[test]
    fn fast_search_stays_within_the_reference_greedys_count(
        degree in 1_usize..=5,
        control in prop::collection::vec(prop::array::uniform3(-20.0_f64..20.0), 6..10),
        weights in prop::collection::vec(0.3_f64..3.0, 10),
        plain in any::<bool>(),
        flat in any::<bool>(),
        feed in 1000.0_f64..8000.0,
        block_time_ms in 1.0_f64..4.0,
        margin in 1.0_f64..1.2,
        mode in prop::sample::select(vec!["window", "curve", "minimum"]),
    ) {
        let control: Vec<Point> =
            control.iter().map(|p| if flat { [p[0], p[1], 0.0] } else { *p }).collect();
        // Half the curves plain B-splines (one weight), whose chords of degree ≤ 3 the search
        // steps to by Newton on the exact deviation.
        let weights = if plain { vec![1.0; control.len()] } else { weights[..control.len()].to_vec() };
        let mut request = json!({
            "curve": {"kind": "bspline", "degree": degree, "control_points": control, "weights": weights},
            "feed": feed, "block_time_ms": block_time_ms, "margin": margin
        });
        match mode {
            "minimum" => request["radius_estimate"] = json!("minimum"),
            other => request["mode"] = json!(other),
        }
        let Some((parsed, answer)) = feasible_request(request) else { return Ok(()); };
        // Near a cusp the two numerics' windows can start a hair apart and one of them meet a
        // radius too tight for the feed: nothing to compare then.
        let reference = match segment::solve_reference(&parsed, None) {
            Ok(reference) => reference,
            Err(error) if error.code().as_str() == "E_INFEASIBLE_FEED_FOR_RADIUS" => return Ok(()),
            Err(error) => panic!("{}: {}", error.code().as_str(), error.message()),
        };
        let (fast, oracle) = (answer.stats.blocks, reference.stats.blocks);
        // docs/spec/segment.md §2.9a item 3, read as 0.5 % with at least one block of slack (the requirement "the
        // block count within 0.5 %"). Not capped at 2: in window mode a chord ending within 1e-8
        // mm of its window's end goes to one window or the next by rounding, and every later
        // window shifts, so a count of thousands drifts by a few blocks between any two numerics
        // (a rational curve of 6 610 blocks: 3 more, the first difference a chord 1e-8 mm from a
        // window end, found by this test; 0.05 %).
        let allowed = (0.005 * oracle as f64).floor().max(1.0) as usize;
        prop_assert!(fast <= oracle + allowed, "{} blocks, the reference greedy {}", fast, oracle);
        let curve = Spline::new(degree, control, weights);
        let target = target_chord(&answer);
        // Twenty dense samples per chord at least; a curve that feasibility drove to tens of
        // thousands of tiny blocks (near a cusp) is beyond a dense check here.
        let samples = ((answer.curve_length / (0.05 * target)).ceil() as usize).max(4000);
        if samples > 200_000 {
            return Ok(());
        }
        check(&answer, &curve, samples, None);
        prop_assert!(answer.max_deviation <= answer.chord_error + SLACK);
    }

    #[test]
    fn guarantee_mode_keeps_every_block_but_the_last_long_enough(
        degree in 1_usize..=5,
        control in prop::collection::vec(prop::array::uniform3(-20.0_f64..20.0), 6..10),
        weights in prop::collection::vec(0.3_f64..3.0, 10),
        plain in any::<bool>(),
        flat in any::<bool>(),
        feed in 1000.0_f64..8000.0,
        block_time_ms in 1.0_f64..4.0,
        margin in 1.0_f64..1.2,
        min_chord_error in prop::option::of(0.0_f64..0.002),
    ) {
        let control: Vec<Point> =
            control.iter().map(|p| if flat { [p[0], p[1], 0.0] } else { *p }).collect();
        let weights = if plain { vec![1.0; control.len()] } else { weights[..control.len()].to_vec() };
        let request = json!({
            "curve": {"kind": "bspline", "degree": degree, "control_points": control, "weights": weights},
            "feed": feed, "block_time_ms": block_time_ms, "margin": margin, "mode": "guarantee",
            "min_chord_error": min_chord_error.unwrap_or(0.0)
        });
        let Some(answer) = solve_feasible(request) else { return Ok(()); };
        prop_assert_eq!(answer.stats.short_blocks, 0);
        let curve = Spline::new(degree, control.clone(), weights);
        let target = target_chord(&answer);
        // Twenty dense samples per chord at least; a curve that feasibility drove to tens of
        // thousands of tiny blocks (near a cusp) is beyond a dense check here.
        let samples = ((answer.curve_length / (0.05 * target)).ceil() as usize).max(4000);
        if samples > 200_000 {
            return Ok(());
        }
        check(&answer, &curve, samples, None);
        // Only the last block, or (degree 1) one ending at a corner of the control polygon, may
        // be short; the smallest radius of a NURBS is sampled: allow 1e-6 of the target.
        let points: Vec<Point> = answer.points.iter().map(to_point).collect();
        let blocks = points.len() - 1;
        for (index, pair) in points.windows(2).enumerate() {
            let length = norm(&sub(&pair[1], &pair[0]));
            let at_corner = degree == 1 && control.iter().any(|c| norm(&sub(c, &pair[1])) <= 1e-9);
            prop_assert!(
                length >= target * (1.0 - 1e-6) || index + 1 == blocks || at_corner,
                "block {} of {}: {} < {}", index, blocks, length, target
            );
        }
    }
}
