//! Every reference case of `solver/tests/fixtures/contour.json` (copied to `tests/fixtures/`): corner
//! classification, miter points, loops, the element list, lengths, division coordinates, the
//! claim-10 check, gouge and stock clearances, detection measures, and the edge-case numbers,
//! all to 1e-6 (the fixture's rounding).

use kerf_cases::{case, fixture, number};
use std::f64::consts::PI;

use kerf_solver::contour::detect::{self, DetectMode};
use kerf_solver::contour::division::{self, collinearity, divide_polygon, replay};
use kerf_solver::contour::loops::LoopShape;
use kerf_solver::contour::{self, Action, ContourRequest, CornerAction, Element, ElementKind, PassPlan, Plan};
use kerf_solver::planar::{Vec2, turn_angle, vec2};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

const TOLERANCE: f64 = 1e-6;

fn point(value: &Value) -> Vec2 {
    Vec2::new(number(&value[0]), number(&value[1]))
}

fn close(what: &str, got: f64, expected: f64) {
    assert!((got - expected).abs() <= TOLERANCE, "{what}: got {got}, expected {expected}");
}

fn close_point(what: &str, got: Vec2, expected: &Value) {
    let expected = point(expected);
    assert!((got - expected).norm() <= TOLERANCE * 1.5, "{what}: got {got:?}, expected {expected:?}");
}

/// The API request for a case ([`kerf_cases::contour::reference_request`]) and its flat tool.
fn request(case: &Value) -> (ContourRequest, Tool) {
    let radius = number(&case["inputs"]["tool_radius"]);
    (serde_json::from_value(kerf_cases::contour::reference_request(case)).unwrap(), Tool::new(ToolKind::Flat, radius))
}

fn plan_of(case: &Value) -> Plan {
    let (request, tool) = request(case);
    contour::plan(&request, &tool).unwrap()
}

fn action_name(action: Action) -> &'static str {
    match action {
        Action::LoopArc => "loop_arc",
        Action::LoopParallelogram => "loop_par",
        Action::LoopTriangle => "loop_tri",
        Action::Round => "round_join",
        other => other.as_str(),
    }
}

fn check_corners(id: &str, pass: &PassPlan, expected: &Value) {
    for corner in expected.as_array().unwrap() {
        let k = corner["k"].as_u64().unwrap() as usize;
        let plan = pass.corners.iter().find(|c| c.k == k).unwrap();
        let what = |name: &str| format!("{id} pass {} corner {k} {name}", pass.index + 1);
        close_point(&what("V"), plan.vertex, &corner["V"]);
        close(&what("phi"), plan.turn.to_degrees(), number(&corner["phi_deg"]));
        close(&what("alpha"), plan.material_angle.to_degrees(), number(&corner["alpha_deg"]));
        assert_eq!(plan.convex, corner["convex"].as_bool().unwrap(), "{}", what("convex"));
        close_point(&what("P"), plan.cl_point, &corner["P"]);
        close(&what("PV"), (plan.cl_point - plan.vertex).norm(), number(&corner["PV"]));
        assert_eq!(action_name(plan.action), corner["action"].as_str().unwrap(), "{}", what("action"));
        let Some(expected_loop) = corner.get("loop") else {
            assert!(plan.loop_shape.is_none(), "{}", what("no loop"));
            continue;
        };
        let shape = plan.loop_shape.unwrap();
        close(&what("L"), shape.leg, number(&expected_loop["L"]));
        close_point(&what("A"), shape.exit_end, &expected_loop["A"]);
        close_point(&what("B"), shape.entry_start, &expected_loop["B"]);
        match expected_loop["type"].as_str().unwrap() {
            "arc" => {
                close(&what("rho"), shape.radius.unwrap(), number(&expected_loop["rho"]));
                close_point(&what("C"), shape.centre.unwrap(), &expected_loop["C"]);
                close(&what("sweep"), shape.sweep.unwrap().to_degrees(), number(&expected_loop["sweep_deg"]));
            }
            "parallelogram" => close_point(&what("M"), shape.far_corner.unwrap(), &expected_loop["M"]),
            other => panic!("unknown loop type {other}"),
        }
    }
}

