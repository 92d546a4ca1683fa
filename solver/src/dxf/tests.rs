//! The DXF reader on files ezdxf wrote (tests/dxf/make_fixtures.py).

use super::*;

fn fixture(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/dxf").join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn area(points: &[[f64; 2]]) -> f64 {
    super::curves::tests_area(points)
}

fn with_layer(layer: &str) -> DxfOptions {
    DxfOptions { layer: Some(layer.to_owned()), ..DxfOptions::default() }
}

#[test]
fn a_plate_with_bulges_a_circle_and_a_slot_of_lines_and_arcs() {
    let profile = read(&fixture("plate_mm.dxf"), "file", &with_layer("CUT")).unwrap();
    assert_eq!(profile.units, DrawingUnits::Mm);
    let corners = 4.0 * (100.0 - std::f64::consts::PI * 25.0);
    assert!((area(&profile.boundary) - (6000.0 - corners)).abs() < 0.05, "{}", area(&profile.boundary));
    assert_eq!(profile.islands.len(), 2);
    let mut islands: Vec<f64> = profile.islands.iter().map(|i| -area(i)).collect();
    islands.sort_by(f64::total_cmp);
    assert!((islands[0] - std::f64::consts::PI * 64.0).abs() < 0.05, "{islands:?}");
    assert!((islands[1] - (200.0 + std::f64::consts::PI * 25.0)).abs() < 0.05, "{islands:?}");
    assert_eq!(profile.layers, ["CUT", "NOTES"]);
    // Every point of the bulged corners is on its radius-10 arc within the chord tolerance.
    for p in profile.boundary.iter().filter(|p| p[0] > 90.0 && p[1] > 50.0) {
        let r = (p[0] - 90.0).hypot(p[1] - 50.0);
        assert!((r - 10.0).abs() < 1e-9, "{p:?}");
    }
}

#[test]
fn every_layer_at_once_finds_the_open_line_of_notes() {
    let error = read(&fixture("plate_mm.dxf"), "file", &DxfOptions::default()).unwrap_err();
    let text = error.to_string();
    assert!(text.contains("open chain") && text.contains("LINE") && text.contains("NOTES"), "{text}");
    assert_eq!(error.field(), Some("file"));
    let error = read(&fixture("plate_mm.dxf"), "file", &with_layer("HOLES")).unwrap_err();
    assert_eq!(error.field(), Some("layer"));
    assert!(error.to_string().contains("CUT, NOTES"), "{error}");
}

#[test]
fn r12_has_no_units_and_is_read_in_the_units_given_ascii_and_binary() {
    for name in ["square_inch_r12.dxf", "square_inch_r12_binary.dxf"] {
        let error = read(&fixture(name), "file", &DxfOptions::default()).unwrap_err();
        assert_eq!(error.field(), Some("units"), "{name}: {error}");
        let options = DxfOptions { units: Some(DrawingUnits::Inch), ..DxfOptions::default() };
        let profile = read(&fixture(name), "file", &options).unwrap();
        assert_eq!(profile.boundary, [[0.0, 0.0], [50.8, 0.0], [50.8, 50.8], [0.0, 50.8]], "{name}");
    }
}

#[test]
fn a_closed_spline_round_an_ellipse_in_cm_binary() {
    let profile = read(&fixture("spline_ellipse_cm_binary.dxf"), "file", &DxfOptions::default()).unwrap();
    assert_eq!(profile.units, DrawingUnits::Cm);
    assert_eq!(profile.islands.len(), 1);
    let ellipse = -area(&profile.islands[0]);
    assert!((ellipse - std::f64::consts::PI * 10.0 * 5.0).abs() < 0.05, "{ellipse}");
    // The spline through points on a 40 x 30 mm ellipse: its area near that ellipse's.
    let spline = area(&profile.boundary);
    assert!((spline - std::f64::consts::PI * 40.0 * 30.0).abs() < 40.0, "{spline}");
}

