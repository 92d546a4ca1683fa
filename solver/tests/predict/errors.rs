//! Bad inputs get a clear error naming the field (and the line for G-code), never a panic; long
//! runs report progress and can be cancelled; other stock forms give the same answers.

use std::sync::Mutex;
use std::sync::atomic::AtomicBool;

use kerf_cases::predict::{bare_request, finishing_tool, inclined_case};
use kerf_solver::SolverError;
use kerf_solver::predict::{self, Control, Method, PassStatus, PathInput, PredictRequest};
use kerf_solver::stock::Stock;
use kerf_solver::tool::{Tool, ToolKind};

fn flat_case() -> (PredictRequest, Tool) {
    // Four raster passes over a flat block, ball R = 3, from a small program.
    let tool = finishing_tool(3.0);
    let program = "%\nO0001 (FLAT)\nN1 G21 G90 G17\nN2 T1 M06\nN3 S8000 M03\nN4 G0 X-10 Y0 Z20\n\
                   N5 G1 Z3.0 F1600\nN6 X30\nN7 Y0.4\nN8 X-10\nN9 Y0.8\nN10 X30 (LAST)\nN11 G0 Z20\nN12 M30\n%\n";
    let mut request = bare_request(
        &tool,
        Stock::Box { min: [0.0, -5.0, -10.0], max: [20.0, 5.0, 0.1] },
        PathInput::Gcode { program: program.to_owned() },
    );
    request.reference = kerf_solver::gcode::Reference::Centre;
    (request, tool)
}

fn expect(result: Result<predict::Predict, SolverError>, code: &str, field: &str) -> SolverError {
    let error = result.expect_err("the request must be refused");
    assert_eq!(error.code().as_str(), code, "{}", error.message());
    assert_eq!(error.field(), Some(field), "{}", error.message());
    error
}

#[test]
fn the_flat_case_predicts() {
    let (request, tool) = flat_case();
    let answer = predict::solve(&request, &tool, None).unwrap();
    // Feed moves: the plunge, two lines, two step-overs, the last line.
    assert_eq!(answer.passes.len(), 6);
    assert_eq!(answer.passes[1].line, Some(8));
    assert_eq!(answer.passes[1].block_number, Some(6));
    // The first line leaves the whole side toward −y: generated above the tip.
    assert!(answer.passes[1].contact_angle_deg.unwrap() > 3.0);
    let middle = &answer.passes[3];
    assert_eq!((middle.line, middle.status), (Some(10), PassStatus::Ok));
    // Between two neighbours on a flat floor: generation at the tip, e = −δ(0) = −0.003 (no
    // deflection data: no cutting coefficients).
    let e = middle.error.unwrap();
    assert!((e + 0.003).abs() < 1e-12, "{e}");
    assert!(middle.flags.contains(&predict::PassFlag::AtTip));
    assert!(answer.warnings.iter().any(|w| w.code == "W_NO_DEFLECTION"));
}

#[test]
fn unparsable_gcode_names_the_line() {
    let (mut request, tool) = flat_case();
    request.path = PathInput::Gcode { program: "G21 G90\nG0 X0 Y0 Z5\nG1 X5 Y$ F100\n".to_owned() };
    let error = expect(predict::solve(&request, &tool, None), "E_GCODE_SYNTAX", "path.program");
    assert!(error.message().starts_with("line 3:"), "{}", error.message());
}

#[test]
fn arcs_that_do_not_close_are_refused() {
    let (mut request, tool) = flat_case();
    request.path =
        PathInput::Gcode { program: "G21 G90 G17 S6000 M3\nG0 X10 Y0 Z3\nG2 X0 Y-10 I-10 J0.5 F500\n".to_owned() };
    let error = expect(predict::solve(&request, &tool, None), "E_ARC_NOT_CLOSED", "path.program");
    assert!(error.message().starts_with("line 3:"), "{}", error.message());
}

#[test]
fn a_tool_without_shape_error_or_not_a_ball_is_refused() {
    let (request, mut tool) = flat_case();
    tool.shape_error = None;
    expect(predict::solve(&request, &tool, None), "E_NO_SHAPE_ERROR", "tool.shape_error");
    let mut flat = finishing_tool(3.0);
    flat.kind = ToolKind::Flat;
    expect(predict::solve(&request, &flat, None), "E_TOOL_KIND", "tool.kind");
    let mut bad = finishing_tool(3.0);
    bad.radius = -1.0;
    expect(predict::solve(&request, &bad, None), "E_INPUT", "tool.radius");
    let _ = Tool::new(ToolKind::Ball, 1.0);
}

