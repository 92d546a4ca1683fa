//! The tool table: create, replace, read, list, delete, and survival across a restart.

use kerf_tests::{Store, TestApp, json_with, problem};
use serde_json::json;

async fn tool_crud_and_restart(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    assert_eq!(json_with(app.get("/healthz").await, 200).await["status"], "ok");
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await, json!([]));

    let ball = json!({"kind": "ball", "radius": 3, "name": "R3 ball", "neck_radius": 1.5});
    let created = json_with(app.put_json("/api/v1/tools/7", &ball).await, 201).await;
    assert_eq!(
        created,
        json!({"number": 7, "kind": "ball", "radius": 3.0, "flutes": 2, "name": "R3 ball", "neck_radius": 1.5})
    );
    let replaced = json_with(app.put_json("/api/v1/tools/7", &json!({"kind": "ball", "radius": 2.5})).await, 200).await;
    assert_eq!(replaced["radius"], 2.5);
    assert!(replaced.get("name").is_none(), "a replace stores the new record whole");

    // A GET → edit → PUT round trip carries the number in the body.
    let mut fetched = json_with(app.get("/api/v1/tools/7").await, 200).await;
    fetched["flutes"] = json!(4);
    assert_eq!(json_with(app.put_json("/api/v1/tools/7", &fetched).await, 200).await["flutes"], 4);

    let bull = json!({"kind": "bull", "radius": 5, "corner_radius": 1});
    json_with(app.put_json("/api/v1/tools/12", &bull).await, 201).await;
    json_with(app.put_json("/api/v1/tools/3", &json!({"kind": "flat", "radius": 4})).await, 201).await;
    let list = json_with(app.get("/api/v1/tools").await, 200).await;
    let numbers: Vec<u64> = list.as_array().unwrap().iter().map(|t| t["number"].as_u64().unwrap()).collect();
    assert_eq!(numbers, [3, 7, 12], "list ordered by number");

    app.restart().await;
    let after = json_with(app.get("/api/v1/tools").await, 200).await;
    assert_eq!(after, list, "tools survive a restart");

    assert_eq!(app.delete("/api/v1/tools/12").await.status(), 204);
    problem(app.get("/api/v1/tools/12").await, 404).await;
    problem(app.delete("/api/v1/tools/12").await, 404).await;
    app.shutdown().await;
}

kerf_tests::on_both_stores!(tool_crud_and_restart);
