//! The tool table: create, replace, read, list, delete, survival across a restart, and the
//! preconditions of a write (`ETag`, `If-Match`, `If-None-Match`), also between concurrent clients.

use kerf_tests::{Store, TestApp, json_with, problem};
use reqwest::Method;
use serde_json::{Value, json};

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

/// One write with optional precondition headers: its status, `ETag` header and body.
async fn send(app: &TestApp, method: Method, path: &str, headers: &[(&str, &str)], body: Option<&Value>) -> Answer {
    let mut request = app.client.request(method, app.url(path));
    for (name, value) in headers {
        request = request.header(*name, *value);
    }
    if let Some(body) = body {
        request = request.json(body);
    }
    let response = request.send().await.expect("request");
    let status = response.status().as_u16();
    let etag = response.headers().get("etag").map(|v| v.to_str().expect("ASCII ETag").to_owned());
    let text = response.text().await.expect("body");
    let body = if text.is_empty() { Value::Null } else { serde_json::from_str(&text).expect("JSON body") };
    Answer { status, etag, body }
}

/// What [`send`] saw.
pub struct Answer {
    pub status: u16,
    pub etag: Option<String>,
    pub body: Value,
}

impl Answer {
    /// The answer's `ETag`, asserting the status first.
    fn tagged(&self, status: u16) -> String {
        assert_eq!(self.status, status, "{}", self.body);
        let etag = self.etag.clone().unwrap_or_else(|| panic!("no ETag on a {status}: {}", self.body));
        assert!(etag.len() > 2 && etag.starts_with('"') && etag.ends_with('"'), "a quoted strong tag: {etag}");
        etag
    }

    /// Asserts a 412 `E_PRECONDITION_FAILED` naming `header`, with `current` as ETag header
    /// and in the detail (`None`: the item is not stored).
    fn refused(&self, header: &str, current: Option<&str>) {
        assert_eq!(self.status, 412, "{}", self.body);
        assert_eq!(self.body["code"], "E_PRECONDITION_FAILED", "{}", self.body);
        assert_eq!(self.body["errors"][0]["path"], header, "{}", self.body);
        assert_eq!(self.etag.as_deref(), current, "current ETag on the 412");
        if let Some(current) = current {
            assert!(self.body["detail"].as_str().unwrap().contains(current), "detail names the tag: {}", self.body);
        }
    }
}

/// `If-Match` and `If-None-Match` on one registry item at `path` (tools, machines, materials):
/// `first`, `second` and `third` are three different valid bodies for it.
pub async fn conditional_writes(app: &TestApp, path: &str, first: &Value, second: &Value, third: &Value) {
    let get = || send(app, Method::GET, path, &[], None);
    let put = |headers: &'static [(&'static str, &'static str)], body: &Value| {
        let body = body.clone();
        async move { send(app, Method::PUT, path, headers, Some(&body)).await }
    };
    // Create-only: the first PUT creates, a second is refused and changes nothing.
    let created = send(app, Method::PUT, path, &[("if-none-match", "*")], Some(first)).await;
    let tag1 = created.tagged(201);
    let fetched = get().await;
    assert_eq!(fetched.tagged(200), tag1, "GET and the PUT answer carry the same tag");
    assert_eq!(fetched.body, created.body);
    put(&[("if-none-match", "*")], second).await.refused("If-None-Match", Some(&tag1));
    assert_eq!(get().await.body, created.body, "a refused create-only PUT keeps the stored item");

    // Replace the version seen; a stale tag is refused and changes nothing.
    let replaced = send(app, Method::PUT, path, &[("if-match", &tag1)], Some(second)).await;
    let tag2 = replaced.tagged(200);
    assert_ne!(tag2, tag1, "another representation, another tag");
    assert_eq!(get().await.etag.as_deref(), Some(tag2.as_str()));
    send(app, Method::PUT, path, &[("if-match", &tag1)], Some(third)).await.refused("If-Match", Some(&tag2));
    assert_eq!(get().await.body, replaced.body, "a stale If-Match keeps the stored item");
    // A weak tag never matches (strong comparison); nor does a tag without its quotes.
    send(app, Method::PUT, path, &[("if-match", &format!("W/{tag2}"))], Some(third))
        .await
        .refused("If-Match", Some(&tag2));
    let bare = tag2.trim_matches('"').to_owned();
    send(app, Method::PUT, path, &[("if-match", &bare)], Some(third)).await.refused("If-Match", Some(&tag2));
    send(app, Method::PUT, path, &[("if-none-match", &bare)], Some(third)).await.refused("If-None-Match", Some(&tag2));
    assert_eq!(get().await.body, replaced.body);
    // One of a list matches; `*` matches any stored item.
    let listed = send(app, Method::PUT, path, &[("if-match", &format!("\"0000\", {tag2}"))], Some(third)).await;
    let tag3 = listed.tagged(200);
    assert_eq!(put(&[("if-match", "*")], third).await.tagged(200), tag3, "same body, same tag");

    // Delete: a stale tag is refused, the current one deletes.
    send(app, Method::DELETE, path, &[("if-match", &tag1)], None).await.refused("If-Match", Some(&tag3));
    assert_eq!(get().await.status, 200);
    assert_eq!(send(app, Method::DELETE, path, &[("if-match", &tag3)], None).await.status, 204);
    assert_eq!(get().await.status, 404);
    // Gone: If-Match (a tag or `*`) is refused without a tag and creates nothing; deleting again too.
    put(&[("if-match", "*")], first).await.refused("If-Match", None);
    send(app, Method::PUT, path, &[("if-match", &tag3)], Some(third)).await.refused("If-Match", None);
    send(app, Method::DELETE, path, &[("if-match", &tag3)], None).await.refused("If-Match", None);
    assert_eq!(get().await.status, 404, "a refused If-Match PUT creates nothing");

    // Without the headers: create and replace as before; a tag from before the delete does not
    // match the item created again with another body.
    assert_eq!(put(&[], second).await.tagged(201), tag2, "the tag is the representation's");
    send(app, Method::PUT, path, &[("if-match", &tag1)], Some(first)).await.refused("If-Match", Some(&tag2));
    put(&[], first).await.tagged(200);
    assert_eq!(send(app, Method::DELETE, path, &[], None).await.status, 204);
}

