//! `POST /api/v1/{name}/stock` over HTTP: the stock as a capability's own verification cuts its
//! program, as binary glTF. Deburr's reference case 1: the cut is the answer's verification (same
//! removed volume), the chamfer band is where the deviation is non-zero and within tolerance,
//! playback up to an early line removes less; contour's sample likewise; predict's and engagement's,
//! which have no part, coloured by what the program cut, enclosing the stock less the removed
//! volume, predict's from JSON and from a form with the STL stock; a request without a model
//! (verification off, segment) is refused naming `verification`, and bad asks naming their field.

use kerf_cases::deburr::case_1;
use kerf_cases::{number, with};
use kerf_server::state::Limits;
use kerf_tests::{TestApp, json_with, problem};
use reqwest::multipart::{Form, Part};
use serde_json::{Value, json};

use crate::predict::box_stl_binary;
use crate::verify_mesh::{chunks, values};

/// A GLB's JSON chunk and the `_DEVIATION` values of its one primitive (none without them).
fn read(bytes: &[u8]) -> (Value, Vec<f64>) {
    let (json, bin) = chunks(bytes);
    if json["meshes"][0]["primitives"][0]["attributes"]["_DEVIATION"].is_null() {
        return (json, Vec::new());
    }
    let deviations = values(&json, &bin, "_DEVIATION");
    (json, deviations)
}

async fn stock(app: &TestApp, path: &str, body: &Value) -> (Value, Vec<f64>) {
    let response = app.client.post(app.url(path)).json(body).send().await.unwrap();
    let status = response.status().as_u16();
    let kind = response.headers()["content-type"].to_str().unwrap().to_owned();
    let bytes = response.bytes().await.unwrap();
    assert_eq!((status, kind.as_str()), (200, "model/gltf-binary"), "{}", String::from_utf8_lossy(&bytes));
    read(&bytes)
}

#[tokio::test(flavor = "multi_thread")]
async fn deburr_stock_is_its_verification_cut_with_the_chamfer_band() {
    let app = TestApp::spawn().await;
    let body = with(case_1(), json!({"verification": {"resolution": 0.1}}));
    let answer = json_with(app.post_json("/api/v1/deburr", &body).await, 200).await;
    let verification = &answer["verification"];
    let (json, deviations) = stock(&app, "/api/v1/deburr/stock", &body).await;
    let cut = &json["extras"]["verification"];
    assert_eq!(cut["removed_volume_mm3"], verification["removed_volume_mm3"], "{cut}");
    assert_eq!(cut["findings"], verification["findings"]);
    // The chamfer band: surfaces a cut left within tolerance of the part (a non-zero deviation);
    // the tube elsewhere is the part exactly.
    let tolerance = verification["tolerance"].as_f64().unwrap();
    let band = deviations.iter().filter(|d| d.abs() > 1e-7 && d.abs() <= tolerance).count();
    let untouched = deviations.iter().filter(|d| **d == 0.0).count();
    assert!(band > 100 && untouched > band, "band {band}, untouched {untouched} of {}", deviations.len());
    // Playback: up to the program's tenth line the tube has lost less.
    let (early, _) = stock(&app, "/api/v1/deburr/stock?upto_line=10", &body).await;
    let removed = |cut: &Value| cut["removed_volume_mm3"].as_f64().unwrap_or(0.0);
    assert!(removed(&early["extras"]["verification"]) < removed(cut), "{}", early["extras"]);
}

#[tokio::test(flavor = "multi_thread")]
async fn contour_stock_is_its_verification_cut() {
    let app = TestApp::spawn().await;
    let body = json!({
        "tool": {"kind": "flat", "radius": 3},
        "contour": [[0, 0], [40, 0], [40, 30], [0, 30]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -4, "step": 2},
        "feed": 600,
    });
    let answer = json_with(app.post_json("/api/v1/contour", &body).await, 200).await;
    let (json, deviations) = stock(&app, "/api/v1/contour/stock", &body).await;
    let cut = &json["extras"]["verification"];
    assert_eq!(cut["removed_volume_mm3"], answer["verification"]["removed_volume_mm3"], "{cut}");
    assert!(!deviations.is_empty());
}

