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
