//! Entries: no program plunges at the cutting feed. Every straight feed move
//! down the tool axis of a segment, contour or engagement program runs at the tool's
//! `plunge_feed`, else the machine's, else half the cutting feed; the programs still pass `rs274`.

use kerf_tests::{TestApp, json_with, problem, rs274_moves};
use serde_json::{Value, json};

/// Every plunge of `program` (G01 with X and Y unchanged and Z lower) with its modal feed, and
/// the largest feed of any other G01.
fn plunges(program: &str) -> (Vec<f64>, f64) {
    let (mut at, mut feed) = ([f64::NAN; 3], f64::NAN);
    let (mut found, mut cutting) = (Vec::new(), 0.0_f64);
    for line in program.lines().filter(|l| l.starts_with("G0")) {
        let word = |axis: char| line.split_whitespace().find_map(|w| w.strip_prefix(axis)?.parse::<f64>().ok());
        if let Some(f) = word('F') {
            feed = f;
        }
        let to = [word('X').unwrap_or(at[0]), word('Y').unwrap_or(at[1]), word('Z').unwrap_or(at[2])];
        if line.starts_with("G01") {
            if to[0] == at[0] && to[1] == at[1] && to[2] < at[2] {
                found.push(feed);
            } else {
                cutting = cutting.max(feed);
            }
        }
        at = to;
    }
    (found, cutting)
}

async fn gcode(app: &TestApp, path: &str, body: &Value) -> String {
    app.post_text(&format!("{path}?format=gcode&dialect=linuxcnc"), body, 200).await
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn plunges_run_at_the_plunge_feed() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3, "plunge_feed": 150})).await;
    app.register_tool(4, &json!({"kind": "flat", "radius": 3})).await;
    let machine = json!({"block_time_ms": 4, "max_feed": 12000, "plunge_feed": 90});
    assert_eq!(app.put_json("/api/v1/machines/plunger", &machine).await.status(), 201);
    let segment = json!({"curve": {"kind": "circle", "centre": [0, 0, -2], "radius": 20}, "feed": 2000,
                         "block_time_ms": 4, "tool": 3});
    let contour = json!({"tool": 3, "contour": [[0, 0], [80, 0], [80, 60], [0, 60]], "side": "outside",
                         "depths": {"top": 0, "bottom": -4, "step": 2}, "feed": 800});
    let engagement = json!({"tool": 3, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
                            "path": [[10, 20], [70, 20]], "spindle_rpm": 3000, "feed": 600, "axial_depth": 2});
    for (name, path, body) in [
        ("segment", "/api/v1/segment", &segment),
        ("contour", "/api/v1/contour", &contour),
        ("engagement", "/api/v1/engagement", &engagement),
    ] {
        // The tool's plunge feed; without it the machine's; without both half the cutting feed.
        let mut on_machine = body.clone();
        on_machine["tool"] = json!(4);
        on_machine["machine"] = json!("plunger");
        let mut plain = body.clone();
        plain["tool"] = json!(4);
        for (variant, request, limit) in
            [("tool", body.clone(), Some(150.0)), ("machine", on_machine, Some(90.0)), ("half", plain, None)]
        {
            let program = gcode(&app, path, &request).await;
            let (found, cutting) = plunges(&program);
            assert!(!found.is_empty(), "{name} {variant}: the program plunges\n{program}");
            let limit = limit.unwrap_or(cutting * 0.5);
            for feed in found {
                assert!(feed <= limit + 1e-9, "{name} {variant}: plunge at F{feed} over {limit}\n{program}");
                assert!(feed < cutting, "{name} {variant}: plunge at the cutting feed F{cutting}");
            }
            rs274_moves(&program, app.directory(), &format!("plunge_{name}_{variant}"));
        }
    }
    // A bad plunge feed names its field.
    let body =
        problem(app.put_json("/api/v1/tools/5", &json!({"kind": "flat", "radius": 3, "plunge_feed": 0})).await, 422)
            .await;
    assert_eq!(body["errors"][0]["path"], "plunge_feed", "{body}");
    let body = problem(
        app.put_json("/api/v1/machines/bad", &json!({"block_time_ms": 4, "max_feed": 1, "plunge_feed": -5})).await,
        422,
    )
    .await;
    assert_eq!(body["errors"][0]["path"], "plunge_feed", "{body}");
    let stored = json_with(app.get("/api/v1/tools/3").await, 200).await;
    assert_eq!(stored["plunge_feed"], 150.0);
}

