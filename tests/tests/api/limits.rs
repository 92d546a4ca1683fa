//! Holding up under slow or bursty work: a synchronous solver call over the time limit is told to
//! submit a job (422 `E_TIMEOUT`, not a 5xx), a burst beyond the solver slots gets 429 instead of piling up, and the
//! service answers normally afterwards.

use std::time::Duration;

use kerf_server::state::Limits;
use kerf_tests::{TestApp, json_with, problem};

use kerf_cases::contour::circle;
use serde_json::json;

/// A deburr request that takes a few hundred milliseconds: exact width at a tiny tolerance.
fn slow_request() -> serde_json::Value {
    kerf_cases::with(kerf_cases::deburr::case_1(), json!({"tolerance": 1e-6, "method": "exact"}))
}

#[tokio::test(flavor = "multi_thread")]
async fn slow_synchronous_call_is_told_to_submit_a_job() {
    let app = TestApp::spawn_with(Limits { solver_time_limit: Duration::from_millis(20), ..Limits::default() }).await;
    let answer = problem(app.post_json("/api/v1/deburr", &slow_request()).await, 422).await;
    assert_eq!(answer["code"], "E_TIMEOUT");
    assert!(answer["detail"].as_str().unwrap().contains("/api/v1/jobs"), "{answer}");
    // The same work as a job runs to the end.
    let job = json!({"operations": [kerf_cases::operation("deburr", slow_request())]});
    let id = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await["id"].as_i64().unwrap();
    let done = kerf_tests::poll_job(&app.client, &app.base, id, 60, kerf_tests::finished).await;
    assert_eq!(done["status"], "done");
}

#[tokio::test(flavor = "multi_thread")]
async fn burst_beyond_the_solver_slots_gets_429() {
    let app = TestApp::spawn_configured(|config| {
        config.solver_slots = 1;
        config.limits.solver_queue_wait = Duration::from_millis(10);
    })
    .await;
    let requests: Vec<_> = (0..8)
        .map(|_| {
            let (client, url, body) = (app.client.clone(), app.url("/api/v1/deburr"), slow_request());
            tokio::spawn(async move { client.post(url).json(&body).send().await.unwrap().status().as_u16() })
        })
        .collect();
    let mut statuses = Vec::new();
    for request in requests {
        statuses.push(request.await.unwrap());
    }
    assert!(statuses.iter().all(|s| *s == 200 || *s == 429), "{statuses:?}");
    assert!(statuses.contains(&200) && statuses.contains(&429), "{statuses:?}");
    // Afterwards the service answers as usual.
    assert_eq!(app.get("/healthz").await.status(), 200);
    let mut quick = slow_request();
    quick["tolerance"] = json!(0.01);
    quick["method"] = json!("tangent");
    json_with(app.post_json("/api/v1/deburr", &quick).await, 200).await;
}

