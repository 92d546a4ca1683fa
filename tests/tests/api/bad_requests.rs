//! Bad input answered with the right 4xx problem+json naming the field, and the database left
//! unchanged (docs/spec/api.md, Errors).

use kerf_server::state::Limits;
use kerf_tests::{TestApp, json_with, problem};
use serde_json::{Value, json};

use kerf_cases::deburr::request;

use crate::deburr::app_with_tools;

/// A valid deburr request to start each bad case from.
fn valid() -> Value {
    request(json!({"shape": "round", "radius": 8}), "outer")
}

fn with(path: &[&str], value: Value) -> Value {
    let mut body = valid();
    let mut slot = &mut body;
    for key in &path[..path.len() - 1] {
        slot = &mut slot[*key];
    }
    slot[path[path.len() - 1]] = value;
    body
}

fn without(key: &str) -> Value {
    let mut body = valid();
    body.as_object_mut().unwrap().remove(key);
    body
}

/// (what, body, expected status, expected field path, expected code)
fn deburr_cases() -> Vec<(&'static str, Value, u16, &'static str, &'static str)> {
    vec![
        ("unknown top-level field", with(&["extra"], json!(1)), 400, "extra", "E_JSON"),
        ("unknown nested field", with(&["hole", "depth"], json!(5)), 400, "hole.depth", "E_JSON"),
        ("missing edge", without("edge"), 400, "body", "E_JSON"),
        ("string for a number", with(&["cut_amount"], json!("0.2")), 400, "cut_amount", "E_JSON"),
        ("unknown edge", with(&["edge"], json!("middle")), 400, "edge", "E_JSON"),
        ("unknown workpiece kind", with(&["workpiece", "kind"], json!("cube")), 400, "workpiece.kind", "E_JSON"),
        ("unknown hole shape", with(&["hole", "shape"], json!("star")), 400, "hole.shape", "E_JSON"),
        ("origin with two coordinates", with(&["workpiece", "origin"], json!([0, 0])), 400, "workpiece", "E_JSON"),
        ("tool number zero", with(&["tool"], json!(0)), 400, "tool", "E_JSON"),
        ("tool as a string", with(&["tool"], json!("7")), 400, "tool", "E_JSON"),
        ("negative hole radius", with(&["hole", "radius"], json!(-8)), 422, "hole.radius", "E_INPUT"),
        ("zero hole radius", with(&["hole", "radius"], json!(0)), 422, "hole.radius", "E_INPUT"),
        ("negative cut amount", with(&["cut_amount"], json!(-0.3)), 422, "cut_amount", "E_INPUT"),
        ("both cut amount and width", with(&["width"], json!(0.4)), 422, "width", "E_INPUT"),
        ("neither cut amount nor width", without("cut_amount"), 422, "cut_amount", "E_INPUT"),
        ("zero feed", with(&["feed"], json!(0)), 422, "feed", "E_INPUT"),
        ("negative tolerance", with(&["tolerance"], json!(-0.01)), 422, "tolerance", "E_INPUT"),
        ("unreachable tolerance", with(&["tolerance"], json!(1e-9)), 422, "tolerance", "E_TOL"),
        ("hole larger than the tube", with(&["hole", "radius"], json!(51)), 422, "hole.radius", "E_HOLE_TOO_LARGE"),
        ("hole larger than the bore", with(&["hole", "eccentricity"], json!(25)), 422, "hole.radius", "E_NOT_THROUGH"),
        (
            "inner radius not below outer",
            with(&["workpiece", "inner_radius"], json!(50)),
            422,
            "workpiece.inner_radius",
            "E_NOT_THROUGH",
        ),
        ("ball too small for W", with(&["cut_amount"], json!(4.5)), 422, "cut_amount", "E_WIDTH_VS_BALL"),
        ("unknown tool", with(&["tool"], json!(4242)), 404, "tool", "E_NOT_FOUND"),
        ("tool of the wrong kind", with(&["tool"], json!(8)), 422, "tool", "E_TOOL_KIND"),
        (
            "inline tool with zero radius",
            with(&["tool"], json!({"kind": "ball", "radius": 0})),
            422,
            "tool.radius",
            "E_INPUT",
        ),
        (
            "outer edge of a bored block",
            with(&["workpiece"], json!({"kind": "bore_block", "origin": [0, 0, 0], "bore_radius": 30})),
            422,
            "edge",
            "E_INPUT",
        ),
        (
            "slot without centre distance",
            with(&["hole", "shape"], json!("slot")),
            422,
            "hole.centre_distance",
            "E_INPUT",
        ),
        (
            "rounded rectangle with one distance",
            with(&["hole"], json!({"shape": "rounded_rect", "radius": 4, "centre_distance": 10})),
            422,
            "hole.centre_distance",
            "E_INPUT",
        ),
        (
            "start angle on a slot",
            with(&["hole"], json!({"shape": "slot", "radius": 4, "centre_distance": 10}))
                .as_object()
                .map(|o| {
                    let mut o = o.clone();
                    o.insert("start_deg".into(), json!(45));
                    Value::Object(o)
                })
                .unwrap(),
            422,
            "start_deg",
            "E_INPUT",
        ),
        (
            "eccentricity disagreeing with the axis point",
            with(&["hole"], json!({"shape": "round", "radius": 8, "eccentricity": 2, "axis_point": [5, 0, 40]})),
            422,
            "hole.eccentricity",
            "E_INCONSISTENT_ECC",
        ),
        ("ball reaching across a small hole", with(&["hole", "radius"], json!(2)), 422, "tool", "E_FAR_GOUGE"),
    ]
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_deburr_requests() {
    let app = app_with_tools().await;
    let tools_before = json_with(app.get("/api/v1/tools").await, 200).await;
    let mut mismatches = Vec::new();
    for (what, body, status, field, code) in deburr_cases() {
        let answer = problem(app.post_json("/api/v1/deburr", &body).await, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await, tools_before, "database unchanged");
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_bodies_headers_paths_and_queries() {
    let app = app_with_tools().await;
    let tools_before = json_with(app.get("/api/v1/tools").await, 200).await;
    let post_raw = |body: &'static str, content_type: Option<&'static str>| {
        let mut builder = app.client.post(app.url("/api/v1/deburr")).body(body);
        if let Some(content_type) = content_type {
            builder = builder.header("content-type", content_type);
        }
        builder.send()
    };
    let json_type = Some("application/json");
    let cases: Vec<(&str, reqwest::Response, u16, Option<&str>)> = vec![
        ("malformed JSON", post_raw("{\"tool\": ", json_type).await.unwrap(), 400, Some("tool")),
        ("not an object", post_raw("[1, 2]", json_type).await.unwrap(), 400, Some("body")),
        ("trailing garbage", post_raw("{} {}", json_type).await.unwrap(), 400, Some("body")),
        (
            "number out of range",
            post_raw(r#"{"tool": 7, "cut_amount": 1e999}"#, json_type).await.unwrap(),
            400,
            Some("cut_amount"),
        ),
        ("empty body", post_raw("", json_type).await.unwrap(), 400, Some("body")),
        ("wrong content type", post_raw("{}", Some("text/plain")).await.unwrap(), 415, None),
        ("no content type", post_raw("{}", None).await.unwrap(), 415, None),
        (
            "bad format",
            app.client.post(app.url("/api/v1/deburr?format=pdf")).json(&valid()).send().await.unwrap(),
            400,
            Some("format"),
        ),
        (
            "bad dialect",
            app.client.post(app.url("/api/v1/deburr?dialect=mazak")).json(&valid()).send().await.unwrap(),
            400,
            Some("dialect"),
        ),
        (
            "unknown query parameter",
            app.client.post(app.url("/api/v1/deburr?colour=red")).json(&valid()).send().await.unwrap(),
            400,
            Some("colour"),
        ),
        ("tool number not a number", app.get("/api/v1/tools/abc").await, 400, Some("number")),
        ("tool number too large for u32", app.get("/api/v1/tools/99999999999").await, 400, Some("number")),
        (
            "tool number out of range",
            app.put_json("/api/v1/tools/10000", &json!({"kind": "ball", "radius": 3})).await,
            422,
            Some("number"),
        ),
        (
            "unknown tool kind",
            app.put_json("/api/v1/tools/5", &json!({"kind": "drill", "radius": 3})).await,
            400,
            Some("kind"),
        ),
        (
            "bull without corner radius",
            app.put_json("/api/v1/tools/5", &json!({"kind": "bull", "radius": 3})).await,
            422,
            Some("corner_radius"),
        ),
        (
            "neck wider than the ball",
            app.put_json("/api/v1/tools/5", &json!({"kind": "ball", "radius": 3, "neck_radius": 4})).await,
            422,
            Some("neck_radius"),
        ),
        (
            "body number differs from the path",
            app.put_json("/api/v1/tools/5", &json!({"number": 6, "kind": "ball", "radius": 3})).await,
            422,
            Some("number"),
        ),
        (
            "unknown tool field",
            app.put_json("/api/v1/tools/5", &json!({"kind": "ball", "radius": 3, "colour": "red"})).await,
            400,
            Some("colour"),
        ),
        ("method not allowed", app.client.patch(app.url("/api/v1/tools/5")).send().await.unwrap(), 405, None),
        ("unknown route", app.get("/api/v1/nothing").await, 404, None),
        ("path escaping the web folder", app.get("/../Cargo.toml").await, 404, None),
        ("encoded path escape", app.get("/%2e%2e/%2e%2e/etc/passwd").await, 404, None),
    ];
    let mut mismatches = Vec::new();
    for (what, response, status, field) in cases {
        let answer = problem(response, status).await;
        if let Some(field) = field
            && answer["errors"][0]["path"] != field
        {
            mismatches.push(format!("{what}: expected {field}, got {answer}"));
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
    let deep = format!("{}{}", "[".repeat(5000), "]".repeat(5000));
    let response = app
        .client
        .post(app.url("/api/v1/deburr"))
        .header("content-type", "application/json")
        .body(deep)
        .send()
        .await
        .unwrap();
    problem(response, 400).await;
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await, tools_before, "database unchanged");
}

#[tokio::test(flavor = "multi_thread")]
async fn oversized_body_is_413() {
    let app = TestApp::spawn_with(Limits { max_body_bytes: 4096, ..Limits::default() }).await;
    let mut body = valid();
    body["padding"] = json!("x".repeat(10_000));
    let answer = problem(app.post_json("/api/v1/deburr", &body).await, 413).await;
    assert_eq!(answer["code"], "E_TOO_LARGE");
    let answer = problem(
        app.put_json("/api/v1/tools/1", &json!({"kind": "ball", "radius": 3, "name": "x".repeat(10_000)})).await,
        413,
    )
    .await;
    assert_eq!(answer["code"], "E_TOO_LARGE");
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await, json!([]));
}

#[tokio::test(flavor = "multi_thread")]
async fn names_that_would_break_a_program_line_are_refused() {
    // Names and descriptions end up in G-code comments and headers: a line break would start a
    // block of its own there (M30, a move...). Nothing is stored.
    let app = TestApp::spawn().await;
    for name in ["T1\nM30", "cut\r", "nul\u{0}", "tab\there"] {
        let answer =
            problem(app.put_json("/api/v1/tools/4", &json!({"kind": "ball", "radius": 3, "name": name})).await, 422)
                .await;
        assert_eq!(answer["errors"][0]["path"], "name", "{name:?}: {answer}");
        let answer = problem(
            app.put_json("/api/v1/machines/mill", &json!({"block_time_ms": 4, "max_feed": 10000, "description": name}))
                .await,
            422,
        )
        .await;
        assert_eq!(answer["errors"][0]["path"], "description", "{name:?}: {answer}");
        let job = json!({"name": name, "operations": [{"operation": "segment",
            "curve": {"kind": "arc", "centre": [0, 0], "radius": 10, "start_deg": 0, "end_deg": 90},
            "feed": 1000, "block_time_ms": 4}]});
        let answer = problem(app.post_json("/api/v1/jobs", &job).await, 422).await;
        assert_eq!(answer["errors"][0]["path"], "name", "{name:?}: {answer}");
    }
    assert_eq!(app.get("/api/v1/tools/4").await.status(), 404);
    assert_eq!(app.get("/api/v1/machines/mill").await.status(), 404);
    let jobs: Value = app.get("/api/v1/jobs").await.json().await.unwrap();
    assert_eq!(jobs["jobs"].as_array().map(Vec::len), Some(0), "{jobs}");
    // Ordinary text, accents included, is kept.
    let tool = json_with(
        app.put_json("/api/v1/tools/4", &json!({"kind": "ball", "radius": 3, "name": "Kugelfräser Ø6 (Schlichten)"}))
            .await,
        201,
    )
    .await;
    assert_eq!(tool["name"], "Kugelfräser Ø6 (Schlichten)");
}
