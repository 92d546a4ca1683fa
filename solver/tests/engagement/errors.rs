//! Bad inputs get a clear error with its code and the field at fault, never a panic
//! (docs/spec/engagement.md §9): self-intersecting stock, empty path, zero feed per tooth,
//! flute counts out of range, a grid over the memory limit (with the limit in the message), too
//! many samples, and the other refusals; a path that never touches the stock is not an error
//! (§9: all zeros with `W_NO_CONTACT`).

use kerf_solver::engagement::{self, EngagementRequest, EngagementSolution, MAX_GRID_DOTS, MAX_SAMPLES, program};
use kerf_solver::gcode::Post;
use kerf_solver::gcode::{Dialect, Reference, ToolCall};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

fn base() -> Value {
    json!({
        "tool": {"kind": "flat", "radius": 5},
        "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "path": [[-10, 20], [70, 20]],
        "spindle_rpm": 3000, "feed_per_tooth": 0.05,
        "flute_counts": [1, 2, 3, 4], "thickness_limit": 0.075, "time_limit_s": 20
    })
}

fn with(changes: Value) -> EngagementRequest {
    let mut body = base();
    for (key, value) in changes.as_object().unwrap() {
        if value.is_null() {
            body.as_object_mut().unwrap().remove(key);
        } else {
            body[key] = value.clone();
        }
    }
    serde_json::from_value(body).unwrap()
}

fn tool() -> Tool {
    Tool::new(ToolKind::Flat, 5.0)
}

fn refused(request: &EngagementRequest) -> (String, Option<String>, String) {
    let Err(error) = engagement::solve(request, &tool()) else {
        panic!("should be refused");
    };
    (error.code().as_str().to_owned(), error.field().map(str::to_owned), error.message().to_owned())
}

#[track_caller]
fn assert_refused(changes: Value, code: &str, field: &str) -> String {
    let (got_code, got_field, message) = refused(&with(changes.clone()));
    assert_eq!(got_code, code, "{changes}: {message}");
    assert_eq!(got_field.as_deref(), Some(field), "{changes}: {message}");
    message
}