/// A closed zigzag of `points` points (radii 30 and 33 alternating): every point is a protruding
/// corner, and its edges crowd the search grid, so looping it takes long.
fn zigzag(points: usize) -> Vec<[f64; 2]> {
    (0..points)
        .map(|k| {
            let angle = std::f64::consts::TAU * k as f64 / points as f64;
            let radius = if k % 2 == 0 { 30.0 } else { 33.0 };
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect()
}

#[tokio::test(flavor = "multi_thread")]
async fn timed_out_work_stops_and_frees_its_slot() {
    // One slot, a short time limit and a queue wait far shorter than the abandoned work would take
    // to finish: a request after two timed-out ones is served only if the work really stopped.
    // The wait is generous (10 s) so that a loaded machine, slow to reach the work's first check,
    // does not fail it; the work would take minutes.
    let app = TestApp::spawn_configured(|config| {
        config.solver_slots = 1;
        config.limits.solver_time_limit = Duration::from_millis(100);
        config.limits.solver_queue_wait = Duration::from_secs(10);
    })
    .await;
    let ball = json!({"kind": "ball", "radius": 3});
    // Looping 199 000 crowded corners takes minutes; the program of 4000 layers of a 600-point
    // circle (2.4 million moves, over the JSON answer's limit) tens of seconds.
    let slow = [
        (
            "/api/v1/contour/loops",
            json!({"tool": ball, "path": zigzag(199_000), "material_side": "left", "tolerance": 1e-6}),
        ),
        (
            "/api/v1/contour?format=gcode",
            json!({"tool": ball, "contour": circle(600), "side": "outside",
                   "depths": {"top": 0, "bottom": -100, "step": 0.025}, "feed": 800}),
        ),
    ];
    for (path, body) in &slow {
        for _ in 0..2 {
            let answer = problem(app.post_json(path, body).await, 422).await;
            assert_eq!(answer["code"], "E_TIMEOUT", "{path}: {answer}");
        }
        let quick = json!({"curve": {"kind": "arc", "centre": [0, 0], "radius": 10, "start_deg": 0, "end_deg": 90},
                           "feed": 1000, "block_time_ms": 4});
        json_with(app.post_json("/api/v1/segment", &quick).await, 200).await;
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn a_segmentation_far_over_the_block_limit_is_refused_before_it_starts() {
    // About 6.5·10¹² blocks at a feed of 10⁻⁷ mm/min: refused from the curve's radii, not after
    // a million blocks. The time limit is shorter than cutting the limit's worth of blocks takes.
    let app = TestApp::spawn_with(Limits { solver_time_limit: Duration::from_millis(300), ..Limits::default() }).await;
    let body = json!({"curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [50, 20], "start_deg": 0, "end_deg": 270},
                      "feed": 1e-7, "block_time_ms": 4});
    for mode in ["curve", "guarantee"] {
        let mut body = body.clone();
        body["mode"] = json!(mode);
        let answer = problem(app.post_json("/api/v1/segment", &body).await, 422).await;
        assert_eq!(answer["code"], "E_TOO_MANY_BLOCKS", "{mode}: {answer}");
        assert!(answer["detail"].as_str().unwrap().contains("at least"), "{answer}");
    }
}

/// A raw connection to `app` that has sent `bytes` (a request head, perhaps part of a body).
async fn raw_request(app: &TestApp, bytes: &[u8]) -> tokio::net::TcpStream {
    use tokio::io::AsyncWriteExt;
    let mut stream = tokio::net::TcpStream::connect(app.base.trim_start_matches("http://")).await.unwrap();
    stream.write_all(bytes).await.unwrap();
    stream
}

/// Reads from `stream` until `done` says what was received is enough or the server closes it;
/// with whether that happened before `seconds` passed.
async fn read_until(stream: &mut tokio::net::TcpStream, seconds: u64, done: fn(&[u8]) -> bool) -> (String, bool) {
    use tokio::io::AsyncReadExt;
    let mut received = Vec::new();
    let finished = tokio::time::timeout(Duration::from_secs(seconds), async {
        let mut buffer = [0_u8; 4096];
        while !done(&received) {
            match stream.read(&mut buffer).await {
                Ok(0) | Err(_) => break,
                Ok(n) => received.extend_from_slice(&buffer[..n]),
            }
        }
    })
    .await;
    (String::from_utf8_lossy(&received).into_owned(), finished.is_ok())
}

/// Reads from `stream` until the server closes it (or 30 s pass, which fails the test).
async fn read_until_closed(stream: &mut tokio::net::TcpStream) -> String {
    let (received, closed) = read_until(stream, 30, |_| false).await;
    assert!(closed, "the server kept the connection open; received: {received}");
    received
}

#[tokio::test(flavor = "multi_thread")]
async fn clients_that_stall_are_cut_off() {
    let app = TestApp::spawn_with(Limits {
        header_read_timeout: Duration::from_millis(500),
        body_idle_timeout: Duration::from_millis(500),
        ..Limits::default()
    })
    .await;
    // Headers that never end: the connection is closed.
    let mut stream = raw_request(&app, b"GET /healthz HTTP/1.1\r\nHost: kerf\r\n").await;
    read_until_closed(&mut stream).await;
    // A body that stops coming: the request ends with a client error and stores nothing.
    let mut stream = raw_request(
        &app,
        b"PUT /api/v1/tools/7 HTTP/1.1\r\nHost: kerf\r\nContent-Type: application/json\r\nContent-Length: 200\r\n\r\n{\"kind\": ",
    )
    .await;
    let answer = read_until_closed(&mut stream).await;
    let status: u16 = answer.split(' ').nth(1).and_then(|s| s.parse().ok()).unwrap_or(0);
    assert!((400..500).contains(&status), "{answer}");
    assert!(answer.contains("application/problem+json"), "{answer}");
    assert_eq!(app.get("/api/v1/tools/7").await.status(), 404);
    // The service still answers.
    assert_eq!(app.get("/healthz").await.status(), 200);
}

#[tokio::test(flavor = "multi_thread")]
async fn a_trickling_client_does_not_keep_a_stopped_server_alive() {
    use tokio::io::AsyncWriteExt;
    let mut app = TestApp::spawn_with(Limits {
        body_idle_timeout: Duration::from_secs(60),
        shutdown_grace: Duration::from_millis(500),
        ..Limits::default()
    })
    .await;
    let mut stream = raw_request(
        &app,
        b"PUT /api/v1/tools/7 HTTP/1.1\r\nHost: kerf\r\nContent-Type: application/json\r\nContent-Length: 500\r\n\r\n{",
    )
    .await;
    // One byte every 200 ms: never idle long enough for the body timeout.
    let trickle = tokio::spawn(async move {
        for _ in 0..400 {
            if stream.write_all(b" ").await.is_err() {
                break;
            }
            tokio::time::sleep(Duration::from_millis(200)).await;
        }
    });
    tokio::time::sleep(Duration::from_millis(600)).await;
    let stopped = tokio::time::timeout(Duration::from_secs(30), app.shutdown()).await;
    assert!(stopped.is_ok(), "the stopped server waited for the trickling client");
    trickle.abort();
    // Nothing half-written: the tool was never stored.
    app.restart().await;
    assert_eq!(app.get("/api/v1/tools/7").await.status(), 404);
}

#[tokio::test(flavor = "multi_thread")]
async fn slow_readers_of_large_answers_hold_a_bounded_budget() {
    // A 32 MiB budget and a 19 MB answer that its client does not read: the next large answer
    // gets 429 with Retry-After until the first one has been read. Without the contour's own
    // verification, which is most of each request's time in a debug build (three solves near
    // the 30 s synchronous limit on a loaded machine) and not what this checks.
    let app = TestApp::spawn_with(Limits { answer_budget_bytes: 32 * 1024 * 1024, ..Limits::default() }).await;
    let large = json!({"tool": {"kind": "ball", "radius": 3}, "contour": circle(600), "side": "outside",
                       "depths": {"top": 0, "bottom": -100, "step": 0.25}, "feed": 800,
                       "verification": {"enabled": false}});
    let unread = app.post_json("/api/v1/contour", &large).await;
    assert_eq!(unread.status(), 200);
    let length: usize = unread.headers()["content-length"].to_str().unwrap().parse().unwrap();
    assert!(length > 10_000_000, "{length}");
    let refused = app.post_json("/api/v1/contour", &large).await;
    assert!(refused.headers().contains_key("retry-after"), "{:?}", refused.headers());
    let answer = problem(refused, 429).await;
    assert_eq!(answer["code"], "E_BUSY", "{answer}");
    // Reading the large answer gives the budget back; it arrives whole.
    let body = unread.bytes().await.unwrap();
    assert_eq!(body.len(), length);
    serde_json::from_slice::<serde_json::Value>(&body).unwrap();
    assert_eq!(app.post_json("/api/v1/contour", &large).await.bytes().await.unwrap(), body);
}

#[tokio::test(flavor = "multi_thread")]
async fn slow_uploads_hold_a_bounded_budget() {
    // An upload that declares 3 MiB, sends 2.5 MiB and stalls holds the 2 MiB budget by what it
    // sent: a second upload gets 429 with Retry-After instead of piling up in memory.
    // The rate window is longer than the test, so the stalled upload is not dropped for its rate
    // before the second one asks, however slowly a loaded machine receives it.
    let app = TestApp::spawn_with(Limits {
        answer_budget_bytes: 2 * 1024 * 1024,
        body_rate_window: Duration::from_secs(120),
        ..Limits::default()
    })
    .await;
    let mut head = b"POST /api/v1/predict HTTP/1.1\r\nHost: kerf\r\nContent-Type: multipart/form-data; boundary=XX\r\n\
          Content-Length: 3145728\r\n\r\n--XX\r\nContent-Disposition: form-data; name=\"stock\"\r\n\r\nsolid"
        .to_vec();
    head.resize(head.len() + 5 * 512 * 1024, b' ');
    // Each second request holds a KiB of the budget while it is read. One read just as the first
    // upload's received bytes reach the whole budget leaves that upload a KiB short, and the
    // upload is refused instead (the budget holds the same either way): the first upload is then
    // sent again, until the second request is the one refused.
    let mut refused = None;
    'uploads: for _ in 0..20 {
        let slow = raw_request(&app, &head).await;
        for _ in 0..400 {
            let response = app
                .client
                .post(app.url("/api/v1/predict"))
                .header("content-type", "application/json")
                .body("{}")
                .send()
                .await
                .unwrap();
            if response.status() == 429 {
                refused = Some((response, slow));
                break 'uploads;
            }
            if server_answered(&slow) {
                continue 'uploads;
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
        break;
    }
    let (refused, mut slow) = refused.expect("a second upload is refused while the first holds the budget");
    assert!(refused.headers().contains_key("retry-after"));
    assert_eq!(problem(refused, 429).await["code"], "E_BUSY");
    // When the slow client goes away, its share comes back: the server reads the end of its
    // body, gives up the upload and closes the connection.
    use tokio::io::AsyncWriteExt;
    slow.shutdown().await.unwrap();
    read_until_closed(&mut slow).await;
    let mut answered = 429;
    for _ in 0..100 {
        answered = app
            .client
            .post(app.url("/api/v1/predict"))
            .header("content-type", "application/json")
            .body("{}")
            .send()
            .await
            .unwrap()
            .status()
            .as_u16();
        if answered != 429 {
            break;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert_eq!(answered, 400, "an empty predict request is a bad request once the budget is free");
}

/// Whether the server has answered on `stream` (or closed it), without waiting.
fn server_answered(stream: &tokio::net::TcpStream) -> bool {
    let mut buffer = [0_u8; 64];
    !matches!(stream.try_read(&mut buffer), Err(error) if error.kind() == std::io::ErrorKind::WouldBlock)
}

#[tokio::test(flavor = "multi_thread")]
async fn slow_readers_of_large_job_programs_hold_a_bounded_budget() {
    // A job whose result and program (some 60 MB together) are built within a 64 MiB budget, then
    // served under a 1 MiB budget: while one client does not read its program of some 20 MB, the
    // next download of a large job output gets 429 with Retry-After instead of another copy in
    // memory.
    let mut app = TestApp::spawn_with(Limits { answer_budget_bytes: 64 * 1024 * 1024, ..Limits::default() }).await;
    let job = json!({"name": "deep contour", "operations": [{"operation": "contour",
        "tool": {"kind": "ball", "radius": 3}, "contour": circle(600), "side": "outside",
        "depths": {"top": 0, "bottom": -250, "step": 0.25}, "feed": 800}]});
    let id = json_with(app.post_json("/api/v1/jobs", &job).await, 202).await["id"].as_i64().unwrap();
    let done = kerf_tests::poll_job(&app.client, &app.base, id, 300, kerf_tests::finished).await;
    assert_eq!(done["status"], "done", "{done}");
    app.config.limits.answer_budget_bytes = 1024 * 1024;
    app.restart().await;
    let program = format!("/api/v1/jobs/{id}/gcode");
    let unread = app.get(&program).await;
    assert_eq!(unread.status(), 200);
    let length: usize = unread.headers()["content-length"].to_str().unwrap().parse().unwrap();
    assert!(length > 15_000_000, "{length}");
    for path in [program.clone(), format!("/api/v1/jobs/{id}")] {
        let refused = app.get(&path).await;
        assert!(refused.headers().contains_key("retry-after"), "{path}: {:?}", refused.headers());
        assert_eq!(problem(refused, 429).await["code"], "E_BUSY", "{path}");
    }
    // Reading it gives the budget back; it arrives whole.
    let first = unread.text().await.unwrap();
    assert_eq!(first.len(), length);
    assert!(first.trim_end().ends_with('%') && first.contains("M30"), "a whole program");
    assert_eq!(app.get_text(&program, 200).await, first);
    json_with(app.get(&format!("/api/v1/jobs/{id}")).await, 200).await;
}

/// Reads from `stream` until the end of a response head (or 10 s pass, which fails the test).
async fn read_head(stream: &mut tokio::net::TcpStream) -> String {
    let (received, read) = read_until(stream, 10, |received| received.windows(4).any(|w| w == b"\r\n\r\n")).await;
    assert!(read, "no answer; received: {received}");
    received
}

#[tokio::test(flavor = "multi_thread")]
async fn a_body_declared_over_the_limit_gets_413_before_100_continue() {
    let app = TestApp::spawn_with(Limits { max_body_bytes: 1024, ..Limits::default() }).await;
    for (route, media_type) in [
        ("PUT /api/v1/tools/7", "application/json"),
        ("POST /api/v1/jobs", "application/toml"),
        ("POST /api/v1/jobs", "multipart/form-data; boundary=XX"),
        ("POST /api/v1/predict", "application/json"),
    ] {
        let head = format!(
            "{route} HTTP/1.1\r\nHost: kerf\r\nContent-Type: {media_type}\r\nContent-Length: 999999999999\r\n\
             Expect: 100-continue\r\n\r\n"
        );
        let mut stream = raw_request(&app, head.as_bytes()).await;
        let answer = read_head(&mut stream).await;
        assert!(answer.starts_with("HTTP/1.1 413"), "{route} ({media_type}): {answer}");
        assert!(answer.contains("application/problem+json"), "{answer}");
    }
    // Within the limit the client is told to go on.
    let mut stream = raw_request(
        &app,
        b"PUT /api/v1/tools/7 HTTP/1.1\r\nHost: kerf\r\nContent-Type: application/json\r\nContent-Length: 30\r\n\
          Expect: 100-continue\r\n\r\n",
    )
    .await;
    assert!(read_head(&mut stream).await.starts_with("HTTP/1.1 100"));
}