/// An inch request's cut stock is in inches, as its answer is: the same solid as the mm
/// request's, scaled by 1/25.4, its `extras` saying `inch`; volumes stay mm³ as their names say.
#[tokio::test(flavor = "multi_thread")]
async fn an_inch_requests_stock_is_in_inches() {
    let app = TestApp::spawn().await;
    let inch = json!({
        "units": "inch",
        "tool": {"kind": "flat", "radius": 0.125},
        "contour": [[0, 0], [1.5, 0], [1.5, 1.25], [0, 1.25]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -0.125, "step": 0.0625},
        "feed": 24,
        "verification": {"resolution": 0.0113},
    });
    // The same contour typed in mm.
    let scaled = json!({
        "tool": {"kind": "flat", "radius": 3.175},
        "contour": [[0, 0], [38.1, 0], [38.1, 31.75], [0, 31.75]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -3.175, "step": 1.5875},
        "feed": 609.6,
        "verification": {"resolution": 0.28702},
    });
    let (mm_json, mm_bin) = glb(&app, "/api/v1/contour/stock", &scaled).await;
    let (inch_json, inch_bin) = glb(&app, "/api/v1/contour/stock", &inch).await;
    assert_eq!(inch_json["extras"]["units"], "inch", "{}", inch_json["extras"]);
    assert_eq!(mm_json["extras"]["units"], "mm", "{}", mm_json["extras"]);
    let position = |json: &Value, bound: &str| -> Vec<f64> {
        let index = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize;
        json["accessors"][index][bound].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect()
    };
    for bound in ["min", "max"] {
        let (inches, millimetres) = (position(&inch_json, bound), position(&mm_json, bound));
        for (a, b) in inches.iter().zip(&millimetres) {
            assert!((a * 25.4 - b).abs() < 1e-3, "{bound}: {inches:?} in against {millimetres:?} mm");
        }
    }
    let (in3, mm3) = (enclosed(&inch_json, &inch_bin), enclosed(&mm_json, &mm_bin));
    // The inch program's coordinates are rounded to 0.0001 in, the mm program's to 0.0001 mm: a
    // ray on a wall may fall either side, hence a relative 1e-3 rather than exactly.
    assert!((in3 * 25.4f64.powi(3) / mm3 - 1.0).abs() < 1e-3, "{in3} in³ against {mm3} mm³");
    let removed = |json: &Value| json["extras"]["verification"]["removed_volume_mm3"].as_f64().unwrap();
    assert!(
        (removed(&inch_json) / removed(&mm_json) - 1.0).abs() < 1e-3,
        "{} against {}",
        inch_json["extras"],
        mm_json["extras"]
    );
}

#[tokio::test(flavor = "multi_thread")]
async fn a_request_without_a_model_is_refused_naming_verification() {
    let app = TestApp::spawn().await;
    let off = with(case_1(), json!({"verification": {"enabled": false}}));
    let refused = problem(app.post_json("/api/v1/deburr/stock", &off).await, 422).await;
    assert!(refused.to_string().contains("verification"), "{refused}");
    let coarse = with(case_1(), json!({"verification": {"resolution": 0}}));
    let refused = problem(app.post_json("/api/v1/deburr/stock", &coarse).await, 422).await;
    assert!(refused.to_string().contains("verification.resolution"), "{refused}");
}

/// The stock of a GLB answer to `path`, as its JSON chunk and binary chunk.
async fn glb(app: &TestApp, path: &str, body: &Value) -> (Value, Vec<u8>) {
    let response = app.client.post(app.url(path)).json(body).send().await.unwrap();
    let status = response.status().as_u16();
    let kind = response.headers()["content-type"].to_str().unwrap().to_owned();
    let bytes = response.bytes().await.unwrap();
    assert_eq!((status, kind.as_str()), (200, "model/gltf-binary"), "{}", String::from_utf8_lossy(&bytes));
    chunks(&bytes)
}

