//! Numbers at the edge of the float range in every endpoint's geometry: each spelling (1e308,
//! -1e308, 5e-324, -0.0, 1e155, 1e-300, integers past 2⁶⁴, ...) put as written into each
//! geometry field of each endpoint's request. Every call answers within its time limit, never a
//! 5xx, never an answer with a non-finite number (serde writes NaN and infinities as `null`); a
//! coordinate outside the one range of every endpoint (±100 000 mm) is refused with 422
//! `E_INPUT` naming the field and the range.

use std::collections::BTreeSet;
use std::time::{Duration, Instant};

use kerf_server::state::Limits;
use kerf_tests::TestApp;
use serde_json::{Value, json};

/// The time limit of the service under test; a call may take a little longer to answer.
const TIME_LIMIT: Duration = Duration::from_secs(4);
const ANSWER_MARGIN: Duration = Duration::from_secs(3);

/// Spellings outside the range, as a client might write them.
const OUTSIDE: [&str; 9] = [
    "1e308",
    "-1e308",
    "1.7976931348623157e308",
    "1e155",
    "-1e155",
    "1E+200",
    "123456789012345678901234567890",
    "-18446744073709551616",
    "100000.001",
];

/// Spellings inside the range (tiny, signed zero, subnormal, the range's end).
const INSIDE: [&str; 6] = ["5e-324", "-0.0", "1e-300", "-1e-300", "0", "1e5"];

/// An endpoint's request, its geometry fields (JSON pointers), and changes to the request whose
/// answers show where a `null` stands for "none" (a pass that never touches the stock).
struct Endpoint {
    url: &'static str,
    body: Value,
    fields: Vec<&'static str>,
    nullable: Vec<(&'static str, Value)>,
}

fn endpoints() -> Vec<Endpoint> {
    let square = json!([[0, 0], [40, 0], [40, 30], [0, 30]]);
    let endpoint = |url, body, fields, nullable| Endpoint { url, body, fields, nullable };
    vec![
        endpoint(
            "/api/v1/segment",
            json!({"curve": {"kind": "polyline", "points": [[0, 0], [10, 0], [20, 5], [30, 15]]},
                   "feed": 3000, "block_time_ms": 4}),
            vec!["/curve/points/1/0", "/curve/points/2/1", "/curve/points/0/0", "/safe_z"],
            Vec::new(),
        ),
        endpoint(
            "/api/v1/segment",
            json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 20}, "feed": 3000, "block_time_ms": 4}),
            vec!["/curve/centre/0", "/curve/centre/1", "/curve/radius"],
            Vec::new(),
        ),
        endpoint(
            "/api/v1/contour",
            json!({"tool": {"kind": "flat", "radius": 3}, "contour": square, "side": "outside",
                   "depths": {"top": 0, "bottom": -2, "step": 1}, "feed": 800}),
            vec![
                "/contour/1/0",
                "/contour/2/1",
                "/contour/0/0",
                "/depths/top",
                "/depths/bottom",
                "/safe_z",
                "/clearance",
                "/lead",
            ],
            Vec::new(),
        ),
        endpoint(
            "/api/v1/contour/loops",
            json!({"tool": {"kind": "flat", "radius": 3}, "path": [[0, 0], [40, 0], [40, 30], [0, 30]]}),
            vec!["/path/0/0", "/path/1/0", "/path/2/1", "/path/3/1"],
            Vec::new(),
        ),
        endpoint(
            "/api/v1/deburr",
            json!({"tool": {"kind": "ball", "radius": 3}, "edge": "outer", "cut_amount": 0.3,
                   "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
                   "hole": {"shape": "round", "radius": 5}}),
            vec!["/workpiece/origin/0", "/workpiece/origin/2", "/workpiece/outer_radius", "/hole/radius", "/clearance"],
            Vec::new(),
        ),
        endpoint(
            "/api/v1/engagement",
            json!({"tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
                   "paths": [{"path": [[-10, 20], [70, 20]]}], "spindle_rpm": 3000, "feed_per_tooth": 0.05,
                   "flute_counts": [2]}),
            vec!["/stock/polygon/1/0", "/stock/polygon/2/1", "/paths/0/path/0/0", "/paths/0/path/1/1"],
            Vec::new(),
        ),
        endpoint(
            "/api/v1/predict",
            json!({"tool": serde_json::to_value(kerf_cases::predict::finishing_tool(5.0)).unwrap(),
                   "stock": {"kind": "box", "min": [-20, -20, -10], "max": [20, 20, 0.2]},
                   "path": {"kind": "points", "points": [[-10, 0, 5], [10, 0, 5]]},
                   "reference": "centre", "feed": 1200, "spindle_rpm": 6000,
                   "cutting": {"ktc": 2000, "krc": 800, "kac": 300}}),
            vec!["/path/points/0/0", "/path/points/1/2", "/stock/min/0", "/stock/max/2"],
            vec![("/stock/max/2", json!(-1))],
        ),
    ]
}

/// `body` as JSON text with the number at `pointer` spelled `spelling`.
fn spelled(body: &Value, pointer: &str, spelling: &str) -> String {
    const MARK: &str = "@edge-number@";
    let mut body = body.clone();
    match body.pointer_mut(pointer) {
        Some(slot) => *slot = json!(MARK),
        None => {
            let (parent, key) = pointer.rsplit_once('/').unwrap();
            body.pointer_mut(parent).and_then(Value::as_object_mut).unwrap().insert(key.to_owned(), json!(MARK));
        }
    }
    serde_json::to_string(&body).unwrap().replace(&format!("\"{MARK}\""), spelling)
}

