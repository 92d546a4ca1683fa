//! Several holes in one deburr request (issue 15, item 5): `holes` or a `pattern` of `hole`
//! gives one program visiting every hole, lifting to the clearance plane between them, and an
//! answer with one entry per hole.

use kerf_tests::{TestApp, json_with, problem, rs274_moves};
use serde_json::{Value, json};

fn four_along() -> Value {
    json!({"tool": 7, "edge": "outer", "cut_amount": 0.3,
           "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
           "hole": {"shape": "round", "radius": 5}, "pattern": {"pitch": 30, "count": 4}})
}

#[tokio::test(flavor = "multi_thread")]
async fn a_four_hole_pattern_is_one_program_with_four_closed_loops() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let answer = json_with(app.post_json("/api/v1/deburr", &four_along()).await, 200).await;
    let holes = answer["holes"].as_array().expect("holes");
    assert_eq!(holes.len(), 4);
    for (index, hole) in holes.iter().enumerate() {
        assert_eq!(hole["axial_position"], 30.0 * index as f64);
        let points = hole["points"].as_array().unwrap();
        assert_eq!(points.first().unwrap()["centre"], points.last().unwrap()["centre"], "hole {index}: closed loop");
        // A1 runs along +Y: each loop sits around its own station.
        let y: Vec<f64> = points.iter().map(|p| p["centre"][1].as_f64().unwrap()).collect();
        let mean = y.iter().sum::<f64>() / y.len() as f64;
        assert!((mean - 30.0 * index as f64).abs() < 0.5, "hole {index} at y {mean}");
    }
    // The same holes listed one by one give the same loops.
    let mut listed = four_along();
    let object = listed.as_object_mut().unwrap();
    object.remove("pattern");
    object.remove("hole");
    object.insert(
        "holes".to_owned(),
        json!((0..4).map(|i| json!({"shape": "round", "radius": 5, "axial_position": 30 * i})).collect::<Vec<_>>()),
    );
    let again = json_with(app.post_json("/api/v1/deburr", &listed).await, 200).await;
    for index in 0..4 {
        assert_eq!(again["holes"][index]["points"], holes[index]["points"]);
    }

    for dialect in ["fanuc", "linuxcnc"] {
        let url = format!("/api/v1/deburr?format=gcode&dialect={dialect}");
        let response = app.client.post(app.url(&url)).json(&four_along()).send().await.unwrap();
        assert_eq!(response.status(), 200);
        let program = response.text().await.unwrap();
        assert_eq!(program.matches("M06").count(), 1, "one tool for every hole");
        let Some(moves) = rs274_moves(&program, app.directory(), &format!("holes_{dialect}")) else { return };
        // Runs of feed moves between traverses: one per hole, each back where it began.
        let mut runs: Vec<Vec<[f64; 3]>> = Vec::new();
        let mut last_traverse = [f64::NAN; 3];
        let mut in_run = false;
        for (feed, to) in &moves {
            if *feed {
                if !in_run {
                    runs.push(vec![last_traverse]);
                    in_run = true;
                }
                runs.last_mut().unwrap().push(*to);
            } else {
                in_run = false;
                last_traverse = *to;
            }
        }
        assert_eq!(runs.len(), 4, "{dialect}: four loops");
        // No move goes through the tube wall: sampled along every move, the ball centre (tip + 3)
        // deeper than 0.5 mm into the outer surface lies within the reach of a hole.
        let mut from = moves[0].1;
        for (_, to) in &moves {
            for step in 0..=20 {
                let s = f64::from(step) / 20.0;
                let c = [
                    from[0] + s * (to[0] - from[0]),
                    from[1] + s * (to[1] - from[1]),
                    from[2] + s * (to[2] - from[2]) + 3.0,
                ];
                let from_axis = c[0].hypot(c[2]);
                let near_hole = (0..4).any(|i| c[0].hypot(c[1] - 30.0 * f64::from(i)) < 5.0 + 3.0);
                assert!(from_axis >= 25.0 + 3.0 - 0.5 || near_hole, "{dialect}: through the wall at {c:?}");
            }
            from = *to;
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_hole_lists_name_their_field() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let mut both = four_along();
    both["holes"] = json!([{"shape": "round", "radius": 5}]);
    both.as_object_mut().unwrap().remove("pattern");
    let mut neither = four_along();
    neither.as_object_mut().unwrap().remove("hole");
    neither.as_object_mut().unwrap().remove("pattern");
    let mut bad_radius = neither.clone();
    bad_radius["holes"] =
        json!([{"shape": "round", "radius": 5}, {"shape": "round", "radius": -1, "axial_position": 30}]);
    let mut no_pitch = four_along();
    no_pitch["pattern"] = json!({"count": 2});
    for (body, field) in
        [(both, "holes"), (neither, "hole"), (bad_radius, "holes[1].radius"), (no_pitch, "pattern.pitch")]
    {
        let problem = problem(app.post_json("/api/v1/deburr", &body).await, 422).await;
        assert_eq!(problem["errors"][0]["path"], field, "{problem}");
    }
}
