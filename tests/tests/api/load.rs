//! Bounded load over loopback: 2 000 mixed requests from 64 concurrent clients (tool writes,
//! tool deletes, deburr calls, job submissions, reads). Every answer must be a success or a
//! documented 4xx/429, none may be lost, and the database must match what the clients were told.
//! Prints requests per second and latency percentiles (measured, never asserted).

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use kerf_tests::{TestApp, finished, poll_job};
use serde_json::{Value, json};

const CLIENTS: usize = 64;
const REQUESTS: usize = 2_000;

fn deburr_body(tool: u32) -> Value {
    kerf_cases::with(kerf_cases::deburr::case_1(), json!({"tool": tool}))
}

/// What one client did: latencies, statuses, final state of its own tools, accepted jobs.
#[derive(Default)]
struct Outcome {
    latencies: Vec<Duration>,
    statuses: BTreeMap<u16, usize>,
    tools: BTreeMap<u32, Option<f64>>,
    jobs: Vec<i64>,
}

async fn client(app_base: String, http: reqwest::Client, id: usize, count: usize) -> Outcome {
    let mut outcome = Outcome::default();
    // Each client owns two tool numbers, so the expected final table is known.
    let own = [u32::try_from(2 * id + 10).unwrap(), u32::try_from(2 * id + 11).unwrap()];
    for step in 0..count {
        let tool = own[step % 2];
        let started = Instant::now();
        let (response, kind) = match step % 10 {
            0..=3 => (http.post(format!("{app_base}/api/v1/deburr")).json(&deburr_body(7)).send().await, "deburr"),
            4..=6 => {
                let radius = 1.0 + (step % 7) as f64 * 0.5;
                let body = json!({"kind": "ball", "radius": radius});
                (http.put(format!("{app_base}/api/v1/tools/{tool}")).json(&body).send().await, "put")
            }
            7 => (http.delete(format!("{app_base}/api/v1/tools/{tool}")).send().await, "delete"),
            8 => {
                let job = json!({"name": format!("load {id}-{step}"), "operations": [
                    {"operation": "deburr", "tool": {"kind": "ball", "radius": 3}, "edge": "outer", "cut_amount": 0.5,
                     "workpiece": {"kind": "tube", "origin": [0, 0, id], "inner_radius": 40, "outer_radius": 50},
                     "hole": {"shape": "round", "radius": 10}}]});
                (http.post(format!("{app_base}/api/v1/jobs")).json(&job).send().await, "job")
            }
            _ => (http.get(format!("{app_base}/api/v1/tools/{tool}")).send().await, "get"),
        };
        let response = response.unwrap_or_else(|error| panic!("client {id} lost a {kind} request: {error}"));
        let status = response.status().as_u16();
        let body = response.bytes().await.expect("a whole answer");
        outcome.latencies.push(started.elapsed());
        *outcome.statuses.entry(status).or_default() += 1;
        let documented = match kind {
            "deburr" => matches!(status, 200 | 429),
            "put" => matches!(status, 200 | 201 | 429),
            "delete" | "get" => matches!(status, 200 | 204 | 404 | 429),
            _ => matches!(status, 200 | 202 | 429),
        };
        assert!(documented, "client {id}: {kind} answered {status}: {}", String::from_utf8_lossy(&body));
        match (kind, status) {
            ("put", 200 | 201) => {
                let stored: Value = serde_json::from_slice(&body).unwrap();
                outcome.tools.insert(tool, stored["radius"].as_f64());
            }
            ("delete", 204 | 404) => {
                outcome.tools.insert(tool, None);
            }
            ("job", 202) => outcome.jobs.push(serde_json::from_slice::<Value>(&body).unwrap()["id"].as_i64().unwrap()),
            _ => {}
        }
    }
    outcome
}

fn percentile(sorted: &[Duration], fraction: f64) -> Duration {
    sorted[((sorted.len() as f64 * fraction) as usize).min(sorted.len() - 1)]
}

#[tokio::test(flavor = "multi_thread")]
async fn mixed_load_from_64_clients() {
    let app = TestApp::spawn().await;
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let http = reqwest::Client::builder().pool_max_idle_per_host(CLIENTS).build().unwrap();
    let started = Instant::now();
    let tasks: Vec<_> = (0..CLIENTS)
        .map(|id| {
            tokio::spawn(client(
                app.base.clone(),
                http.clone(),
                id,
                REQUESTS / CLIENTS + usize::from(id < REQUESTS % CLIENTS),
            ))
        })
        .collect();
    let mut outcomes = Vec::new();
    for task in tasks {
        outcomes.push(task.await.expect("client task"));
    }
    let elapsed = started.elapsed();

    let mut latencies: Vec<Duration> = outcomes.iter().flat_map(|o| o.latencies.iter().copied()).collect();
    assert_eq!(latencies.len(), REQUESTS, "every request answered");
    latencies.sort();
    let mut statuses = BTreeMap::new();
    for outcome in &outcomes {
        for (status, count) in &outcome.statuses {
            *statuses.entry(*status).or_insert(0) += count;
        }
    }
    eprintln!(
        "mixed load: {REQUESTS} requests, {CLIENTS} clients, {:.0} req/s, p50 {:?}, p99 {:?}, max {:?}, statuses {statuses:?}",
        REQUESTS as f64 / elapsed.as_secs_f64(),
        percentile(&latencies, 0.5),
        percentile(&latencies, 0.99),
        latencies[latencies.len() - 1]
    );

    // The tool table is exactly what the clients were told.
    let stored: Vec<Value> = app.get("/api/v1/tools").await.json().await.unwrap();
    let stored: BTreeMap<u32, f64> = stored
        .iter()
        .map(|t| (u32::try_from(t["number"].as_u64().unwrap()).unwrap(), t["radius"].as_f64().unwrap()))
        .collect();
    let mut expected: BTreeMap<u32, f64> = BTreeMap::from([(7, 3.0)]);
    for outcome in &outcomes {
        for (number, radius) in &outcome.tools {
            if let Some(radius) = radius {
                expected.insert(*number, *radius);
            }
        }
    }
    assert_eq!(stored, expected, "tool table consistent with the answers");

    // Every accepted job runs to done.
    let job_started = Instant::now();
    let jobs: Vec<i64> = outcomes.iter().flat_map(|o| o.jobs.iter().copied()).collect();
    for id in &jobs {
        let job = poll_job(&app.client, &app.base, *id, 120, finished).await;
        assert_eq!(job["status"], "done", "{job}");
    }
    eprintln!("{} small jobs accepted; all done {:?} after the load ended", jobs.len(), job_started.elapsed());
}