/// Rest to rest over `length` mm at cruise `speed` mm/s with acceleration `accel` mm/s².
fn rest_to_rest(length: f64, speed: f64, accel: f64) -> f64 {
    if length >= speed * speed / accel { length / speed + speed / accel } else { 2.0 * (length / accel).sqrt() }
}

#[tokio::test(flavor = "multi_thread")]
async fn cycle_time_with_acceleration_rapids_and_tool_change() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3})).await;
    let machine = json!({"block_time_ms": 1, "max_feed": 12000, "max_accel": 500, "rapid_feed": 30000,
                         "tool_change_s": 4});
    assert_eq!(app.put_json("/api/v1/machines/accel", &machine).await.status(), 201);
    // A straight line of 100 mm at 6000 mm/min (100 mm/s): 1 s cruising plus v/a = 0.2 s; the
    // plunge of 5 mm at half the feed and the 5 mm retract are triangles of 2·√(5/500) s.
    let body = json!({"curve": {"kind": "polyline", "points": [[0, 0], [50, 0], [100, 0]]}, "feed": 6000,
                      "machine": "accel", "tool": 3});
    let answer = json_with(app.post_json("/api/v1/segment", &body).await, 200).await;
    let time = &answer["cycle_time"];
    let number = |v: &Value| v.as_f64().unwrap();
    let close = |label: &str, got: f64, want: f64| assert!((got - want).abs() < 1e-9, "{label}: {got} vs {want}");
    close("cutting", number(&time["cutting_s"]), rest_to_rest(100.0, 100.0, 500.0));
    close("air", number(&time["air_s"]), rest_to_rest(5.0, 50.0, 500.0));
    close("rapid", number(&time["rapid_s"]), rest_to_rest(5.0, 500.0, 500.0));
    close("tool change", number(&time["tool_change_s"]), 4.0);
    let parts: f64 = ["cutting_s", "air_s", "rapid_s", "tool_change_s"].iter().map(|k| number(&time[k])).sum();
    close("total", number(&time["total_s"]), parts);
    // Without max_accel there is no cycle time.
    let plain = json!({"curve": {"kind": "polyline", "points": [[0, 0], [100, 0]]}, "feed": 6000, "block_time_ms": 1});
    let answer = json_with(app.post_json("/api/v1/segment", &plain).await, 200).await;
    assert!(answer.get("cycle_time").is_none());

    // A square island: the tool stops at the corners, so the control takes longer than length
    // over feed; loops and leads are air.
    let contour = json!({"tool": 3, "contour": [[0, 0], [40, 0], [40, 40], [0, 40]], "side": "outside",
                         "depths": {"top": 0, "bottom": -2, "step": 2}, "feed": 3000, "machine": "accel"});
    let answer = json_with(app.post_json("/api/v1/contour", &contour).await, 200).await;
    let summary = &answer["summary"];
    let time = &summary["cycle_time"];
    assert!(number(&time["cutting_s"]) > 0.0 && number(&time["air_s"]) > 0.0 && number(&time["rapid_s"]) > 0.0);
    let feed_time = number(&summary["estimated_time_s"]);
    assert!(number(&time["cutting_s"]) + number(&time["air_s"]) > feed_time, "{summary}");
    let parts: f64 = ["cutting_s", "air_s", "rapid_s", "tool_change_s"].iter().map(|k| number(&time[k])).sum();
    close("contour total", number(&time["total_s"]), parts);

    // Bad values name their fields.
    for (field, value) in [
        ("max_accel", json!(0)),
        ("rapid_feed", json!(-1)),
        ("tool_change_s", json!(-2)),
        ("max_jerk", json!(0)),
        ("max_jerk", json!(-5)),
        ("max_jerk", json!(2e9)),
    ] {
        let mut bad = machine.clone();
        bad[field] = value;
        let body = problem(app.put_json("/api/v1/machines/bad", &bad).await, 422).await;
        assert_eq!(body["errors"][0]["path"], field, "{body}");
    }
}

