//! Unit tests of B-spline and NURBS evaluation, knots and radii of curvature (docs/spec/segment.md §2).

use super::*;
use crate::segment::radius::radius_of;
use approx::assert_abs_diff_eq;

fn points(list: &[[f64; 2]]) -> Vec<Vec3> {
    list.iter().map(|p| Vec3::new(p[0], p[1], 0.0)).collect()
}

#[test]
fn rational_quadratic_is_an_exact_quarter_circle() {
    let control = points(&[[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let weights = [1.0, std::f64::consts::FRAC_1_SQRT_2, 1.0];
    let curve = Nurbs::new(2, &control, None, Some(&weights), "curve").unwrap();
    for k in 0..=10 {
        let u = f64::from(k) / 10.0;
        let [point, first, second] = curve.derivatives(u);
        assert_abs_diff_eq!(point.norm(), 1.0, epsilon = 1e-14);
        assert_abs_diff_eq!((curve.point(u) - point).norm(), 0.0, epsilon = 1e-15);
        // Curvature of the unit circle is 1.
        let curvature = first.cross(&second).norm() / first.norm().powi(3);
        assert_abs_diff_eq!(curvature, 1.0, epsilon = 1e-12);
    }
}

#[test]
fn derivatives_match_finite_differences() {
    let control = points(&[[0.0, 0.0], [1.0, 2.0], [3.0, 3.0], [4.0, 0.0], [6.0, 1.0], [7.0, 4.0]]);
    let weights = [1.0, 2.0, 0.5, 1.0, 3.0, 1.0];
    for degree in 1..=5 {
        let curve = Nurbs::new(degree, &control, None, Some(&weights), "curve").unwrap();
        let step = 1e-5;
        for k in 1..10 {
            let u = f64::from(k) / 10.0 + 0.013;
            let [_, first, second] = curve.derivatives(u);
            let difference = (curve.point(u + step) - curve.point(u - step)) / (2.0 * step);
            assert_abs_diff_eq!((first - difference).norm(), 0.0, epsilon = 1e-6 * (1.0 + first.norm()));
            // The speed without the second derivative agrees with the full evaluation.
            assert_abs_diff_eq!(curve.speed(u), first.norm(), epsilon = 1e-12 * first.norm());
            // On a plain B-spline the speed comes from the squared-speed polynomial.
            let plain = Nurbs::new(degree, &control, None, None, "curve").unwrap();
            let plain_first = plain.derivatives(u)[1].norm();
            assert_abs_diff_eq!(plain.speed(u), plain_first, epsilon = 1e-12 * plain_first);
            if degree >= 3 {
                let [_, ahead, _] = curve.derivatives(u + step);
                let [_, behind, _] = curve.derivatives(u - step);
                let change = (ahead - behind) / (2.0 * step);
                assert_abs_diff_eq!((second - change).norm(), 0.0, epsilon = 1e-5 * (1.0 + second.norm()));
            }
        }
    }
}

#[test]
fn power_form_matches_the_basis_functions() {
    // Far from the origin, uneven knots with a double knot, weights: degrees 1–5.
    let control: Vec<Vec3> = (0..9)
        .map(|i| Vec3::new(5000.0 + 7.0 * f64::from(i), -3000.0 + (f64::from(i) * 1.3).sin() * 4.0, f64::from(i % 3)))
        .collect();
    let weights = [1.0, 2.0, 0.5, 1.0, 3.0, 1.0, 0.7, 1.4, 1.0];
    for degree in 1..=5_usize {
        let inner = 9 - degree - 1;
        let mut knots = vec![0.0; degree + 1];
        for k in 1..=inner {
            knots.push(if k == inner && inner > 1 && degree > 1 {
                knots[knots.len() - 1]
            } else {
                (k as f64).powf(1.3)
            });
        }
        let last = knots[knots.len() - 1] + 1.0;
        knots.extend(std::iter::repeat_n(last, degree + 1));
        let curve = Nurbs::new(degree, &control, Some(&knots), Some(&weights), "curve").unwrap();
        let (start, end) = curve.domain();
        for k in 0..=200 {
            let u = start + (end - start) * f64::from(k) / 200.0;
            let span = curve.span(u);
            let h = curve.homogeneous_by_basis(span, u, &Vec3::zeros());
            let by_basis = Vec3::new(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
            assert_abs_diff_eq!((curve.point(u) - by_basis).norm(), 0.0, epsilon = 1e-10);
            let [p, d1, d2] = curve.derivatives(u);
            let [q, e1, e2] = curve.derivatives_by_basis(span, u);
            assert_abs_diff_eq!((p - by_basis).norm(), 0.0, epsilon = 1e-10);
            assert_abs_diff_eq!((q - by_basis).norm(), 0.0, epsilon = 1e-10);
            assert_abs_diff_eq!((d1 - e1).norm(), 0.0, epsilon = 1e-9 * (1.0 + e1.norm()));
            assert_abs_diff_eq!((d2 - e2).norm(), 0.0, epsilon = 1e-8 * (1.0 + e2.norm()));
        }
    }
}

#[test]
fn the_plain_radius_matches_the_homogeneous_one() {
    // Uneven knots, far from the origin, degrees 1-3; rational curves and knots have none.
    let control: Vec<Vec3> = (0..9)
        .map(|k| {
            let k = f64::from(k);
            Vec3::new(1000.0 + 7.0 * k, -500.0 + 4.0 * (1.1 * k).sin(), 2.0 * (0.6 * k).cos())
        })
        .collect();
    for degree in 1..=3 {
        // Straight (degree 1): infinite; else within 1e-11 of the basis functions' value.
        let same_radius = |plain: f64, reference: f64, at: &str| {
            if degree == 1 {
                assert_eq!(plain, f64::INFINITY, "{at}");
            } else {
                assert!((plain - reference).abs() <= 1e-11 * reference, "{at}: {plain} vs {reference}");
            }
        };
        let inner = control.len() - degree - 1;
        let mut knots = vec![0.0; degree + 1];
        knots.extend((1..=inner).map(|k| (f64::from(k as u32) / (inner + 1) as f64).powf(1.3)));
        knots.extend(vec![1.0; degree + 1]);
        let curve = Nurbs::new(degree, &control, Some(&knots), None, "curve").unwrap();
        for k in 1..500 {
            let u = f64::from(k) / 500.0;
            let Some(plain) = curve.plain_radius_inside(u) else {
                assert!(knots.contains(&u), "degree {degree}: no plain radius at {u}");
                continue;
            };
            same_radius(plain, radius_of(curve.derivatives(u)), &format!("degree {degree}, u = {u}"));
        }
        assert_eq!(curve.plain_radius_inside(knots[degree + 1]), None, "at a knot");
        // At the interior knots: both one-sided radii and the speed after the knot, as the
        // basis functions give them.
        for &knot in &knots[degree + 1..knots.len() - degree - 1] {
            let right = curve.derivatives(knot);
            let by_basis = curve
                .derivatives_from_left(knot)
                .map_or(radius_of(right), |left| radius_of(left).min(radius_of(right)));
            let plain = curve.plain_radius_at_knot(knot).expect("the curve moves at its knots");
            same_radius(plain, by_basis, &format!("degree {degree}, knot {knot}"));
            let speed = curve.plain_speed_at_knot(knot).unwrap();
            assert!((speed - curve.speed(knot)).abs() <= 1e-12 * speed, "degree {degree}, knot {knot}");
        }
    }
    // A cusp: three coincident control points of a cubic stop the curve at a knot, where only
    // the basis functions are exact.
    let mut cusp = control.clone();
    (cusp[4], cusp[5]) = (cusp[3], cusp[3]);
    let curve = Nurbs::new(3, &cusp, None, None, "curve").unwrap();
    let slowest = (1..6).map(|k| f64::from(k) / 6.0).min_by(|a, b| curve.speed(*a).total_cmp(&curve.speed(*b)));
    let knot = slowest.unwrap();
    assert!(curve.speed(knot) < 1e-12, "the curve stops at a knot: {}", curve.speed(knot));
    assert_eq!(curve.plain_radius_at_knot(knot), None);
    assert_eq!(curve.plain_speed_at_knot(knot), None);
    let weights = vec![1.0, 2.0, 1.0, 1.0, 0.5, 1.0, 1.0, 3.0, 1.0];
    let rational = Nurbs::new(3, &control, None, Some(&weights), "curve").unwrap();
    assert_eq!(rational.plain_radius_inside(0.3), None);
}

#[test]
fn knot_vectors_are_checked() {
    let control = points(&[[0.0, 0.0], [1.0, 1.0], [2.0, 0.0], [3.0, 1.0]]);
    let field =
        |knots: &[f64]| Nurbs::new(2, &control, Some(knots), None, "curve").unwrap_err().field().map(str::to_owned);
    assert_eq!(field(&[0.0, 0.0, 0.0, 1.0, 1.0, 1.0]).as_deref(), Some("curve.knots"));
    assert_eq!(field(&[0.0, 0.0, 0.0, 0.6, 0.5, 1.0, 1.0]).as_deref(), Some("curve.knots[4]"));
    assert_eq!(field(&[0.0, 0.0, 0.1, 0.5, 1.0, 1.0, 1.0]).as_deref(), Some("curve.knots[2]"));
    assert_eq!(field(&[0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 2.0]).as_deref(), Some("curve.knots[5]"));
    assert_eq!(field(&[0.0, 0.0, 0.0, f64::NAN, 1.0, 1.0, 1.0]).as_deref(), Some("curve.knots[3]"));
    assert!(Nurbs::new(2, &control, Some(&[0.0, 0.0, 0.0, 0.5, 1.0, 1.0, 1.0]), None, "curve").is_ok());
    let weights = Nurbs::new(2, &control, None, Some(&[1.0, 0.0, 1.0, 1.0]), "curve").unwrap_err();
    assert_eq!(weights.field(), Some("curve.weights[1]"));
    assert_eq!(Nurbs::new(6, &control, None, None, "curve").unwrap_err().field(), Some("curve.degree"));
    assert_eq!(Nurbs::new(3, &control[..3], None, None, "curve").unwrap_err().field(), Some("curve.control_points"));
}

#[test]
fn interior_knots_may_repeat_up_to_the_degree() {
    let control = points(&[[0.0, 0.0], [1.0, 1.0], [2.0, 0.0], [3.0, 1.0], [4.0, 0.0]]);
    let ok = [0.0, 0.0, 0.0, 0.5, 0.5, 1.0, 1.0, 1.0];
    assert!(Nurbs::new(2, &control, Some(&ok), None, "curve").is_ok());
    let control6 = points(&[[0.0, 0.0], [1.0, 1.0], [2.0, 0.0], [3.0, 1.0], [4.0, 0.0], [5.0, 1.0]]);
    let bad = [0.0, 0.0, 0.0, 0.5, 0.5, 0.5, 1.0, 1.0, 1.0];
    let error = Nurbs::new(2, &control6, Some(&bad), None, "curve").unwrap_err();
    assert_eq!(error.field(), Some("curve.knots[5]"));
    let curve = Nurbs::new(2, &control, Some(&ok), None, "curve").unwrap();
    assert_eq!(curve.breaks(), vec![(0.0, 3), (0.5, 2), (1.0, 3)]);
    // Clamped: the ends are the end control points.
    assert_abs_diff_eq!((curve.point(0.0) - control[0]).norm(), 0.0);
    assert_abs_diff_eq!((curve.point(1.0) - control[4]).norm(), 0.0, epsilon = 1e-15);
}
