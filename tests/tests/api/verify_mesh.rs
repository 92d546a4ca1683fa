//! The cut stock of `POST /api/v1/verify` as binary glTF over HTTP: negotiated by `Accept` or
//! `?format=glb`, the mesh encloses the final volume the JSON answer reports within the stock's
//! extent, a deliberate gouge is coloured by a negative deviation where the finding is, playback
//! cuts up to a line, and a mesh over the answer budget is refused naming `resolution`.

use kerf_cases::number;
use kerf_server::state::Limits;
use kerf_tests::{TestApp, json_with, problem};
use serde_json::{Value, json};

/// A GLB's JSON chunk and binary chunk, the container checked on the way.
pub(crate) fn chunks(bytes: &[u8]) -> (Value, Vec<u8>) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!((word(4), word(8)), (2, bytes.len()));
    assert_eq!(&bytes[16..20], b"JSON");
    let length = word(12);
    let json = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
    let at = 20 + length;
    assert_eq!(&bytes[at + 4..at + 8], b"BIN\0");
    (json, bytes[at + 8..at + 8 + word(at)].to_vec())
}

/// The values of accessor `name` of the first primitive (`indices` or an attribute), as f64.
pub(crate) fn values(json: &Value, bin: &[u8], name: &str) -> Vec<f64> {
    let primitive = &json["meshes"][0]["primitives"][0];
    let index = if name == "indices" { &primitive["indices"] } else { &primitive["attributes"][name] };
    let accessor = &json["accessors"][index.as_u64().unwrap() as usize];
    let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap() as usize;
    let bytes = &bin[offset..offset + view["byteLength"].as_u64().unwrap() as usize];
    match accessor["componentType"].as_u64().unwrap() {
        5126 => bytes.chunks(4).map(|b| f64::from(f32::from_le_bytes(b.try_into().unwrap()))).collect(),
        5125 => bytes.chunks(4).map(|b| f64::from(u32::from_le_bytes(b.try_into().unwrap()))).collect(),
        5121 => bytes.iter().map(|&b| f64::from(b)).collect(),
        other => panic!("component type {other}"),
    }
}

/// The faults case of `verify.rs`, first tool only: T1 faces the part's top at z = −1 and dips
/// 0.2 into it between x 10 and 14 (line 5).
fn dip() -> Value {
    json!({
        "program": "T1 M6\nG0 X-10 Y0 Z5\nG1 Z-1 F500\nG1 X10\nG1 X12 Z-1.2\nG1 X14 Z-1\nG1 X30\nG0 Z50\nM30",
        "tools": [{"number": 1, "kind": "flat", "radius": 5}],
        "stock": {"kind": "box", "min": [-5, -4, -10], "max": [25, 30, 0]},
        "part": {"kind": "box", "min": [-5, -4, -10], "max": [25, 30, -1]},
        "resolution": 0.25,
    })
}

async fn glb(app: &TestApp, query: &str, body: &Value) -> (Value, Vec<u8>) {
    let response = app.client.post(app.url(&format!("/api/v1/verify{query}"))).json(body).send().await.unwrap();
    assert_eq!(response.status().as_u16(), 200);
    assert_eq!(response.headers()["content-type"], "model/gltf-binary");
    chunks(&response.bytes().await.unwrap())
}

