//! The page's files: strong ETags with 304 on revalidation, gzip when the browser accepts it.

use kerf_tests::TestApp;

#[tokio::test(flavor = "multi_thread")]
async fn page_files_revalidate_and_compress() {
    let app = TestApp::spawn().await;
    for path in ["/", "/app.js", "/style.css"] {
        let first = app.get(path).await;
        assert_eq!(first.status(), 200, "{path}");
        let tag = first.headers().get("etag").expect("an ETag").to_str().unwrap().to_owned();
        assert!(tag.starts_with('"') && tag.ends_with('"'), "{path}: a strong ETag: {tag}");
        let plain = first.bytes().await.unwrap();
        assert!(!plain.is_empty());

        let again = app.client.get(app.url(path)).header("if-none-match", &tag).send().await.unwrap();
        assert_eq!(again.status(), 304, "{path}: unchanged file");
        assert!(again.bytes().await.unwrap().is_empty());
        let other = app.client.get(app.url(path)).header("if-none-match", "\"other\"").send().await.unwrap();
        assert_eq!(other.status(), 200, "{path}: another tag gets the file");

        let zipped = app.client.get(app.url(path)).header("accept-encoding", "gzip").send().await.unwrap();
        assert_eq!(zipped.status(), 200);
        assert_eq!(zipped.headers().get("content-encoding").map(|v| v.to_str().unwrap()), Some("gzip"), "{path}");
        let compressed = zipped.bytes().await.unwrap();
        assert!(compressed.len() < plain.len(), "{path}: {} gzip bytes of {}", compressed.len(), plain.len());
    }
}

/// The page's capability views come from the registry: `/capabilities.js` names every capability
/// the API serves (the OpenAPI document's `POST /api/v1/{name}` with a tag of that name, and its
/// program route unless it writes none), and each has its view module, which exports `view`.
#[tokio::test(flavor = "multi_thread")]
async fn capability_views_follow_the_registry() {
    let app = TestApp::spawn().await;
    let module = app.get("/capabilities.js").await;
    assert_eq!(module.status(), 200);
    assert!(module.headers()["content-type"].to_str().unwrap().starts_with("text/javascript"));
    let text = module.text().await.unwrap();
    let list = text.split("export const CAPABILITIES = ").nth(1).expect("the export").trim().trim_end_matches(';');
    let names: Vec<String> = serde_json::from_str(list).expect("a JSON list of names");
    assert_eq!(names, ["deburr", "segment", "resegment", "contour", "engagement", "predict", "verify"]);

    let document: serde_json::Value = app.get("/api/v1/openapi.json").await.json().await.unwrap();
    for name in &names {
        let operation = &document["paths"][format!("/api/v1/{name}")]["post"];
        assert_eq!(operation["tags"][0], name.as_str(), "{name}: the endpoint is the capability's");
        assert_eq!(operation["operationId"], name.as_str());
        // Verify answers findings only: it writes no program.
        let program = &document["paths"][format!("/api/v1/{name}/program")]["post"]["operationId"];
        if name == "verify" {
            assert!(program.is_null(), "{name}: no program route");
        } else {
            assert_eq!(program, &format!("{name}_program"));
        }
        assert!(operation["summary"].as_str().is_some_and(|s| !s.is_empty()), "{name}: documented");
        let view = app.get(&format!("/views/{name}.js")).await;
        assert_eq!(view.status(), 200, "{name}: its view module");
        assert!(view.text().await.unwrap().contains("export const view = {"), "{name}: exports `view`");
    }
}
