//! Unit tests of the curve shapes: points, tangents, radii, arc lengths and corners of every kind
//! (docs/spec/segment.md §2).

use super::*;
use approx::assert_relative_eq;

#[test]
fn a_hairpin_beyond_the_chord_end_counts() {
    // A rational quadratic that runs 0.009 mm past a chord's end and turns back between two
    // of the 32 samples (found by the property tests): the deviation is the tip's distance
    // from that end, not the few micrometres the samples alone see.
    let control: Vec<Vec3> = [
        [6.3178282535315535, 0.0],
        [-5.278122233799347, -11.483615078424297],
        [3.9571577762024446, -7.539654064436308],
        [0.0, 7.151824819702683],
        [-14.628399769836593, 13.930560152940036],
        [-14.207321980790294, -9.675831506395363],
        [16.021925858200994, 11.955354107956543],
        [1.7083640345294515, 1.7133571694329857],
    ]
    .iter()
    .map(|p| Vec3::new(p[0], p[1], 0.0))
    .collect();
    let weights = [
        2.4877905030426497,
        0.8473523686460599,
        2.3344922658374028,
        0.3,
        2.1120301725436215,
        1.9240425844729563,
        0.3,
        0.3,
    ];
    let nurbs = Nurbs::new(2, &control, None, Some(&weights), "curve").unwrap();
    let breaks: Vec<f64> = nurbs.breaks().iter().map(|(knot, _)| *knot).collect();
    let table = ArcLengthTable::build(&|u| nurbs.speed(u), &breaks, 4, "curve").unwrap();
    let shape = Shape::Spline(Spline::new(nurbs.clone(), table));
    let (ua, ub) = (0.833_099_343_911_542_7, 0.971_634_124_853_778_8);
    let (a, b) = (nurbs.point(ua), nurbs.point(ub));
    let dense = (0..=200_000)
        .map(|j| distance_to_segment(&nurbs.point(ua + (ub - ua) * f64::from(j) / 200_000.0), &a, &b))
        .fold(0.0, f64::max);
    assert!(dense > 0.008, "{dense}");
    for (what, deviation) in [
        ("reference", shape.deviation(ua, ub)),
        ("checked", shape.checked_deviation(ua, ub).unwrap()),
        ("fast", shape.fast_deviation(ua, ub, f64::INFINITY).0),
    ] {
        assert!(deviation >= dense * (1.0 - 1e-6), "{what}: {deviation} below {dense}");
    }
}

#[test]
fn one_panel_per_knot_span_gives_the_arc_length_of_sixty_four() {
    // Rational curves of degree 2 to 5 with weights from 0.05 to 20, and plain ones, with a
    // near-cusp (two control points 1e-4 apart): the table the chord job builds against a
    // fine one.
    for (degree, rational) in (2..=5).flat_map(|degree| [(degree, true), (degree, false)]) {
        let control: Vec<Vec3> = (0..14)
            .map(|k| {
                let k = f64::from(k);
                let nudge = if k == 7.0 { 1e-4 } else { 0.0 };
                Vec3::new(10.0 * (k - 1.0).max(0.0) + nudge, 8.0 * (1.3 * k).sin(), 3.0 * (0.7 * k).cos())
            })
            .collect();
        let weights: Vec<f64> =
            (0..14).map(|k| if rational { [0.05, 1.0, 20.0, 0.7, 3.0][k % 5] } else { 1.0 }).collect();
        let nurbs = Nurbs::new(degree, &control, None, Some(&weights), "curve").unwrap();
        let breaks: Vec<f64> = nurbs.breaks().iter().map(|(knot, _)| *knot).collect();
        // The coarse table as the job builds it (the span found once per panel), the fine one
        // node by node through the plain closure.
        let speed = |u: f64| nurbs.speed(u);
        let coarse = ArcLengthTable::build(&nurbs, &breaks, super::super::job::NURBS_PANELS_PER_SPAN, "curve").unwrap();
        let fine = ArcLengthTable::build(&speed, &breaks, 64, "curve").unwrap();
        assert_relative_eq!(coarse.length(), fine.length(), max_relative = 1e-13);
        for k in 0..=1000 {
            let u = f64::from(k) / 1000.0;
            let (a, b) = (coarse.s_at(&nurbs, u), fine.s_at(&speed, u));
            assert!((a - b).abs() <= 1e-13 * fine.length(), "degree {degree}, u = {u}: {a} vs {b}");
            let s = fine.length() * f64::from(k) / 1000.0;
            let (a, b) = (coarse.u_at(&nurbs, s), fine.u_at(&speed, s));
            assert!((a - b).abs() <= 1e-12, "degree {degree}, s = {s}: {a} vs {b}");
        }
    }
}