/// The volume the GLB's closed mesh encloses (divergence theorem), mm³.
fn enclosed(json: &Value, bin: &[u8]) -> f64 {
    let positions = values(json, bin, "POSITION");
    let p = |k: f64| {
        let at = 3 * k as usize;
        [positions[at], positions[at + 1], positions[at + 2]]
    };
    values(json, bin, "indices")
        .chunks(3)
        .map(|t| {
            let (a, b, c) = (p(t[0]), p(t[1]), p(t[2]));
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum()
}

/// Colours of a cut stock without a part (linear RGB of sRGB #2ca02c and #b0b0b0).
const CUT: [f64; 4] = [6.0, 90.0, 6.0, 255.0];
const GIVEN: [f64; 4] = [111.0, 111.0, 111.0, 255.0];

/// Checks the stock of a model without a part against the answer's `verification`: the same cut,
/// said to be coloured by what was cut, no deviation, faces of both colours, and the mesh
/// enclosing the stock less the removed volume. The count of cut-coloured vertices.
fn assert_cut_against(json: &Value, bin: &[u8], verification: &Value) -> usize {
    let cut = &json["extras"]["verification"];
    assert_eq!(cut["removed_volume_mm3"], verification["removed_volume_mm3"], "{cut}");
    assert_eq!(cut["findings"], verification["findings"]);
    assert_eq!(json["extras"]["colouring"], "cut", "{}", json["extras"]);
    let attributes = &json["meshes"][0]["primitives"][0]["attributes"];
    assert!(attributes.get("_DEVIATION").is_none(), "{attributes}");
    let colours = values(json, bin, "COLOR_0");
    let count = |colour: [f64; 4]| colours.chunks(4).filter(|c| *c == colour).count();
    let (cut_vertices, given) = (count(CUT), count(GIVEN));
    assert_eq!(cut_vertices + given, colours.len() / 4, "only the two colours");
    assert!(cut_vertices > 0 && given > 0, "cut {cut_vertices}, as given {given}");
    let left = number(&verification["stock_volume_mm3"]) - number(&verification["removed_volume_mm3"]);
    let volume = enclosed(json, bin);
    assert!((volume / left - 1.0).abs() < 1e-5, "the mesh encloses {volume}, the stock less the cut {left}");
    cut_vertices
}

/// A finishing program of a Ø6 ball 0.25 into a box stock (lines 4 to 7 cut).
fn predict_request() -> Value {
    json!({
        "tool": {"kind": "ball", "radius": 3, "flutes": 2,
                 "shape_error": [{"angle_deg": 0, "error": 0.004}, {"angle_deg": 90, "error": 0.009}]},
        "stock": {"kind": "box", "min": [-20, -20, -10], "max": [20, 20, 0.25]},
        "path": {"kind": "gcode", "program": "G21 G90 G17\nS8000 M03\nG0 X-4 Y-3 Z10\nG1 Z0 F1600\nX4\nY-2.5\nX-4\nG0 Z10\nM05\nM30\n"},
        "resolution": 32,
        "verification": {"resolution": 0.2},
    })
}

#[tokio::test(flavor = "multi_thread")]
async fn predict_stock_is_its_verification_cut_coloured_by_what_was_cut() {
    let app = TestApp::spawn().await;
    let body = predict_request();
    let answer = json_with(app.post_json("/api/v1/predict", &body).await, 200).await;
    let (json, bin) = glb(&app, "/api/v1/predict/stock", &body).await;
    assert_cut_against(&json, &bin, &answer["verification"]);
    // Playback: up to the first pass (line 5) less is removed than by the whole program.
    let (early, _) = glb(&app, "/api/v1/predict/stock?upto_line=5", &body).await;
    let removed = |json: &Value| number(&json["extras"]["verification"]["removed_volume_mm3"]);
    assert!(
        removed(&early) > 0.0 && removed(&early) < removed(&json),
        "{} against {}",
        removed(&early),
        removed(&json)
    );
    // Before the plunge nothing is cut: the stock as given, all grey, still said to have no part.
    let (before, bin) = glb(&app, "/api/v1/predict/stock?upto_line=3", &body).await;
    assert_eq!(before["extras"], json!({"colouring": "cut", "units": "mm"}));
    assert!(values(&before, &bin, "COLOR_0").chunks(4).all(|c| c == GIVEN));

    // The same request as a form with the stock's STL file: the same cut as its JSON answer.
    let mut meshed = body.clone();
    meshed["stock"] = json!({"kind": "mesh"});
    let form = || {
        Form::new()
            .part("request", Part::text(meshed.to_string()).mime_str("application/json").unwrap())
            .part("stock", Part::bytes(box_stl_binary([-20.0, -20.0, -10.0], [20.0, 20.0, 0.25])).file_name("box.stl"))
    };
    let response = app.client.post(app.url("/api/v1/predict")).multipart(form()).send().await.unwrap();
    let answer = json_with(response, 200).await;
    let response = app.client.post(app.url("/api/v1/predict/stock")).multipart(form()).send().await.unwrap();
    assert_eq!(response.status().as_u16(), 200);
    let (json, bin) = chunks(&response.bytes().await.unwrap());
    assert_cut_against(&json, &bin, &answer["verification"]);
    assert!(json["extras"]["verification"]["model"].as_str().unwrap().contains("mesh"));
}

#[tokio::test(flavor = "multi_thread")]
async fn predict_stock_refuses_bad_asks_naming_the_field() {
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: 32 << 20, ..Limits::default() }).await;
    let body = predict_request();
    let off = with(body.clone(), json!({"verification": {"enabled": false}}));
    let refused = problem(app.post_json("/api/v1/predict/stock", &off).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "verification", "{refused}");
    let fine = with(body.clone(), json!({"verification": {"resolution": 0.0005}}));
    let refused = problem(app.post_json("/api/v1/predict/stock", &fine).await, 422).await;
    assert_eq!(
        (&refused["code"], &refused["errors"][0]["path"]),
        (&json!("E_GRID_MEMORY"), &json!("verification.resolution"))
    );
    // 400 × 400 rays: a mesh bound of about 190 MB over the 32 MiB answer budget.
    let large = with(body.clone(), json!({"verification": {"resolution": 0.1}}));
    let refused = problem(app.post_json("/api/v1/predict/stock", &large).await, 422).await;
    assert_eq!(
        (&refused["code"], &refused["errors"][0]["path"]),
        (&json!("E_TOO_LARGE_ANSWER"), &json!("verification.resolution"))
    );
    problem(app.post_json("/api/v1/predict/stock?upto_line=first", &body).await, 400).await;
    let mut meshed = body;
    meshed["stock"] = json!({"kind": "mesh"});
    let refused = problem(app.post_json("/api/v1/predict/stock", &meshed).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "stock", "{refused}");
    let response = app.client.post(app.url("/api/v1/predict/stock")).body("G0 X0").send().await.unwrap();
    assert_eq!(response.status().as_u16(), 415);
}

