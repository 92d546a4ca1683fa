//! Memory bounded before it is spent: an answer that cannot fit the answer budget is refused with
//! `E_TOO_LARGE_ANSWER` (the estimate and the limit in the message) instead of being built whole,
//! synchronously and in a job; uploads hold the budget by the bytes they have sent, not the bytes
//! they declare, and a body slower than the minimum receive rate is dropped with 408.

use std::time::Duration;

use kerf_server::state::Limits;
use kerf_tests::{TestApp, json_with, problem};
use serde_json::{Value, json};
use tokio::io::AsyncWriteExt;

/// A 24 MiB budget: the fine request below needs some 1.1 GB as JSON, its coarse twin 9 MB.
const BUDGET: usize = 24 * 1024 * 1024;

/// 100 holes deburred at both edges (200 loops) in an 8 kB request: at tolerance 1e-6 its JSON
/// answer is some 1.1 GB (5.6 MB a loop).
fn many_loops(tolerance: f64) -> Value {
    let holes: Vec<Value> = (0..100)
        .map(|k| json!({"shape": "round", "radius": 16, "axial_position": 40 * k, "arrangement_angle_deg": (k * 37) % 360}))
        .collect();
    json!({
        "tool": {"kind": "ball", "radius": 2}, "edge": "both", "cut_amount": 0.3, "tolerance": tolerance,
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 60},
        "holes": holes,
    })
}

/// Checks a refusal for an answer over [`BUDGET`]: its code, and its estimate (more than the
/// budget) and limit in the message.
fn assert_too_large(answer: &Value) {
    assert_too_large_for(answer, BUDGET);
}

/// Checks a refusal for an answer over `budget`, as [`assert_too_large`].
fn assert_too_large_for(answer: &Value, budget: usize) {
    assert_eq!(answer["code"], "E_TOO_LARGE_ANSWER", "{answer}");
    let detail = answer["detail"].as_str().unwrap();
    assert!(detail.contains(&format!("over the limit of {budget} bytes")), "{detail}");
    let estimate: u64 =
        detail.split("about ").nth(1).and_then(|rest| rest.split(' ').next()).and_then(|n| n.parse().ok()).unwrap();
    assert!(estimate > budget as u64, "{detail}");
}

#[tokio::test(flavor = "multi_thread")]
async fn an_answer_over_the_budget_is_refused_before_it_is_built() {
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: BUDGET, ..Limits::default() }).await;
    let request = many_loops(1e-6);
    assert!(serde_json::to_vec(&request).unwrap().len() < 9_500);
    for path in ["/api/v1/deburr", "/api/v1/deburr?format=gcode"] {
        assert_too_large(&problem(app.post_json(path, &request).await, 422).await);
    }
    // The same holes at the default tolerance fit: answered whole, within the budget.
    let coarse = app.post_json("/api/v1/deburr", &many_loops(0.01)).await;
    let body = coarse.bytes().await.unwrap();
    assert!(body.len() < BUDGET, "{}", body.len());
    let answer: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(answer["holes"].as_array().unwrap().len(), 200);
    // The service answers as before.
    assert_eq!(app.get("/healthz").await.status(), 200);
}

#[tokio::test(flavor = "multi_thread")]
async fn engagement_samples_over_the_budget_are_refused_before_their_json() {
    // 100 000 samples along a 100 mm cut at a step of 0.001 mm: some 30 MB of JSON, their
    // count known before any of it is written.
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: BUDGET, ..Limits::default() }).await;
    let request = |step: f64| {
        json!({"tool": {"kind": "flat", "radius": 5}, "spindle_rpm": 8000, "feed_per_tooth": 0.04, "flute_counts": [4],
               "stock": {"polygon": [[0, 0], [100, 0], [100, 80], [0, 80]]},
               "path": [[-10, 40], [90, 40]], "step": step})
    };
    assert_too_large(&problem(app.post_json("/api/v1/engagement", &request(0.001)).await, 422).await);
    json_with(app.post_json("/api/v1/engagement", &request(0.2)).await, 200).await;
}

#[tokio::test(flavor = "multi_thread")]
async fn segment_points_over_the_budget_are_refused_as_they_are_cut() {
    // An ellipse arc of some 180 mm in chords of feed × 4 ms: some 270 000 command points at
    // 10 mm/min (tens of MB built), 2 700 at 1 000 mm/min.
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: BUDGET, ..Limits::default() }).await;
    let request = |feed: f64| {
        json!({"curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [50, 20], "start_deg": 0, "end_deg": 270},
               "feed": feed, "block_time_ms": 4})
    };
    for path in ["/api/v1/segment", "/api/v1/segment?format=gcode"] {
        assert_too_large(&problem(app.post_json(path, &request(10.0)).await, 422).await);
    }
    let answer = json_with(app.post_json("/api/v1/segment", &request(1000.0)).await, 200).await;
    assert!(answer["points"].as_array().unwrap().len() > 1000, "{}", answer["points"].as_array().unwrap().len());
}

#[tokio::test(flavor = "multi_thread")]
async fn contour_layers_over_the_budget_are_refused_as_they_are_made() {
    // A 600-gon of some 606 moves a layer: as JSON 400 layers (some 240 000 moves, within the
    // JSON move limit) take 14 MB in memory and 19 MB as JSON; as a program 990 layers (600 000
    // moves) take 34 MB in memory; 10 layers well under 1 MB.
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: BUDGET, ..Limits::default() }).await;
    let request = |layers: f64| {
        json!({"tool": {"kind": "flat", "radius": 3}, "contour": kerf_cases::contour::circle(600), "side": "outside",
               "depths": {"top": 0, "bottom": -layers * 0.1, "step": 0.1}, "feed": 800})
    };
    for (path, layers) in [("/api/v1/contour", 400.0), ("/api/v1/contour?format=gcode", 990.0)] {
        assert_too_large(&problem(app.post_json(path, &request(layers)).await, 422).await);
    }
    let answer = json_with(app.post_json("/api/v1/contour", &request(10.0)).await, 200).await;
    assert_eq!(answer["layers"].as_array().unwrap().len(), 10);
}

