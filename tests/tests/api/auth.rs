//! The optional API token: writes need it, reads stay open unless private.

use kerf_server::auth::Auth;
use kerf_tests::{Store, TestApp, json_with, problem};
use serde_json::json;

async fn app(store: Store, private: bool) -> Option<TestApp> {
    TestApp::spawn_on(store, |config| config.auth = Auth { token: Some("shop-floor-7".to_owned()), private }).await
}

async fn token_guards_writes(store: Store) {
    let Some(app) = app(store, false).await else { return };
    let tool = json!({"kind": "ball", "radius": 3});
    let answer = problem(app.put_json("/api/v1/tools/7", &tool).await, 401).await;
    assert_eq!(answer["code"], "E_UNAUTHORIZED");
    let wrong =
        app.client.put(app.url("/api/v1/tools/7")).bearer_auth("shop-floor-8").json(&tool).send().await.unwrap();
    problem(wrong, 401).await;
    let right =
        app.client.put(app.url("/api/v1/tools/7")).bearer_auth("shop-floor-7").json(&tool).send().await.unwrap();
    json_with(right, 201).await;
    // Reads, the page and the health check stay open.
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await.as_array().unwrap().len(), 1);
    assert_eq!(app.get("/").await.status(), 200);
    // Solver calls and job submissions change nothing stored but use the machine: they need it too.
    let body = json!({"tool": 7, "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 5}, "edge": "outer", "cut_amount": 0.2});
    problem(app.post_json("/api/v1/deburr", &body).await, 401).await;
    let response =
        app.client.post(app.url("/api/v1/deburr")).bearer_auth("shop-floor-7").json(&body).send().await.unwrap();
    assert_eq!(response.status(), 200);
    // A job operation's cut stock is read with GET but solves the operation again.
    problem(app.get("/api/v1/jobs/1/stock?operation=0").await, 401).await;
    problem(app.get("/api/v1/jobs/1/stock/program?operation=0").await, 401).await;
    let response =
        app.client.get(app.url("/api/v1/jobs/1/stock?operation=0")).bearer_auth("shop-floor-7").send().await.unwrap();
    problem(response, 404).await;
    problem(app.delete("/api/v1/tools/7").await, 401).await;
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await.as_array().unwrap().len(), 1, "not deleted");
}

async fn private_mode_guards_reads(store: Store) {
    let Some(app) = app(store, true).await else { return };
    problem(app.get("/api/v1/tools").await, 401).await;
    problem(app.get("/api/v1/jobs").await, 401).await;
    let response = app.client.get(app.url("/api/v1/tools")).bearer_auth("shop-floor-7").send().await.unwrap();
    assert_eq!(json_with(response, 200).await, json!([]));
    assert_eq!(app.get("/healthz").await.status(), 200);
    assert_eq!(app.get("/").await.status(), 200);
    assert_eq!(app.get("/api/v1/openapi.json").await.status(), 200);
}

kerf_tests::on_both_stores!(token_guards_writes, private_mode_guards_reads);
