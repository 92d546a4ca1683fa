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
    assert!(error.contains("open chain") && error.contains("(40.0000, 30.0000)"), "{error}");
    assert!(error.contains("0.5000 mm"), "{error}");
    let wide = DxfOptions { join_tolerance: 0.6, ..DxfOptions::default() };
    assert_eq!(read(&fixture("broken_chain.dxf"), "file", &wide).unwrap().boundary.len(), 4);
    let error = read(&fixture("bow_tie.dxf"), "file", &DxfOptions::default()).unwrap_err().to_string();
    assert!(error.contains("self-intersection") && error.contains("(5.0000, 5.0000)"), "{error}");
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