#[test]
fn the_deviation_rate_matches_a_difference_inside_a_span_and_across_a_knot() {
    // A plain cubic B-spline through a wavy 3-D polygon; chords from a third to eight tenths of
    // a span, the end moved a little either way (staying on its side of a knot).
    let control: Vec<Vec3> = (0..12)
        .map(|k| {
            let k = f64::from(k);
            Vec3::new(10.0 * k, 6.0 * (0.9 * k).sin(), 2.0 * (0.5 * k).cos())
        })
        .collect();
    let nurbs = Nurbs::new(3, &control, None, None, "curve").unwrap();
    let breaks: Vec<f64> = nurbs.breaks().iter().map(|(knot, _)| *knot).collect();
    let table = ArcLengthTable::build(&|u| nurbs.speed(u), &breaks, 4, "curve").unwrap();
    let spline = Spline::new(nurbs, table);
    let span = 1.0 / 9.0;
    let (mut inside, mut across) = (0, 0);
    for k in 0..100 {
        let lo = 0.9 * f64::from(k) / 100.0;
        for width in [0.3, 0.8] {
            let hi = lo + width * span;
            let Some((deviation, rate)) = spline.deviation_with_rate(lo, hi) else { continue };
            let Some(rate) = rate.per_u() else { continue };
            let step = 1e-7;
            let knot = breaks.iter().any(|&knot| knot > lo && knot < hi);
            if breaks.iter().any(|&knot| (knot - hi).abs() < 2.0 * step) {
                continue;
            }
            let moved = |end: f64| spline.exact_deviation(lo, end).unwrap();
            let difference = (moved(hi + step) - moved(hi - step)) / (2.0 * step);
            assert_eq!(deviation, moved(hi));
            assert!((rate - difference).abs() <= 1e-5 * difference.abs(), "[{lo}, {hi}]: {rate} vs {difference}");
            if knot {
                across += 1;
            } else {
                inside += 1;
            }
        }
    }
    assert!(inside > 50 && across > 50, "{inside} inside, {across} across a knot");
}

fn ellipse() -> Shape {
    let (a, b) = (100.0_f64, 50.0_f64);
    let speed = |t: f64| (a * t.sin()).hypot(b * t.cos());
    let table = ArcLengthTable::build(&speed, &[0.0, std::f64::consts::FRAC_PI_2], 16, "curve").unwrap();
    Shape::Ellipse(Ellipse {
        centre: Vec3::zeros(),
        semi_axes: [a, b],
        rotation_sin_cos: (0.0, 1.0),
        start: 0.0,
        sense: 1.0,
        sweep: std::f64::consts::FRAC_PI_2,
        table,
        angles: AngleMemo::default(),
    })
}

#[test]
fn the_ellipse_deviation_rate_matches_a_difference_both_ways_round() {
    for sense in [1.0, -1.0] {
        let Shape::Ellipse(mut ellipse) = ellipse() else { unreachable!() };
        (ellipse.sense, ellipse.start) = (sense, 0.4);
        let shape = Shape::Ellipse(ellipse);
        for (ua, ub) in [(0.0, 0.01), (0.3, 0.35), (0.7, 1.5), (1.0, 1.0 + std::f64::consts::FRAC_PI_2)] {
            let (deviation, rate) = shape.deviation_with_rate(ua, ub).expect("a quarter turn or less");
            let rate = rate.per_u().expect("a rate");
            assert_relative_eq!(deviation, shape.fast_deviation(ua, ub, f64::INFINITY).0, max_relative = 1e-15);
            assert_relative_eq!(deviation, shape.deviation(ua, ub), max_relative = 1e-9);
            let step = 1e-7;
            let moved = |end: f64| shape.fast_deviation(ua, end, f64::INFINITY).0;
            let difference = (moved(ub + step) - moved(ub - step)) / (2.0 * step);
            assert_relative_eq!(rate, difference, max_relative = 1e-6);
        }
        assert_eq!(shape.deviation_with_rate(0.0, 1.6), None, "past a quarter turn");
    }
}

#[test]
fn the_ellipse_panel_turns_its_nodes_to_the_same_integral() {
    for sense in [1.0, -1.0] {
        let Shape::Ellipse(mut ellipse) = ellipse() else { unreachable!() };
        (ellipse.sense, ellipse.start) = (sense, 0.4);
        for (a, b) in [(0.0, 1e-6), (0.1, 0.3), (0.7, 1.5), (0.2, 0.2 + std::f64::consts::PI)] {
            let turned = Speed::panel(&ellipse, a, b);
            let node_by_node = crate::segment::arclength::gauss_panel(|u| ellipse.speed(u), a, b);
            assert_relative_eq!(turned, node_by_node, max_relative = 1e-14);
        }
    }
}

#[test]
fn circumradius_of_points_on_a_circle() {
    let on = |angle: f64| Vec3::new(7.0 * angle.cos(), 7.0 * angle.sin(), 0.0);
    assert_relative_eq!(circumradius(&on(0.1), &on(0.5), &on(1.3)), 7.0, max_relative = 1e-12);
    let line = circumradius(&Vec3::zeros(), &Vec3::x(), &(2.0 * Vec3::x()));
    assert!(line.is_infinite());
}

