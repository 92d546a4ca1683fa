//! Re-segmenting a CAM program over HTTP: a dense circle loses its short blocks, every other line
//! stays byte for byte, the new path stays within the chord error of the old, `rs274` runs both,
//! the same as a job, and bad programs are refused naming the field and the line.

use serde_json::{Value, json};

use kerf_tests::{TestApp, external_program, finished, json_with, poll_job, problem, rs274_moves};

/// A 0.01 mm-step program of a 200 mm circle at 6000 mm/min, between a tool change, spindle,
/// coolant, comments and rapids, and a second tool that drills one hole.
fn dense_circle_program() -> String {
    let mut text = String::from(
        "%\nO1234 (DENSE CIRCLE FROM CAM)\nG21 G17 G90 G40 G49 G80 G94\nT1 M06\nG00 G43 H1 Z25.\nS8000 M03\nM08\n\
         (CONTOUR)\nG00 X100. Y0.\nG00 Z2.\nG01 Z-1. F300\n",
    );
    let steps = (std::f64::consts::TAU * 100.0 / 0.01).round() as usize;
    for k in 1..=steps {
        let angle = std::f64::consts::TAU * k as f64 / steps as f64;
        let feed = if k == 1 { " F6000" } else { "" };
        text.push_str(&format!("X{:.4} Y{:.4}{feed}\n", 100.0 * angle.cos(), 100.0 * angle.sin()));
    }
    text.push_str(
        "G00 Z25.\nM09\nM05\n(SECOND TOOL)\nT2 M06\nG00 G43 H2 Z25.\nS3000 M03\nG00 X0. Y0.\nG00 Z2.\n\
         G01 Z-5. F100\nG00 Z25.\nM05\nM30\n%\n",
    );
    text
}

fn distance(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// Distance from `p` to the segment `a`–`b`.
fn to_segment(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let length = ab.iter().map(|v| v * v).sum::<f64>();
    let t =
        if length > 0.0 { (ab.iter().zip(&ap).map(|(x, y)| x * y).sum::<f64>() / length).clamp(0.0, 1.0) } else { 0.0 };
    distance(p, &[a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]])
}

