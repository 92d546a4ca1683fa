//! Emitted G-code through LinuxCNC's `rs274` interpreter: it must accept every program (both
//! dialects, both references, several jobs) and its feed and rapid end points must equal the JSON
//! answer's moves within 1e-4 mm.

use kerf_tests::{TestApp, assert_moves_match, external_program, json_with, rs274_moves};
use serde_json::{Value, json};

/// The moves the JSON answer describes after the tool change, in `reference` coordinates.
fn json_moves(answer: &Value, reference: &str) -> Vec<(bool, [f64; 3])> {
    let key = if reference == "tip" { "tip" } else { "centre" };
    let point = |v: &Value| {
        let a = v[key].as_array().unwrap();
        [a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap()]
    };
    let mut moves = Vec::new();
    for step in answer["lead_in"].as_array().unwrap() {
        moves.push((step["motion"] == "feed", point(step)));
    }
    for p in answer["points"].as_array().unwrap().iter().skip(1) {
        moves.push((true, point(p)));
    }
    for step in answer["lead_out"].as_array().unwrap() {
        moves.push((step["motion"] == "feed", point(step)));
    }
    moves
}

fn jobs() -> Vec<(&'static str, Value)> {
    let tube = json!({"kind": "tube", "origin": [10, -5, 2], "arrangement_angle_deg": 30, "inner_radius": 30, "outer_radius": 50});
    vec![
        (
            "round_outer_tilted",
            json!({"tool": 7, "workpiece": tube, "hole": {"shape": "round", "radius": 8, "eccentricity": 2, "penetration_angle_deg": 12}, "edge": "outer", "cut_amount": 0.3}),
        ),
        (
            "slot_inner",
            json!({"tool": 9, "workpiece": tube, "hole": {"shape": "slot", "radius": 6, "centre_distance": 16, "eccentricity": -3}, "edge": "inner", "cut_amount": 0.2, "feed": 450}),
        ),
        (
            "rect_block",
            json!({"tool": 7, "workpiece": {"kind": "bore_block", "origin": [0, 0, 0], "arrangement_angle_deg": 90, "bore_radius": 45, "face_distance": 70}, "hole": {"shape": "rounded_rect", "radius": 4, "centre_distance": [20, 30], "eccentricity": 5}, "edge": "inner", "cut_amount": 0.4}),
        ),
        (
            "inline_tool_exact",
            json!({"tool": {"kind": "ball", "radius": 3}, "workpiece": tube, "hole": {"shape": "round", "radius": 10}, "edge": "outer", "cut_amount": 0.5, "method": "exact", "direction": "cw"}),
        ),
    ]
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn programs_pass_rs274_and_match_json() {
    if external_program("rs274", "the LinuxCNC G-code check").is_none() {
        return;
    }
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    app.register_tool(9, &json!({"kind": "ball", "radius": 2, "neck_radius": 1})).await;
    for (name, body) in jobs() {
        let answer = json_with(app.post_json("/api/v1/deburr", &body).await, 200).await;
        for dialect in ["fanuc", "linuxcnc"] {
            for reference in ["tip", "centre"] {
                let url = app.url(&format!("/api/v1/deburr?dialect={dialect}&reference={reference}"));
                let response = app.client.post(url).header("accept", "text/x-gcode").json(&body).send().await.unwrap();
                assert_eq!(response.status(), 200, "{name} {dialect} {reference}");
                assert!(response.headers()["content-type"].to_str().unwrap().starts_with("text/x-gcode"));
                let program = response.text().await.unwrap();
                let label = format!("{name}_{dialect}_{reference}");
                let mut interpreted = rs274_moves(&program, app.directory(), &label).expect("rs274 present");
                // The first two traverses go to the clearance plane (length-offset block, then X Y).
                let expected = json_moves(&answer, reference);
                let first_rapid = interpreted.iter().position(|m| !m.0).unwrap();
                interpreted.drain(..=first_rapid);
                // The last traverse is the program's final return to the clearance plane.
                interpreted.pop();
                assert_moves_match(&label, &interpreted, &expected);
                if name == "inline_tool_exact" {
                    assert!(program.contains("M00"), "an inline tool without a number stops for a manual change");
                }
            }
        }
    }
}