#[test]
fn ellipse_deviation_peaks_at_the_mean_angle() {
    // Affine image of a circle: the farthest point from the chord is at t = (ta + tb)/2.
    let shape = ellipse();
    let (ta, tb) = (0.2, 0.35);
    let (a, b) = (shape.point(ta), shape.point(tb));
    let expected = distance_to_segment(&shape.point(0.5 * (ta + tb)), &a, &b);
    assert_relative_eq!(shape.deviation(ta, tb), expected, max_relative = 1e-12);
}

#[test]
fn ellipse_minimum_radius_is_b_squared_over_a() {
    let shape = ellipse();
    let (radius, at) = shape.min_radius(0.0, 1.0, 1.0);
    assert_relative_eq!(radius, 25.0, max_relative = 1e-15);
    assert_eq!(at, 0.0);
    let (top, _) = shape.min_radius(1.0, std::f64::consts::FRAC_PI_2, 1.0);
    assert_relative_eq!(top, shape_radius_at(1.0), max_relative = 1e-12);
}

fn shape_radius_at(t: f64) -> f64 {
    let (a, b) = (100.0_f64, 50.0_f64);
    (a * t.sin()).hypot(b * t.cos()).powi(3) / (a * b)
}

#[test]
fn arc_sagitta_equals_sampled_deviation() {
    let arc =
        Shape::Arc(Arc { centre: Vec3::zeros(), radius: 50.0, start: 0.0, sense: 1.0, sweep: std::f64::consts::TAU });
    let exact = arc.deviation(1.0, 1.7);
    assert_relative_eq!(exact, arc.sampled_deviation(1.0, 1.7, None), max_relative = 1e-10);
}

#[test]
fn polyline_deviation_is_the_farthest_vertex() {
    let vertices = vec![Vec3::zeros(), Vec3::new(1.0, 0.2, 0.0), Vec3::new(2.0, 0.0, 0.0)];
    let first = (vertices[1] - vertices[0]).norm();
    let stations = vec![0.0, first, 2.0 * first];
    let line = Shape::Polyline(Polyline { vertices, stations, last_edge: std::cell::Cell::new(0) });
    assert_relative_eq!(line.deviation(0.0, 2.0 * first), 0.2, max_relative = 1e-15);
    assert_eq!(line.corners(10f64.to_radians()), vec![first]);
    assert!(line.corners(30f64.to_radians()).is_empty());
}

/// The galloping edge lookup finds what a search of the whole list finds, and the
/// deviation's own edge walk gives, bit for bit, what looking up both ends afresh and
/// scanning every vertex gives: on a wavy line with repeated vertices, for chords in both
/// directions, starting anywhere, with the hint left anywhere.
#[test]
fn polyline_deviation_walk_equals_a_fresh_lookup() {
    let mut vertices: Vec<Vec3> = (0..400)
        .map(|k| {
            let t = f64::from(k) * 0.05;
            Vec3::new(t, (3.0 * t).sin() * 0.3, 0.0)
        })
        .collect();
    vertices.insert(100, vertices[100]); // a zero-length edge
    let mut stations = vec![0.0];
    for pair in vertices.windows(2) {
        stations.push(stations.last().unwrap() + (pair[1] - pair[0]).norm());
    }
    let total = *stations.last().unwrap();
    let line = Polyline { vertices: vertices.clone(), stations: stations.clone(), last_edge: std::cell::Cell::new(0) };
    let shape = Shape::Polyline(line);
    let Shape::Polyline(line) = &shape else { unreachable!() };
    let fresh_point = |s: f64| {
        let k = stations.partition_point(|&x| x <= s).saturating_sub(1).min(vertices.len() - 2);
        line.point_on(k, s)
    };
    let mut state = 12_345_u64;
    let mut next = || {
        state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    for _ in 0..2000 {
        let s = (next() - 0.01) * total * 1.02;
        line.last_edge.set((next() * 402.0) as usize);
        let whole = stations.partition_point(|&x| x <= s).saturating_sub(1).min(vertices.len() - 2);
        assert_eq!(line.edge(s), whole, "{s}");
        let ua = next() * total * 1.01;
        let ub = (ua + (next() - 0.3) * 3.0).clamp(0.0, total * 1.01);
        line.last_edge.set((next() * 400.0) as usize);
        let (a, b) = (fresh_point(ua), fresh_point(ub));
        let (lo, hi) = (ua.min(ub), ua.max(ub));
        let expected = vertices
            .iter()
            .zip(&stations)
            .filter(|&(_, &station)| station > lo && station < hi)
            .fold(0.0_f64, |worst, (vertex, _)| worst.max(distance_to_segment(vertex, &a, &b)));
        assert_eq!(shape.deviation(ua, ub).to_bits(), expected.to_bits(), "{ua} {ub}");
    }
}