#[test]
fn a_depth_buffer_over_the_memory_limit_is_refused() {
    let (mut request, tool) = flat_case();
    request.method = Method::DepthBuffer;
    request.resolution = Some(4096);
    let error = expect(predict::solve(&request, &tool, None), "E_RESOLUTION_LIMIT", "resolution");
    assert!(error.message().contains("256 MiB"), "{}", error.message());
    assert!(error.message().contains("at most 2048"), "{}", error.message());
    request.resolution = Some(2048);
    request.pass_range = Some([0, 0]);
    assert!(predict::solve(&request, &tool, None).is_ok());
    request.method = Method::Sampling;
    request.resolution = Some(100_000);
    expect(predict::solve(&request, &tool, None), "E_INPUT", "resolution");
}

#[test]
fn an_open_mesh_is_refused_and_a_closed_one_equals_the_box() {
    let (mut request, tool) = flat_case();
    let box_answer = predict::solve(&request, &tool, None).unwrap();
    request.stock = Stock::Mesh { units: None };
    expect(predict::solve(&request, &tool, None), "E_INPUT", "stock");
    let mut triangles = box_triangles([0.0, -5.0, -10.0], [20.0, 5.0, 0.1]);
    let closed = stl(&triangles);
    let mesh_answer = predict::solve(&request, &tool, Some(&closed)).unwrap();
    for (a, b) in box_answer.passes.iter().zip(&mesh_answer.passes) {
        assert_eq!(a.status, b.status);
        match (a.error, b.error) {
            (Some(x), Some(y)) => assert!((x - y).abs() < 1e-9, "{x} vs {y}"),
            (x, y) => assert_eq!(x, y),
        }
    }
    triangles.pop();
    let error = expect(predict::solve(&request, &tool, Some(&stl(&triangles))), "E_MESH_NOT_CLOSED", "stock");
    assert!(error.message().contains("not closed"), "{}", error.message());
    expect(predict::solve(&request, &tool, Some(b"garbage")), "E_MESH_FORMAT", "stock");
}

#[test]
fn inch_programs_are_converted() {
    let (request, tool) = flat_case();
    let metric = predict::solve(&request, &tool, None).unwrap();
    let PathInput::Gcode { program } = &request.path else { unreachable!() };
    // The same program in inches (the block's geometry is exact in inches too).
    let inch = program
        .replace("G21", "G20")
        .replace("X-10", &format!("X{}", -10.0 / 25.4))
        .replace("X30", &format!("X{}", 30.0 / 25.4))
        .replace("Y0.4", &format!("Y{}", 0.4 / 25.4))
        .replace("Y0.8", &format!("Y{}", 0.8 / 25.4))
        .replace("Z20", &format!("Z{}", 20.0 / 25.4))
        .replace("Z3.0", &format!("Z{}", 3.0 / 25.4))
        .replace("F1600", &format!("F{}", 1600.0 / 25.4));
    let mut imperial = request.clone();
    imperial.path = PathInput::Gcode { program: inch };
    let converted = predict::solve(&imperial, &tool, None).unwrap();
    for (a, b) in metric.passes.iter().zip(&converted.passes) {
        assert_eq!(a.status, b.status);
        if let (Some(x), Some(y)) = (a.error, b.error) {
            assert!((x - y).abs() < 1e-9);
        }
    }
}

#[test]
fn missing_cutting_conditions_name_the_line() {
    let (mut request, tool) = flat_case();
    request.path = PathInput::Gcode { program: "G21 G90\nG0 X0 Y0 Z3\nG1 X5 F100\n".to_owned() };
    let error = expect(predict::solve(&request, &tool, None), "E_NO_SPINDLE", "path.program");
    assert!(error.message().starts_with("line 3:"));
    request.spindle_rpm = Some(6000.0);
    request.path = PathInput::Gcode { program: "G21 G90\nG0 X0 Y0 Z3\nG1 X5\n".to_owned() };
    expect(predict::solve(&request, &tool, None), "E_NO_FEED", "path.program");
    request.path = PathInput::Gcode { program: "G21 G90\nG0 X0 Y0 Z3\n".to_owned() };
    expect(predict::solve(&request, &tool, None), "E_NO_PASSES", "path");
    request.path = PathInput::Points { points: vec![[0.0, 0.0, 3.0], [5.0, 0.0, 3.0]] };
    expect(predict::solve(&request, &tool, None), "E_INPUT", "feed");
    request.feed = Some(f64::NAN);
    expect(predict::solve(&request, &tool, None), "E_INPUT", "feed");
    request.feed = Some(800.0);
    request.path = PathInput::Points { points: vec![[0.0, 0.0, 3.0], [5.0, f64::INFINITY, 3.0]] };
    expect(predict::solve(&request, &tool, None), "E_INPUT", "path.points[1][1]");
}

