//! `GET /metrics` (Prometheus text from the `prometheus-client` crate) and `GET /readyz`, on both
//! stores. The metrics belong to the process, which the tests share: counts only grow.

use kerf_tests::{Store, TestApp, finished, json_with, poll_job};
use serde_json::json;

/// The value of the first sample line that starts with `prefix`.
fn sample(text: &str, prefix: &str) -> Option<f64> {
    text.lines().find(|line| line.starts_with(prefix)).and_then(|line| line.rsplit(' ').next()?.parse().ok())
}

async fn metrics_and_readiness(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let ready = json_with(app.get("/readyz").await, 200).await;
    assert_eq!(ready["status"], "ready");
    assert_eq!(ready["database"], if store == Store::Postgres { "postgres" } else { "sqlite" });

    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    json_with(app.get("/api/v1/tools/7").await, 200).await;
    let deburr = json!({"tool": 7, "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15,
        "outer_radius": 25}, "hole": {"shape": "round", "radius": 5}, "edge": "outer", "cut_amount": 0.2});
    assert_eq!(app.post_json("/api/v1/deburr", &deburr).await.status(), 200);
    let mut operation = deburr.clone();
    operation["operation"] = json!("deburr");
    operation["cut_amount"] = json!(0.25);
    let submitted = json_with(app.post_json("/api/v1/jobs", &json!({"operations": [operation]})).await, 202).await;
    let id = submitted["id"].as_i64().unwrap();
    assert_eq!(poll_job(&app.client, &app.base, id, 60, finished).await["status"], "done");

    let response = app.get("/metrics").await;
    assert_eq!(response.status(), 200);
    let content_type = response.headers()["content-type"].to_str().unwrap().to_owned();
    assert!(content_type.starts_with("application/openmetrics-text"), "{content_type}");
    let text = response.text().await.unwrap();
    let requests = sample(&text, r#"kerf_http_requests_total{route="/api/v1/tools/{number}",status="200"}"#);
    assert!(requests.is_some_and(|n| n >= 1.0), "{text}");
    assert!(text.contains("# TYPE kerf_http_request_duration_seconds histogram"), "{text}");
    assert!(text.contains(r#"kerf_http_request_duration_seconds_bucket{le="#), "{text}");
    assert!(text.contains("# TYPE kerf_solver_seconds histogram"), "{text}");
    let solves = sample(&text, r#"kerf_solver_seconds_count{capability="deburr"}"#);
    assert!(solves.is_some_and(|n| n >= 2.0), "the request and the job's operation: {text}");
    assert!(sample(&text, r#"kerf_jobs{state="done"}"#).is_some_and(|n| n >= 1.0), "{text}");
    assert_eq!(sample(&text, r#"kerf_jobs{state="running"}"#), Some(0.0), "{text}");
    assert!(sample(&text, "kerf_job_store_bytes").is_some_and(|n| n > 100.0), "the stored job: {text}");
    assert!(sample(&text, "kerf_job_chunks_claimed_total").is_some_and(|n| n >= 1.0), "{text}");
    // Unknown paths are one label, not one per path.
    app.get("/no/such/path/12345").await;
    let text = app.get("/metrics").await.text().await.unwrap();
    assert!(text.contains(r#"route="unmatched",status="404""#), "{text}");
    assert!(!text.contains("12345"), "{text}");
}

kerf_tests::on_both_stores!(metrics_and_readiness);
