//! Arcs as G02/G03: segment circles and arcs, contour loops and round joins,
//! engagement arc segments, written with `?arcs=g2g3` (or a machine's `arcs`, or a job's
//! `[output] arcs`), through LinuxCNC's `rs274` in both dialects: every `ARC_FEED` ends where the
//! chord program's run of `STRAIGHT_FEED`s ends, and everything else is the same move.

use kerf_tests::{TestApp, external_program, finished, json_with, poll_job, problem, rs274_moves};
use serde_json::{Value, json};

type Moves = Vec<(bool, [f64; 3])>;

fn same_point(a: &[f64; 3], b: &[f64; 3]) -> bool {
    (0..3).all(|axis| (a[axis] - b[axis]).abs() <= 1e-4)
}

/// The program of `body` at `path` with the extra query `query`.
async fn program(app: &TestApp, path: &str, query: &str, body: &Value) -> String {
    app.post_text(&format!("{path}?format=gcode&{query}"), body, 200).await
}

/// Asserts that the arc program's moves are the chord program's with each run of chords replaced
/// by arcs ending where the run ends: walking both lists, every move of the arc program (rapid,
/// straight or arc end) is found in order among the chord program's moves, rapids and straight
/// moves at the next position, and the two end at the same place. Returns how many arc blocks
/// the program had.
///
/// Under the block-time rule (`exact_lines` false) the straight move before an arc may end at
/// the arc's exact start where the chord program lengthened it to the first chord vertex: such
/// a move is only checked to be a feed move whose end lies within the chord tolerance of the
/// chord program's next end point.
fn assert_arcs_replace_chords(
    label: &str,
    arcs_program: &str,
    chords: &Moves,
    arcs: &Moves,
    exact_lines: bool,
) -> usize {
    let arc_blocks = arcs_program.lines().filter(|l| l.starts_with("G02") || l.starts_with("G03")).count();
    let mut at = 0;
    let is_arc = |line: &str| line.starts_with("G02") || line.starts_with("G03");
    let lines: Vec<&str> = arcs_program.lines().filter(|l| l.starts_with("G0")).collect();
    assert_eq!(lines.len(), arcs.len(), "{label}: one move per motion block");
    for (index, (feed, end)) in arcs.iter().enumerate() {
        if is_arc(lines[index]) {
            // The arc skips the chords of its run: its end is a later chord end point, unless
            // it is a piece of a longer arc split in half turns and another arc follows.
            let found = chords[at..].iter().position(|(f, p)| *f && same_point(p, end));
            match found {
                Some(offset) => at += offset + 1,
                // Under the block-time rule the chord program joined the arc's last half chord to
                // the straight move after it: the arc's exact end lies on that move.
                None => assert!(
                    lines.get(index + 1).is_some_and(|next| is_arc(next) || (!exact_lines && next.starts_with("G01"))),
                    "{label}: arc {index} ends at {end:?}, which no chord ends at after move {at}"
                ),
            }
        } else {
            let matches = |(f, p): &(bool, [f64; 3])| {
                let near = exact_lines || !lines.get(index + 1).is_some_and(|next| is_arc(next));
                let close = if near {
                    same_point(p, end)
                } else {
                    (0..3).map(|axis| (p[axis] - end[axis]).powi(2)).sum::<f64>().sqrt() <= 0.5
                };
                *f == *feed && close
            };
            if exact_lines {
                let Some(chord) = chords.get(at) else { panic!("{label}: move {index} beyond the chord program") };
                assert!(matches(chord), "{label}: move {index} {end:?} vs chord move {at} {chord:?}");
                at += 1;
            } else {
                // After an arc whose end the chords do not share, the next straight move is found
                // further on.
                let Some(offset) = chords[at..].iter().position(matches) else {
                    panic!("{label}: move {index} {end:?}: no chord move like it after move {at}")
                };
                at += offset + 1;
            }
        }
    }
    assert_eq!(at, chords.len(), "{label}: both programs end with the same moves");
    arc_blocks
}

async fn check(app: &TestApp, name: &str, path: &str, body: &Value, query: &str, expect_arcs: bool) {
    check_with(app, name, path, body, query, expect_arcs, true).await;
}

