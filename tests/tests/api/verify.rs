//! `POST /api/v1/verify` over HTTP: a slot's removed volume with a tool from the table, faults
//! found at their lines, bad requests refused naming their field (nothing stored), removed
//! volumes against a CSG computation by manifold3d (`tests/verify_csg.py`), and a part (and
//! stock) uploaded as STL files.

use std::f64::consts::PI;
use std::io::Write;
use std::process::{Command, Stdio};

use kerf_cases::number;
use kerf_server::state::Limits;
use kerf_tests::{TestApp, external_program, json_with, problem};
use reqwest::multipart::{Form, Part};
use serde_json::{Value, json};

async fn verify(app: &TestApp, body: &Value) -> Value {
    json_with(app.post_json("/api/v1/verify", body).await, 200).await
}

fn slot_program() -> &'static str {
    "G21 G90\nT5 M6\nG0 X0 Y0 Z5\nG1 Z-2 F300\nG1 X50 F600\nG0 Z5\nM30"
}

#[tokio::test(flavor = "multi_thread")]
async fn a_slot_with_a_table_tool_removes_its_volume() {
    let app = TestApp::spawn().await;
    app.register_tool(5, &json!({"kind": "flat", "radius": 5, "holder_diameter": 40})).await;
    let body = json!({
        "program": slot_program(),
        "tools": [5],
        "stock": {"kind": "box", "min": [-20, -20, -10], "max": [70, 20, 0]},
    });
    let answer = verify(&app, &body).await;
    let exact = 2.0 * (10.0 * 50.0 + 25.0 * PI);
    let removed = number(&answer["removed_volume_mm3"]);
    assert!((removed / exact - 1.0).abs() < 0.005, "{removed} against {exact}");
    assert_eq!(answer["ok"], true, "{answer}");
    assert_eq!(answer["resolution"], 0.25);
    assert_eq!(answer["tools"][0]["holder_diameter"], 40.0);
    let lines: Vec<u64> = answer["blocks"].as_array().unwrap().iter().map(|b| b["line"].as_u64().unwrap()).collect();
    assert_eq!(lines, [4, 5]);
    assert_eq!(answer["blocks"][1]["tool"], 5);
    assert_eq!(answer["blocks"][1]["time_s"], 5.0);
    // JSON only: there is no program to write.
    let gcode = app.client.post(app.url("/api/v1/verify?format=gcode")).json(&body).send().await.unwrap();
    problem(gcode, 400).await;
}

