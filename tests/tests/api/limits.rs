//! Holding up under slow or bursty work: a synchronous solver call over the time limit is told to
//! submit a job (422 `E_TIMEOUT`, not a 5xx), a burst beyond the solver slots gets 429 instead of piling up, and the
//! service answers normally afterwards.

use std::time::Duration;

use kerf_server::state::Limits;
use kerf_tests::{TestApp, json_with, problem};
use serde_json::json;

/// A deburr request that takes a few hundred milliseconds: exact width at a tiny tolerance.
fn slow_request() -> serde_json::Value {
    json!({"tool": {"kind": "ball", "radius": 3},
           "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
           "hole": {"shape": "round", "radius": 10}, "edge": "outer", "cut_amount": 0.5,
           "tolerance": 1e-6, "method": "exact"})
}

#[tokio::test(flavor = "multi_thread")]
async fn slow_synchronous_call_is_told_to_submit_a_job() {
    let app = TestApp::spawn_with(Limits { solver_time_limit: Duration::from_millis(20), ..Limits::default() }).await;
    let answer = problem(app.post_json("/api/v1/deburr", &slow_request()).await, 422).await;
    assert_eq!(answer["code"], "E_TIMEOUT");
    assert!(answer["detail"].as_str().unwrap().contains("/api/v1/jobs"), "{answer}");
    // The same work as a job runs to the end.
    let job = json!({"operations": [{"operation": "deburr", "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
        "hole": {"shape": "round", "radius": 10}, "edge": "outer", "cut_amount": 0.5, "tolerance": 1e-6, "method": "exact"}]});
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
