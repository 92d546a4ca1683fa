//! The served OpenAPI document covers every route, and the docs page is served offline.

use kerf_tests::{TestApp, json_with};

#[tokio::test(flavor = "multi_thread")]
async fn document_covers_every_route_and_docs_are_served() {
    let app = TestApp::spawn().await;
    let document = json_with(app.get("/api/v1/openapi.json").await, 200).await;
    let (_, built) = kerf_server::app::api();
    assert_eq!(document, serde_json::to_value(&built).unwrap(), "served document is the built one");
    let paths = document["paths"].as_object().unwrap();
    for path in [
        "/healthz",
        "/api/v1/tools",
        "/api/v1/tools/{number}",
        "/api/v1/deburr",
        "/api/v1/contour",
        "/api/v1/contour/loops",
        "/api/v1/predict",
    ] {
        assert!(paths.contains_key(path), "{path} documented");
    }
    let html = app.get_text("/docs/", 200).await;
    assert!(html.contains("swagger"), "swagger UI page");
    let initializer = app.get_text("/docs/swagger-initializer.js", 200).await;
    assert!(initializer.contains("/api/v1/openapi.json"));
    // A file the docs do not have is a problem document like every other 404.
    let missing = kerf_tests::problem(app.get("/docs/no-such-file.js").await, 404).await;
    assert_eq!(missing["code"], "E_NOT_FOUND");
}

/// Each path-producing endpoint's `/program` route answers the same program as the endpoint with
/// `?format=gcode` (which keeps working), as `text/x-gcode`, with the same output options; it
/// takes no `format` (a 400 naming it), and the endpoint without options still answers JSON.
#[tokio::test(flavor = "multi_thread")]
async fn program_routes_answer_the_program_of_the_same_request() {
    let app = TestApp::spawn().await;
    let request = kerf_cases::deburr::case_1();
    let program =
        app.client.post(app.url("/api/v1/deburr/program?dialect=linuxcnc")).json(&request).send().await.unwrap();
    assert_eq!(program.status(), 200);
    assert!(program.headers()["content-type"].to_str().unwrap().starts_with("text/x-gcode"));
    let program = program.text().await.unwrap();
    let negotiated = app.post_text("/api/v1/deburr?format=gcode&dialect=linuxcnc", &request, 200).await;
    assert_eq!(program, negotiated);
    let fanuc = app.post_text("/api/v1/deburr/program", &request, 200).await;
    assert_ne!(program, fanuc, "the dialect is the query's");
    let refused = kerf_tests::problem(app.post_json("/api/v1/deburr/program?format=json", &request).await, 400).await;
    assert_eq!(refused["code"], "E_QUERY", "{refused}");
    let json = json_with(app.post_json("/api/v1/deburr", &request).await, 200).await;
    assert!(json["points"].is_array());
}