#[test]
fn options_out_of_range_name_their_field() {
    let (base, tool) = flat_case();
    type Change = Box<dyn Fn(&mut PredictRequest)>;
    let cases: Vec<(Change, &str)> = vec![
        (Box::new(|r| r.tooth_feed_gap = Some(4)), "tooth_feed_gap"),
        (Box::new(|r| r.view_correction_deg = Some(95.0)), "view_correction_deg"),
        (Box::new(|r| r.samples_per_revolution = Some(10)), "samples_per_revolution"),
        (Box::new(|r| r.edge_elements = Some(5000)), "edge_elements"),
        (Box::new(|r| r.arc_tolerance = Some(0.0)), "arc_tolerance"),
        (Box::new(|r| r.pass_range = Some([3, 99])), "pass_range"),
        (Box::new(|r| r.history = Some(vec![99])), "history[0]"),
        (
            Box::new(|r| r.deflection = Some(predict::PrescribedDeflection { x: vec![0.0, 0.0], y: vec![0.0] })),
            "deflection.y",
        ),
        (
            Box::new(|r| {
                r.correction = Some(predict::CorrectionOptions { max_correction: Some(-1.0), iterations: None })
            }),
            "correction.max_correction",
        ),
        (
            Box::new(|r| {
                r.stock = Stock::Grid {
                    origin: [0.0, 0.0],
                    spacing: 1.0,
                    heights: vec![vec![0.0, 1.0], vec![0.0, f64::NAN]],
                    bottom: None,
                }
            }),
            "stock.heights[1][1]",
        ),
    ];
    for (change, field) in cases {
        let mut request = base.clone();
        change(&mut request);
        expect(predict::solve(&request, &tool, None), "E_INPUT", field);
    }
}

#[test]
fn json_requests_reject_unknown_fields() {
    let good = r#"{"tool": 3, "stock": {"kind": "box", "min": [0,0,0], "max": [1,1,1]},
                   "path": {"kind": "gcode", "program": "G0 X0"}}"#;
    let request: PredictRequest = serde_json::from_str(good).unwrap();
    assert_eq!(request.method, Method::Sampling);
    for bad in [
        r#"{"tool": 3, "stock": {"kind": "box", "min": [0,0,0], "max": [1,1,1]}, "path": {"kind": "gcode", "program": ""}, "colour": 1}"#,
        r#"{"tool": 3, "stock": {"kind": "sphere"}, "path": {"kind": "gcode", "program": ""}}"#,
        r#"{"tool": 3, "stock": {"kind": "mesh", "file": "x"}, "path": {"kind": "gcode", "program": ""}}"#,
    ] {
        assert!(serde_json::from_str::<PredictRequest>(bad).is_err(), "{bad}");
    }
}

#[test]
fn progress_is_reported_and_cancellation_stops_the_run() {
    let (mut request, tool) = inclined_case(30.0, 10.0, 0.0, [0.0; 3], Method::Sampling);
    request.pass_range = None;
    let seen = Mutex::new(Vec::new());
    let record = |fraction: f64| seen.lock().unwrap().push(fraction);
    let control = Control { progress: Some(&record), cancel: None };
    let answer = predict::solve_with(&request, &tool, None, &control).unwrap();
    assert_eq!(answer, predict::solve(&request, &tool, None).unwrap());
    let seen = seen.into_inner().unwrap();
    assert!(!seen.is_empty());
    assert!((seen.iter().copied().fold(0.0, f64::max) - 1.0).abs() < 1e-12);
    assert!(seen.iter().all(|f| (0.0..=1.0).contains(f)));
    let stop = AtomicBool::new(true);
    let cancelled = predict::solve_with(&request, &tool, None, &Control { progress: None, cancel: Some(&stop) });
    assert_eq!(cancelled.unwrap_err().code().as_str(), "E_CANCELLED");
}