async fn tool_preconditions(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    conditional_writes(
        &app,
        "/api/v1/tools/7",
        &json!({"kind": "ball", "radius": 3, "name": "R3 ball"}),
        &json!({"kind": "flat", "radius": 5}),
        &json!({"kind": "flat", "radius": 5, "flutes": 4}),
    )
    .await;
    // A request refused for its number is refused for that, whatever its preconditions say.
    let out_of_range = send(
        &app,
        Method::PUT,
        "/api/v1/tools/0",
        &[("if-match", "junk")],
        Some(&json!({"kind": "flat", "radius": 5})),
    )
    .await;
    assert_eq!(
        (out_of_range.status, &out_of_range.body["errors"][0]["path"]),
        (422, &json!("number")),
        "{}",
        out_of_range.body
    );
    app.shutdown().await;
}

/// Two clients replace the same tool with the tag they both read: exactly one wins, the other
/// gets 412 with the winner's tag, and the stored tool is the winner's (no lost update).
async fn concurrent_if_match_one_wins(store: Store) {
    let Some(mut app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let path = "/api/v1/tools/7";
    let mut tag = send(&app, Method::PUT, path, &[], Some(&json!({"kind": "flat", "radius": 1}))).await.tagged(201);
    // The second client talks to a second API node on the same database.
    let mut other = app.spawn_beside(|_| {}).await;
    for round in 0..20_u32 {
        let a = json!({"kind": "flat", "radius": 2 + round});
        let b = json!({"kind": "ball", "radius": 2 + round});
        let seen = [("if-match", tag.as_str())];
        let (first, second) = tokio::join!(
            send(&app, Method::PUT, path, &seen, Some(&a)),
            send(&other, Method::PUT, path, &seen, Some(&b)),
        );
        let (winner, loser, body) = match (first.status, second.status) {
            (200, 412) => (first, second, a),
            (412, 200) => (second, first, b),
            statuses => panic!("round {round}: statuses {statuses:?}, want one 200 and one 412"),
        };
        let won = winner.tagged(200);
        loser.refused("If-Match", Some(&won));
        let stored = send(&app, Method::GET, path, &[], None).await;
        assert_eq!(stored.etag.as_deref(), Some(won.as_str()), "round {round}");
        assert_eq!(stored.body["kind"], body["kind"], "round {round}: the winner's tool is stored");
        tag = won;
    }
    other.shutdown().await;
    app.shutdown().await;
}

kerf_tests::on_both_stores!(tool_crud_and_restart, tool_preconditions, concurrent_if_match_one_wins);