/// The engagement example of docs/spec/api.md cut 2 deep along y = 20 through a 60 × 40 block.
fn engagement_request() -> Value {
    json!({"tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0,0],[60,0],[60,40],[0,40]]},
           "path": [[-10,20],[30,20],[70,20]], "spindle_rpm": 3000, "feed_per_tooth": 0.05, "axial_depth": 2})
}

#[tokio::test(flavor = "multi_thread")]
async fn engagement_stock_is_its_verification_cut_coloured_by_what_was_cut() {
    let app = TestApp::spawn().await;
    let body = engagement_request();
    let answer = json_with(app.post_json("/api/v1/engagement", &body).await, 200).await;
    let (json, bin) = glb(&app, "/api/v1/engagement/stock", &body).await;
    assert_cut_against(&json, &bin, &answer["verification"]);
    // Playback up to the first cutting move's line: only the slot's first half is cut.
    let program = app.post_text("/api/v1/engagement/program?dialect=fanuc", &body, 200).await;
    let first = program.lines().position(|line| line.contains("X30.")).expect("the move to the path's middle") + 1;
    let (early, bin) = glb(&app, &format!("/api/v1/engagement/stock?upto_line={first}"), &body).await;
    let removed = |json: &Value| number(&json["extras"]["verification"]["removed_volume_mm3"]);
    assert!(
        removed(&early) > 0.0 && removed(&early) < removed(&json),
        "{} against {}",
        removed(&early),
        removed(&json)
    );
    assert_cut_against(&early, &bin, &early["extras"]["verification"]);
    let fine = with(body, json!({"verification": {"resolution": 0.0005}}));
    let refused = problem(app.post_json("/api/v1/engagement/stock", &fine).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "verification.resolution", "{refused}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_gltf_validator),
    ignore = "node or the Khronos glTF validator not found: apt-get install npm; npm ci --prefix tests/gltf"
)]
async fn the_khronos_validator_passes_the_stocks_without_a_part() {
    let node = kerf_tests::external_program("node", "the Khronos glTF validator").unwrap();
    let app = TestApp::spawn().await;
    let folder = std::env::temp_dir().join(format!("kerf-own-glb-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    for (name, path, body) in [
        ("predict", "/api/v1/predict/stock", predict_request()),
        ("engagement", "/api/v1/engagement/stock", engagement_request()),
    ] {
        let response = app.client.post(app.url(path)).json(&body).send().await.unwrap();
        assert_eq!(response.status().as_u16(), 200, "{name}");
        let file = folder.join(format!("{name}.glb"));
        std::fs::write(&file, response.bytes().await.unwrap()).unwrap();
        let output = std::process::Command::new(&node)
            .arg(kerf_tests::external::gltf_folder().join("validate.mjs"))
            .arg(&file)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{name}: {}{}",
            String::from_utf8_lossy(&output.stdout),
            String::from_utf8_lossy(&output.stderr)
        );
    }
    std::fs::remove_dir_all(&folder).unwrap();
}