/// Rest to rest over `length` mm at cruise `v` mm/s with acceleration `a` mm/s² and jerk `j`
/// mm/s³ (the S-curve: v/a + a/j to reach v while a is reached, else 2√(v/j)).
fn s_curve_rest_to_rest(length: f64, v: f64, a: f64, j: f64) -> f64 {
    let to_cruise = if v >= a * a / j { v / a + a / j } else { 2.0 * (v / j).sqrt() };
    if length >= v * to_cruise {
        return length / v + to_cruise;
    }
    if length >= 2.0 * a * a * a / (j * j) {
        let k = a * a / j;
        let peak = 0.5 * (-k + (k * k + 4.0 * a * length).sqrt());
        2.0 * (peak / a + a / j)
    } else {
        4.0 * (length / (2.0 * j)).cbrt()
    }
}

/// A machine with `max_jerk`: the straight cut takes the S-curve's closed form, longer than the
/// trapezoid's, and the answer says which jerk it used; `edge: both` with an inner tool counts
/// two tool changes.
#[tokio::test(flavor = "multi_thread")]
async fn a_jerk_limit_takes_the_s_curve() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3})).await;
    let machine = json!({"block_time_ms": 1, "max_feed": 12000, "max_accel": 500, "max_jerk": 5000,
                         "rapid_feed": 30000, "tool_change_s": 4});
    assert_eq!(app.put_json("/api/v1/machines/jerk", &machine).await.status(), 201);
    let stored = json_with(app.get("/api/v1/machines/jerk").await, 200).await;
    assert_eq!(stored["max_jerk"], 5000.0);
    let body = json!({"curve": {"kind": "polyline", "points": [[0, 0], [50, 0], [100, 0]]}, "feed": 6000,
                      "machine": "jerk", "tool": 3});
    let answer = json_with(app.post_json("/api/v1/segment", &body).await, 200).await;
    let time = &answer["cycle_time"];
    let cutting = time["cutting_s"].as_f64().unwrap();
    let expected = s_curve_rest_to_rest(100.0, 100.0, 500.0, 5000.0);
    assert!((cutting - expected).abs() < 1e-9, "{cutting} vs {expected}");
    assert!(cutting > rest_to_rest(100.0, 100.0, 500.0));
    assert_eq!(time["max_jerk"], 5000.0);
    assert!(answer["machine"]["max_jerk"] == 5000.0, "{}", answer["machine"]);

    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    app.register_tool(8, &json!({"kind": "ball", "radius": 2})).await;
    let deburr = json!({"tool": 7, "inner_tool": 8, "edge": "both", "machine": "jerk", "cut_amount": 0.3,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 5}});
    let answer = json_with(app.post_json("/api/v1/deburr", &deburr).await, 200).await;
    assert_eq!(answer["cycle_time"]["tool_change_s"], 8.0, "{}", answer["cycle_time"]);
}

