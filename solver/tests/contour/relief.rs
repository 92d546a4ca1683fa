//! Inside-corner relief: dogbone and T-bone reach the vertex (no material left), cut only where
//! the tool cannot reach, and report the over-cut; the reported areas are checked against an
//! independent grid count of the swept capsule in the material.

use kerf_solver::contour::{self, ContourSolution, Convexity, CornerAction};
use kerf_solver::planar::{Containment, Vec2, point_in_polygon, point_segment_distance, vec2};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::json;

const L_SHAPE: [[f64; 2]; 6] = [[0.0, 0.0], [30.0, 0.0], [30.0, 10.0], [10.0, 10.0], [10.0, 25.0], [0.0, 25.0]];

fn solve(relief: &str, edge: &str, side: &str, contour: &[[f64; 2]], radius: f64) -> ContourSolution {
    let request = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": radius},
        "contour": contour,
        "side": side,
        "depths": {"top": 0, "bottom": -1, "step": 1},
        "inside_corner_relief": relief,
        "tbone_edge": edge,
        "feed": 600
    }))
    .unwrap();
    contour::solve(&request, &Tool::new(ToolKind::Flat, radius)).unwrap()
}

/// Area of {within `radius` of segment [p, target]} ∩ material near `vertex`, by counting the
/// centres of a fine grid.
fn grid_overcut(contour: &[[f64; 2]], outside: bool, vertex: Vec2, p: Vec2, target: Vec2, radius: f64) -> f64 {
    let polygon: Vec<Vec2> = contour.iter().copied().map(vec2).collect();
    let step = 0.004;
    // Cell edges on the vertex's coordinates, so the axis-parallel faces through it are cell
    // boundaries and the count has no half-cell bias along them.
    let half = ((p - vertex).norm() + radius + 0.1) / step;
    let count = 2 * half.ceil() as i64;
    let reach = half.ceil() * step;
    let mut inside = 0u64;
    for i in 0..count {
        for j in 0..count {
            let x = vertex + Vec2::new(-reach + (i as f64 + 0.5) * step, -reach + (j as f64 + 0.5) * step);
            if point_segment_distance(&x, &p, &target) > radius {
                continue;
            }
            let containment = point_in_polygon(&x, &polygon);
            let material =
                if outside { containment == Containment::Inside } else { containment == Containment::Outside };
            if material {
                inside += 1;
            }
        }
    }
    inside as f64 * step * step
}

#[test]
fn dogbone_reaches_the_vertex_and_reports_its_overcut() {
    let answer = solve("dogbone", "longer", "outside", &L_SHAPE, 2.0);
    let corner = answer.corners.iter().find(|c| c.index == 3).unwrap();
    assert_eq!(corner.action, CornerAction::Dogbone);
    let relief = corner.relief.as_ref().unwrap();
    let (vertex, target, p) = (vec2(corner.vertex), vec2(relief.target), vec2(corner.cl_point));
    assert!(((target - vertex).norm() - 2.0).abs() < 1e-12, "the tool circle passes through V");
    assert!(corner.material.left_area < 1e-9 && corner.material.left_depth < 1e-12);
    // Over-cut depth r(1 − sin(γ/2)) for γ = 90°.
    assert!((corner.material.overcut_depth - 2.0 * (1.0 - 0.5f64.sqrt())).abs() < 1e-12);
    let counted = grid_overcut(&L_SHAPE, true, vertex, p, target, 2.0);
    assert!(
        (corner.material.overcut_area - counted).abs() < 2e-3 * counted.max(1.0),
        "{} vs {counted}",
        corner.material.overcut_area
    );
    // Only the inside corner is relieved; the convex ones keep their loops.
    for other in answer.corners.iter().filter(|c| c.index != 3) {
        assert_eq!(other.convexity, Convexity::Convex);
        assert!(other.relief.is_none() && other.looped);
    }
    assert!(!answer.warnings.iter().any(|w| w.code == "W_INSIDE_CORNER"));
}

