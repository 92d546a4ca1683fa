//! Reading DXF drawings over HTTP (files ezdxf wrote: tests/dxf/make_fixtures.py): a plate with
//! bulges, a circle and a slot of lines and arcs; binary R12 in the units given; lines that make
//! the same contour as the typed polygon; refusals naming the entity, the gap, the point, the units.

use serde_json::{Value, json};

use kerf_tests::{TestApp, json_with, problem};

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("dxf").join(name)).unwrap()
}

async fn upload(app: &TestApp, name: &str, query: &str) -> reqwest::Response {
    app.client
        .post(app.url(&format!("/api/v1/dxf{query}")))
        .header("content-type", "application/dxf")
        .body(fixture(name))
        .send()
        .await
        .unwrap()
}

fn area(points: &Value) -> f64 {
    let points: Vec<[f64; 2]> = serde_json::from_value(points.clone()).unwrap();
    let n = points.len();
    (0..n).map(|i| points[i][0] * points[(i + 1) % n][1] - points[(i + 1) % n][0] * points[i][1]).sum::<f64>() / 2.0
}

#[tokio::test(flavor = "multi_thread")]
async fn drawings_are_read_into_a_boundary_and_islands_in_mm() {
    let app = TestApp::spawn().await;
    let plate = json_with(upload(&app, "plate_mm.dxf", "?layer=CUT").await, 200).await;
    assert_eq!(plate["units"], "mm");
    let corners = 4.0 * (100.0 - std::f64::consts::PI * 25.0);
    assert!((area(&plate["boundary"]) - (6000.0 - corners)).abs() < 0.05, "{}", area(&plate["boundary"]));
    assert_eq!(plate["islands"].as_array().unwrap().len(), 2);
    assert_eq!(plate["layers"], json!(["CUT", "NOTES"]));

    let square = json_with(upload(&app, "square_inch_r12_binary.dxf", "?units=inch").await, 200).await;
    assert_eq!(square["boundary"], json!([[0.0, 0.0], [50.8, 0.0], [50.8, 50.8], [0.0, 50.8]]));
    let blob = json_with(upload(&app, "spline_ellipse_cm_binary.dxf", "").await, 200).await;
    assert_eq!(blob["units"], "cm");
    assert!((-area(&blob["islands"][0]) - std::f64::consts::PI * 50.0).abs() < 0.05, "{blob}");
}

#[tokio::test(flavor = "multi_thread")]
async fn lines_give_the_same_contour_as_the_typed_polygon() {
    let app = TestApp::spawn().await;
    let profile = json_with(upload(&app, "l_plate_lines.dxf", "").await, 200).await;
    let mut boundary: Vec<[f64; 2]> = serde_json::from_value(profile["boundary"].clone()).unwrap();
    let start = boundary.iter().position(|p| *p == [0.0, 0.0]).expect("the corner at the origin");
    boundary.rotate_left(start);
    let typed = json!([[0, 0], [80, 0], [80, 30], [40, 30], [40, 60], [0, 60]]);
    let request = |contour: Value| {
        json!({"tool": {"kind": "flat", "radius": 3}, "contour": contour, "side": "outside",
               "depths": {"top": 0, "bottom": -4, "step": 2}, "corner_loop": {"style": "arc"}, "feed": 800})
    };
    let from_dxf = json_with(app.post_json("/api/v1/contour", &request(json!(boundary))).await, 200).await;
    let from_typing = json_with(app.post_json("/api/v1/contour", &request(typed)).await, 200).await;
    assert_eq!(from_dxf, from_typing);
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_drawings_are_refused_naming_the_entity() {
    let app = TestApp::spawn().await;
    let cases = [
        ("broken_chain.dxf", "", "file", "open chain"),
        ("broken_chain.dxf", "", "file", "(40.0000, 30.0000)"),
        ("bow_tie.dxf", "", "file", "crosses itself at (5.0000, 5.0000)"),
        ("bow_tie.dxf", "", "file", "LWPOLYLINE"),
        ("plate_mm.dxf", "", "file", "LINE"),
        ("plate_mm.dxf", "?layer=HOLES", "layer", "CUT, NOTES"),
        ("no_units.dxf", "", "units", "give units"),
        ("square_inch_r12.dxf", "", "units", "give units"),
        ("plate_mm.dxf", "?units=inch", "units", "disagree"),
    ];
    for (name, query, field, words) in cases {
        let answer = problem(upload(&app, name, query).await, 422).await;
        assert_eq!(answer["errors"][0]["path"], field, "{name}{query}: {answer}");
        assert!(answer.to_string().contains(words), "{name}{query}: {answer}");
    }
    let response =
        app.client.post(app.url("/api/v1/dxf")).body("0\nSECTION\n2\nENTITIES\n0\nLINE\n").send().await.unwrap();
    let answer = problem(response, 422).await;
    assert_eq!(answer["errors"][0]["path"], "units", "{answer}");
    let response = app.client.post(app.url("/api/v1/dxf?units=mm")).body("hello").send().await.unwrap();
    let answer = problem(response, 422).await;
    assert_eq!(answer["errors"][0]["path"], "file", "{answer}");
    let answer = problem(upload(&app, "plate_mm.dxf", "?units=yards").await, 400).await;
    assert!(answer.to_string().contains("units"), "{answer}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn the_page_draws_a_drawing_before_computing() {
    let app = TestApp::spawn().await;
    let plate = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("dxf/plate_mm.dxf");
    let Some(result) = crate::browser::run_scenario(&app, "dxf", &[plate.to_str().unwrap()]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["loops"], 3, "{result}");
}