#[tokio::test(flavor = "multi_thread")]
async fn faults_are_found_at_their_lines() {
    let app = TestApp::spawn().await;
    // Two tools: T1 faces the part's top at z = −1 and dips 0.2 into it (line 5); T2, a long
    // Ø6 in a Ø30 holder 20 out, takes a pocket down until the holder meets the top (line 10).
    let program = "T1 M6\nG0 X-10 Y0 Z5\nG1 Z-1 F500\nG1 X10\nG1 X12 Z-1.2\nG1 X14 Z-1\nG1 X30\nG0 Z50\n\
                   T2 M6\nG0 X0 Y20 Z5\nG1 Z-12 F200\nG1 Z-24\nG1 X8\nG0 Z50\nM30";
    let answer = verify(
        &app,
        &json!({
            "program": program,
            "tools": [{"number": 1, "kind": "flat", "radius": 5},
                      {"number": 2, "kind": "flat", "radius": 3, "stickout": 20, "flute_length": 20, "holder_diameter": 30}],
            "stock": {"kind": "box", "min": [-5, -4, -40], "max": [25, 30, 0]},
            "part": {"kind": "box", "min": [-5, -4, -40], "max": [25, 4, -1]},
            "allowance": 50,
        }),
    )
    .await;
    let found: Vec<(String, u64)> = answer["findings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| (f["kind"].as_str().unwrap().to_owned(), f["line"].as_u64().unwrap_or(0)))
        .collect();
    let gouge = found.iter().position(|(kind, _)| kind == "gouge").expect("a gouge");
    assert_eq!(found[gouge].1, 5, "{found:?}");
    close_to(&answer["findings"][gouge]["depth"], 0.2);
    let holder = found.iter().position(|(kind, _)| kind == "holder_contact").expect("a holder contact");
    assert_eq!(found[holder].1, 12, "{found:?}");
    assert_eq!(answer["findings"][holder]["tool"], 2);
    close_to(&answer["findings"][holder]["depth"], 4.0);
    assert_eq!(answer["ok"], false);
    // T1 gives no holder: the one the cut took is named; T2 gives its own.
    assert_eq!(
        answer["assumed"],
        json!([
            "T1: the holder face 40.000 mm above the tip and the holder 30.000 mm across assumed (the tool gives no stickout or holder_diameter)"
        ])
    );
}

fn close_to(value: &Value, expected: f64) {
    assert!((number(value) - expected).abs() < 1e-9, "{value} against {expected}");
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_requests_name_their_field() {
    let app = TestApp::spawn().await;
    let jobs_before = json_with(app.get("/api/v1/jobs").await, 200).await;
    let block = json!({"kind": "box", "min": [0, 0, -5], "max": [20, 20, 0]});
    let flat = json!({"kind": "flat", "radius": 2});
    let cases = [
        (
            "a program the reader refuses",
            json!({"program": "G1 X5 Y5 Z-1 F100\nG41 X1", "tools": [flat], "stock": block}),
            422,
            "program",
            "E_GCODE_UNSUPPORTED",
        ),
        (
            "a stock no tool reaches",
            json!({"program": "G0 X100 Y100 Z5\nG1 Z-1 F100\nG1 X150", "tools": [flat], "stock": block}),
            422,
            "stock",
            "E_STOCK",
        ),
        (
            "a resolution over the memory bound",
            json!({"program": "G1 X5 Y5 Z-1 F100", "tools": [flat], "stock": block,
         "resolution": 0.001}),
            422,
            "resolution",
            "E_GRID_MEMORY",
        ),
        (
            "a tool number not in the table",
            json!({"program": "G1 X5 Y5 Z-1 F100", "tools": [7], "stock": block}),
            404,
            "tools",
            "E_NOT_FOUND",
        ),
        (
            "a tube with its bore as wide as itself",
            json!({"program": "G1 X5 Y5 Z-1 F100", "tools": [flat],
         "stock": {"kind": "tube", "start": [0, 0, 0], "end": [0, 0, 10], "outer_radius": 5, "inner_radius": 5}}),
            422,
            "stock.inner_radius",
            "E_INPUT",
        ),
        (
            "a plane stock, which has no bottom",
            json!({"program": "G1 X5 Y5 Z-1 F100", "tools": [flat],
         "stock": {"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "min": [0, 0], "max": [9, 9]}}),
            422,
            "stock.kind",
            "E_INPUT",
        ),
        (
            "a move calling a tool not named",
            json!({"program": "T4 M6\nG1 X5 Y5 Z-1 F100",
         "tools": [{"kind": "flat", "radius": 2, "number": 3}, {"kind": "flat", "radius": 1, "number": 2}], "stock": block}),
            422,
            "tools",
            "E_INPUT",
        ),
        (
            "a share over 1",
            json!({"program": "G1 X5 Y5 Z-1 F100", "tools": [flat], "stock": block, "air_share_limit": 2}),
            422,
            "air_share_limit",
            "E_INPUT",
        ),
    ];
    let mut mismatches = Vec::new();
    for (what, body, status, field, code) in cases {
        let answer = problem(app.post_json("/api/v1/verify", &body).await, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
    }
    assert!(mismatches.is_empty(), "{mismatches:#?}");
    assert_eq!(json_with(app.get("/api/v1/jobs").await, 200).await, jobs_before, "nothing stored");
}

/// A program of G1 moves through `points` (tip positions), with the same polyline for the CSG.
fn polyline_case(tool: &Value, length: f64, points: &[[f64; 3]], stock: ([f64; 3], [f64; 3])) -> (Value, Value) {
    let mut program = format!("G0 X{:.6} Y{:.6} Z5\nF400\n", points[0][0], points[0][1]);
    for p in points {
        program.push_str(&format!("G1 X{:.6} Y{:.6} Z{:.6}\n", p[0], p[1], p[2]));
    }
    let mut path = vec![[points[0][0], points[0][1], 5.0]];
    path.extend_from_slice(points);
    let request = json!({
        "program": program, "tools": [tool], "resolution": 0.05,
        "stock": {"kind": "box", "min": stock.0, "max": stock.1},
    });
    let csg = json!({
        "stock": {"min": stock.0, "max": stock.1},
        "tool": {"kind": tool["kind"], "radius": tool["radius"], "length": length},
        "paths": [path],
    });
    (request, csg)
}

fn csg_removed(python: &std::path::Path, case: &Value) -> f64 {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/verify_csg.py");
    let mut child = Command::new(python)
        .arg(script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("python3 runs");
    child.stdin.take().unwrap().write_all(case.to_string().as_bytes()).unwrap();
    let output = child.wait_with_output().unwrap();
    assert!(output.status.success(), "verify_csg.py: {}", String::from_utf8_lossy(&output.stderr));
    let answer: Value = serde_json::from_slice(&output.stdout).expect("JSON from verify_csg.py");
    number(&answer["removed_mm3"])
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_manifold3d), ignore = "manifold3d not found: pip install -r tests/requirements.txt")]
async fn removed_volumes_agree_with_manifold3d() {
    let python = external_program("python3", "the CSG check of removed volumes").unwrap();
    let app = TestApp::spawn().await;
    let flat = json!({"kind": "flat", "radius": 5});
    let ball = json!({"kind": "ball", "radius": 3});
    let helix: Vec<[f64; 3]> = (0..=60)
        .map(|k| {
            let angle = 3.0 * PI * f64::from(k) / 60.0;
            [8.0 * angle.cos(), 8.0 * angle.sin(), 0.5 - 3.0 * f64::from(k) / 60.0]
        })
        .collect();
    let cases = [
        (
            "flat slot",
            polyline_case(
                &flat,
                20.0,
                &[[0.0, 0.0, -2.0], [50.0, 0.0, -2.0]],
                ([-20.0, -20.0, -10.0], [70.0, 20.0, 0.0]),
            ),
        ),
        (
            "ball ramps",
            polyline_case(
                &ball,
                12.0,
                &[[-5.0, -3.0, 1.0], [30.0, 10.0, -2.0], [40.0, -5.0, -1.0], [20.0, -8.0, -2.5]],
                ([-10.0, -15.0, -8.0], [45.0, 15.0, 0.0]),
            ),
        ),
        ("ball helix", polyline_case(&ball, 12.0, &helix, ([-15.0, -15.0, -8.0], [15.0, 15.0, 0.0]))),
    ];
    for (what, (request, csg)) in cases {
        let simulated = number(&verify(&app, &request).await["removed_volume_mm3"]);
        let independent = csg_removed(&python, &csg);
        assert!(
            (simulated / independent - 1.0).abs() < 0.005,
            "{what}: simulated {simulated} mm³, manifold3d {independent} mm³"
        );
    }
}

/// A binary STL file of `triangles`, each turned so its normal (right-hand rule) points along
/// the outward direction given with it.
fn stl(triangles: &[([[f64; 3]; 3], [f64; 3])]) -> Vec<u8> {
    let mut bytes = vec![0u8; 80];
    bytes.extend_from_slice(&u32::try_from(triangles.len()).unwrap().to_le_bytes());
    for &([a, b, c], outward) in triangles {
        let (u, v) = ([b[0] - a[0], b[1] - a[1], b[2] - a[2]], [c[0] - a[0], c[1] - a[1], c[2] - a[2]]);
        let normal = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]];
        let along: f64 = (0..3).map(|k| normal[k] * outward[k]).sum();
        let corners = if along > 0.0 { [a, b, c] } else { [a, c, b] };
        bytes.extend_from_slice(&[0u8; 12]);
        for corner in corners {
            for coordinate in corner {
                #[allow(clippy::cast_possible_truncation, reason = "STL stores f32; the figures here are exact in it")]
                bytes.extend_from_slice(&(coordinate as f32).to_le_bytes());
            }
        }
        bytes.extend_from_slice(&[0u8; 2]);
    }
    bytes
}

/// A stepped part as an STL file: the L profile 40 wide in x, 10 high for x < 20 and 6 high
/// beyond, extruded 40 along y from y = 0 (its volume 40·(20·10 + 20·6) = 12 800 mm³).
fn stepped_part() -> Vec<u8> {
    // Counter-clockwise in (x, z), so the outward normal of edge p → q is (dz, −dx).
    let profile = [[0.0, 0.0], [40.0, 0.0], [40.0, 6.0], [20.0, 6.0], [20.0, 10.0], [0.0, 10.0]];
    let at = |[x, z]: [f64; 2], y: f64| [x, y, z];
    let mut triangles = Vec::new();
    for (k, &p) in profile.iter().enumerate() {
        let q = profile[(k + 1) % profile.len()];
        let outward = [q[1] - p[1], 0.0, p[0] - q[0]];
        triangles.push(([at(p, 0.0), at(q, 0.0), at(q, 40.0)], outward));
        triangles.push(([at(p, 0.0), at(q, 40.0), at(p, 40.0)], outward));
    }
    // The L cut into four triangles; each cap faces away from the part.
    for [a, b, c] in [[0, 1, 2], [0, 2, 3], [0, 3, 5], [3, 4, 5]] {
        let corners = |y: f64| [at(profile[a], y), at(profile[b], y), at(profile[c], y)];
        triangles.push((corners(0.0), [0.0, -1.0, 0.0]));
        triangles.push((corners(40.0), [0.0, 1.0, 0.0]));
    }
    stl(&triangles)
}

/// Posts `body` with the STL `files` (form part name and bytes) as a multipart form.
async fn verify_form(app: &TestApp, body: &Value, files: Vec<(&'static str, Vec<u8>)>) -> reqwest::Response {
    let mut form = Form::new().part("request", Part::text(body.to_string()).mime_str("application/json").unwrap());
    for (name, bytes) in files {
        form = form.part(name, Part::bytes(bytes).file_name(format!("{name}.stl")));
    }
    app.client.post(app.url("/api/v1/verify")).multipart(form).send().await.unwrap()
}

/// Facing the step's lower level (z = 6, x > 20) with a flat Ø10 in four passes along y;
/// `dip` lowers the third pass (line 7) by that much.
fn step_program(dip: f64) -> String {
    format!(
        "G0 X25 Y-10 Z15\nG0 Z6\nG1 Y50 F1000\nG1 X30\nG1 Y-10\nG1 X35 Z{}\nG1 Y50\nG1 X40 Z6\nG1 Y-10\nG0 Z15\nM30",
        6.0 - dip
    )
}

#[tokio::test(flavor = "multi_thread")]
async fn an_stl_part_is_cut_to_and_a_gouge_into_it_found_at_its_line() {
    let app = TestApp::spawn().await;
    let body = |program: String| {
        json!({
            "program": program,
            "tools": [{"kind": "flat", "radius": 5}],
            "stock": {"kind": "box", "min": [0, 0, 0], "max": [40, 40, 10]},
            "part": {"kind": "mesh"},
        })
    };
    let follows =
        json_with(verify_form(&app, &body(step_program(0.0)), vec![("part", stepped_part())]).await, 200).await;
    assert_eq!(follows["ok"], true, "{follows}");
    for (field, exact) in [("part_volume_mm3", 12_800.0), ("removed_volume_mm3", 20.0 * 40.0 * 4.0)] {
        assert!((number(&follows[field]) / exact - 1.0).abs() < 1e-9, "{field}: {follows}");
    }
    let gouges =
        json_with(verify_form(&app, &body(step_program(0.2)), vec![("part", stepped_part())]).await, 200).await;
    let findings = gouges["findings"].as_array().unwrap();
    assert_eq!(findings.len(), 1, "{gouges}");
    assert_eq!((&findings[0]["kind"], &findings[0]["line"]), (&json!("gouge"), &json!(7)), "{gouges}");
    assert!((number(&findings[0]["depth"]) - 0.2).abs() < 1e-6, "{gouges}");
    // The stock as an STL file too, in the same form: the same answer.
    let block = stl(&[
        ([[0.0, 0.0, 0.0], [40.0, 0.0, 0.0], [40.0, 40.0, 0.0]], [0.0, 0.0, -1.0]),
        ([[0.0, 0.0, 0.0], [40.0, 40.0, 0.0], [0.0, 40.0, 0.0]], [0.0, 0.0, -1.0]),
        ([[0.0, 0.0, 10.0], [40.0, 0.0, 10.0], [40.0, 40.0, 10.0]], [0.0, 0.0, 1.0]),
        ([[0.0, 0.0, 10.0], [40.0, 40.0, 10.0], [0.0, 40.0, 10.0]], [0.0, 0.0, 1.0]),
        ([[0.0, 0.0, 0.0], [40.0, 0.0, 0.0], [40.0, 0.0, 10.0]], [0.0, -1.0, 0.0]),
        ([[0.0, 0.0, 0.0], [40.0, 0.0, 10.0], [0.0, 0.0, 10.0]], [0.0, -1.0, 0.0]),
        ([[0.0, 40.0, 0.0], [40.0, 40.0, 0.0], [40.0, 40.0, 10.0]], [0.0, 1.0, 0.0]),
        ([[0.0, 40.0, 0.0], [40.0, 40.0, 10.0], [0.0, 40.0, 10.0]], [0.0, 1.0, 0.0]),
        ([[0.0, 0.0, 0.0], [0.0, 40.0, 0.0], [0.0, 40.0, 10.0]], [-1.0, 0.0, 0.0]),
        ([[0.0, 0.0, 0.0], [0.0, 40.0, 10.0], [0.0, 0.0, 10.0]], [-1.0, 0.0, 0.0]),
        ([[40.0, 0.0, 0.0], [40.0, 40.0, 0.0], [40.0, 40.0, 10.0]], [1.0, 0.0, 0.0]),
        ([[40.0, 0.0, 0.0], [40.0, 40.0, 10.0], [40.0, 0.0, 10.0]], [1.0, 0.0, 0.0]),
    ]);
    let mut both = body(step_program(0.2));
    both["stock"] = json!({"kind": "mesh"});
    let answer = json_with(verify_form(&app, &both, vec![("part", stepped_part()), ("stock", block)]).await, 200).await;
    assert_eq!(answer["findings"], gouges["findings"]);
    assert_eq!(answer["removed_volume_mm3"], gouges["removed_volume_mm3"]);
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_stl_uploads_are_refused_naming_their_field() {
    let app = TestApp::spawn_with(Limits { max_upload_bytes: 256 * 1024, ..Limits::default() }).await;
    let jobs_before = json_with(app.get("/api/v1/jobs").await, 200).await;
    let body = json!({
        "program": step_program(0.0),
        "tools": [{"kind": "flat", "radius": 5}],
        "stock": {"kind": "box", "min": [0, 0, 0], "max": [40, 40, 10]},
        "part": {"kind": "mesh"},
    });
    let part = stepped_part();
    // Without its last triangle (50 bytes, the count lowered to match).
    let mut open = part[..part.len() - 50].to_vec();
    let count = u32::from_le_bytes(open[80..84].try_into().unwrap()) - 1;
    open[80..84].copy_from_slice(&count.to_le_bytes());
    // Every triangle's second and third corners swapped: the same surface, normals inward.
    let mut inside_out = part.clone();
    for record in inside_out[84..].chunks_exact_mut(50) {
        let (second, third) = (record[24..36].to_vec(), record[36..48].to_vec());
        record[24..36].copy_from_slice(&third);
        record[36..48].copy_from_slice(&second);
    }
    let mut box_part = body.clone();
    box_part["part"] = json!({"kind": "box", "min": [0, 0, 0], "max": [40, 40, 6]});
    let mut raised = body.clone();
    raised["stock"] = json!({"kind": "box", "min": [0, 0, 0], "max": [40, 40, 8]});
    let cases = [
        ("an open mesh", &body, vec![("part", open)], 422, "part", "E_MESH_NOT_CLOSED"),
        ("an inside-out mesh", &body, vec![("part", inside_out)], 422, "part", "E_INPUT"),
        ("a part reaching out of the stock", &raised, vec![("part", part.clone())], 422, "part", "E_INPUT"),
        ("a mesh part without its file", &body, vec![], 422, "part", "E_INPUT"),
        ("a file for a box part", &box_part, vec![("part", part.clone())], 422, "part.kind", "E_INPUT"),
        ("not an STL file", &body, vec![("part", b"not an stl".to_vec())], 422, "part", "E_MESH_FORMAT"),
        ("a file over the upload limit", &body, vec![("part", vec![b' '; 400 * 1024])], 413, "", "E_TOO_LARGE"),
    ];
    let mut mismatches = Vec::new();
    for (what, body, files, status, field, code) in cases {
        let answer = problem(verify_form(&app, body, files).await, status).await;
        if answer["code"] != code || (!field.is_empty() && answer["errors"][0]["path"] != field) {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
    }
    assert!(mismatches.is_empty(), "{mismatches:#?}");
    assert_eq!(json_with(app.get("/api/v1/jobs").await, 200).await, jobs_before, "nothing stored");
}

#[tokio::test(flavor = "multi_thread")]
async fn verify_runs_as_a_job_with_the_same_answer_and_the_spindle_power() {
    let app = TestApp::spawn().await;
    app.register_tool(5, &json!({"kind": "flat", "radius": 5, "flutes": 2})).await;
    json_with(app.put_json("/api/v1/materials/steel", &json!({"kc11": 1800, "mc": 0.25})).await, 201).await;
    json_with(
        app.put_json("/api/v1/machines/mill", &json!({"block_time_ms": 2, "max_feed": 10000, "spindle_power_kw": 0.5}))
            .await,
        201,
    )
    .await;
    // The slot of the solver's spindle-power test: 0.870 kW over the mill's 0.5 at line 5.
    let request = json!({
        "program": "T5 M6\nS10000 M3\nG0 X-10 Y0 Z5\nG0 Z-2\nG1 X50 F600\nG0 Z5\nM30",
        "tools": [5],
        "stock": {"kind": "box", "min": [0, -20, -10], "max": [70, 20, 0]},
        "material": "steel",
        "machine": "mill",
    });
    let answer = verify(&app, &request).await;
    let findings = answer["findings"].as_array().unwrap();
    assert_eq!(findings.len(), 1, "{answer}");
    assert_eq!((&findings[0]["kind"], &findings[0]["line"]), (&json!("spindle_power"), &json!(5)));
    assert!((number(&findings[0]["power_kw"]) / 0.870_376 - 1.0).abs() < 0.005, "{answer}");
    assert_eq!(findings[0]["limit_kw"], 0.5);
    let mut operation = request.clone();
    operation["operation"] = json!("verify");
    let job = json!({"operations": [operation]});
    let id = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await["id"].as_i64().unwrap();
    let done = kerf_tests::poll_job(&app.client, &app.base, id, 120, kerf_tests::finished).await;
    assert_eq!(done["status"], "done", "{done}");
    assert_eq!(done["results"][0]["operation"], "verify");
    assert_eq!(done["results"][0]["result"], answer, "the job answers as the endpoint does");
    // A job file carries no STL file: refused when submitted.
    let mut mesh = operation.clone();
    mesh["part"] = json!({"kind": "mesh"});
    let refused = problem(app.post_json("/api/v1/jobs", &json!({"operations": [mesh]})).await, 400).await;
    assert_eq!(refused["errors"][0]["path"], "operations[0].part.kind", "{refused}");
}