/// Lines that are not straight feed blocks (`G01` or a bare `X…`), in order.
fn other_lines(program: &str) -> Vec<&str> {
    program.lines().filter(|l| !(l.starts_with("G01 X") || l.starts_with('X'))).collect()
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn a_dense_circle_loses_its_short_blocks_within_the_chord_error() {
    if external_program("rs274", "the LinuxCNC G-code check").is_none() {
        return;
    }
    let app = TestApp::spawn().await;
    let source = dense_circle_program();
    let body = json!({"program": source, "block_time_ms": 4});
    let answer = json_with(app.post_json("/api/v1/resegment", &body).await, 200).await;
    let before = &answer["before"];
    let after = &answer["after"];
    assert!(before["short_blocks"].as_u64().unwrap() > 60_000, "{answer}");
    assert_eq!(after["short_blocks"], 0, "{answer}");
    assert!(after["blocks"].as_u64().unwrap() < 2_000, "{answer}");
    assert!(after["estimated_time_s"].as_f64().unwrap() < before["estimated_time_s"].as_f64().unwrap() / 5.0);
    assert_eq!(answer["runs"], 1, "{answer}");
    let chord_error = answer["chord_error"].as_f64().unwrap();
    let max_deviation = answer["max_deviation"].as_f64().unwrap();
    assert!(chord_error > 0.0 && max_deviation <= chord_error + 1e-9, "{answer}");

    let response = app.client.post(app.url("/api/v1/resegment?format=gcode")).json(&body).send().await.unwrap();
    assert_eq!(response.status(), 200);
    let program = response.text().await.unwrap();
    // Rapids, tool changes, spindle, coolant and comments: the same lines in the same order.
    assert_eq!(other_lines(&program), other_lines(&source));

    let old = rs274_moves(&source, app.directory(), "resegment_old").expect("rs274 present");
    let new = rs274_moves(&program, app.directory(), "resegment_new").expect("rs274 present");
    let rapids = |moves: &[(bool, [f64; 3])]| moves.iter().filter(|m| !m.0).map(|m| m.1).collect::<Vec<_>>();
    assert_eq!(rapids(&new), rapids(&old));
    let old_path: Vec<[f64; 3]> = old.iter().filter(|m| m.0).map(|m| m.1).collect();
    let new_path: Vec<[f64; 3]> = new.iter().filter(|m| m.0).map(|m| m.1).collect();
    assert!(new_path.len() * 30 < old_path.len(), "{} blocks of {}", new_path.len(), old_path.len());
    // Every point of the new path (each block sampled) is within the chord error of the old
    // path, plus the rounding of the written coordinates (0.5e-4 per axis).
    let bound = chord_error + 1e-4;
    let mut near = 0;
    for pair in new_path.windows(2) {
        for step in 0..=8 {
            let t = f64::from(step) / 8.0;
            let p = [0, 1, 2].map(|axis| pair[0][axis] + t * (pair[1][axis] - pair[0][axis]));
            // Both paths run the same way: the nearest old segment is at or after the last one.
            let window = near..(near + 2_000).min(old_path.len() - 1);
            let (index, gap) = window
                .map(|i| (i, to_segment(&p, &old_path[i], &old_path[i + 1])))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(gap <= bound, "{p:?} is {gap} mm off the old path (chord error {chord_error})");
            near = index;
        }
    }
}

/// The re-segmented program of `body` in `dialect`.
async fn reposted(app: &TestApp, body: &Value, dialect: &str) -> String {
    let url = app.url(&format!("/api/v1/resegment?format=gcode&dialect={dialect}"));
    let response = app.client.post(url).json(body).send().await.unwrap();
    assert_eq!(response.status(), 200, "{dialect}");
    response.text().await.unwrap()
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
#[cfg_attr(
    not(kerf_has_nc_gcode_interpreter),
    ignore = "nc-gcode-interpreter not found: pip install -r tests/requirements.txt"
)]
async fn a_fanuc_program_reposted_for_linuxcnc_and_sinumerik_moves_the_same() {
    let app = TestApp::spawn().await;
    let source = dense_circle_program();
    let body = json!({"program": source, "block_time_ms": 4});
    let fanuc = reposted(&app, &body, "fanuc").await;
    let linuxcnc = reposted(&app, &body, "linuxcnc").await;
    assert!(linuxcnc.starts_with("(DENSE CIRCLE FROM CAM)\nG21 G17 G90 G40 G49 G80 G94\nT1 M06\n"), "{linuxcnc}");
    assert!(!linuxcnc.contains('%') && !linuxcnc.contains("O1234"), "LinuxCNC reads O words as subroutines");
    let want = rs274_moves(&fanuc, app.directory(), "reposted_fanuc").expect("rs274 present");
    let got = rs274_moves(&linuxcnc, app.directory(), "reposted_linuxcnc").expect("rs274 present");
    assert!(want.len() > 100, "{} moves", want.len());
    assert_eq!(got, want, "the LinuxCNC program moves as the Fanuc one");

    // The machine's post writes the program when the request names one.
    let machine = json!({"block_time_ms": 4, "max_feed": 10000, "dialect": "sinumerik"});
    assert!(app.put_json("/api/v1/machines/840d", &machine).await.status().is_success());
    let on_machine = json!({"program": source, "machine": "840d"});
    let response = app.client.post(app.url("/api/v1/resegment?format=gcode")).json(&on_machine).send().await.unwrap();
    assert_eq!(response.status(), 200);
    let sinumerik = response.text().await.unwrap();
    assert_eq!(sinumerik, reposted(&app, &body, "sinumerik").await);
    assert!(
        sinumerik
            .starts_with("; DENSE CIRCLE FROM CAM\nG71 G17 G90 G40 G94\nT1 D1\nM6\nG0 Z25.\nS8000 M3\nM8\n; CONTOUR\n"),
        "{sinumerik}"
    );
    assert!(sinumerik.contains("\n; SECOND TOOL\nT2 D1\nM6\nG0 Z25.\nS3000 M3\n"), "{sinumerik}");
    assert!(!sinumerik.contains('(') && !sinumerik.contains("G01") && !sinumerik.contains('%'), "{sinumerik}");
    let got = crate::posts::moves_of(&crate::posts::python(crate::posts::SINUMERIK, &sinumerik, "reposted_sinumerik"));
    // The reader starts at 0, 0, 0 and counts `G0 Z25.` after the tool change as a move, as rs274 does.
    assert_eq!(got.len(), want.len(), "move count");
    for (index, (got, want)) in got.iter().zip(&want).enumerate() {
        assert_eq!(got.0, want.0, "move {index} kind");
        assert!((0..3).all(|k| (got.1[k] - want.1[k]).abs() <= 1e-4), "move {index}: {got:?} vs {want:?}");
    }

    // A line with no counterpart on the 840D is refused naming it; in the program's own post it stays.
    let dwell = json!({"program": "G21 G90\nG00 X0 Y0 Z1\nG04 P500\nM30\n", "block_time_ms": 4});
    let url = app.url("/api/v1/resegment?format=gcode&dialect=sinumerik");
    let answer = problem(app.client.post(url).json(&dwell).send().await.unwrap(), 422).await;
    assert_eq!(answer["errors"][0]["path"], "program", "{answer}");
    assert!(answer.to_string().contains("line 3: G04"), "{answer}");
    assert!(reposted(&app, &dwell, "fanuc").await.contains("\nG04 P500\n"));
    let url = app.url("/api/v1/resegment?format=gcode&dialect=heidenhain");
    let answer = problem(app.client.post(url).json(&dwell).send().await.unwrap(), 422).await;
    assert_eq!(answer["errors"][0]["path"], "program", "{answer}");
    assert!(answer.to_string().contains("line 3: G04"), "{answer}");
}

