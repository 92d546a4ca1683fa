//! Engagement paths given as G-code text (read by `gcode::reader`) give the same engagement as
//! the same moves given as segments; errors name the field and the line.

use kerf_solver::engagement::{self, EngagementRequest};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

fn request(path: Value) -> EngagementRequest {
    serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 5},
        "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "path": path, "spindle_rpm": 3000, "feed_per_tooth": 0.05, "flute_counts": [2, 4],
        "thickness_limit": 0.075, "time_limit_s": 20
    }))
    .unwrap()
}

fn solve(path: Value) -> Result<Value, kerf_solver::SolverError> {
    let tool = Tool::new(ToolKind::Flat, 5.0);
    engagement::solve(&request(path), &tool).map(|answer| serde_json::to_value(answer).unwrap())
}

#[test]
fn gcode_path_equals_the_same_segments() {
    let program = "%\n(PASS WITH A TURN)\nG21 G90 G17\nG0 X-10 Y20 Z5\nG1 Z-2 F500\nG1 X30 Y20\nG2 X40 Y10 I0 J-10\nG1 X70\nM30\n%\n";
    let from_gcode = solve(json!({"gcode": program})).unwrap();
    let from_segments = solve(json!({"start": [-10, 20], "segments": [
        {"type": "line", "to": [30, 20]},
        {"type": "arc", "to": [40, 10], "center": [30, 10], "dir": "cw"},
        {"type": "line", "to": [70, 10]}]}))
    .unwrap();
    let without_segment = |answer: &Value| -> Vec<Value> {
        answer["samples"]
            .as_array()
            .unwrap()
            .iter()
            .map(|sample| {
                let mut sample = sample.clone();
                sample.as_object_mut().unwrap().remove("segment");
                sample
            })
            .collect()
    };
    assert!(from_gcode["samples"].as_array().unwrap().len() > 100);
    assert!(without_segment(&from_gcode) == without_segment(&from_segments), "same engagement");
    // A G-code path's samples name their program line.
    let lines: std::collections::BTreeSet<u64> =
        from_gcode["samples"].as_array().unwrap().iter().map(|s| s["segment"].as_u64().unwrap()).collect();
    assert_eq!(lines.into_iter().collect::<Vec<_>>(), [6, 7, 8]);
    assert_eq!(from_gcode["flutes"], from_segments["flutes"]);
    // The plunge has no length in the plane: dropped with a warning that names its line.
    let warnings = from_gcode["warnings"].as_array().unwrap();
    assert!(
        warnings.iter().any(|w| w["code"] == "W_SEGMENT_ZERO" && w["message"].as_str().unwrap().contains("line 5"))
    );

    // Inch and incremental programs read the same.
    let inch = "G20 G91 G17\nG0 X0 Y0\nG90 G0 X-0.3937008 Y0.7874016\nG1 X1.1811024 F20\nG2 X1.5748031 Y0.3937008 I0 J-0.3937008\nG1 X2.7559055\n";
    let from_inch = solve(json!({"gcode": inch})).unwrap();
    let (a, b) = (&from_inch["flutes"][0]["time_s"], &from_segments["flutes"][0]["time_s"]);
    assert!((a.as_f64().unwrap() - b.as_f64().unwrap()).abs() < 1e-3, "{a} vs {b}");
}

#[test]
fn gcode_path_errors_name_the_line() {
    let error = solve(json!({"gcode": "G1 X10 Y10 F100\nG1 X20 Y$\n"})).unwrap_err();
    assert_eq!(error.field(), Some("path.gcode"));
    assert!(error.message().contains("line 2"), "{}", error.message());

    let error = solve(json!({"gcode": "G18\nG0 X0 Y20 Z0\nG2 X10 Z10 I10 K0\n"})).unwrap_err();
    assert_eq!(error.code().as_str(), "E_PATH");
    assert!(error.message().contains("line 3"), "{}", error.message());

    let error = solve(json!({"gcode": "G0 X0 Y0", "start": [0, 0]})).unwrap_err();
    assert_eq!(error.field(), Some("path.gcode"));

    let error = solve(json!({"gcode": "(nothing moves)\nM30\n"})).unwrap_err();
    assert_eq!(error.code().as_str(), "E_PATH");
}