/// Every G01 that goes down in `program`: (from, to, modal feed).
fn descents(program: &str) -> Vec<([f64; 3], [f64; 3], f64)> {
    let (mut at, mut feed) = ([f64::NAN; 3], f64::NAN);
    let mut found = Vec::new();
    for line in program.lines().filter(|l| l.starts_with("G0")) {
        let word = |axis: char| line.split_whitespace().find_map(|w| w.strip_prefix(axis)?.parse::<f64>().ok());
        if let Some(f) = word('F') {
            feed = f;
        }
        let to = [word('X').unwrap_or(at[0]), word('Y').unwrap_or(at[1]), word('Z').unwrap_or(at[2])];
        if line.starts_with("G01") && to[2] < at[2] {
            found.push((at, to, feed));
        }
        at = to;
    }
    found
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn tools_that_do_not_cut_at_the_centre_ramp_into_contour_layers() {
    let app = TestApp::spawn().await;
    app.register_tool(6, &json!({"kind": "flat", "radius": 4, "centre_cutting": false, "plunge_feed": 200})).await;
    assert_eq!(json_with(app.get("/api/v1/tools/6").await, 200).await["centre_cutting"], false);
    // A pocket (the lead point lies in the material) and an island, two layers each.
    for side in ["inside", "outside"] {
        for (ramp_angle, plunge_feed) in [(None, None), (Some(5.0), Some(120.0))] {
            let mut body = json!({"tool": 6, "contour": [[0, 0], [80, 0], [80, 60], [0, 60]], "side": side,
                                  "depths": {"top": 0, "bottom": -6, "step": 3}, "feed": 900});
            if let Some(angle) = ramp_angle {
                body["ramp_angle_deg"] = json!(angle);
            }
            if let Some(feed) = plunge_feed {
                body["plunge_feed"] = json!(feed);
            }
            let (angle, limit) = (ramp_angle.unwrap_or(3.0_f64), plunge_feed.unwrap_or(200.0));
            for dialect in ["fanuc", "linuxcnc"] {
                let url = format!("/api/v1/contour?format=gcode&dialect={dialect}");
                let program = app.post_text(&url, &body, 200).await;
                let label = format!("{side} {dialect} {ramp_angle:?}");
                let below_top: Vec<_> = descents(&program).into_iter().filter(|(_, to, _)| to[2] < 0.0).collect();
                assert!(below_top.len() >= 4, "{label}: each layer ramps down in legs\n{program}");
                for (from, to, feed) in below_top {
                    let run = (to[0] - from[0]).hypot(to[1] - from[1]);
                    assert!(run > 0.0, "{label}: straight down into the material at {to:?}");
                    // 4 decimals in the program: the slope within their rounding.
                    assert!((from[2] - to[2]) <= run * angle.to_radians().tan() + 2e-4, "{label}: {from:?} → {to:?}");
                    assert!(feed <= limit, "{label}: down at F{feed}, above the plunge feed F{limit}");
                }
                rs274_moves(&program, app.directory(), &format!("ramp_{side}_{dialect}"));
            }
        }
    }
    // A centre-cutting tool of the same size plunges (at its plunge feed, straight down).
    app.register_tool(5, &json!({"kind": "flat", "radius": 4, "plunge_feed": 200})).await;
    let body = json!({"tool": 5, "contour": [[0, 0], [80, 0], [80, 60], [0, 60]], "side": "inside",
                      "depths": {"top": 0, "bottom": -6, "step": 3}, "feed": 900});
    let response = app.client.post(app.url("/api/v1/contour?format=gcode")).json(&body).send().await.unwrap();
    let program = response.text().await.unwrap();
    assert!(descents(&program).iter().any(|(from, to, feed)| from[0] == to[0] && from[1] == to[1] && *feed == 200.0));
}

#[tokio::test(flavor = "multi_thread")]
async fn a_request_plunge_feed_wins_and_bad_entries_name_their_field() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3, "plunge_feed": 150})).await;
    let segment = json!({"curve": {"kind": "circle", "centre": [0, 0, -2], "radius": 20}, "feed": 2000,
                         "block_time_ms": 4, "tool": 3, "plunge_feed": 70});
    let engagement = json!({"tool": 3, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
                            "path": [[10, 20], [70, 20]], "spindle_rpm": 3000, "feed": 600, "axial_depth": 2,
                            "plunge_feed": 70});
    let contour = json!({"tool": 3, "contour": [[0, 0], [80, 0], [80, 60], [0, 60]], "side": "outside",
                         "depths": {"top": 0, "bottom": -4, "step": 2}, "feed": 800, "plunge_feed": 70});
    for (path, body) in
        [("/api/v1/segment", &segment), ("/api/v1/engagement", &engagement), ("/api/v1/contour", &contour)]
    {
        let program = gcode(&app, path, body).await;
        let (found, _) = plunges(&program);
        assert!(!found.is_empty() && found.iter().all(|feed| *feed == 70.0), "{path}: {found:?}");
        for (field, value) in [("plunge_feed", json!(0)), ("plunge_feed", json!(-3))] {
            let mut bad = body.clone();
            bad[field] = value;
            let body = problem(app.post_json(path, &bad).await, 422).await;
            assert_eq!(body["errors"][0]["path"], field, "{path}: {body}");
        }
    }
    for angle in [0.0, 60.0] {
        let mut bad = contour.clone();
        bad["ramp_angle_deg"] = json!(angle);
        let body = problem(app.post_json("/api/v1/contour", &bad).await, 422).await;
        assert_eq!(body["errors"][0]["path"], "ramp_angle_deg", "{body}");
    }
    let ball = json!({"kind": "ball", "radius": 3, "centre_cutting": false});
    let body = problem(app.put_json("/api/v1/tools/9", &ball).await, 422).await;
    assert_eq!(body["errors"][0]["path"], "centre_cutting", "{body}");
}