#[test]
fn a_grid_of_a_plane_equals_the_plane() {
    let (request, tool) = inclined_case(25.0, 30.0, 0.0, [0.0; 3], Method::Sampling);
    let plane = predict::solve(&request, &tool, None).unwrap();
    let Stock::Plane { point, normal, .. } = request.stock.clone() else { unreachable!() };
    let height = |x: f64, y: f64| point[2] - (normal[0] * (x - point[0]) + normal[1] * (y - point[1])) / normal[2];
    let heights =
        (0..=120).map(|j| (0..=120).map(|i| height(-60.0 + f64::from(i), -60.0 + f64::from(j))).collect()).collect();
    let mut gridded = request.clone();
    gridded.stock = Stock::Grid { origin: [-60.0, -60.0], spacing: 1.0, heights, bottom: None };
    let grid = predict::solve(&gridded, &tool, None).unwrap();
    let (a, b) = (&plane.passes[5], &grid.passes[5]);
    assert!((a.contact_angle_deg.unwrap() - b.contact_angle_deg.unwrap()).abs() < 1e-6);
    assert!((a.error.unwrap() - b.error.unwrap()).abs() < 1e-4 * a.error.unwrap().abs().max(1e-3));
}

fn box_triangles(lo: [f64; 3], hi: [f64; 3]) -> Vec<[[f64; 3]; 3]> {
    let corner = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let mut triangles = Vec::new();
    for q in quads {
        triangles.push([corner(q[0]), corner(q[1]), corner(q[2])]);
        triangles.push([corner(q[0]), corner(q[2]), corner(q[3])]);
    }
    triangles
}

/// ASCII STL text of the triangles.
fn stl(triangles: &[[[f64; 3]; 3]]) -> Vec<u8> {
    let mut text = String::from("solid stock\n");
    for t in triangles {
        text.push_str("  facet normal 0 0 0\n    outer loop\n");
        for v in t {
            text.push_str(&format!("      vertex {} {} {}\n", v[0], v[1], v[2]));
        }
        text.push_str("    endloop\n  endfacet\n");
    }
    text.push_str("endsolid stock\n");
    text.into_bytes()
}

#[test]
fn rapids_through_uncut_stock_are_reported() {
    let (request, tool) = flat_case();
    let answer = predict::solve(&request, &tool, None).unwrap();
    assert!(!answer.warnings.iter().any(|w| w.code == "W_RAPID_COLLISION"));
    let mut crash = request.clone();
    crash.path = PathInput::Gcode {
        program: "G21 G90 S8000 M3\nG0 X-10 Y0 Z20\nG1 Z3 F1600\nX30\nG0 X10 Y-2 Z3\nG0 Z20\nM30\n".to_owned(),
    };
    let answer = predict::solve(&crash, &tool, None).unwrap();
    let warning = answer
        .warnings
        .iter()
        .find(|w| w.code == "W_RAPID_COLLISION")
        .expect("the rapid to Y-2 at cutting depth crosses uncut stock");
    assert!(warning.message.contains("line(s) 5"), "{}", warning.message);
}

#[test]
fn a_retraced_spring_pass_gets_the_surface() {
    let (mut request, tool) = flat_case();
    // The middle line (N100 X28 at Y0.4) is cut twice: the second time is a spring pass.
    request.path = PathInput::Gcode {
        program: "G21 G90 S8000 M3\nG0 X-10 Y0 Z20\nG1 Z3 F1600\nX30\nY0.4\nX-10\nG0 Z20\nG0 X-10 Y0.4\nG1 Z3\nX30\n\
                  Y0.8\nX-10\nG0 Z20\nM30\n"
            .to_owned(),
    };
    let answer = predict::solve(&request, &tool, None).unwrap();
    let first = answer.passes.iter().find(|p| p.line == Some(6)).unwrap();
    let again = answer.passes.iter().find(|p| p.line == Some(10)).unwrap();
    assert_eq!(first.status, PassStatus::NoSurface, "{first:?}");
    assert_eq!(again.status, PassStatus::Ok, "{again:?}");
    assert!(again.flags.contains(&predict::PassFlag::Retraced), "{:?}", again.flags);
}