/// The places of an answer, array indices left out (`/layers/moves/to`), where a number stands,
/// and where a `null` does.
fn places(value: &Value, at: &str, numbers: &mut BTreeSet<String>, nulls: &mut BTreeSet<String>) {
    match value {
        Value::Number(_) => {
            numbers.insert(at.to_owned());
        }
        Value::Null => {
            nulls.insert(at.to_owned());
        }
        Value::Array(items) => items.iter().for_each(|item| places(item, at, numbers, nulls)),
        Value::Object(map) => map.iter().for_each(|(key, item)| places(item, &format!("{at}/{key}"), numbers, nulls)),
        _ => {}
    }
}

/// Where `answer` has a `null` in a place the reference answers only ever hold numbers in: a
/// NaN or infinity written by serde.
fn non_finite(references: &[Value], answer: &Value) -> Vec<String> {
    let (mut numbers, mut nulls) = (BTreeSet::new(), BTreeSet::new());
    for reference in references {
        places(reference, "", &mut numbers, &mut nulls);
    }
    let (mut answer_numbers, mut answer_nulls) = (BTreeSet::new(), BTreeSet::new());
    places(answer, "", &mut answer_numbers, &mut answer_nulls);
    answer_nulls.into_iter().filter(|place| numbers.contains(place) && !nulls.contains(place)).collect()
}

async fn post(app: &TestApp, url: &str, text: String) -> (u16, Value, Duration) {
    let started = Instant::now();
    let response = app
        .client
        .post(app.url(url))
        .header("content-type", "application/json")
        .body(text.clone())
        .send()
        .await
        .unwrap_or_else(|error| panic!("{url}: no answer ({error}) to {text}"));
    let status = response.status().as_u16();
    let bytes = response.bytes().await.unwrap_or_default();
    let body = serde_json::from_slice(&bytes).unwrap_or(Value::Null);
    (status, body, started.elapsed())
}

#[tokio::test(flavor = "multi_thread")]
async fn edge_numbers_in_every_geometry_field_are_answered_or_refused_at_once() {
    let app = TestApp::spawn_with(Limits { solver_time_limit: TIME_LIMIT, ..Limits::default() }).await;
    let mut failures = Vec::new();
    let mut calls = 0;
    for Endpoint { url, body: base, fields, nullable } in endpoints() {
        let (status, reference, _) = post(&app, url, base.to_string()).await;
        assert_eq!(status, 200, "{url}: the unchanged request is answered: {reference}");
        let mut references = vec![reference];
        for (pointer, value) in nullable {
            let mut body = base.clone();
            *body.pointer_mut(pointer).unwrap() = value;
            let (status, reference, _) = post(&app, url, body.to_string()).await;
            assert_eq!(status, 200, "{url}: {body} is answered: {reference}");
            references.push(reference);
        }
        for field in fields {
            for spelling in OUTSIDE.iter().chain(&INSIDE) {
                let text = spelled(&base, field, spelling);
                let (status, answer, took) = post(&app, url, text).await;
                calls += 1;
                let call = format!("{url} {field} = {spelling}");
                if took > TIME_LIMIT + ANSWER_MARGIN {
                    failures.push(format!("{call}: answered after {took:?}, past the time limit"));
                }
                match status {
                    200 => {
                        let found = non_finite(&references, &answer);
                        if !found.is_empty() {
                            failures.push(format!("{call}: non-finite numbers written as null at {found:?}"));
                        }
                    }
                    400 | 404 | 413 | 422 => {}
                    other => failures.push(format!("{call}: {other} {answer}")),
                }
                if OUTSIDE.contains(spelling) {
                    let named = field.trim_start_matches('/').split('/').fold(String::new(), |name, part| {
                        match (name.is_empty(), part.parse::<usize>()) {
                            (true, _) => part.to_owned(),
                            (false, Ok(index)) => format!("{name}[{index}]"),
                            (false, Err(_)) => format!("{name}.{part}"),
                        }
                    });
                    let refused = status == 422
                        && answer["code"] == "E_INPUT"
                        && answer["errors"][0]["path"].as_str().is_some_and(|path| named.starts_with(path))
                        // A negative size is refused as one before its range is checked.
                        && (spelling.starts_with('-')
                            || answer["detail"].as_str().is_some_and(|detail| detail.contains("100000")));
                    if !refused {
                        failures.push(format!("{call}: not refused as out of range at {named}: {status} {answer}"));
                    }
                }
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {calls} calls failed:\n{}",
        failures.len(),
        failures[..failures.len().min(40)].join("\n")
    );
    assert!(app.get("/healthz").await.status().is_success());
}

#[tokio::test(flavor = "multi_thread")]
async fn a_loops_path_at_the_end_of_the_float_range_is_refused_at_once() {
    let app = TestApp::spawn_with(Limits { solver_time_limit: TIME_LIMIT, ..Limits::default() }).await;
    let body = r#"{"tool": {"kind": "flat", "radius": 3},
                   "path": [[-1e308, -1e308], [1e308, -1e308], [1e308, 1e308], [-1e308, 1e308]]}"#;
    let (status, answer, took) = post(&app, "/api/v1/contour/loops", body.to_owned()).await;
    assert_eq!(status, 422, "{answer}");
    assert_eq!(answer["code"], "E_INPUT", "{answer}");
    assert_eq!(answer["errors"][0]["path"], "path[0][0]", "{answer}");
    assert!(answer["detail"].as_str().unwrap().ends_with("±100000 mm (got -1e308 mm)"), "{answer}");
    assert!(took < TIME_LIMIT, "refused before any work, not at the time limit: {took:?}");
}