fn check_elements(id: &str, pass: &PassPlan, expected: &Value) {
    let expected = expected.as_array().unwrap();
    assert_eq!(pass.elements.len(), expected.len(), "{id} element count");
    for (index, (element, want)) in pass.elements.iter().zip(expected).enumerate() {
        let what = |name: &str| format!("{id} pass {} element {index} {name}", pass.index + 1);
        assert_eq!(element.kind().as_str(), want["kind"].as_str().unwrap(), "{}", what("kind"));
        close_point(&what("start"), element.start(), &want["start"]);
        close_point(&what("end"), element.end(), &want["end"]);
        close(&what("length"), element.length(), number(&want["length"]));
        match (element, want["type"].as_str().unwrap()) {
            (Element::Line { .. }, "line") => {}
            (Element::Arc { centre, radius, sweep, .. }, "arc") => {
                close_point(&what("centre"), *centre, &want["centre"]);
                close(&what("radius"), *radius, number(&want["radius"]));
                close(&what("sweep"), sweep.to_degrees(), number(&want["sweep_deg"]));
            }
            (got, expected) => panic!("{}: {got:?} is not a {expected}", what("type")),
        }
    }
}

fn check_lengths(id: &str, pass: &PassPlan, expected: &Value) {
    let total: f64 = pass.elements.iter().map(Element::length).sum();
    close(&format!("{id} total length"), total, number(&expected["length_total"]));
    for (name, kind) in [
        ("cut", ElementKind::Cut),
        ("exit", ElementKind::Exit),
        ("loop", ElementKind::Loop),
        ("entry", ElementKind::Entry),
    ] {
        let length: f64 = pass.elements.iter().filter(|e| e.kind() == kind).map(Element::length).sum();
        let want = expected["length_by_kind"].get(name).map_or(0.0, number);
        close(&format!("{id} {name} length"), length, want);
    }
}

fn check_division(id: &str, pass: &PassPlan, h: f64, expected: &Value) {
    let division = division::divide(&pass.elements, h);
    let want = &expected["division_points"];
    assert_eq!(
        division.points.len() as u64,
        want["count"].as_u64().unwrap(),
        "{id} pass {} division count",
        pass.index + 1
    );
    for (index, (got, point)) in division.points.iter().zip(want["points"].as_array().unwrap()).enumerate() {
        close_point(&format!("{id} division point {index}"), *got, point);
    }
    let visits = want["corner_visits"].as_array().unwrap();
    assert_eq!(division.corner_visits.len(), visits.len(), "{id} corner visit count");
    for (&index, visit) in division.corner_visits.iter().zip(visits) {
        assert_eq!(index as u64, visit["index"].as_u64().unwrap(), "{id} visit index");
        close(&format!("{id} visit s"), division.s[index], number(&visit["s"]));
        close_point(&format!("{id} visit point"), division.points[index], &visit["point"]);
    }
    for (index, (got, step)) in division.turtle.iter().zip(expected["turtle_first10"].as_array().unwrap()).enumerate() {
        let heading = got.0.to_degrees();
        let want_heading = number(&step["heading_deg"]);
        let difference = (heading - want_heading + 540.0).rem_euclid(360.0) - 180.0;
        assert!(difference.abs() <= TOLERANCE, "{id} turtle {index} heading {heading} vs {want_heading}");
        close(&format!("{id} turtle {index} length"), got.1, number(&step["length"]));
    }
    // T1: the turtle replays the points exactly.
    let replayed = replay(division.points[0], &division.turtle);
    for (a, b) in replayed.iter().zip(&division.points) {
        assert!((a - b).norm() < 1e-9, "{id} turtle replay");
    }
    if let Some(claim10) = expected.get("claim10_collinearity") {
        let (cross, dot) =
            collinearity(&division, claim10["f"].as_u64().unwrap() as usize, claim10["k"].as_u64().unwrap() as usize);
        assert!(cross <= 1e-9, "{id} claim 10 cross {cross}");
        close(&format!("{id} claim 10 dot"), dot, number(&claim10["min_dot"]));
    }
}