#[tokio::test(flavor = "multi_thread")]
async fn the_cut_stock_as_glb_matches_the_json_answer_and_shows_the_gouge() {
    let app = TestApp::spawn().await;
    let body = dip();
    let answer = json_with(app.post_json("/api/v1/verify", &body).await, 200).await;
    let response = app
        .client
        .post(app.url("/api/v1/verify"))
        .header("accept", "application/json;q=0.5, model/gltf-binary")
        .json(&body)
        .send()
        .await
        .unwrap();
    assert_eq!(response.headers()["content-type"], "model/gltf-binary");
    let (json, bin) = chunks(&response.bytes().await.unwrap());
    assert_eq!(json["extras"]["verify"], answer, "the JSON answer rides along");
    // Divergence theorem: the closed surface encloses the final volume.
    let positions = values(&json, &bin, "POSITION");
    let triangles = values(&json, &bin, "indices");
    let point = |k: f64| {
        let at = 3 * k as usize;
        [positions[at], positions[at + 1], positions[at + 2]]
    };
    let enclosed: f64 = triangles
        .chunks(3)
        .map(|t| {
            let (a, b, c) = (point(t[0]), point(t[1]), point(t[2]));
            (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
                + a[2] * (b[0] * c[1] - b[1] * c[0]))
                / 6.0
        })
        .sum();
    let reported = number(&answer["final_volume_mm3"]);
    assert!((enclosed / reported - 1.0).abs() < 1e-6, "{enclosed} against {reported}");
    let accessor =
        &json["accessors"][json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize];
    assert_eq!((&accessor["min"], &accessor["max"]), (&json!([-5.0, -4.0, -10.0]), &json!([25.0, 30.0, 0.0])));
    // At the gouge finding's position the top faces carry −0.2 and are red.
    let gouge = answer["findings"].as_array().unwrap().iter().find(|f| f["kind"] == "gouge").expect("a gouge");
    assert_eq!(gouge["line"], 5);
    let (gx, gy) = (number(&gouge["position"][0]), number(&gouge["position"][1]));
    let deviations = values(&json, &bin, "_DEVIATION");
    let normals = values(&json, &bin, "NORMAL");
    let colours = values(&json, &bin, "COLOR_0");
    let near: Vec<usize> = (0..deviations.len())
        .filter(|&k| {
            normals[3 * k + 2] == 1.0 && (positions[3 * k] - gx).abs() < 1.0 && (positions[3 * k + 1] - gy).abs() < 1.0
        })
        .collect();
    let deepest = near.iter().map(|&k| deviations[k]).fold(f64::INFINITY, f64::min);
    assert!((deepest + 0.2).abs() < 1e-5, "deepest deviation near the gouge {deepest}");
    let red = near.iter().find(|&&k| deviations[k] == deepest).unwrap();
    assert_eq!(&colours[4 * red..4 * red + 4], &[171.0, 5.0, 5.0, 255.0]);
    // Away from the cutter's path the top is 1 of material left, blue.
    let far = (0..deviations.len()).find(|&k| normals[3 * k + 2] == 1.0 && positions[3 * k + 1] > 20.0).unwrap();
    assert!((deviations[far] - 1.0).abs() < 1e-6);
    assert_eq!(&colours[4 * far..4 * far + 4], &[3.0, 47.0, 116.0, 255.0]);
}

#[tokio::test(flavor = "multi_thread")]
async fn playback_cuts_up_to_a_line_and_bad_asks_are_refused() {
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: 32 << 20, ..Limits::default() }).await;
    let body = dip();
    let whole = glb(&app, "?format=glb", &body).await.0;
    let facing = glb(&app, "?format=glb&upto_line=4", &body).await.0;
    let removed = |json: &Value| number(&json["extras"]["verify"]["removed_volume_mm3"]);
    assert!(removed(&facing) < removed(&whole), "{} against {}", removed(&facing), removed(&whole));
    let findings =
        |json: &Value| json["extras"]["verify"]["findings"].as_array().unwrap().iter().any(|f| f["kind"] == "gouge");
    assert!(findings(&whole) && !findings(&facing), "the dip on line 5 is not cut by line 4");
    let before = glb(&app, "?format=glb&upto_line=1", &body).await.0;
    assert_eq!(before["extras"], json!({}), "nothing cut by line 1: the stock as given");
    let json_upto = problem(app.post_json("/api/v1/verify?upto_line=3", &body).await, 422).await;
    assert_eq!(json_upto["errors"][0]["path"], "upto_line");
    let mut fine = body.clone();
    fine["resolution"] = json!(0.05);
    let refused = problem(app.post_json("/api/v1/verify?format=glb", &fine).await, 422).await;
    assert_eq!((&refused["code"], &refused["errors"][0]["path"]), (&json!("E_TOO_LARGE_ANSWER"), &json!("resolution")));
    problem(app.post_json("/api/v1/verify?format=stl", &body).await, 400).await;
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_gltf_validator),
    ignore = "node or the Khronos glTF validator not found: apt-get install npm; npm ci --prefix tests/gltf"
)]
async fn the_khronos_validator_finds_no_error_or_warning() {
    let node = kerf_tests::external_program("node", "the Khronos glTF validator").unwrap();
    let app = TestApp::spawn().await;
    let folder = std::env::temp_dir().join(format!("kerf-glb-{}", std::process::id()));
    std::fs::create_dir_all(&folder).unwrap();
    // With a part (`_DEVIATION`), without one (grey, no deviation), and a tube whose rays hold two
    // intervals (the bore's surfaces).
    let mut plain = dip();
    plain.as_object_mut().unwrap().remove("part");
    let tube = json!({
        "program": "G0 X0 Y0 Z15\nG1 Z5 F200\nG0 Z15",
        "tools": [{"kind": "flat", "radius": 2}],
        "stock": {"kind": "tube", "start": [-15, 0, 0], "end": [15, 0, 0], "outer_radius": 10, "inner_radius": 6},
        "resolution": 0.25,
    });
    for (name, body) in [("dip", dip()), ("plain", plain), ("tube", tube)] {
        let response = app.client.post(app.url("/api/v1/verify?format=glb")).json(&body).send().await.unwrap();
        assert_eq!(response.status().as_u16(), 200, "{name}");
        let path = folder.join(format!("{name}.glb"));
        std::fs::write(&path, response.bytes().await.unwrap()).unwrap();
        let output = std::process::Command::new(&node)
            .arg(kerf_tests::external::gltf_folder().join("validate.mjs"))
            .arg(&path)
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