#[test]
fn a_gap_a_crossing_and_missing_units_are_named() {
    let error = read(&fixture("broken_chain.dxf"), "file", &DxfOptions::default()).unwrap_err().to_string();
    assert!(error.contains("open chain") && error.contains("(40.0000 mm, 30.0000 mm)"), "{error}");
    assert!(error.contains("0.5000 mm"), "{error}");
    let wide = DxfOptions { join_tolerance: 0.6, ..DxfOptions::default() };
    assert_eq!(read(&fixture("broken_chain.dxf"), "file", &wide).unwrap().boundary.len(), 4);
    let error = read(&fixture("bow_tie.dxf"), "file", &DxfOptions::default()).unwrap_err().to_string();
    assert!(error.contains("self-intersection") && error.contains("(5.0000 mm, 5.0000 mm)"), "{error}");
    assert!(error.contains("LWPOLYLINE"), "{error}");
    let error = read(&fixture("no_units.dxf"), "file", &DxfOptions::default()).unwrap_err();
    assert_eq!(error.field(), Some("units"));
    assert!(error.to_string().contains("give units"), "{error}");
    let error = read(b"0\nSECTION\n2\nENTITIES\n0\nLINE\n8\nA\n10\nx\n", "file", &DxfOptions::default()).unwrap_err();
    assert_eq!(error.field(), Some("units"));
    let options = DxfOptions { units: Some(DrawingUnits::Mm), ..DxfOptions::default() };
    let error = read(b"0\nSECTION\n2\nENTITIES\n0\nLINE\n8\nA\n10\nx\n", "file", &options).unwrap_err();
    assert!(error.to_string().contains("LINE on layer A: group code 10"), "{error}");
    let error = read(b"not a drawing", "file", &options).unwrap_err();
    assert_eq!(error.field(), Some("file"));
}

#[test]
fn lines_round_trip_to_the_typed_polygon() {
    let profile = read(&fixture("l_plate_lines.dxf"), "file", &DxfOptions::default()).unwrap();
    let typed = [[0.0, 0.0], [80.0, 0.0], [80.0, 30.0], [40.0, 30.0], [40.0, 60.0], [0.0, 60.0]];
    let start = profile.boundary.iter().position(|p| *p == typed[0]).unwrap();
    let mut rotated = profile.boundary.clone();
    rotated.rotate_left(start);
    assert_eq!(rotated, typed);
}

#[test]
fn lines_shorter_than_the_join_tolerance_close_only_at_the_start() {
    // A 1000-gon of 0.0063 mm lines in a stride order, every other one reversed: with a join
    // tolerance of 0.01 mm the chain could close one line early.
    let count = 1000;
    let point = |k: usize| {
        let angle = std::f64::consts::TAU * (k % count) as f64 / count as f64;
        [angle.cos(), angle.sin()]
    };
    let mut text = String::from("0\nSECTION\n2\nENTITIES\n");
    for index in 0..count {
        let k = (index * 7) % count;
        let (mut a, mut b) = (point(k), point(k + 1));
        if index % 2 == 1 {
            std::mem::swap(&mut a, &mut b);
        }
        text.push_str(&format!("0\nLINE\n8\nA\n10\n{}\n20\n{}\n11\n{}\n21\n{}\n", a[0], a[1], b[0], b[1]));
    }
    text.push_str("0\nENDSEC\n0\nEOF\n");
    let options = DxfOptions { units: Some(DrawingUnits::Mm), ..DxfOptions::default() };
    let profile = read(text.as_bytes(), "file", &options).unwrap();
    assert_eq!(profile.boundary.len(), count);
    assert!(profile.islands.is_empty());
}

#[test]
fn blocks_are_placed_scaled_turned_mirrored_and_arrayed_ascii_and_binary() {
    let ascii = read(&fixture("blocks_mm.dxf"), "file", &with_layer("CUT")).unwrap();
    let binary = read(&fixture("blocks_mm_binary.dxf"), "file", &with_layer("CUT")).unwrap();
    assert_eq!(ascii, binary);
    assert_eq!(ascii.layers, ["CUT"]);
    assert!((area(&ascii.boundary) - 9600.0).abs() < 1e-9, "{}", area(&ascii.boundary));
    assert_eq!(ascii.islands.len(), 8);
    let pi = std::f64::consts::PI;
    let holes: f64 = ascii.islands.iter().map(|i| -area(i)).sum();
    assert!((holes - (47.0 * pi + 48.0)).abs() < 0.1, "{holes}");
    let centre = |island: &Vec<[f64; 2]>| {
        let n = island.len() as f64;
        [island.iter().map(|p| p[0]).sum::<f64>() / n, island.iter().map(|p| p[1]).sum::<f64>() / n]
    };
    let near = |c: [f64; 2], x: f64, y: f64| (c[0] - x).abs() < 0.01 && (c[1] - y).abs() < 0.01;
    for (x, y, r) in [(30.0, 40.0, 3.0), (60.0, 40.0, 3.0), (70.0, 20.0, 2.0), (70.0, 40.0, 2.0), (40.0, 70.0, 2.0)] {
        let island = ascii.islands.iter().find(|i| near(centre(i), x, y)).unwrap_or_else(|| panic!("({x}, {y})"));
        assert!((-area(island) - pi * r * r).abs() < 0.02, "({x}, {y})");
    }
    // The slot placed with x scale −1: its arcs' centres at x = 100 and 92.
    let slot = ascii.islands.iter().find(|i| -area(i) > 60.0).unwrap();
    let xs = slot.iter().map(|p| p[0]);
    let (low, high) = (xs.clone().fold(f64::INFINITY, f64::min), xs.fold(f64::NEG_INFINITY, f64::max));
    assert!((low - 89.0).abs() < 0.002 && (high - 103.0).abs() < 0.002, "{low} {high}");
}

