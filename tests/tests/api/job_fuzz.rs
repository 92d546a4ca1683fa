//! Random and mutated job files never panic the parser and never get a 5xx.

use kerf_server::jobs::file::{self, Format};
use kerf_tests::TestApp;
use proptest::prelude::*;
use proptest::strategy::ValueTree;

use crate::jobs::examples;

fn example_texts() -> Vec<String> {
    examples().iter().map(|p| std::fs::read_to_string(p).unwrap()).collect()
}

/// Mutations of an example: cut it, duplicate a slice, replace a byte, insert a token.
fn mutated() -> impl Strategy<Value = String> {
    let texts = example_texts();
    let count = texts.len();
    (0..count, any::<u16>(), any::<u16>(), any::<u8>(), 0_u8..5).prop_map(move |(pick, at, len, byte, how)| {
        let text = texts[pick].as_bytes();
        let at = usize::from(at) % text.len();
        let end = (at + usize::from(len) % 64).min(text.len());
        let mut out = text.to_vec();
        match how {
            0 => out.truncate(at),
            1 => out.splice(at..at, text[at..end].to_vec()).for_each(drop),
            2 => out[at] = byte,
            3 => out.splice(at..at, b"[[operations]]\n".to_vec()).for_each(drop),
            _ => out.splice(at..end, b"nan".to_vec()).for_each(drop),
        }
        String::from_utf8_lossy(&out).into_owned()
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn parser_never_panics(text in prop_oneof![mutated(), ".{0,300}"], toml in any::<bool>()) {
        let format = if toml { Format::Toml } else { Format::Json };
        if let Err(error) = file::parse(&text, format) {
            let status = error.problem().status;
            prop_assert!((400..500).contains(&status), "{status}");
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn mutated_uploads_never_get_5xx() {
    let app = TestApp::spawn().await;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = mutated();
    for _ in 0..150 {
        let text = strategy.new_tree(&mut runner).unwrap().current();
        let media = if text.trim_start().starts_with('{') { "application/json" } else { "application/toml" };
        let response = app
            .client
            .post(app.url("/api/v1/jobs"))
            .header("content-type", media)
            .body(text.clone())
            .send()
            .await
            .unwrap();
        let status = response.status().as_u16();
        assert!(status < 500, "{status} for:\n{text}");
    }
    // Whatever was accepted runs to an end without a 5xx anywhere.
    let page: serde_json::Value =
        app.client.get(app.url("/api/v1/jobs?limit=200")).send().await.unwrap().json().await.unwrap();
    for job in page["jobs"].as_array().unwrap() {
        let id = job["id"].as_i64().unwrap();
        let done = kerf_tests::poll_job(&app.client, &app.base, id, 60, kerf_tests::finished).await;
        assert!(kerf_tests::finished(&done), "{done}");
    }
}