fn check_detection(id: &str, pass: &PassPlan, h: f64, sigma: f64, expected: &Value) {
    let (points, vertices) = divide_polygon(&pass.cl, h);
    let (centre, measures) = detect::measures(&points);
    close_point(&format!("{id} detection centre"), centre, &expected["centre_ab"]);
    for corner in expected["at_corners"].as_array().unwrap() {
        let k = corner["k"].as_u64().unwrap() as usize;
        let what = |name: &str| format!("{id} pass {} detection {k} {name}", pass.index + 1);
        let measure = measures[vertices[k]];
        match corner["kappa_a"].as_f64() {
            None => assert!(measure.curvature.is_none(), "{}", what("kappa undefined")),
            Some(kappa) => {
                let got = measure.curvature.unwrap();
                assert!((got - kappa).abs() <= 1e-6 * kappa.max(1.0), "{}: {got} vs {kappa}", what("kappa"));
            }
        }
        assert_eq!(measure.protrudes, corner["d_ok"].as_bool().unwrap(), "{}", what("d"));
        close(&what("dL"), measure.delta_l, number(&corner["dL"]));
        close(&what("dL/h"), measure.delta_l_per_step, number(&corner["dL_over_h"]));
        close(&what("phi"), measure.turn.to_degrees(), number(&corner["phi_deg"]));
        // TurnAngle finds every convex corner; claim 9's rule agrees with it wherever ΔL/h > 0.
        let convex = detect::is_corner(&measure, DetectMode::TurnAngle, 1f64.to_radians(), sigma);
        assert_eq!(convex, number(&corner["phi_deg"]) * sigma > 0.0, "{}", what("turn rule"));
    }
}

fn check_case(id: &str) {
    let case = case("contour", id);
    let plan = plan_of(&case);
    let h = number(&case["inputs"]["division_step_h"]);
    let detection_h = number(&case["inputs"]["detection_step_h"]);
    let expected_passes = case["expected"]["passes"].as_array().unwrap();
    assert_eq!(plan.passes.len(), expected_passes.len());
    for (pass, expected) in plan.passes.iter().zip(expected_passes) {
        let label = format!("{id} pass {}", pass.index + 1);
        close(&format!("{label} offset"), pass.offset, number(&expected["offset"]));
        close_point(&format!("{label} start"), pass.start, &expected["start"]);
        check_corners(id, pass, &expected["corners"]);
        check_elements(id, pass, &expected["elements"]);
        check_lengths(id, pass, expected);
        check_division(id, pass, h, expected);
        check_detection(id, pass, detection_h, plan.sigma, &expected["detection"]);
        match expected.get("gouge_min_clearance") {
            Some(value) => close(&format!("{label} gouge clearance"), pass.gouge_min_clearance.unwrap(), number(value)),
            None => assert!(pass.gouge_min_clearance.is_none()),
        }
        if let Some(value) = expected.get("stock_min_clearance_of_noncut_moves") {
            close(&format!("{label} stock clearance"), pass.stock_min_clearance.unwrap(), number(value));
        }
    }
}

#[test]
fn c1_square_island_arc_loop() {
    check_case("C1");
}

#[test]
fn c2_quadrilateral_parallelogram_loop() {
    check_case("C2");
    // The arc variant for comparison (ρ = 0.5) at the same corner points.
    let case = case("contour", "C2");
    let plan = plan_of(&case);
    let pass = &plan.passes[0];
    for want in case["expected"]["arc_variant_for_comparison"].as_array().unwrap() {
        let k = want["k"].as_u64().unwrap() as usize;
        let corner = pass.corners.iter().find(|c| c.k == k).unwrap();
        let n = pass.cl.len();
        let d1 = (pass.cl[k] - pass.cl[(k + n - 1) % n]).normalize();
        let d2 = (pass.cl[(k + 1) % n] - pass.cl[k]).normalize();
        let shape = LoopShape::arc(&corner.cl_point, &d1, &d2, plan.sigma, 0.5);
        close("arc variant L", shape.leg, number(&want["arc_variant_rho_0p5_leg_L"]));
        close_point("arc variant A", shape.exit_end, &want["A"]);
        close_point("arc variant C", shape.centre.unwrap(), &want["C"]);
        close_point("arc variant B", shape.entry_start, &want["B"]);
        close("arc variant sweep", shape.sweep.unwrap().to_degrees(), number(&want["sweep_deg"]));
    }
}

#[test]
fn c3_l_shape_three_passes() {
    check_case("C3");
    // The inside corner's fillet, reported by the full solver on the final pass.
    let case = case("contour", "C3");
    let (request, tool) = request(&case);
    let answer = contour::solve(&request, &tool).unwrap();
    let inside = answer.corners.iter().find(|c| c.index == 3).unwrap();
    assert_eq!(inside.action, CornerAction::Reflex);
    let expected = &case["expected"]["with_without_loop"]["closed_form"];
    close("C3 inside corner left-over", inside.material.left_area, number(&expected["inside_corner_leftover_area"]));
    close("C3 inside corner depth", inside.material.left_depth, 2.0 * 2f64.sqrt() - 2.0);
    for corner in answer.corners.iter().filter(|c| c.index != 3) {
        assert_eq!(corner.material.left_area, 0.0);
        assert_eq!(corner.material.overcut_area, 0.0);
    }
    assert!(answer.warnings.iter().any(|w| w.code == "W_INSIDE_CORNER"));
}