#[test]
fn a_block_that_places_itself_is_refused_at_the_depth_bound() {
    let error = read(&fixture("block_loop.dxf"), "file", &DxfOptions::default()).unwrap_err().to_string();
    assert!(error.contains("INSERT") && error.contains("block LOOP") && error.contains("8 deep"), "{error}");
}

#[test]
fn an_open_spline_is_segments_curve_exactly() {
    let profile = read(&fixture("spline_open_mm.dxf"), "file", &DxfOptions::default()).unwrap();
    assert!(profile.boundary.is_empty() && profile.islands.is_empty());
    let Some(crate::segment::Curve::Bspline { degree, control_points, knots, weights, .. }) = profile.curve else {
        panic!("{:?}", profile.curve)
    };
    assert_eq!(degree, 3);
    assert_eq!(control_points, [[0.0, 0.0], [20.0, 30.0], [50.0, -10.0], [80.0, 25.0], [100.0, 0.0]]);
    let knots = knots.unwrap();
    assert_eq!((&knots[..4], &knots[5..]), (&[0.0; 4][..], &[knots[8]; 4][..]), "{knots:?}");
    assert_eq!(weights, None);
}

#[test]
fn a_rational_spline_in_inch_keeps_its_weights_and_lies_on_its_circle() {
    let profile = read(&fixture("spline_rational_inch.dxf"), "file", &DxfOptions::default()).unwrap();
    let Some(crate::segment::Curve::Bspline { degree, control_points, knots, weights, .. }) = profile.curve else {
        panic!("{:?}", profile.curve)
    };
    assert_eq!(degree, 2);
    assert_eq!(control_points, [[50.8, 0.0], [50.8, 50.8], [0.0, 50.8]]);
    let weights = weights.unwrap();
    assert!((weights[1] - 0.5f64.sqrt()).abs() < 1e-12, "{weights:?}");
    let control: Vec<[f64; 2]> = control_points.iter().map(|p| [p[0], p[1]]).collect();
    for k in 0..=10 {
        let p = super::curves::nurbs_point(2, &control, &knots.clone().unwrap(), &weights, k as f64 / 10.0);
        assert!((p[0].hypot(p[1]) - 50.8).abs() < 1e-9, "{p:?}");
    }
}

#[test]
fn a_periodic_spline_is_clamped_to_the_same_curve() {
    let profile = read(&fixture("spline_periodic_mm.dxf"), "file", &DxfOptions::default()).unwrap();
    assert!(area(&profile.boundary) > 100.0);
    let Some(crate::segment::Curve::Bspline { degree, control_points, knots, weights, .. }) = profile.curve else {
        panic!("{:?}", profile.curve)
    };
    let knots = knots.unwrap();
    assert_eq!(degree, 3);
    assert!(knots[..4].iter().all(|k| *k == 3.0) && knots[knots.len() - 4..].iter().all(|k| *k == 11.0), "{knots:?}");
    // The fixture's curve: 11 control points on uniform knots 0 to 14, domain [3, 11].
    let blob: Vec<[f64; 2]> = (0..11)
        .map(|k| {
            let t = (k % 8) as f64 * std::f64::consts::TAU / 8.0;
            [20.0 * t.cos(), 15.0 * t.sin()]
        })
        .collect();
    let uniform: Vec<f64> = (0..15).map(f64::from).collect();
    let clamped: Vec<[f64; 2]> = control_points.iter().map(|p| [p[0], p[1]]).collect();
    let weights = weights.unwrap_or_else(|| vec![1.0; clamped.len()]);
    for k in 0..=80 {
        let u = 3.0 + 8.0 * f64::from(k) / 80.0;
        let a = super::curves::nurbs_point(3, &blob, &uniform, &[1.0; 11], u);
        let b = super::curves::nurbs_point(3, &clamped, &knots, &weights, u);
        assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9, "{u}: {a:?} {b:?}");
    }
}
