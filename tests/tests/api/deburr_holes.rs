//! Several holes in one deburr request: `holes` or a `pattern` of `hole`
//! gives one program visiting every hole in a short order, lifting to the clearance plane between
//! them, and an answer with one entry per hole and edge; `edge: both` deburrs both ridges, with a
//! tool change to `inner_tool`; holes pointing down are deburred with the tube turned.

use kerf_tests::{TestApp, finished, json_with, poll_job, problem, rs274_moves};
use serde_json::{Value, json};

/// The tube of these tests: inner and outer radius, mm (axis along +Y through the origin).
const TUBE: (f64, f64) = (15.0, 25.0);

/// A radial round hole of the tube: radius, penetration angle (from +Z about the tube axis,
/// degrees) and position along the axis.
#[derive(Debug, Clone, Copy)]
struct RadialHole {
    radius: f64,
    angle_deg: f64,
    along: f64,
}

/// Asserts that no move of `moves` (rs274's, of the programmed tip) takes the ball centre (tip +
/// `ball`, the ball of the tool in the spindle at that move) through the tube wall. Sampled along
/// every move, the centre is clear when the ball stays out of the tube by more than `tolerance`
/// (0.5 mm: the chamfer the loops cut is less), or inside the bore by as much, or when the centre
/// is within reach of a hole (its distance from the hole's axis below hole radius + ball, on the
/// hole's side) without being in the wall's material itself (the tube between its radii, outside
/// every hole).
fn assert_clear_of_the_wall(label: &str, moves: &[(bool, [f64; 3])], balls: &[f64], holes: &[RadialHole]) {
    let (inner, outer) = TUBE;
    let tolerance = 0.5;
    assert_eq!(moves.len(), balls.len(), "{label}: one ball per move");
    let mut from = moves[0].1;
    for ((_, to), ball) in moves.iter().zip(balls) {
        for step in 0..=20 {
            let s = f64::from(step) / 20.0;
            let c = [
                from[0] + s * (to[0] - from[0]),
                from[1] + s * (to[1] - from[1]),
                from[2] + s * (to[2] - from[2]) + ball,
            ];
            let from_axis = c[0].hypot(c[2]);
            // Distance from each hole's axis, and whether the centre is on that hole's side.
            let reach = |hole: &RadialHole| {
                let t = hole.angle_deg.to_radians();
                let (dx, dz) = (-t.sin(), t.cos());
                let along = c[0] * dx + c[2] * dz;
                let across = (c[0] * dz - c[2] * dx).hypot(c[1] - hole.along);
                (along > 0.0).then_some(across)
            };
            let near = holes.iter().any(|hole| reach(hole).is_some_and(|d| d < hole.radius + ball));
            let in_a_hole = holes.iter().any(|hole| reach(hole).is_some_and(|d| d <= hole.radius + 0.05));
            let in_material = from_axis > inner + 0.05 && from_axis < outer - 0.05 && !in_a_hole;
            let clear = from_axis >= outer + ball - tolerance
                || from_axis <= inner - ball + tolerance
                || (near && !in_material);
            assert!(clear, "{label}: through the wall at {c:?} (ball {ball}, {from_axis:.3} from the axis)");
        }
        from = *to;
    }
}

/// Runs of feed moves between traverses: one per loop.
fn feed_runs(moves: &[(bool, [f64; 3])]) -> usize {
    let mut runs = 0;
    let mut in_run = false;
    for (feed, _) in moves {
        if *feed && !in_run {
            runs += 1;
        }
        in_run = *feed;
    }
    runs
}

/// The ball radius in the spindle at each move rs274 reports, from the program's tool changes
/// (`T n M06`) and the radii of `tools`: rs274 reports one move per motion line (the length
/// offset's `G00 G43` too), in order.
fn balls_per_move(program: &str, tools: &[(u32, f64)]) -> Vec<f64> {
    let mut ball = 0.0;
    let mut balls = Vec::new();
    for line in program.lines() {
        if let Some(number) = line.strip_prefix('T').and_then(|rest| rest.strip_suffix(" M06")) {
            let number: u32 = number.parse().unwrap();
            ball = tools.iter().find(|(n, _)| *n == number).unwrap().1;
        }
        if ["G00 ", "G01 ", "G02 ", "G03 "].iter().any(|start| line.starts_with(start)) {
            balls.push(ball);
        }
    }
    balls
}