#[test]
fn table_of_bad_inputs() {
    // Self-intersecting stock (a bow tie), and two regions that overlap.
    assert_refused(json!({"stock": {"polygon": [[0, 0], [60, 40], [60, 0], [0, 40]]}}), "E_STOCK", "stock.polygon[0]");
    assert_refused(
        json!({"stock": {"polygons": [
            {"outer": [[0, 0], [30, 0], [30, 30], [0, 30]]},
            {"outer": [[20, 20], [50, 20], [50, 50], [20, 50]]}]}}),
        "E_STOCK",
        "stock.polygons[0].outer[1]",
    );
    assert_refused(json!({"stock": {"polygon": [[0, 0], [1, 1], [0, 0]]}}), "E_STOCK", "stock.polygon");
    assert_refused(json!({"stock": {"polygon": [[0, 0], [1, 1], [2, 2]]}}), "E_STOCK", "stock.polygon[0]");
    // Empty paths.
    assert_refused(json!({"path": []}), "E_PATH", "path");
    assert_refused(json!({"path": [[1, 1]]}), "E_PATH", "path");
    assert_refused(json!({"path": [[1, 1], [1, 1]]}), "E_PATH", "path");
    assert_refused(json!({"path": {"start": [0, 0], "segments": []}}), "E_PATH", "path");
    assert_refused(json!({"path": {"segments": [{"type": "line", "to": [1, 0]}]}}), "E_PATH", "path.start");
    assert_refused(json!({"path": null}), "E_PATH", "path");
    // Arc centre not equidistant (§2.3).
    assert_refused(
        json!({"path": {"start": [0, 0], "segments": [{"type": "arc", "to": [10, 0], "center": [5, 1], "dir": "ccw"}, {"type": "arc", "to": [20, 0], "center": [15.5, 0], "dir": "cw"}]}}),
        "E_PATH",
        "path.segments[1].center",
    );
    // Zero or missing feed.
    assert_refused(json!({"feed_per_tooth": 0}), "E_INPUT", "feed_per_tooth");
    assert_refused(json!({"feed_per_tooth": -0.1}), "E_INPUT", "feed_per_tooth");
    assert_refused(json!({"feed_per_tooth": null}), "E_INPUT", "feed_per_tooth");
    assert_refused(json!({"feed": 400}), "E_INPUT", "feed");
    assert_refused(json!({"spindle_rpm": 0}), "E_INPUT", "spindle_rpm");
    // Flute counts out of range, repeated or empty.
    assert_refused(json!({"flute_counts": [1, 0]}), "E_INPUT", "flute_counts[1]");
    assert_refused(json!({"flute_counts": [33]}), "E_INPUT", "flute_counts[0]");
    assert_refused(json!({"flute_counts": [2, 4, 2]}), "E_INPUT", "flute_counts[2]");
    assert_refused(json!({"flute_counts": []}), "E_INPUT", "flute_counts");
    // Numbers out of range (coordinates beyond ±1 km, absurd feeds).
    assert_refused(json!({"path": [[0, 0], [2e6, 0]]}), "E_INPUT", "path[1][0]");
    assert_refused(json!({"feed_per_tooth": 1e5}), "E_INPUT", "feed_per_tooth");
    // Other numbers.
    assert_refused(json!({"step": 0}), "E_INPUT", "step");
    assert_refused(json!({"thickness_limit": -1}), "E_INPUT", "thickness_limit");
    assert_refused(json!({"grid": 0.1}), "E_INPUT", "grid");
    assert_refused(json!({"engine": "dots", "grid": 0}), "E_INPUT", "grid");
    assert_refused(json!({"burr_disengage_deg": 200}), "E_INPUT", "burr_disengage_deg");
    assert_refused(json!({"feed_plan": {"target_thickness": 0.05}}), "E_INPUT", "feed_plan.max_feed");
    assert_refused(
        json!({"feed_plan": {"target_thickness": 0, "max_feed": 5000}}),
        "E_INPUT",
        "feed_plan.target_thickness",
    );
    assert_refused(json!({"path": [[0, 0], [1, 1]], "paths": [{"path": [[0, 0], [1, 1]]}]}), "E_INPUT", "paths");
    assert_refused(
        json!({"path": null, "paths": [{"path": [[0, 0], [5, 0]]}, {"path": [[3, 3]]}]}),
        "E_PATH",
        "paths[1].path",
    );
    assert_refused(
        json!({"stock": {"polygon": [[0, 0], [1, 0], [0, 1]], "bitmap": {"origin": [0, 0], "cell": 1, "width": 1, "height": 1, "data": "gA=="}}}),
        "E_INPUT",
        "stock",
    );
    assert_refused(
        json!({"stock": {"bitmap": {"origin": [0, 0], "cell": 1, "width": 4, "height": 4, "data": "/w=="}}}),
        "E_STOCK",
        "stock.bitmap.data",
    );
    assert_refused(
        json!({"stock": {"bitmap": {"origin": [0, 0], "cell": 1, "width": 4, "height": 4, "data": "*"}}}),
        "E_STOCK",
        "stock.bitmap.data",
    );
    assert_refused(
        json!({"stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]], "previous_cuts": [{"path": [[0, 0], [5, 0]], "radius": 0}]}}),
        "E_INPUT",
        "stock.previous_cuts[0].radius",
    );
}

#[test]
fn non_finite_numbers_name_their_field() {
    let mut request = with(json!({}));
    request.spindle_rpm = f64::NAN;
    assert_eq!(refused(&request).1.as_deref(), Some("spindle_rpm"));
    let mut request = with(json!({}));
    request.path = Some(engagement::PathInput::Points(vec![[0.0, 0.0], [f64::INFINITY, 1.0]]));
    assert_eq!(refused(&request).1.as_deref(), Some("path[1][0]"));
    let mut request = with(json!({}));
    request.stock.polygon = Some(vec![[0.0, 0.0], [1.0, f64::NAN], [0.0, 1.0]]);
    assert_eq!(refused(&request).1.as_deref(), Some("stock.polygon[1][1]"));
    let bad_tool = Tool::new(ToolKind::Flat, 0.0);
    let error = engagement::solve(&with(json!({})), &bad_tool).unwrap_err();
    assert_eq!(error.field(), Some("tool.radius"));
}

#[test]
fn grid_over_the_memory_limit_is_refused_with_the_limit() {
    // 1 m × 1 m of stock at a 0.01 mm grid: 10¹⁰ dots.
    let message = assert_refused(
        json!({"stock": {"polygon": [[0, 0], [1000, 0], [1000, 1000], [0, 1000]]},
               "path": [[-10, -10], [1010, 1010]], "engine": "dots", "grid": 0.01, "step": 2}),
        "E_GRID_MEMORY",
        "grid",
    );
    assert!(message.contains(&MAX_GRID_DOTS.to_string()), "{message}");
    // The same path at 0.1 mm fits (10⁸ dots would be allocated; only validate here).
    let (code, _, _) = refused(&with(json!({
        "stock": {"polygon": [[0, 0], [1000, 0], [1000, 1000], [0, 1000]]},
        "path": [[-10, -10], [1010, 1010]], "engine": "dots", "grid": 0.1, "step": 0.0001,
    })));
    assert_eq!(code, "E_TOO_MANY_SAMPLES", "the grid passed, the samples did not");
    let bitmap = assert_refused(
        json!({"stock": {"bitmap": {"origin": [0, 0], "cell": 0.001, "width": 100_000, "height": 100_000, "data": ""}}}),
        "E_GRID_MEMORY",
        "stock.bitmap",
    );
    assert!(bitmap.contains(&MAX_GRID_DOTS.to_string()), "{bitmap}");
}

#[test]
fn dots_work_over_the_limit_is_refused() {
    // A tall strip of stock under a big tool at a fine grid: few dots, but 10⁵ rows per sample.
    let request = with(json!({
        "stock": {"polygon": [[0, 0], [1, 0], [1, 100], [0, 100]]},
        "path": [[-60, 50], [61, 50]], "engine": "dots", "grid": 0.001, "step": 0.01,
    }));
    let error = engagement::solve(&request, &Tool::new(ToolKind::Flat, 50.0)).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_WORK_LIMIT", Some("grid")));
    assert!(error.message().contains("5e8"), "{}", error.message());
}

#[test]
fn too_many_samples_is_refused_with_the_limit() {
    let message = assert_refused(json!({"step": 1e-4}), "E_TOO_MANY_SAMPLES", "step");
    assert!(message.contains(&MAX_SAMPLES.to_string()), "{message}");
    let candidates: Vec<Value> = (0..17).map(|_| json!({"path": [[0, 0], [5, 0]]})).collect();
    assert_refused(json!({"path": null, "paths": candidates}), "E_TOO_LARGE", "paths");
}

#[test]
fn a_path_that_never_touches_the_stock_gives_zeros_and_a_warning() {
    let request = with(json!({"path": [[-10, 60], [70, 60]]}));
    let answer = engagement::solve(&request, &tool()).unwrap();
    let EngagementSolution::Single(result) = answer else {
        panic!("single path expected");
    };
    let warning = result.warnings.iter().find(|w| w.code == "W_NO_CONTACT").expect("W_NO_CONTACT");
    assert!(warning.message.contains("never touches"), "{}", warning.message);
    assert!(result.samples.iter().all(|s| s.arcs.is_empty() && s.radial_depth == 0.0));
    assert!(result.flutes.iter().all(|f| f.max_thickness == 0.0 && f.mean_thickness == 0.0));
    assert!(result.engaged_intervals.is_empty());
    // T1 is trivially met; T2 = 20 s is met from k = 2 (L = 80 mm: 32 s / k).
    assert_eq!(result.recommended, vec![4, 3, 2]);
}

#[test]
fn program_needs_the_cutting_depth() {
    let answer = engagement::solve(&with(json!({})), &tool()).unwrap();
    let post = Post {
        dialect: Dialect::Fanuc,
        reference: Reference::Tip,
        tool: ToolCall::Table(3),
        arcs: kerf_solver::gcode::Arcs::Chords,
        plunge_feed: None,
        units: kerf_solver::units::Units::Mm,
    };
    let error = program(&answer, 0, &post).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("axial_depth")));
    let error = program(&answer, 1, &post).unwrap_err();
    assert_eq!(error.field(), Some("candidate"));
}

#[test]
fn malformed_json_is_rejected_by_serde() {
    for bad in [
        json!({"unknown_field": 1}),
        json!({"path": [[0, 0, 0]]}),
        json!({"path": {"start": [0, 0], "segments": [{"type": "spline", "to": [1, 0]}]}}),
        json!({"path": {"start": [0, 0], "segments": [{"type": "line", "to": [1, 0], "center": [0, 0]}]}}),
        json!({"stock": {"polygon": [[0, 0], [1, 0], [0, 1]], "extra": true}}),
        json!({"engine": "voxels"}),
    ] {
        let mut body = base();
        for (key, value) in bad.as_object().unwrap() {
            body[key] = value.clone();
        }
        assert!(serde_json::from_value::<EngagementRequest>(body).is_err(), "{bad}");
    }
}
