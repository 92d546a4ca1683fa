//! The server against its own OpenAPI document, checked from outside by schemathesis (PyPI):
//! thousands of generated requests on every route, failing on any 5xx, a status the document does
//! not list, a wrong content type, or an answer that breaks its schema. The patent is fixed so a
//! failure reproduces; one worker, because hypothesis's lambda-source cache is not thread-safe
//! (a run with two workers once died of it). `.ci/run` installs schemathesis in a venv.

use kerf_tests::{TestApp, external_program};

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_schemathesis), ignore = "schemathesis not found: pip install schemathesis")]
async fn the_server_keeps_to_its_openapi_document() {
    let Some(schemathesis) = external_program("schemathesis", "the OpenAPI conformance run") else {
        return;
    };
    let app = TestApp::spawn().await;
    let output = tokio::process::Command::new(schemathesis)
        .args(["run", &app.url("/api/v1/openapi.json"), "--max-examples", "15", "--seed", "20261124", "--workers", "1"])
        .args([
            "--checks",
            "not_a_server_error,status_code_conformance,content_type_conformance,response_schema_conformance,\
             response_headers_conformance",
        ])
        .env("NO_COLOR", "1")
        .output()
        .await
        .expect("schemathesis runs");
    let report = String::from_utf8_lossy(&output.stdout);
    let summary: Vec<&str> = report.lines().filter(|line| line.contains("generated")).collect();
    eprintln!("schemathesis: {summary:?}");
    assert!(
        output.status.success(),
        "schemathesis found failures:\n{report}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(!summary.is_empty(), "no test cases were generated:\n{report}");
}