fn four_along() -> Value {
    json!({"tool": 7, "edge": "outer", "cut_amount": 0.3,
           "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
           "hole": {"shape": "round", "radius": 5}, "pattern": {"pitch": 30, "count": 4}})
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
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
        let program = app.post_text(&url, &four_along(), 200).await;
        assert_eq!(program.matches("M06").count(), 1, "one tool for every hole");
        let Some(moves) = rs274_moves(&program, app.directory(), &format!("holes_{dialect}")) else { return };
        assert_eq!(feed_runs(&moves), 4, "{dialect}: four loops");
        let holes: Vec<RadialHole> =
            (0..4).map(|i| RadialHole { radius: 5.0, angle_deg: 0.0, along: 30.0 * f64::from(i) }).collect();
        assert_clear_of_the_wall(dialect, &moves, &balls_per_move(&program, &[(7, 3.0)]), &holes);
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

fn around(angles: &[f64]) -> Value {
    json!({"tool": 7, "edge": "outer", "cut_amount": 0.3,
           "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
           "hole": {"shape": "round", "radius": 5}, "pattern": {"around_deg": angles}})
}

/// Four holes around the tube at 0°, 90°, 180° and 270°: four closed loops, the one pointing down
/// deburred with the tube turned (an `M00` to turn it), and no move through the wall, in both
/// dialects. The same holes listed in `holes` give the same loops.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn four_holes_around_the_tube_are_four_loops_clear_of_the_wall() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let request = around(&[0.0, 90.0, 180.0, 270.0]);
    let answer = json_with(app.post_json("/api/v1/deburr", &request).await, 200).await;
    let holes = answer["holes"].as_array().expect("holes");
    assert_eq!(holes.len(), 4);
    let mut angles: Vec<f64> = holes.iter().map(|h| h["penetration_angle_deg"].as_f64().unwrap()).collect();
    angles.sort_by(f64::total_cmp);
    assert_eq!(angles, [0.0, 90.0, 180.0, 270.0]);
    for hole in holes {
        let points = hole["points"].as_array().unwrap();
        assert_eq!(
            points.first().unwrap()["centre"],
            points.last().unwrap()["centre"],
            "closed loop: {}",
            hole["index"]
        );
        // Only the hole pointing down is turned up.
        let down = hole["penetration_angle_deg"] == 180.0;
        assert_eq!(hole["turned"].as_bool().unwrap_or(false), down, "{}", hole["index"]);
    }
    assert_eq!(answer["visiting_order"]["turns"], 1);
    let listed_holes = [0, 90, 180, 270].map(|a| json!({"shape": "round", "radius": 5, "penetration_angle_deg": a}));
    let listed = json!({"tool": 7, "edge": "outer", "cut_amount": 0.3, "workpiece": request["workpiece"],
        "holes": listed_holes});
    let again = json_with(app.post_json("/api/v1/deburr", &listed).await, 200).await;
    assert_eq!(again["holes"].as_array().unwrap().len(), 4);
    for (first, second) in holes.iter().zip(again["holes"].as_array().unwrap()) {
        assert_eq!(first["points"], second["points"]);
    }

    let radial: Vec<RadialHole> =
        [0.0, 90.0, 180.0, 270.0].map(|angle_deg| RadialHole { radius: 5.0, angle_deg, along: 0.0 }).to_vec();
    for dialect in ["fanuc", "linuxcnc"] {
        let url = format!("/api/v1/deburr?format=gcode&dialect={dialect}");
        let program = app.post_text(&url, &request, 200).await;
        assert_eq!(program.matches("M06").count(), 1, "{dialect}: one tool");
        assert_eq!(program.lines().filter(|l| *l == "M00").count(), 1, "{dialect}: one stop to turn the tube");
        assert!(program.contains("(TURN THE TUBE 180 DEG ABOUT ITS AXIS"), "{program}");
        let Some(moves) = rs274_moves(&program, app.directory(), &format!("around_{dialect}")) else { return };
        assert_eq!(feed_runs(&moves), 4, "{dialect}: four loops");
        // Turned half a turn the tube shows the same four holes.
        assert_clear_of_the_wall(dialect, &moves, &balls_per_move(&program, &[(7, 3.0)]), &radial);
    }
}

fn both_edges() -> Value {
    json!({"tool": 7, "inner_tool": 8, "edge": "both", "cut_amount": 0.3,
           "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
           "hole": {"shape": "round", "radius": 5}, "pattern": {"around_deg": [0, 90, 270], "pitch": 40, "count": 2}})
}

