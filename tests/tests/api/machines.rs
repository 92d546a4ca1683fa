//! The machines registry: create, replace, read, list, delete, bad names and values, and
//! survival across a restart, and the preconditions of a write (`If-Match`, `If-None-Match`).

use kerf_tests::{Store, TestApp, json_with, problem};
use serde_json::json;

async fn machine_crud_and_restart(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await, json!([]));

    let hsc = json!({"block_time_ms": 4, "max_feed": 12000, "dialect": "linuxcnc", "margin": 1.1,
                     "min_chord_error": 0.001, "description": "HSC mode, 3 axes, look-ahead on"});
    let created = json_with(app.put_json("/api/v1/machines/dmu-50_hsc.2", &hsc).await, 201).await;
    assert_eq!(
        created,
        json!({"name": "dmu-50_hsc.2", "block_time_ms": 4.0, "max_feed": 12000.0, "dialect": "linuxcnc",
               "margin": 1.1, "min_chord_error": 0.001, "description": "HSC mode, 3 axes, look-ahead on"})
    );
    // A replace stores the new record whole; dialect defaults to fanuc.
    let replaced = json_with(
        app.put_json("/api/v1/machines/dmu-50_hsc.2", &json!({"block_time_ms": 2, "max_feed": 15000})).await,
        200,
    )
    .await;
    assert_eq!(
        replaced,
        json!({"name": "dmu-50_hsc.2", "block_time_ms": 2.0, "max_feed": 15000.0, "dialect": "fanuc"})
    );

    // A GET → edit → PUT round trip carries the name in the body.
    let mut fetched = json_with(app.get("/api/v1/machines/dmu-50_hsc.2").await, 200).await;
    fetched["margin"] = json!(1.2);
    assert_eq!(json_with(app.put_json("/api/v1/machines/dmu-50_hsc.2", &fetched).await, 200).await["margin"], 1.2);

    json_with(app.put_json("/api/v1/machines/old-fanuc", &json!({"block_time_ms": 8, "max_feed": 6000})).await, 201)
        .await;
    json_with(app.put_json("/api/v1/machines/Bench", &json!({"block_time_ms": 1, "max_feed": 30000})).await, 201).await;
    let list = json_with(app.get("/api/v1/machines").await, 200).await;
    let names: Vec<&str> = list.as_array().unwrap().iter().map(|m| m["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["Bench", "dmu-50_hsc.2", "old-fanuc"], "list ordered by name");

    app.restart().await;
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await, list, "machines survive a restart");

    assert_eq!(app.delete("/api/v1/machines/old-fanuc").await.status(), 204);
    let answer = problem(app.get("/api/v1/machines/old-fanuc").await, 404).await;
    assert_eq!(answer["code"], "E_NOT_FOUND");
    problem(app.delete("/api/v1/machines/old-fanuc").await, 404).await;
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await.as_array().unwrap().len(), 2);
    app.shutdown().await;
}

async fn bad_machines_are_refused_and_nothing_is_stored(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let good = json!({"block_time_ms": 4, "max_feed": 10000});
    let long_name = format!("/api/v1/machines/{}", "m".repeat(65));
    let long_text = "x".repeat(201);
    // (what, path, body, status, field, code)
    let cases = vec![
        ("name with a space", "/api/v1/machines/a%20b", good.clone(), 422, "name", "E_INPUT"),
        ("name starting with a dot", "/api/v1/machines/.hidden", good.clone(), 422, "name", "E_INPUT"),
        ("name with a slash", "/api/v1/machines/a%2Fb", good.clone(), 422, "name", "E_INPUT"),
        ("name too long", long_name.as_str(), good.clone(), 422, "name", "E_INPUT"),
        (
            "body name differs",
            "/api/v1/machines/m1",
            json!({"name": "m2", "block_time_ms": 4, "max_feed": 1}),
            422,
            "name",
            "E_INPUT",
        ),
        (
            "zero block time",
            "/api/v1/machines/m1",
            json!({"block_time_ms": 0, "max_feed": 10000}),
            422,
            "block_time_ms",
            "E_INPUT",
        ),
        (
            "negative block time",
            "/api/v1/machines/m1",
            json!({"block_time_ms": -4, "max_feed": 10000}),
            422,
            "block_time_ms",
            "E_INPUT",
        ),
        ("zero feed", "/api/v1/machines/m1", json!({"block_time_ms": 4, "max_feed": 0}), 422, "max_feed", "E_INPUT"),
        (
            "margin below 1",
            "/api/v1/machines/m1",
            json!({"block_time_ms": 4, "max_feed": 1e4, "margin": 0.9}),
            422,
            "margin",
            "E_INPUT",
        ),
        (
            "negative minimum chord error",
            "/api/v1/machines/m1",
            json!({"block_time_ms": 4, "max_feed": 1e4, "min_chord_error": -1}),
            422,
            "min_chord_error",
            "E_INPUT",
        ),
        (
            "description too long",
            "/api/v1/machines/m1",
            json!({"block_time_ms": 4, "max_feed": 1e4, "description": long_text}),
            422,
            "description",
            "E_INPUT",
        ),
        ("missing block time", "/api/v1/machines/m1", json!({"max_feed": 10000}), 400, "body", "E_JSON"),
        (
            "unknown field",
            "/api/v1/machines/m1",
            json!({"block_time_ms": 4, "max_feed": 1e4, "axes": 5}),
            400,
            "axes",
            "E_JSON",
        ),
        (
            "unknown dialect",
            "/api/v1/machines/m1",
            json!({"block_time_ms": 4, "max_feed": 1e4, "dialect": "mazak"}),
            400,
            "dialect",
            "E_JSON",
        ),
        (
            "string for a number",
            "/api/v1/machines/m1",
            json!({"block_time_ms": "4", "max_feed": 1e4}),
            400,
            "block_time_ms",
            "E_JSON",
        ),
    ];
    let mut mismatches = Vec::new();
    for (what, path, body, status, field, code) in cases {
        let answer = problem(app.put_json(path, &body).await, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
    }
    let answer = problem(app.get("/api/v1/machines/.x").await, 422).await;
    assert_eq!(answer["errors"][0]["path"], "name");
    let answer = problem(app.delete("/api/v1/machines/a%20b").await, 422).await;
    assert_eq!(answer["errors"][0]["path"], "name");
    let raw = app
        .client
        .put(app.url("/api/v1/machines/m1"))
        .header("content-type", "text/plain")
        .body("{}")
        .send()
        .await
        .unwrap();
    problem(raw, 415).await;
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
    assert_eq!(json_with(app.get("/api/v1/machines").await, 200).await, json!([]), "database unchanged");
}

async fn machine_preconditions(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    super::tools::conditional_writes(
        &app,
        "/api/v1/machines/dmu50",
        &json!({"block_time_ms": 4, "max_feed": 12000, "dialect": "linuxcnc"}),
        &json!({"block_time_ms": 2, "max_feed": 15000}),
        &json!({"block_time_ms": 2, "max_feed": 15000, "margin": 1.2}),
    )
    .await;
    app.shutdown().await;
}

kerf_tests::on_both_stores!(
    machine_crud_and_restart,
    bad_machines_are_refused_and_nothing_is_stored,
    machine_preconditions
);
