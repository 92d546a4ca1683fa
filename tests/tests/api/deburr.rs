//! `POST /api/v1/deburr` over HTTP: every hole shape on both edges, the reference case 1 numbers,
//! determinism and the exact method.

use kerf_cases::deburr::{case_1, request};
use kerf_cases::with;
use kerf_tests::{TestApp, json_with, problem};
use serde_json::{Value, json};

pub async fn app_with_tools() -> TestApp {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3, "neck_radius": 1.5})).await;
    app.register_tool(8, &json!({"kind": "flat", "radius": 3})).await;
    app
}

fn point3(value: &Value) -> [f64; 3] {
    let a = value.as_array().expect("point");
    [a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap()]
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Checks what every answer must satisfy: closed loop, count, tip below centre by D, CL.
fn check_answer(body: &Value, ball: f64) {
    let points = body["points"].as_array().expect("points");
    assert!(points.len() > 8);
    assert_eq!(body["summary"]["count"].as_u64().unwrap() as usize, points.len() - 1);
    assert_eq!(points.first().unwrap()["centre"], points.last().unwrap()["centre"], "closed loop");
    for point in points {
        let (centre, tip, target) = (point3(&point["centre"]), point3(&point["tip"]), point3(&point["target"]));
        assert!((centre[2] - tip[2] - ball).abs() < 1e-12 && centre[0] == tip[0] && centre[1] == tip[1]);
        let offset = point["centre_offset"].as_f64().unwrap();
        assert!((distance(centre, target) - offset.abs()).abs() < 1e-9);
    }
    assert!(body["summary"]["max_deviation"].as_f64().unwrap() <= body["summary"]["tolerance"].as_f64().unwrap());
}

#[tokio::test(flavor = "multi_thread")]
async fn every_hole_shape_on_both_edges() {
    let app = app_with_tools().await;
    let holes = [
        json!({"shape": "round", "radius": 8, "eccentricity": 3}),
        json!({"shape": "slot", "radius": 6, "centre_distance": 20, "penetration_angle_deg": 10}),
        json!({"shape": "rounded_rect", "radius": 4, "centre_distance": [12, 20]}),
    ];
    for hole in &holes {
        for edge in ["outer", "inner"] {
            let body = json_with(app.post_json("/api/v1/deburr", &request(hole.clone(), edge)).await, 200).await;
            assert_eq!(body["edge"], edge);
            assert_eq!(body["tool"]["number"], 7);
            check_answer(&body, 3.0);
            let segments: Vec<&str> =
                body["points"].as_array().unwrap().iter().map(|p| p["segment"].as_str().unwrap()).collect();
            match hole["shape"].as_str().unwrap() {
                "round" => assert!(segments.iter().all(|s| *s == "arc")),
                "slot" => assert!(segments.contains(&"line_y+x") && segments.contains(&"arc_cs1")),
                _ => assert!(segments.contains(&"line_x+y") && segments.contains(&"arc_q4")),
            }
            assert!(!body["lead_in"].as_array().unwrap().is_empty(), "a tube always has a clearance plane");
        }
    }
    // The bored block: inner edge only.
    let mut block = request(json!({"shape": "round", "radius": 8}), "inner");
    block["workpiece"] = json!({"kind": "bore_block", "origin": [10, 20, 30], "arrangement_angle_deg": 90, "bore_radius": 40, "face_distance": 60});
    check_answer(&json_with(app.post_json("/api/v1/deburr", &block).await, 200).await, 3.0);
}

#[tokio::test(flavor = "multi_thread")]
async fn reference_case_1_over_http() {
    let app = app_with_tools().await;
    let body = with(case_1(), json!({"tolerance": 0.01}));
    let answer = json_with(app.post_json("/api/v1/deburr", &body).await, 200).await;
    assert_eq!(answer["summary"]["count"], 92);
    let first = point3(&answer["points"][0]["centre"]);
    assert!(distance(first, [8.389_716_911, 0.0, 50.961_980_811]) < 1e-6);
    assert!((answer["points"][0]["wedge_angle_deg"].as_f64().unwrap() - 78.463_040_967).abs() < 1e-6);

    // Determinism: byte-identical answers.
    let again = app.client.post(app.url("/api/v1/deburr")).json(&body).send().await.unwrap().bytes().await.unwrap();
    let once = app.client.post(app.url("/api/v1/deburr")).json(&body).send().await.unwrap().bytes().await.unwrap();
    assert_eq!(again, once);

    // Clockwise runs the same loop backwards from the same start.
    let mut reverse = body.clone();
    reverse["direction"] = json!("cw");
    let backwards = json_with(app.post_json("/api/v1/deburr", &reverse).await, 200).await;
    let forward_points = answer["points"].as_array().unwrap();
    let backward_points = backwards["points"].as_array().unwrap();
    assert_eq!(forward_points[1]["centre"], backward_points[backward_points.len() - 2]["centre"]);

    // The exact method sweeps a chamfer W wide on the true surfaces (within max(0.005 mm, TA))
    // and says how far the patent is off.
    let mut exact = body.clone();
    exact["method"] = json!("exact");
    let exact_answer = json_with(app.post_json("/api/v1/deburr", &exact).await, 200).await;
    let offset = exact_answer["summary"]["max_exact_offset"].as_f64().unwrap();
    assert!(offset > 1e-5 && offset < 0.05, "exact offset {offset}");
    let width = exact_answer["summary"]["width"].as_f64().unwrap();
    for field in ["swept_width_min", "swept_width_max"] {
        let swept = exact_answer["summary"][field].as_f64().unwrap();
        assert!((swept - width).abs() <= 0.01, "{field} {swept}, W {width}");
    }
    check_answer(&exact_answer, 3.0);

    // The same job by width instead of Q gives the same loop.
    let mut by_width = body.clone();
    by_width.as_object_mut().unwrap().remove("cut_amount");
    by_width["width"] = json!(0.5 * std::f64::consts::SQRT_2);
    let width_answer = json_with(app.post_json("/api/v1/deburr", &by_width).await, 200).await;
    assert_eq!(width_answer["summary"]["count"], 92);
}

#[tokio::test(flavor = "multi_thread")]
async fn warnings_are_reported() {
    let app = app_with_tools().await;
    // An inner edge with a plain ball end mill (no neck radius) warns about the shank.
    app.register_tool(9, &json!({"kind": "ball", "radius": 2})).await;
    let mut body = request(json!({"shape": "round", "radius": 8}), "inner");
    body["tool"] = json!(9);
    let answer = json_with(app.post_json("/api/v1/deburr", &body).await, 200).await;
    let codes: Vec<&str> = answer["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"W_INNER_ACCESS"), "{codes:?}");

    // A wide chamfer on a small, sharply curved part trips the tangent-line accuracy warning.
    let sharp = json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 13, "outer_radius": 16},
        "hole": {"shape": "round", "radius": 12},
        "edge": "outer", "cut_amount": 1.2
    });
    let answer = json_with(app.post_json("/api/v1/deburr", &sharp).await, 200).await;
    let codes: Vec<&str> = answer["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"W_APPROX"), "{codes:?}");

    // A hole far round the side of the tube: the vertical shank of a plain ball end mill would
    // meet the tube (a necked tool still reaches this one at 70°).
    let mut side = request(json!({"shape": "round", "radius": 8, "penetration_angle_deg": 80}), "outer");
    side["tool"] = json!({"kind": "ball", "radius": 3});
    let answer = json_with(app.post_json("/api/v1/deburr", &side).await, 200).await;
    let codes: Vec<&str> = answer["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"W_SHANK_CLEARANCE"), "{codes:?}");
    side["hole"]["penetration_angle_deg"] = json!(0);
    let answer = json_with(app.post_json("/api/v1/deburr", &side).await, 200).await;
    assert!(answer["warnings"].as_array().unwrap().iter().all(|w| w["code"] != "W_SHANK_CLEARANCE"));
}

#[tokio::test(flavor = "multi_thread")]
async fn od_id_and_diameter_give_the_path_of_the_radii_and_errors_quote_what_was_typed() {
    let app = app_with_tools().await;
    let by_radius = request(json!({"shape": "slot", "radius": 8, "centre_distance": 6}), "inner");
    let mut by_diameter = by_radius.clone();
    by_diameter["workpiece"] =
        json!({"kind": "tube", "origin": [0, 0, 0], "inner_diameter": 60, "outer_diameter": 100});
    by_diameter["hole"] = json!({"shape": "slot", "diameter": 16, "centre_distance": 6});
    let radii = json_with(app.post_json("/api/v1/deburr", &by_radius).await, 200).await;
    let diameters = json_with(app.post_json("/api/v1/deburr", &by_diameter).await, 200).await;
    assert_eq!(radii["points"], diameters["points"]);
    assert_eq!(radii["lead_in"], diameters["lead_in"]);
    // A radius and a diameter may be mixed, one per size.
    let mut mixed = by_diameter.clone();
    mixed["workpiece"] = json!({"kind": "tube", "origin": [0, 0, 0], "inner_radius": 30, "outer_diameter": 100});
    let mixed = json_with(app.post_json("/api/v1/deburr", &mixed).await, 200).await;
    assert_eq!(radii["points"], mixed["points"]);
    // The same program, its header quoting the radii either way.
    let mut programs = Vec::new();
    for body in [&by_radius, &by_diameter] {
        let response = app.post_json("/api/v1/deburr?format=gcode", body).await;
        assert_eq!(response.status(), 200);
        programs.push(response.text().await.unwrap());
    }
    assert_eq!(programs[0], programs[1]);

    // Errors quote the field and the value typed, never the radius made of it.
    let mut negative = by_diameter.clone();
    negative["workpiece"]["outer_diameter"] = json!(-6);
    let refused = problem(app.post_json("/api/v1/deburr", &negative).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "workpiece.outer_diameter", "{refused}");
    let message = refused["errors"][0]["message"].as_str().unwrap();
    assert!(message.contains("outer_diameter") && message.contains("-6") && !message.contains("-3"), "{refused}");
    let mut hole = by_diameter.clone();
    hole["hole"]["diameter"] = json!(-16);
    let refused = problem(app.post_json("/api/v1/deburr", &hole).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "hole.diameter", "{refused}");
    assert!(refused["errors"][0]["message"].as_str().unwrap().contains("-16"), "{refused}");
    let mut inverted = by_diameter.clone();
    inverted["workpiece"]["inner_diameter"] = json!(120);
    let refused = problem(app.post_json("/api/v1/deburr", &inverted).await, 422).await;
    let message = refused["errors"][0]["message"].as_str().unwrap();
    assert!(message.contains("inner_diameter 120") && message.contains("outer_diameter 100"), "{refused}");

    // Exactly one of the two: both, or neither, is refused naming both fields.
    let mut both = by_diameter.clone();
    both["hole"]["radius"] = json!(8);
    let refused = problem(app.post_json("/api/v1/deburr", &both).await, 422).await;
    let message = refused["errors"][0]["message"].as_str().unwrap();
    assert!(message.contains("radius") && message.contains("diameter"), "{refused}");
    let mut neither = by_diameter.clone();
    neither["workpiece"].as_object_mut().unwrap().remove("outer_diameter");
    let refused = problem(app.post_json("/api/v1/deburr", &neither).await, 422).await;
    let message = refused["errors"][0]["message"].as_str().unwrap();
    assert!(message.contains("outer_radius") && message.contains("outer_diameter"), "{refused}");
    let mut both_tube = by_diameter.clone();
    both_tube["workpiece"]["inner_radius"] = json!(30);
    let refused = problem(app.post_json("/api/v1/deburr", &both_tube).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "workpiece.inner_diameter", "{refused}");
}
