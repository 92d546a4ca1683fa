//! Reading DXF drawings over HTTP (files ezdxf wrote: tests/dxf/make_fixtures.py): a plate with
//! bulges, a circle and a slot of lines and arcs; binary R12 in the units given; lines that make
//! the same contour as the typed polygon; refusals naming the entity, the gap, the point, the units;
//! contour and segment requests that carry their drawing as a form part.

use reqwest::multipart::{Form, Part};
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
        ("broken_chain.dxf", "", "file", "(40.0000 mm, 30.0000 mm)"),
        ("bow_tie.dxf", "", "file", "crosses itself at (5.0000 mm, 5.0000 mm)"),
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

/// `request` with the DXF file `name` as a form to `path`.
async fn with_drawing(app: &TestApp, path: &str, request: &Value, name: &str) -> reqwest::Response {
    let form = Form::new()
        .part("request", Part::text(request.to_string()).mime_str("application/json").unwrap())
        .part("drawing", Part::bytes(fixture(name)).file_name(name.to_owned()));
    app.client.post(app.url(path)).multipart(form).send().await.unwrap()
}

fn contour_request(outline: (&str, Value)) -> Value {
    let mut request = json!({"tool": {"kind": "flat", "radius": 3}, "side": "outside",
        "depths": {"top": 0, "bottom": -4, "step": 2}, "corner_loop": {"style": "arc"}, "feed": 800});
    request[outline.0] = outline.1;
    request
}

#[tokio::test(flavor = "multi_thread")]
async fn contour_takes_its_polygon_from_the_drawing_sent_with_it() {
    let app = TestApp::spawn().await;
    let typed = json!([[0, 0], [80, 0], [80, 30], [40, 30], [40, 60], [0, 60]]);
    // The reader's boundary starts where the drawing's first line does: the same polygon from
    // that vertex, typed in.
    let profile = json_with(upload(&app, "l_plate_lines.dxf", "").await, 200).await;
    let from_read = json_with(
        app.post_json("/api/v1/contour", &contour_request(("contour", profile["boundary"].clone()))).await,
        200,
    )
    .await;
    let request = contour_request(("drawing", json!({"layer": "0"})));
    let from_drawing = json_with(with_drawing(&app, "/api/v1/contour", &request, "l_plate_lines.dxf").await, 200).await;
    assert_eq!(from_drawing, from_read);
    let from_typing =
        json_with(app.post_json("/api/v1/contour", &contour_request(("contour", typed))).await, 200).await;
    assert_eq!(from_drawing["summary"], from_typing["summary"]);
    // The program route takes the form too.
    let program = with_drawing(&app, "/api/v1/contour/program", &request, "l_plate_lines.dxf").await;
    assert_eq!(program.status(), 200);
    assert!(program.text().await.unwrap().contains("G1"));
    // An island of a drawing with blocks: the radius-3 hole placed by PAIR at (30, 40).
    let request = contour_request(("drawing", json!({"layer": "CUT", "island": 1})));
    let answer = json_with(with_drawing(&app, "/api/v1/contour", &request, "blocks_mm_binary.dxf").await, 200).await;
    assert!(answer["layers"].as_array().is_some_and(|layers| !layers.is_empty()), "{answer}");
}

#[tokio::test(flavor = "multi_thread")]
async fn segment_cuts_a_drawings_spline_exactly_as_the_curve_typed_in() {
    let app = TestApp::spawn().await;
    let request = |curve: Value| json!({"curve": curve, "feed": 3000, "block_time_ms": 4, "tolerance": 0.01});
    // The control points and knots make_fixtures.py gave ezdxf.
    let typed = json!({"kind": "bspline", "degree": 3,
        "control_points": [[0, 0], [20, 30], [50, -10], [80, 25], [100, 0]],
        "knots": [0, 0, 0, 0, 0.5, 1, 1, 1, 1]});
    let profile = json_with(upload(&app, "spline_open_mm.dxf", "").await, 200).await;
    assert_eq!(profile["curve"]["kind"], "bspline", "{profile}");
    let control: Vec<[f64; 2]> = serde_json::from_value(profile["curve"]["control_points"].clone()).unwrap();
    assert_eq!(control, [[0.0, 0.0], [20.0, 30.0], [50.0, -10.0], [80.0, 25.0], [100.0, 0.0]]);
    let knots: Vec<f64> = serde_json::from_value(profile["curve"]["knots"].clone()).unwrap();
    let typed = json!({"kind": "bspline", "degree": 3, "control_points": typed["control_points"], "knots": knots});
    let from_typing = json_with(app.post_json("/api/v1/segment", &request(typed)).await, 200).await;
    let from_drawing = json_with(
        with_drawing(&app, "/api/v1/segment", &request(json!({"kind": "drawing"})), "spline_open_mm.dxf").await,
        200,
    )
    .await;
    assert_eq!(from_drawing, from_typing);
    assert!(from_drawing["points"].as_array().is_some_and(|p| p.len() > 100), "{}", from_drawing["blocks"]);
}

#[tokio::test(flavor = "multi_thread")]
async fn a_drawing_request_refuses_what_it_cannot_read_naming_the_field() {
    let app = TestApp::spawn().await;
    let contour = |drawing: Value| contour_request(("drawing", drawing));
    let cases = [
        ("/api/v1/contour", contour(json!({})), "broken_chain.dxf", 422, "drawing", "open chain"),
        (
            "/api/v1/contour",
            contour(json!({})),
            "bow_tie.dxf",
            422,
            "drawing",
            "crosses itself at (5.0000 mm, 5.0000 mm)",
        ),
        ("/api/v1/contour", contour(json!({})), "square_inch_r12.dxf", 422, "drawing.units", "give units"),
        ("/api/v1/contour", contour(json!({"layer": "HOLES"})), "plate_mm.dxf", 422, "drawing.layer", "CUT, NOTES"),
        ("/api/v1/contour", contour(json!({"island": 3})), "l_plate_lines.dxf", 422, "drawing.island", "no island 3"),
        ("/api/v1/contour", contour(json!({})), "block_loop.dxf", 422, "drawing", "8 deep"),
        (
            "/api/v1/segment",
            json!({"curve": {"kind": "drawing"}, "feed": 3000}),
            "no_units.dxf",
            422,
            "curve.units",
            "give units",
        ),
        (
            "/api/v1/segment",
            json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 5}}),
            "no_units.dxf",
            422,
            "drawing",
            "curve.kind is not",
        ),
    ];
    for (path, request, name, status, field, words) in cases {
        let answer = problem(with_drawing(&app, path, &request, name).await, status).await;
        assert_eq!(answer["errors"][0]["path"], field, "{path} {name}: {answer}");
        assert!(answer.to_string().contains(words), "{path} {name}: {answer}");
    }
    // A drawing sent without its file, as JSON.
    let answer = problem(app.post_json("/api/v1/contour", &contour(json!({}))).await, 422).await;
    assert_eq!(answer["errors"][0]["path"], "drawing", "{answer}");
    assert!(answer.to_string().contains("part `drawing`"), "{answer}");
    // A form without its JSON part.
    let form = Form::new().part("drawing", Part::bytes(fixture("plate_mm.dxf")));
    let response = app.client.post(app.url("/api/v1/contour")).multipart(form).send().await.unwrap();
    let answer = problem(response, 400).await;
    assert_eq!(answer["errors"][0]["path"], "request", "{answer}");
}
