//! `POST /api/v1/{name}/stock` over HTTP: the stock as a capability's own verification cuts its
//! program, as binary glTF. Deburr's reference case 1: the cut is the answer's verification (same
//! removed volume), the chamfer band is where the deviation is non-zero and within tolerance,
//! playback up to an early line removes less; contour's sample likewise; a request without a model
//! (verification off, segment) is refused naming `verification`.

use kerf_cases::deburr::case_1;
use kerf_cases::with;
use kerf_tests::{TestApp, json_with, problem};
use serde_json::{Value, json};

/// A GLB's JSON chunk and the `_DEVIATION` values of its one primitive.
fn read(bytes: &[u8]) -> (Value, Vec<f32>) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(word(8), bytes.len());
    let length = word(12);
    let json: Value = serde_json::from_slice(&bytes[20..20 + length]).unwrap();
    let bin = &bytes[20 + length + 8..];
    let Some(index) = json["meshes"][0]["primitives"][0]["attributes"]["_DEVIATION"].as_u64() else {
        return (json, Vec::new());
    };
    let accessor = &json["accessors"][index as usize];
    let view = &json["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
    let offset = view["byteOffset"].as_u64().unwrap() as usize;
    let deviations = bin[offset..offset + view["byteLength"].as_u64().unwrap() as usize]
        .chunks(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    (json, deviations)
}

async fn stock(app: &TestApp, path: &str, body: &Value) -> (Value, Vec<f32>) {
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
    let tolerance = verification["tolerance"].as_f64().unwrap() as f32;
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