async fn check_with(
    app: &TestApp,
    name: &str,
    path: &str,
    body: &Value,
    query: &str,
    expect_arcs: bool,
    exact_lines: bool,
) {
    for dialect in ["fanuc", "linuxcnc"] {
        let chords = program(app, path, &format!("dialect={dialect}&arcs=chords&{query}"), body).await;
        let arcs = program(app, path, &format!("dialect={dialect}&arcs=g2g3&{query}"), body).await;
        let label = format!("{name}_{dialect}");
        let (Some(chord_moves), Some(arc_moves)) = (
            rs274_moves(&chords, app.directory(), &format!("{label}_chords")),
            rs274_moves(&arcs, app.directory(), &format!("{label}_g2g3")),
        ) else {
            return;
        };
        assert!(!chords.contains("G02") && !chords.contains("G03"), "{label}: chords only");
        let count = assert_arcs_replace_chords(&label, &arcs, &chord_moves, &arc_moves, exact_lines);
        assert_eq!(count > 0, expect_arcs, "{label}: arc blocks {count}\n{arcs}");
        if expect_arcs {
            assert!(arc_moves.len() < chord_moves.len(), "{label}: fewer blocks with arcs");
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn arcs_end_where_the_chords_end() {
    if external_program("rs274", "the LinuxCNC G-code check").is_none() {
        return;
    }
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 3})).await;
    // Segment: a full circle (two half turns), a clockwise arc over 270°, an ellipse (chords).
    for (name, curve, arcs) in [
        ("circle", json!({"kind": "circle", "centre": [5, -2, -1], "radius": 20, "start_deg": 30}), true),
        (
            "arc_cw",
            json!({"kind": "arc", "centre": [0, 0], "radius": 12, "start_deg": 10, "end_deg": 100, "direction": "cw"}),
            true,
        ),
        ("ellipse", json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [30, 10], "end_deg": 180}), false),
    ] {
        let body = json!({"curve": curve, "feed": 3000, "block_time_ms": 4, "tool": 3});
        check(&app, &format!("segment_{name}"), "/api/v1/segment", &body, "", arcs).await;
    }
    // Contour: an island with arc loops and round joins on a roughing pass, two layers.
    let contour = json!({
        "tool": 3, "contour": [[0, 0], [80, 0], [80, 60], [50, 60], [40, 40], [30, 60], [0, 60]],
        "side": "outside", "depths": {"top": 0, "bottom": -4, "step": 2},
        "corner_loop": {"style": "arc"}, "feed": 800, "loop_feed": 1500,
        "passes": [{"allowance": 0.5, "join": "round"}, {"allowance": 0}]});
    check(&app, "contour", "/api/v1/contour", &contour, "", true).await;
    check(&app, "contour_centre", "/api/v1/contour", &contour, "reference=centre", true).await;
    let mut blocks = contour.clone();
    blocks["block_time_ms"] = json!(4);
    check_with(&app, "contour_block_time", "/api/v1/contour", &blocks, "", true, false).await;
    // Engagement: a path with a clockwise and a counter-clockwise arc.
    let engagement = json!({
        "tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "path": {"start": [-10, 20], "segments": [
            {"type": "line", "to": [20, 20]},
            {"type": "arc", "to": [40, 20], "center": [30, 20], "dir": "cw"},
            {"type": "arc", "to": [60, 20], "center": [50, 20], "dir": "ccw"},
            {"type": "line", "to": [70, 20]}]},
        "spindle_rpm": 3000, "feed_per_tooth": 0.05, "axial_depth": 2});
    check(&app, "engagement", "/api/v1/engagement", &engagement, "", true).await;
}

#[tokio::test(flavor = "multi_thread")]
async fn the_machine_and_the_job_file_choose_arcs() {
    let app = TestApp::spawn().await;
    let machine = json!({"block_time_ms": 4, "max_feed": 12000, "dialect": "linuxcnc", "arcs": "g2g3"});
    assert_eq!(app.put_json("/api/v1/machines/arcs-hsc", &machine).await.status(), 201);
    let stored = json_with(app.get("/api/v1/machines/arcs-hsc").await, 200).await;
    assert_eq!(stored["arcs"], "g2g3");
    let body = json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 10}, "machine": "arcs-hsc"});
    let by_machine = program(&app, "/api/v1/segment", "", &body).await;
    assert_eq!(by_machine.lines().filter(|l| l.starts_with("G03")).count(), 2, "{by_machine}");
    let overridden = program(&app, "/api/v1/segment", "arcs=chords", &body).await;
    assert!(!overridden.contains("G03"));
    // Without a machine: chords.
    let plain = json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 10}, "feed": 3000, "block_time_ms": 4});
    assert!(!program(&app, "/api/v1/segment", "", &plain).await.contains("G03"));

    // A bad value names the parameter; a machine with a bad one names the field.
    let response =
        app.client.post(app.url("/api/v1/segment?format=gcode&arcs=helix")).json(&plain).send().await.unwrap();
    let body = problem(response, 400).await;
    assert!(body["detail"].as_str().unwrap().contains("arcs"), "{body}");
    let bad = json!({"block_time_ms": 4, "max_feed": 12000, "arcs": "yes"});
    let body = problem(app.put_json("/api/v1/machines/bad-arcs", &bad).await, 400).await;
    assert!(body.to_string().contains("arcs"), "{body}");

    // A job file's [output] arcs.
    let file = "[output]\narcs = \"g2g3\"\ndialect = \"fanuc\"\n\n[[operations]]\noperation = \"segment\"\nfeed = 3000\nblock_time_ms = 4\ncurve = { kind = \"arc\", centre = [0, 0], radius = 10, start_deg = 0, end_deg = 90 }\n";
    let response = app
        .client
        .post(app.url("/api/v1/jobs"))
        .header("content-type", "application/toml")
        .body(file)
        .send()
        .await
        .unwrap();
    let created = json_with(response, 202).await;
    let id = created["id"].as_i64().unwrap();
    let job = poll_job(&app.client, &app.url(""), id, 120, finished).await;
    assert_eq!(job["status"], "done", "{job}");
    let program = app
        .client
        .get(app.url(&format!("/api/v1/jobs/{id}/gcode?operation=0")))
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert_eq!(program.lines().filter(|l| l.starts_with("G03")).count(), 1, "{program}");
    let bad = file.replace("\"g2g3\"", "\"g4\"");
    let response = app
        .client
        .post(app.url("/api/v1/jobs"))
        .header("content-type", "application/toml")
        .body(bad)
        .send()
        .await
        .unwrap();
    let body = problem(response, 400).await;
    assert!(body["detail"].as_str().unwrap().contains("arcs"), "{body}");
}
