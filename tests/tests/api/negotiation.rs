//! `Accept` negotiation of path-producing answers (RFC 9110 §12.5.1): the q-values rank JSON and
//! G-code, ties and answers nothing listed keep JSON, unreadable elements count as not sent, and
//! `?format=` wins over the header.

use kerf_tests::TestApp;
use serde_json::json;

/// The media type of the segment answer to a request sent with these `Accept` lines (and query).
async fn answered(app: &TestApp, query: &str, accept: &[&str]) -> String {
    let body = json!({"curve": {"kind": "circle", "centre": [0, 0], "radius": 20},
        "feed": 6000, "block_time_ms": 4, "margin": 1.1});
    let mut request = app.client.post(app.url(&format!("/api/v1/segment{query}"))).json(&body);
    for line in accept {
        request = request.header("accept", *line);
    }
    let response = request.send().await.expect("request");
    let status = response.status().as_u16();
    let media = response.headers().get("content-type").and_then(|v| v.to_str().ok()).unwrap_or_default().to_owned();
    let text = response.text().await.expect("body");
    assert_eq!(status, 200, "Accept {accept:?}: {text}");
    let essence = media.split(';').next().unwrap_or_default().trim().to_owned();
    match essence.as_str() {
        "application/json" => assert!(text.starts_with('{'), "Accept {accept:?}: JSON body"),
        "text/x-gcode" => assert!(text.contains("G01") || text.contains("G1 "), "Accept {accept:?}: a program"),
        other => panic!("Accept {accept:?}: answered {other}"),
    }
    essence
}

const JSON: &str = "application/json";
const GCODE: &str = "text/x-gcode";

#[tokio::test(flavor = "multi_thread")]
async fn accept_q_values_choose_the_answer() {
    let app = TestApp::spawn().await;
    let cases: &[(&str, &[&str], &str)] = &[
        ("no Accept", &[], JSON),
        ("G-code alone", &["text/x-gcode"], GCODE),
        ("JSON preferred by q", &["application/json, text/x-gcode;q=0.1"], JSON),
        ("G-code preferred by q", &["application/json;q=0.5, text/x-gcode"], GCODE),
        ("G-code preferred, listed second", &["text/x-gcode;q=0.9,application/json;q=0.8"], GCODE),
        ("tie keeps JSON", &["text/x-gcode, application/json"], JSON),
        ("tie at equal q keeps JSON", &["text/x-gcode;q=0.5, application/json;q=0.5"], JSON),
        ("q=0 is not acceptable", &["text/x-gcode;q=0"], JSON),
        ("q=0 on JSON", &["application/json;q=0, text/x-gcode;q=0.001"], GCODE),
        ("any", &["*/*"], JSON),
        ("any, G-code preferred", &["*/*;q=0.1, text/x-gcode"], GCODE),
        ("text/* covers G-code", &["text/*"], GCODE),
        ("application/* over text/*", &["text/*;q=0.5, application/*"], JSON),
        ("exact range overrides text/*", &["text/*, text/x-gcode;q=0"], JSON),
        ("browser navigation", &["text/html,application/xhtml+xml,application/xml;q=0.9,*/*;q=0.8"], JSON),
        ("nothing kerf writes", &["text/html"], JSON),
        ("spaces and case", &["Application/JSON ; q=0.2 ,\tTEXT/X-GCODE ; Q=0.3"], GCODE),
        ("several lines", &["application/json;q=0.2", "text/x-gcode;q=0.3"], GCODE),
        ("malformed q counts as not sent", &["text/x-gcode;q=high"], JSON),
        ("q above 1 counts as not sent", &["text/x-gcode;q=2, application/json;q=0.1"], JSON),
        ("decimal comma splits the list", &["text/x-gcode;q=0,5"], JSON),
        ("malformed q beside a good one", &["application/json;q=x, text/x-gcode;q=0.1"], GCODE),
    ];
    for (what, accept, expected) in cases {
        assert_eq!(answered(&app, "", accept).await, *expected, "{what}: Accept {accept:?}");
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn format_parameter_wins_over_accept() {
    let app = TestApp::spawn().await;
    assert_eq!(answered(&app, "?format=json", &["text/x-gcode"]).await, JSON);
    assert_eq!(answered(&app, "?format=gcode", &["application/json, text/x-gcode;q=0"]).await, GCODE);
}
