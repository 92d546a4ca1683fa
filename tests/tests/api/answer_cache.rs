//! The answer cache: a question asked again is answered from the cache with
//! the same bytes; a changed tool, machine, format or program option is a new question; a
//! zero budget keeps nothing. (Requests with `?timings=true` or an upload are never looked up:
//! `server/src/http/solve.rs`.)

use kerf_tests::TestApp;
use reqwest::Response;
use serde_json::{Value, json};

fn deburr() -> Value {
    kerf_cases::with(kerf_cases::deburr::case_1(), json!({"tool": 7, "tolerance": 0.01}))
}

/// Whether the answer came from the cache (its `Server-Timing` says so), and its bytes.
async fn answer(response: Response) -> (bool, Vec<u8>) {
    assert_eq!(response.status(), 200);
    let timing = response.headers()["server-timing"].to_str().unwrap().to_owned();
    (timing.starts_with("cache"), response.bytes().await.unwrap().to_vec())
}

#[tokio::test]
async fn the_same_question_is_answered_from_the_cache_a_changed_one_is_solved() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let (cached, first) = answer(app.post_json("/api/v1/deburr", &deburr()).await).await;
    assert!(!cached, "a first question is solved");
    let (cached, again) = answer(app.post_json("/api/v1/deburr", &deburr()).await).await;
    assert!(cached, "the same question is answered from the cache");
    assert_eq!(first, again, "byte for byte");

    // The program is a different question; asked twice, the second comes from the cache too.
    let gcode = app.client.post(app.url("/api/v1/deburr?format=gcode")).json(&deburr()).send().await.unwrap();
    let (cached, program) = answer(gcode).await;
    assert!(!cached && program.starts_with(b"%"), "{}", String::from_utf8_lossy(&program[..40]));
    let linuxcnc = app.client.post(app.url("/api/v1/deburr?format=gcode&dialect=linuxcnc")).json(&deburr());
    let (cached, other) = answer(linuxcnc.send().await.unwrap()).await;
    assert!(!cached && other != program, "another dialect is another question");

    // A changed tool is a new question: the answer follows the table, never a stale one.
    app.register_tool(7, &json!({"kind": "ball", "radius": 2})).await;
    let (cached, smaller) = answer(app.post_json("/api/v1/deburr", &deburr()).await).await;
    assert!(!cached, "the tool changed");
    assert_ne!(smaller, first, "the centres follow the smaller ball");
    // The old tool back: its answer again, byte for byte.
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let (_, back) = answer(app.post_json("/api/v1/deburr", &deburr()).await).await;
    assert_eq!(back, first);

    let metrics = app.get("/metrics").await.text().await.unwrap();
    assert!(metrics.contains(r#"kerf_answer_cache_lookups_total{result="hit"}"#), "{metrics}");
}

#[tokio::test]
async fn a_zero_budget_caches_nothing() {
    let app = TestApp::spawn_configured(|config| config.limits.answer_cache_bytes = 0).await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let (cached, first) = answer(app.post_json("/api/v1/deburr", &deburr()).await).await;
    let (cached_again, again) = answer(app.post_json("/api/v1/deburr", &deburr()).await).await;
    assert!(!cached && !cached_again, "solved both times");
    assert_eq!(first, again, "the solver is deterministic");
}