#[tokio::test(flavor = "multi_thread")]
async fn predict_passes_over_the_budget_are_refused_as_they_are_predicted() {
    // 1 MiB: a raster of 40 lines × 81 points (3 240 passes, some 1 kB each) does not fit, one
    // of 6 × 9 does.
    const SMALL: usize = 1024 * 1024;
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: SMALL, ..Limits::default() }).await;
    let request = |lines: usize, points: usize| {
        let mut request = crate::predict::raster_request(crate::predict::finishing_tool(), lines, points);
        request["resolution"] = json!(32);
        request
    };
    assert_too_large_for(&problem(app.post_json("/api/v1/predict", &request(40, 81)).await, 422).await, SMALL);
    let answer = json_with(app.post_json("/api/v1/predict", &request(6, 9)).await, 200).await;
    assert_eq!(answer["passes"].as_array().unwrap().len(), 54);
}

#[tokio::test(flavor = "multi_thread")]
async fn a_job_over_the_budget_fails_instead_of_taking_the_process_down() {
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: BUDGET, ..Limits::default() }).await;
    let job = json!({"operations": [
        kerf_cases::operation("deburr", kerf_cases::deburr::case_1()),
        kerf_cases::operation("deburr", many_loops(1e-6)),
    ]});
    let id = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await["id"].as_i64().unwrap();
    let done = kerf_tests::poll_job(&app.client, &app.base, id, 300, kerf_tests::finished).await;
    assert_eq!(done["status"], "failed", "{done}");
    assert_too_large(&done["error"]);
    assert_eq!(done["error"]["errors"][0]["path"], "operations[1]", "{done}");
    // A job within it runs to the end.
    let job = json!({"operations": [kerf_cases::operation("deburr", many_loops(0.01))]});
    let id = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await["id"].as_i64().unwrap();
    let done = kerf_tests::poll_job(&app.client, &app.base, id, 300, kerf_tests::finished).await;
    assert_eq!(done["status"], "done", "{done}");
}

/// A raw connection to `app` that has sent `head`.
async fn connect(app: &TestApp, head: &[u8]) -> tokio::net::TcpStream {
    let mut stream = tokio::net::TcpStream::connect(app.base.trim_start_matches("http://")).await.unwrap();
    stream.write_all(head).await.unwrap();
    stream
}

#[tokio::test(flavor = "multi_thread")]
async fn trickling_uploads_do_not_starve_a_small_call() {
    // Four uploads (three predict uploads declaring 128 MiB, a job file as a form) that send a
    // byte every 200 ms: they hold the budget by what they sent (a few bytes), so a small call is
    // answered while they trickle; then each is dropped with 408 for arriving slower than
    // 1 KiB/s over the window.
    let app = TestApp::spawn_with(Limits {
        answer_budget_bytes: 2 * 1024 * 1024,
        min_body_rate: 1024,
        body_rate_window: Duration::from_secs(2),
        ..Limits::default()
    })
    .await;
    let predict: &[u8] =
        b"POST /api/v1/predict HTTP/1.1\r\nHost: kerf\r\nContent-Type: multipart/form-data; boundary=XX\r\n\
                 Content-Length: 134217728\r\n\r\n--XX\r\nContent-Disposition: form-data; name=\"stock\"\r\n\r\n";
    // A job file sent as a form is held to the same rate.
    let job: &[u8] = b"POST /api/v1/jobs HTTP/1.1\r\nHost: kerf\r\nContent-Type: multipart/form-data; boundary=XX\r\n\
                 Content-Length: 1000000\r\n\r\n--XX\r\nContent-Disposition: form-data; name=\"file\"\r\n\r\n";
    let mut trickles = Vec::new();
    for head in [predict, predict, predict, job] {
        let mut stream = connect(&app, head).await;
        trickles.push(tokio::spawn(async move {
            use tokio::io::AsyncReadExt;
            let mut answer = Vec::new();
            for _ in 0..300 {
                if stream.write_all(b"s").await.is_err() {
                    break;
                }
                let mut buffer = [0_u8; 4096];
                match tokio::time::timeout(Duration::from_millis(200), stream.read(&mut buffer)).await {
                    Ok(Ok(0) | Err(_)) => break,
                    Ok(Ok(n)) => answer.extend_from_slice(&buffer[..n]),
                    Err(_) => {}
                }
            }
            String::from_utf8_lossy(&answer).into_owned()
        }));
    }
    // The uploads are being received by now.
    tokio::time::sleep(Duration::from_millis(400)).await;
    let quick = json!({"curve": {"kind": "arc", "centre": [0, 0], "radius": 10, "start_deg": 0, "end_deg": 90},
                       "feed": 1000, "block_time_ms": 4});
    json_with(app.post_json("/api/v1/segment", &quick).await, 200).await;
    for trickle in trickles {
        let answer = trickle.await.unwrap();
        assert!(answer.starts_with("HTTP/1.1 408"), "{answer}");
        assert!(answer.contains("application/problem+json") && answer.contains("E_BODY"), "{answer}");
        assert!(answer.contains("minimum of 1024 bytes/s"), "{answer}");
    }
}