#[test]
fn c1_and_c2_material_with_and_without_loops_under_m1() {
    // C1 corner (20, 20) with ρ_b = 1.5 and C2 with ρ_b = 1: the miter path over-cuts
    // A_f(ρ_b − r, α); the loop path loses nothing.
    for (id, blend, key) in
        [("C1", 1.5, "M1_miter_rho_b_1p5_overcut_per_corner"), ("C2", 1.0, "M1_miter_rho_b_1_overcut_per_corner")]
    {
        let case = case("contour", id);
        let closed = &case["expected"]["with_without_loop"]["closed_form"];
        for style in ["none", "loop"] {
            let (mut request, tool) = request(&case);
            request.controller =
                Some(contour::ControllerModel { blend_radius: Some(blend), servo_time_constant_ms: None });
            if style == "none" {
                request.corner_loop.style = contour::LoopStyle::None;
            }
            let answer = contour::solve(&request, &tool).unwrap();
            for corner in &answer.corners {
                let predicted = corner.predicted.unwrap();
                if style == "loop" {
                    assert_eq!(predicted.overcut_area, 0.0, "{id} loop corner {}", corner.index);
                    continue;
                }
                let want = if closed[key].is_object() {
                    let alpha = format!("{:.0}", corner.angle_deg);
                    number(&closed[key][alpha.as_str()])
                } else {
                    number(&closed[key])
                };
                assert!(
                    (predicted.overcut_area - want).abs() <= 1e-5,
                    "{id} corner {}: {} vs {want}",
                    corner.index,
                    predicted.overcut_area
                );
            }
        }
    }
}

fn edge_case(label_start: &str) -> Value {
    fixture("contour")["edge_cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["label"].as_str().unwrap().starts_with(label_start))
        .unwrap()
        .clone()
}

#[test]
fn edge_cases_of_acute_and_flat_corners() {
    for alpha_deg in [5.0_f64, 15.0, 170.0, 179.0] {
        let want = edge_case(&format!("convex corner alpha={alpha_deg:.0} deg"));
        let alpha = alpha_deg.to_radians();
        let psi = PI - alpha;
        // A corner at the origin turning left by ψ, r = 1, ρ = 1.
        let d1 = Vec2::x();
        let d2 = Vec2::new(psi.cos(), psi.sin());
        let n1 = Vec2::new(d1.y, -d1.x);
        let n2 = Vec2::new(d2.y, -d2.x);
        let p = kerf_solver::planar::miter_point(&Vec2::zeros(), &n1, 1.0, &n2, 1.0).unwrap();
        close("PV", p.norm(), number(&want["PV"]));
        let shape = LoopShape::arc(&p, &d1, &d2, 1.0, 1.0);
        close("arc leg", shape.leg, number(&want["arc_leg_L"]));
        close("arc sweep", -shape.sweep.unwrap().to_degrees(), number(&want["arc_sweep_deg"]));
        assert!((shape.length() - number(&want["loop_length"])).abs() <= 1e-5);
        close("turn", turn_angle(&d1, &d2), psi);
    }
}

#[test]
fn edge_case_notch_collapses() {
    let want = edge_case("notch 3 wide");
    let notch =
        [[0.0, 0.0], [30.0, 0.0], [30.0, 20.0], [17.0, 20.0], [17.0, 10.0], [14.0, 10.0], [14.0, 20.0], [0.0, 20.0]];
    // O4 on the miter offset with o = 2.
    let polygon: Vec<Vec2> = notch.iter().copied().map(vec2).collect();
    let offset = kerf_solver::planar::miter_offset(&polygon, &[2.0; 8], false).unwrap();
    for (k, expected) in want["offset_edge_lengths"].as_array().unwrap().iter().enumerate() {
        let t = (polygon[(k + 1) % 8] - polygon[k]).normalize();
        close("offset edge length", (offset[(k + 1) % 8] - offset[k]).dot(&t), number(expected));
    }
    let request: ContourRequest = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 2}, "contour": notch, "side": "outside",
        "depths": {"top": 0, "bottom": -1, "step": 1}, "feed": 500
    }))
    .unwrap();
    let error = contour::solve(&request, &Tool::new(ToolKind::Flat, 2.0)).unwrap_err();
    assert_eq!(error.code().as_str(), "E_OFFSET_COLLAPSE");
    assert_eq!(error.field(), Some("contour[4]"));
}

