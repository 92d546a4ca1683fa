//! Snapshot of the whole OpenAPI document, so every API change shows up in review
//! (`cargo insta review`, or `INSTA_UPDATE=always cargo test -p kerf-server` to accept).

#[test]
fn openapi_document_snapshot() {
    let (_, document) = kerf_server::app::api();
    insta::assert_json_snapshot!("openapi", document);
}