/// `edge: both` with an `inner_tool`: one entry per hole and edge, the outer ridges with the
/// request's tool and then the inner ones with the inner tool, one tool change between them; the
/// program passes rs274 in both dialects without a move through the wall.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn both_edges_change_to_the_inner_tool_once() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    app.register_tool(8, &json!({"kind": "ball", "radius": 2})).await;
    let answer = json_with(app.post_json("/api/v1/deburr", &both_edges()).await, 200).await;
    let holes = answer["holes"].as_array().expect("holes");
    assert_eq!(holes.len(), 12, "six holes, two edges each");
    assert_eq!(answer["inner_tool"]["radius"], 2.0);
    let edges: Vec<&str> = holes.iter().map(|h| h["edge"].as_str().unwrap()).collect();
    assert_eq!(edges, [["outer"; 6], ["inner"; 6]].concat(), "grouped by tool");
    for hole in holes {
        let inner = hole["edge"] == "inner";
        assert_eq!(hole["tool_field"], if inner { "inner_tool" } else { "tool" });
        let points = hole["points"].as_array().unwrap();
        assert_eq!(points.first().unwrap()["centre"], points.last().unwrap()["centre"]);
    }
    for index in 0..6 {
        for edge in ["outer", "inner"] {
            assert_eq!(holes.iter().filter(|h| h["index"] == index && h["edge"] == edge).count(), 1, "{index} {edge}");
        }
    }
    let order = &answer["visiting_order"];
    assert_eq!(order["tool_changes"], 1);
    assert_eq!(order["loops"].as_array().unwrap().len(), 12);
    assert!(order["travel"].as_f64().unwrap() <= order["request_order_travel"].as_f64().unwrap() + 1e-9, "{order}");

    let holes: Vec<RadialHole> = [0.0, 40.0]
        .into_iter()
        .flat_map(|along| [0.0, 90.0, 270.0].map(|angle_deg| RadialHole { radius: 5.0, angle_deg, along }))
        .collect();
    for dialect in ["fanuc", "linuxcnc"] {
        let url = format!("/api/v1/deburr?format=gcode&dialect={dialect}");
        let program = app.post_text(&url, &both_edges(), 200).await;
        let changes: Vec<&str> = program.lines().filter(|l| l.contains("M06")).collect();
        assert_eq!(changes, ["T7 M06", "T8 M06"], "{dialect}: one change per tool");
        assert_eq!(program.matches("G43 H8 ").count(), 1, "{dialect}");
        let Some(moves) = rs274_moves(&program, app.directory(), &format!("both_{dialect}")) else { return };
        assert_eq!(feed_runs(&moves), 12, "{dialect}: twelve loops");
        let balls = balls_per_move(&program, &[(7, 3.0), (8, 2.0)]);
        assert_clear_of_the_wall(dialect, &moves, &balls, &holes);
    }

    // The inner tool the same as the tool: no change.
    let mut same = both_edges();
    same["inner_tool"] = json!(7);
    let url = "/api/v1/deburr?format=gcode";
    let program = app.client.post(app.url(url)).json(&same).send().await.unwrap().text().await.unwrap();
    assert_eq!(program.matches("M06").count(), 1, "{program}");
    // Without inner_tool, `both` cuts both ridges with the tool.
    same.as_object_mut().unwrap().remove("inner_tool");
    let answer = json_with(app.post_json("/api/v1/deburr", &same).await, 200).await;
    assert_eq!(answer["holes"].as_array().unwrap().len(), 12);
    assert!(answer["holes"].as_array().unwrap().iter().all(|h| h["tool_field"] == "tool"));
    assert_eq!(answer["visiting_order"]["tool_changes"], 0);
}

/// A bad or unknown inner tool is named as `inner_tool`, over HTTP and in a job file; `both` on a
/// block with a bore and `inner_tool` without `both` are 422.
#[tokio::test(flavor = "multi_thread")]
async fn the_inner_tool_is_resolved_and_checked_like_the_tool() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    app.register_tool(8, &json!({"kind": "ball", "radius": 2})).await;
    app.register_tool(9, &json!({"kind": "flat", "radius": 2})).await;
    let mut unknown = both_edges();
    unknown["inner_tool"] = json!(88);
    let body = problem(app.post_json("/api/v1/deburr", &unknown).await, 404).await;
    assert_eq!(body["errors"][0]["path"], "inner_tool", "{body}");
    let mut flat = both_edges();
    flat["inner_tool"] = json!(9);
    let body = problem(app.post_json("/api/v1/deburr", &flat).await, 422).await;
    assert_eq!(body["errors"][0]["path"], "inner_tool", "{body}");
    let mut outer_only = both_edges();
    outer_only["edge"] = json!("outer");
    let body = problem(app.post_json("/api/v1/deburr", &outer_only).await, 422).await;
    assert_eq!(body["errors"][0]["path"], "inner_tool", "{body}");
    let block = json!({"tool": 7, "edge": "both", "cut_amount": 0.3,
        "workpiece": {"kind": "bore_block", "origin": [0, 0, 0], "bore_radius": 20, "face_distance": 40},
        "hole": {"shape": "round", "radius": 5}});
    let body = problem(app.post_json("/api/v1/deburr", &block).await, 422).await;
    assert_eq!(body["errors"][0]["path"], "edge", "{body}");

    let job = json!({"name": "unknown inner", "operations": [{"operation": "deburr", "tool": 7, "inner_tool": 88,
        "edge": "both", "cut_amount": 0.3, "workpiece": both_edges()["workpiece"], "hole": {"shape": "round", "radius": 5}}]});
    let body = problem(app.post_json("/api/v1/jobs", &job).await, 404).await;
    assert_eq!(body["errors"][0]["path"], "operations[0].inner_tool", "{body}");
}

