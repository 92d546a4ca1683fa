//! The example jobs' operations, one to three of their numbers replaced by extremes (0,
//! negatives, 1e308, 2⁶³, tiny values), posted to the synchronous endpoints: every answer
//! is a documented 4xx or a 200, never a 5xx, a dropped connection or a hang. This found an
//! ellipse start angle of 2⁶³° that made the segment solver allocate until the server died.

use kerf_server::state::Limits;
use kerf_tests::TestApp;
use serde_json::{Value, json};
use std::time::Duration;

use crate::jobs::examples;

/// Numbers a mutation puts in place of a number.
const EXTREMES: [f64; 14] = [0.0, -1.0, 1.0, 1e308, -1e308, 1e-308, 1e9, -1e9, 1e5, 0.5, 3.0, -0.0, 1e-9, 9.2e18];

/// Requests per run: enough to reach every operation's numbers several times, few enough to stay
/// a short test.
const REQUESTS: usize = 240;

/// The example jobs' operations as (endpoint, request) with inline tools and the file's machine
/// renamed to one registered here.
fn operations() -> Vec<(String, Value)> {
    let mut operations = Vec::new();
    for path in examples() {
        let text = std::fs::read_to_string(&path).unwrap();
        let job: Value = if path.extension().is_some_and(|e| e == "toml") {
            toml::from_str(&text).unwrap()
        } else {
            serde_json::from_str(&text).unwrap()
        };
        let tools = job["tools"].as_array().cloned().unwrap_or_default();
        for operation in job["operations"].as_array().unwrap() {
            let mut request = operation.clone();
            let object = request.as_object_mut().unwrap();
            let kind = object.remove("operation").unwrap();
            object.remove("name");
            if let Some(number) = object.get("tool").and_then(Value::as_u64)
                && let Some(tool) = tools.iter().find(|t| t["number"].as_u64() == Some(number))
            {
                let mut inline = tool.clone();
                inline.as_object_mut().unwrap().remove("number");
                object.insert("tool".to_owned(), inline);
            }
            if object.contains_key("machine") {
                object.insert("machine".to_owned(), json!("fuzz"));
            }
            operations.push((format!("/api/v1/{}", kind.as_str().unwrap()), request));
        }
    }
    operations
}

/// Paths to every number in `value` (the first eight entries of each array).
fn number_paths(value: &Value, path: &mut Vec<Value>, out: &mut Vec<Vec<Value>>) {
    match value {
        Value::Number(_) => out.push(path.clone()),
        Value::Object(map) => {
            for (key, item) in map {
                path.push(json!(key));
                number_paths(item, path, out);
                path.pop();
            }
        }
        Value::Array(items) => {
            for (index, item) in items.iter().take(8).enumerate() {
                path.push(json!(index));
                number_paths(item, path, out);
                path.pop();
            }
        }
        _ => {}
    }
}

/// splitmix64 with a fixed seed: the same mutations on every run.
struct Mix(u64);

impl Mix {
    fn below(&mut self, bound: usize) -> usize {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) % bound as u64) as usize
    }
}

fn at<'a>(value: &'a mut Value, path: &[Value]) -> &'a mut Value {
    path.iter().fold(value, |node, key| match key {
        Value::String(name) => &mut node[name.as_str()],
        _ => &mut node[key.as_u64().unwrap() as usize],
    })
}

#[tokio::test(flavor = "multi_thread")]
async fn extreme_numbers_in_every_request_never_get_5xx() {
    let app = TestApp::spawn_with(Limits { solver_time_limit: Duration::from_secs(3), ..Limits::default() }).await;
    let machine = json!({"block_time_ms": 4, "max_feed": 6000});
    assert!(app.put_json("/api/v1/machines/fuzz", &machine).await.status().is_success());
    let operations = operations();
    let mut rng = Mix(7);
    let mut statuses = std::collections::BTreeMap::new();
    for round in 0..REQUESTS {
        let (url, original) = &operations[round % operations.len()];
        let mut request = original.clone();
        let mut paths = Vec::new();
        number_paths(&request, &mut Vec::new(), &mut paths);
        for _ in 0..1 + rng.below(3) {
            let path = &paths[rng.below(paths.len())];
            let number = EXTREMES[rng.below(EXTREMES.len())];
            *at(&mut request, path) = json!(number);
        }
        let query = ["", "?format=gcode"][round % 2];
        let response = app.client.post(app.url(&format!("{url}{query}"))).json(&request).send().await;
        let status = match response {
            Ok(response) => response.status().as_u16(),
            Err(error) => panic!("{url}{query}: no answer ({error}) to {request}"),
        };
        assert!([200, 400, 404, 413, 422, 429].contains(&status), "{url}{query}: {status} for {request}");
        *statuses.entry(status).or_insert(0) += 1;
    }
    assert!(statuses.len() >= 2, "the mutations reach the solvers and their checks: {statuses:?}");
    assert!(app.get("/healthz").await.status().is_success());
}