#[test]
fn tbone_runs_along_the_chosen_edge() {
    for (edge, along) in [("longer", 2), ("shorter", 3), ("previous", 2), ("next", 3)] {
        let answer = solve("tbone", edge, "outside", &L_SHAPE, 2.0);
        let corner = answer.corners.iter().find(|c| c.index == 3).unwrap();
        assert_eq!(corner.action, CornerAction::Tbone, "{edge}");
        let relief = corner.relief.as_ref().unwrap();
        assert_eq!(relief.along_edge, Some(along), "{edge}");
        let (vertex, target, p) = (vec2(corner.vertex), vec2(relief.target), vec2(corner.cl_point));
        assert!(((target - vertex).norm() - 2.0).abs() < 1e-12);
        // Along edge 2 (y = 10) the relief moves in x only; along edge 3 (x = 10) in y only.
        let travel = target - p;
        if along == 2 {
            assert!(travel.y.abs() < 1e-12)
        } else {
            assert!(travel.x.abs() < 1e-12)
        }
        assert!(corner.material.left_area < 1e-9, "{edge}: {}", corner.material.left_area);
        assert!((corner.material.overcut_depth - 2.0).abs() < 1e-12, "a T-bone cuts r deep into the other face");
        let counted = grid_overcut(&L_SHAPE, true, vertex, p, target, 2.0);
        assert!(
            (corner.material.overcut_area - counted).abs() < 2e-3 * counted.max(1.0),
            "{edge}: {} vs {counted}",
            corner.material.overcut_area
        );
    }
}

#[test]
fn pocket_corners_get_dogbones_and_no_loops() {
    let pocket = [[0.0, 0.0], [40.0, 0.0], [40.0, 30.0], [0.0, 30.0]];
    let answer = solve("dogbone", "longer", "inside", &pocket, 3.0);
    for corner in &answer.corners {
        assert_eq!(corner.convexity, Convexity::Concave);
        assert_eq!(corner.action, CornerAction::Dogbone);
        assert!(!corner.looped);
        let relief = corner.relief.as_ref().unwrap();
        let counted =
            grid_overcut(&pocket, false, vec2(corner.vertex), vec2(corner.cl_point), vec2(relief.target), 3.0);
        assert!(
            (corner.material.overcut_area - counted).abs() < 2e-3 * counted.max(1.0),
            "{} {} vs {counted}",
            corner.index,
            corner.material.overcut_area
        );
    }
    // Without relief the same pocket keeps four fillets of A_f(3, 90°) = 9(1 − π/4).
    let plain = solve("none", "longer", "inside", &pocket, 3.0);
    for corner in &plain.corners {
        assert_eq!(corner.action, CornerAction::Reflex);
        assert!((corner.material.left_area - 9.0 * (1.0 - std::f64::consts::FRAC_PI_4)).abs() < 1e-9);
    }
}

#[test]
fn fillet_tighter_than_the_tool_is_passed_over_and_reported() {
    // The L-shape's inside corner rounded with radius 0.5 in 10 chords; the tool (r = 2) cannot
    // follow the chords, cuts past them at one merged corner point, and leaves the area between
    // its own r = 2 fillet and the contour's: A_f(2, 90°) − A_f(0.5, 90°) up to the chords.
    let mut contour: Vec<[f64; 2]> = vec![[0.0, 0.0], [30.0, 0.0], [30.0, 10.0]];
    for i in 0..=10 {
        let angle = -std::f64::consts::FRAC_PI_2 * f64::from(i) / 10.0;
        // Centre (10.5, 10.5): from (10.5, 10) round to (10, 10.5), concave (centre in the air).
        let a = -std::f64::consts::FRAC_PI_2 + angle;
        contour.push([10.5 + 0.5 * a.cos(), 10.5 + 0.5 * a.sin()]);
    }
    contour.extend([[10.0, 25.0], [0.0, 25.0]]);
    let answer = solve("none", "longer", "outside", &contour, 2.0);
    let unreached: Vec<_> = answer.corners.iter().filter(|c| c.action == CornerAction::Unreached).collect();
    assert_eq!(unreached.len(), 11);
    let left: f64 = unreached.iter().map(|c| c.material.left_area).sum();
    let expected = 4.0 * (1.0 - std::f64::consts::FRAC_PI_4) - 0.25 * (1.0 - std::f64::consts::FRAC_PI_4);
    assert!((left - expected).abs() < 2e-3, "{left} vs {expected}");
    assert!(answer.warnings.iter().any(|w| w.code == "W_EDGE_UNREACHED"));
    // All corner points of the stretch share one CL point, 2 from both straight faces.
    let p = vec2(unreached[0].cl_point);
    assert!(unreached.iter().all(|c| (vec2(c.cl_point) - p).norm() < 1e-12));
    assert!((p - Vec2::new(12.0, 12.0)).norm() < 1e-9, "{p:?}");
}