/// A job with `edge: both` and an inner tool from the tool table: the job keeps both tools (it
/// runs on its own, and a later change in the table does not change it), and its one program
/// changes to the inner tool once inside the deburr operation.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn a_job_keeps_its_inner_tool_and_its_program_changes_to_it() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    app.register_tool(8, &json!({"kind": "ball", "radius": 2})).await;
    let mut operation = both_edges();
    operation["operation"] = json!("deburr");
    let job = json!({"name": "both edges", "operations": [operation]});
    let id = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await["id"].as_i64().unwrap();
    // The table's tool 8 changes after submission: the job keeps the one it was resolved with.
    app.register_tool(8, &json!({"kind": "flat", "radius": 2})).await;
    let state = poll_job(&app.client, &app.base, id, 120, finished).await;
    assert_eq!(state["status"], "done", "{state}");
    assert_eq!(
        state["results"][0]["result"]["inner_tool"]["kind"], "ball",
        "{}",
        state["results"][0]["result"]["inner_tool"]
    );
    let program = app.get(&format!("/api/v1/jobs/{id}/program")).await.text().await.unwrap();
    let changes: Vec<&str> = program.lines().filter(|l| l.contains("M06")).collect();
    assert_eq!(changes, ["T7 M06", "T8 M06"], "{program}");
    assert!(program.contains("TOOLS T7 T8"), "{program}");
    assert!(program.contains("(1 DEBURR: T7 THEN T8 "), "{program}");
    rs274_moves(&program, app.directory(), "job_both");
}

/// The holes of a scrambled list are visited in a short order (along the axis here), never longer
/// than the request's; the answer lists them in visiting order.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn scrambled_holes_are_visited_in_a_short_order() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let positions = [0, 120, 30, 150, 60, 90];
    let listed = positions.map(|p| json!({"shape": "round", "radius": 5, "axial_position": p}));
    let body = json!({"tool": 7, "edge": "outer", "cut_amount": 0.3,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "holes": listed});
    let answer = json_with(app.post_json("/api/v1/deburr", &body).await, 200).await;
    let order = &answer["visiting_order"];
    let visited: Vec<i64> =
        answer["holes"].as_array().unwrap().iter().map(|h| h["axial_position"].as_f64().unwrap() as i64).collect();
    assert_eq!(visited, [0, 30, 60, 90, 120, 150], "{order}");
    let indices: Vec<u64> = order["loops"].as_array().unwrap().iter().map(|l| l["index"].as_u64().unwrap()).collect();
    assert_eq!(indices, [0, 2, 4, 5, 1, 3]);
    let (travel, given) = (order["travel"].as_f64().unwrap(), order["request_order_travel"].as_f64().unwrap());
    assert!(travel < given - 100.0, "shorter on a scrambled list: {travel} vs {given}");
    // In order already: the same order and travel.
    let answer = json_with(app.post_json("/api/v1/deburr", &four_along()).await, 200).await;
    let order = &answer["visiting_order"];
    assert_eq!(order["travel"], order["request_order_travel"]);
    let indices: Vec<u64> = order["loops"].as_array().unwrap().iter().map(|l| l["index"].as_u64().unwrap()).collect();
    assert_eq!(indices, [0, 1, 2, 3]);
    // The program visits them in that order: its loops run along +Y.
    let program =
        app.client.post(app.url("/api/v1/deburr?format=gcode")).json(&body).send().await.unwrap().text().await.unwrap();
    let Some(moves) = rs274_moves(&program, app.directory(), "scrambled") else { return };
    let mut stations = Vec::new();
    let mut in_run = false;
    for (feed, to) in &moves {
        if *feed && !in_run {
            stations.push((to[1] / 30.0).round() as i64 * 30);
        }
        in_run = *feed;
    }
    assert_eq!(stations, [0, 30, 60, 90, 120, 150]);
}