#[tokio::test(flavor = "multi_thread")]
async fn deburr_and_engagement_have_a_cycle_time_too() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3})).await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let machine = json!({"block_time_ms": 1, "max_feed": 12000, "max_accel": 500, "rapid_feed": 30000,
                         "tool_change_s": 4});
    assert_eq!(app.put_json("/api/v1/machines/accel", &machine).await.status(), 201);
    let number = |v: &Value| v.as_f64().unwrap();
    let close = |label: &str, got: f64, want: f64| assert!((got - want).abs() < 1e-9, "{label}: {got} vs {want}");
    let parts =
        |time: &Value| ["cutting_s", "air_s", "rapid_s", "tool_change_s"].iter().map(|k| number(&time[*k])).sum();

    // Engagement: one straight cut of 80 mm at 600 mm/min (10 mm/s) from rest to rest, the
    // plunge in the air at half the feed.
    let engagement = json!({"tool": 3, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
                            "path": [[-10, 20], [70, 20]], "spindle_rpm": 3000, "feed": 600, "axial_depth": 2,
                            "machine": "accel"});
    let answer = json_with(app.post_json("/api/v1/engagement", &engagement).await, 200).await;
    let time = &answer["cycle_time"];
    close("engagement cutting", number(&time["cutting_s"]), rest_to_rest(80.0, 10.0, 500.0));
    assert!(number(&time["air_s"]) > 0.0 && number(&time["rapid_s"]) > 0.0, "{time}");
    close("engagement tool change", number(&time["tool_change_s"]), 4.0);
    close("engagement total", number(&time["total_s"]), parts(time));
    let mut plain = engagement.clone();
    plain.as_object_mut().unwrap().remove("machine");
    assert!(json_with(app.post_json("/api/v1/engagement", &plain).await, 200).await.get("cycle_time").is_none());

    // Deburr: the loop cuts, the leads are air; with accelerations and stops the control takes at
    // least the feed time of the loop.
    let deburr = json!({"tool": 7, "machine": "accel", "edge": "outer", "cut_amount": 0.3, "feed": 400,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 6}});
    let answer = json_with(app.post_json("/api/v1/deburr", &deburr).await, 200).await;
    let time = &answer["cycle_time"];
    let points = answer["points"].as_array().unwrap();
    let loop_length: f64 = points
        .windows(2)
        .map(|pair| {
            let (a, b) = (&pair[0]["centre"], &pair[1]["centre"]);
            (0..3).map(|k| (number(&b[k]) - number(&a[k])).powi(2)).sum::<f64>().sqrt()
        })
        .sum();
    let cutting = number(&time["cutting_s"]);
    assert!(cutting >= loop_length / (400.0 / 60.0) - 1e-9 && cutting < 2.0 * loop_length / (400.0 / 60.0), "{time}");
    assert!(number(&time["air_s"]) > 0.0 && number(&time["rapid_s"]) > 0.0, "{time}");
    close("deburr total", number(&time["total_s"]), parts(time));
}