#[test]
fn edge_case_tilted_tool_offsets() {
    let want = edge_case("claim 3 tilted tool");
    let (o1, o2) = (1.0 / 10f64.to_radians().cos(), 1.0 / 30f64.to_radians().cos());
    close("o1", o1, number(&want["o1"]));
    close("o2", o2, number(&want["o2"]));
    // Square island corner (20, 20): face 21 is the right wall (air +x), face 22 the top (air +y).
    let p = kerf_solver::planar::miter_point(&Vec2::new(20.0, 20.0), &Vec2::x(), o1, &Vec2::y(), o2).unwrap();
    close_point("P", p, &want["P"]);
    // The same through the solver: a square with walls tilted 10° (right) and 30° (top).
    let request: ContourRequest = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 1}, "contour": [[0, 0], [20, 0], [20, 20], [0, 20]],
        "side": "outside", "direction": "conventional",
        "depths": {"top": 1, "bottom": 0, "step": 1}, "feed": 500,
        "tilt_deg": [0, 10, 30, 0]
    }))
    .unwrap();
    let answer = contour::solve(&request, &Tool::new(ToolKind::Flat, 1.0)).unwrap();
    let corner = answer.corners.iter().find(|c| c.index == 2).unwrap();
    close_point("solver P", vec2(corner.cl_point), &want["P"]);
    assert!(answer.layers[0].moves.iter().all(|m| m.axis.is_some()));
}

#[test]
fn edge_case_detection_on_a_thin_triangle() {
    let want = edge_case("criterion (d) on triangle");
    let request: ContourRequest = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 0.01}, "contour": [[0, 0], [10, 0], [1, 1]],
        "side": "outside", "direction": "conventional",
        "depths": {"top": 1, "bottom": 0, "step": 1}, "feed": 500
    }))
    .unwrap();
    let plan = contour::plan(&request, &Tool::new(ToolKind::Flat, 0.01)).unwrap();
    let pass = &plan.passes[0];
    let (points, vertices) = divide_polygon(&pass.cl, 0.05);
    let (_, measures) = detect::measures(&points);
    for k in 0..3 {
        // This edge case is rounded to 1e-4.
        let alpha = pass.corners.iter().find(|c| c.k == k).unwrap().material_angle.to_degrees();
        assert!((alpha - number(&want["alpha_deg"][k])).abs() <= 1e-4, "alpha {alpha}");
        let measure = measures[vertices[k]];
        assert_eq!(measure.protrudes, want["d_ok"][k].as_bool().unwrap());
        assert!((measure.delta_l_per_step - number(&want["dL_over_h"][k])).abs() <= 1e-4);
    }
}

#[test]
fn loops_shrink_where_the_full_loop_would_gouge_a_neighbour() {
    // §3.5.5 global check: a tooth (1 wide, 5 high) standing in a bay 2.6 from each bay wall.
    // Full arc loops (ρ = r = 1) at the tooth's tip would reach past the bay walls; halving twice
    // (ρ = 0.25) clears them by 0.1. The other corners keep ρ = 1.
    let contour = json!([
        [0, 0],
        [30, 0],
        [30, 30],
        [18.1, 30],
        [18.1, 20],
        [15.5, 20],
        [15.5, 25],
        [14.5, 25],
        [14.5, 20],
        [11.9, 20],
        [11.9, 30],
        [0, 30]
    ]);
    let request: ContourRequest = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 1}, "contour": contour, "side": "outside",
        "direction": "conventional", "depths": {"top": 1, "bottom": 0, "step": 1}, "feed": 500
    }))
    .unwrap();
    let answer = contour::solve(&request, &Tool::new(ToolKind::Flat, 1.0)).unwrap();
    for corner in answer.corners.iter().filter(|c| c.looped) {
        let report = corner.corner_loop.as_ref().unwrap();
        assert!(report.clearance >= -1e-9, "corner {}", corner.index);
        let tooth_tip = corner.index == 6 || corner.index == 7;
        let expected = if tooth_tip { 0.25 } else { 1.0 };
        assert!((report.radius.unwrap() - expected).abs() < 1e-12, "corner {}: ρ {:?}", corner.index, report.radius);
        if tooth_tip {
            assert!((report.clearance - 0.1).abs() < 0.011, "corner {}: {}", corner.index, report.clearance);
        }
    }
    assert_eq!(answer.corners.iter().filter(|c| c.looped).count(), 8);
    assert!(!answer.warnings.iter().any(|w| w.code == "W_LOOP_SKIPPED_GOUGE"));
}