/// The feed points of the dense circle program as written: the plunge's end, then every point.
fn dense_circle_path(source: &str) -> Vec<[f64; 3]> {
    let mut path = vec![[100.0, 0.0, -1.0]];
    for line in source.lines().filter(|l| l.starts_with('X')) {
        let mut point = [0.0, 0.0, -1.0];
        for word in line.split(' ') {
            match word.split_at(1) {
                ("X", value) => point[0] = value.parse().unwrap(),
                ("Y", value) => point[1] = value.parse().unwrap(),
                _ => {}
            }
        }
        path.push(point);
    }
    path
}

#[tokio::test(flavor = "multi_thread")]
async fn a_dense_circle_reposted_as_klartext_moves_within_the_chord_error() {
    let app = TestApp::spawn().await;
    let source = dense_circle_program();
    let body = json!({"program": source, "block_time_ms": 4});
    let answer = json_with(app.post_json("/api/v1/resegment", &body).await, 200).await;
    let chord_error = answer["chord_error"].as_f64().unwrap();
    let klartext = reposted(&app, &body, "heidenhain").await;
    assert!(
        klartext.starts_with(
            "0 BEGIN PGM KERF1234 MM\n1 ; DENSE CIRCLE FROM CAM\n2 TOOL CALL 1 Z\n3 L Z+25.0000 R0 FMAX\n"
        ),
        "{klartext}"
    );
    assert!(klartext.contains("\n; SECOND TOOL\n") || klartext.contains(" ; SECOND TOOL\n"), "{klartext}");
    let moves = crate::posts::read_klartext("resegment_klartext", &klartext);
    // The rapids: the same end points in the same order (a block that carries an M function where
    // the tool already is goes nowhere).
    let mut rapids: Vec<[f64; 3]> = Vec::new();
    for (feed, point) in &moves {
        if !feed && rapids.last() != Some(point) {
            rapids.push(*point);
        }
    }
    let want = [
        [0.0, 0.0, 25.0],
        [100.0, 0.0, 25.0],
        [100.0, 0.0, 2.0],
        [100.0, 0.0, 25.0],
        [0.0, 0.0, 25.0],
        [0.0, 0.0, 2.0],
    ];
    assert_eq!(rapids[..want.len()], want, "{rapids:?}");
    // The circle: every point of the new blocks within the chord error of the program's path.
    let old_path = dense_circle_path(&source);
    let new_path: Vec<[f64; 3]> = moves.iter().filter(|m| m.0 && m.1[2] == -1.0).map(|m| m.1).collect();
    assert_eq!(new_path.len() as u64, answer["after"]["blocks"].as_u64().unwrap() - 1, "{}", answer["after"]);
    let bound = chord_error + 1e-4;
    let mut near = 0;
    for pair in new_path.windows(2) {
        for step in 0..=8 {
            let t = f64::from(step) / 8.0;
            let p = [0, 1, 2].map(|axis| pair[0][axis] + t * (pair[1][axis] - pair[0][axis]));
            let window = near..(near + 2_000).min(old_path.len() - 1);
            let (index, gap) = window
                .map(|i| (i, to_segment(&p, &old_path[i], &old_path[i + 1])))
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap();
            assert!(gap <= bound, "{p:?} is {gap} mm off the old path (chord error {chord_error})");
            near = index;
        }
    }
    assert!(near + 2_100 > old_path.len(), "the new blocks run round the whole circle");
    // The second tool drills at 100 mm/min after its own tool call.
    assert!(klartext.contains(" TOOL CALL 2 Z S8000\n"), "{klartext}");
    assert!(klartext.contains(" L Z-5.0000 R0 F100\n"), "{klartext}");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_program_is_resegmented_as_a_job() {
    let app = TestApp::spawn().await;
    let mut source = String::from("G21 G17 G90\nG00 X0 Y0 Z1\nG01 Z0 F500\n");
    for k in 1..=2000 {
        let feed = if k == 1 { " F3000" } else { "" };
        let x = f64::from(k) * 0.01;
        source.push_str(&format!("G01 X{x:.3} Y{:.3}{feed}\n", (x / 5.0).sin() * 3.0));
    }
    source.push_str("G00 Z10\nM30\n");
    let job =
        json!({"name": "resegment", "operations": [{"operation": "resegment", "program": source, "block_time_ms": 2}]});
    let created = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await;
    let id = created["id"].as_i64().unwrap();
    let done = poll_job(&app.client, &app.url(""), id, 120, finished).await;
    assert_eq!(done["status"], "done", "{done}");
    let result = &done["results"][0]["result"];
    assert!(result["before"]["short_blocks"].as_u64().unwrap() > 1000, "{result}");
    assert_eq!(result["after"]["short_blocks"], 0, "{result}");
    let program = app.get_text(&format!("/api/v1/jobs/{id}/gcode?operation=0"), 200).await;
    assert!(program.starts_with("G21 G17 G90\nG00 X0 Y0 Z1\nG01 Z0 F500\nG01 X"), "{program}");
    assert!(program.ends_with("\nG00 Z10\nM30\n"), "{program}");
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_programs_are_refused_naming_the_field_and_line() {
    let app = TestApp::spawn().await;
    let cases: [(Value, &str, &str); 6] = [
        (json!({"program": "G00 X0 Y0\nG01 X1 Y( F100\n", "block_time_ms": 4}), "program", "line 2"),
        (json!({"program": "G00 X0 Y0\nG41 D1\n", "block_time_ms": 4}), "program", "line 2"),
        (json!({"program": "G00 X0 Y0\nG01 X1 F100\n"}), "block_time_ms", "block_time_ms"),
        (json!({"program": "  \n", "block_time_ms": 4}), "program", "empty"),
        (json!({"program": "G01 X1 F100\n", "block_time_ms": 4, "margin": 0.5}), "margin", "at least 1"),
        (
            json!({"program": "G01 X1 F100\n", "block_time_ms": 4, "program_dialect": "heidenhain"}),
            "program_dialect",
            "RS274",
        ),
    ];
    for (body, field, words) in cases {
        let answer = problem(app.post_json("/api/v1/resegment", &body).await, 422).await;
        assert_eq!(answer["errors"][0]["path"], field, "{answer}");
        assert!(answer.to_string().contains(words), "{answer}");
    }
    let answer =
        problem(app.post_json("/api/v1/resegment", &json!({"program": "G01 X1", "machine": "nowhere"})).await, 404)
            .await;
    assert_eq!(answer["errors"][0]["path"], "machine", "{answer}");
    let answer = problem(app.post_json("/api/v1/resegment", &json!({"program": 5})).await, 400).await;
    assert!(answer.to_string().contains("program"), "{answer}");
}
