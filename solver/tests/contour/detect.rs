//! Corners detected on a CL point list made elsewhere and looped (claims 8–10, docs/spec/contour.md §3.4,
//! §3.7): the three detection rules on the CL paths of the reference cases, the loops' straight
//! passes through the corner points, and their staying out of the material.

use kerf_solver::contour::detect::{DetectMode, MaterialSide, PathLoopRequest, loop_path};
use kerf_solver::contour::division::divide_polygon;
use kerf_solver::contour::{self, ContourRequest, MoveKind};
use kerf_solver::planar::{Containment, Vec2, point_in_polygon, vec2};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::json;

/// The CL polygon of a contour's single pass, divided with spacing `h`.
fn cl_points(contour: serde_json::Value, radius: f64, h: f64) -> (Vec<[f64; 2]>, Vec<usize>) {
    let request: ContourRequest = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": radius}, "contour": contour, "side": "outside",
        "direction": "conventional", "depths": {"top": 1, "bottom": 0, "step": 1}, "feed": 500
    }))
    .unwrap();
    let plan = contour::plan(&request, &Tool::new(ToolKind::Flat, radius)).unwrap();
    let (points, vertices) = divide_polygon(&plan.passes[0].cl, h);
    (points.iter().map(|p| [p.x, p.y]).collect(), vertices)
}

fn c2() -> serde_json::Value {
    json!([[0.0, 0.0], [20.0, 0.0], [24.0, 4.0], [18.0 + 3f64.sqrt(), 1.0 + 6.0 * 3f64.sqrt()]])
}

fn request(path: &[[f64; 2]], detect: DetectMode, threshold: Option<f64>) -> PathLoopRequest {
    PathLoopRequest {
        path: path.to_vec(),
        material_side: MaterialSide::Left,
        detect,
        threshold,
        tool_radius: 0.5,
        corner_loop: serde_json::from_value(json!({"style": "parallelogram", "leg": 1.0})).unwrap(),
        tolerance: None,
    }
}

#[test]
fn the_three_rules_on_case_c2() {
    let (path, vertices) = cl_points(c2(), 0.5, 0.25);
    let turn = loop_path(&request(&path, DetectMode::TurnAngle, None)).unwrap();
    let delta = loop_path(&request(&path, DetectMode::PatentDeltaL, None)).unwrap();
    let curvature = loop_path(&request(&path, DetectMode::PatentCurvature, Some(2.0))).unwrap();
    for (k, &index) in vertices.iter().enumerate() {
        assert!(turn.points[index].corner, "turn angle finds corner {k}");
        assert!(delta.points[index].corner, "claim 9 finds corner {k}");
        // Claim 8's condition (d) misses the 135° corner (k = 1).
        assert_eq!(curvature.points[index].corner, k != 1, "claim 8 at corner {k}");
    }
    // Nothing else is a corner: the straight runs between have no turn.
    assert_eq!(turn.points.iter().filter(|p| p.corner).count(), 4);
    assert!(curvature.warnings.iter().any(|w| w.code == "W_DETECT_DISAGREE"));
    assert!((turn.centre[0] - 14.253013).abs() < 1e-6 && (turn.centre[1] - 3.942080).abs() < 1e-6);
}

#[test]
fn loops_pass_the_corner_points_straight_and_stay_in_the_air() {
    let (path, vertices) = cl_points(c2(), 0.5, 0.25);
    let answer = loop_path(&request(&path, DetectMode::TurnAngle, None)).unwrap();
    assert!(answer.max_abs_cross <= 1e-9, "{}", answer.max_abs_cross);
    assert!((answer.min_dot - 1.0).abs() <= 1e-12);
    let polygon: Vec<Vec2> = path.iter().copied().map(vec2).collect();
    for &index in &vertices {
        assert!(answer.points[index].looped);
        let p = polygon[index];
        let visits = answer.moves.iter().filter(|m| (vec2(m.to) - p).norm() < 1e-9).count();
        assert_eq!(visits, 2, "corner point passed twice");
    }
    for step in answer.moves.iter().filter(|m| m.kind == MoveKind::Loop) {
        assert_eq!(point_in_polygon(&vec2(step.to), &polygon), Containment::Outside);
    }
    // The path is the given one plus 4 moves per parallelogram loop.
    assert_eq!(answer.moves.len(), path.len() + 4 * 4);
}

#[test]
fn curvature_is_undefined_on_axis_parallel_squares() {
    let (path, _) = cl_points(json!([[0, 0], [20, 0], [20, 20], [0, 20]]), 1.0, 0.5);
    let answer = loop_path(&request(&path, DetectMode::PatentCurvature, Some(1.0))).unwrap();
    assert!(answer.warnings.iter().any(|w| w.code == "W_DETECT_UNDEFINED"));
    assert_eq!(answer.points.iter().filter(|p| p.looped).count(), 0);
}

#[test]
fn bad_paths_are_refused() {
    let mut bad = request(&[[0.0, 0.0], [1.0, 0.0]], DetectMode::TurnAngle, None);
    assert_eq!(loop_path(&bad).unwrap_err().code().as_str(), "E_DEGENERATE");
    bad.path = vec![[0.0, 0.0], [1.0, f64::NAN], [1.0, 1.0]];
    let error = loop_path(&bad).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("path[1][1]")));
    bad.path = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]];
    bad.tool_radius = 0.0;
    assert_eq!(loop_path(&bad).unwrap_err().field(), Some("tool_radius"));
}
