//! Work no one waits for stops: a contour G-code request over the time limit, timed out while its
//! program is being written, leaves no CPU use 100 ms after its 422; and SIGTERM ends the real
//! program promptly while a long request is being solved (its work is cancelled, not waited for).

use std::time::{Duration, Instant};

use kerf_cases::contour::circle;
use kerf_tests::{ServerProcess, problem};
use serde_json::{Value, json};

/// A contour of `layers` layers of a `points`-point circle: that many moves and more per layer, so
/// its program takes seconds to write (over the JSON answer's move limit: G-code only). Upright
/// walls share one plan across the layers (a fast solve); tilted ones (`tilt_deg`) are planned
/// layer by layer (a long solve).
fn long_contour(layers: usize, points: usize, tilt_deg: Option<f64>) -> Value {
    let mut body = json!({"tool": {"kind": "ball", "radius": 3}, "contour": circle(points), "side": "outside",
           "depths": {"top": 0, "bottom": -(layers as f64) * 0.025, "step": 0.025}, "feed": 800});
    if let Some(tilt) = tilt_deg {
        body["tilt_deg"] = json!(tilt);
    }
    body
}

/// CPU time process `id` has used (user and system), from `/proc/{id}/stat`.
fn process_cpu(id: u32) -> Duration {
    let stat = std::fs::read_to_string(format!("/proc/{id}/stat")).expect("the process's stat");
    // The fields after the command name (which may hold spaces) in parentheses.
    let fields: Vec<&str> = stat.rsplit_once(") ").expect("stat fields").1.split(' ').collect();
    let ticks: u64 = fields[11].parse::<u64>().unwrap() + fields[12].parse::<u64>().unwrap();
    // The kernel counts in USER_HZ, 100 per second on Linux.
    Duration::from_millis(ticks * 10)
}

/// The seconds the service reports for the solve in `Server-Timing` (`solve;dur=MS`).
fn solve_seconds(response: &reqwest::Response) -> f64 {
    let timing = response.headers()["server-timing"].to_str().unwrap();
    let ms: f64 = timing.split("dur=").nth(1).and_then(|ms| ms.parse().ok()).unwrap();
    ms / 1e3
}

/// The real program serving a new database in `folder` with a time limit of `limit_s` seconds
/// and no answer cache (a process of its own, so its CPU time is its work alone).
async fn server(folder: &std::path::Path, limit_s: f64) -> ServerProcess {
    let program = std::path::PathBuf::from(env!("CARGO_BIN_EXE_kerf-under-test"));
    let database = folder.join(format!("kerf-{limit_s}.db"));
    let limit = limit_s.to_string();
    ServerProcess::start_with(
        &program,
        &[
            "serve",
            "--database",
            &database.to_string_lossy(),
            "--solver-time-limit-s",
            &limit,
            "--answer-cache-mb",
            "0",
        ],
    )
    .await
}

#[tokio::test(flavor = "multi_thread")]
async fn a_program_timed_out_while_being_written_stops_at_once() {
    let folder = tempfile::tempdir().unwrap();
    let client = reqwest::Client::new();
    // The most moves a contour may have (6 000 000), on upright walls: a short solve, a long write.
    let mut body = long_contour(10_000, 590, None);
    // The program alone: the verification would write and cut it within the solve.
    body["verification"] = json!({"enabled": false});
    // How long the solve and the writing take here, with no limit.
    let generous = server(folder.path(), 600.0).await;
    let started = Instant::now();
    let url = format!("{}/api/v1/contour?format=gcode", generous.base);
    let response = client.post(&url).json(&body).send().await.unwrap();
    assert_eq!(response.status(), 200);
    let solve = solve_seconds(&response);
    let _ = response.bytes().await.unwrap();
    let total = started.elapsed().as_secs_f64();
    generous.terminate();

    // A limit 0.1 s after the solve and at least 0.4 s before the writing ends: the request is
    // told to submit a job while its program is being written.
    let limit = solve + 0.1;
    assert!(limit + 0.4 < total, "solve {solve:.2} s, solve and writing {total:.2} s: use more layers");
    let server = server(folder.path(), limit).await;
    let url = format!("{}/api/v1/contour?format=gcode", server.base);
    let answer = problem(client.post(&url).json(&body).send().await.unwrap(), 422).await;
    assert_eq!(answer["code"], "E_TIMEOUT", "{answer}");
    tokio::time::sleep(Duration::from_millis(100)).await;
    let (before, at) = (process_cpu(server.id()), Instant::now());
    tokio::time::sleep(Duration::from_millis(300)).await;
    let (used, over) = (process_cpu(server.id()).saturating_sub(before), at.elapsed());
    // An idle service uses next to nothing; the abandoned writing would use a whole core.
    assert!(
        used < over / 10,
        "{used:?} of CPU in the {over:?} after the 422: the program is still being written (limit {limit} s)"
    );
}

/// Whether process `id` has ended (gone, or a zombie its parent has not reaped yet).
fn ended(id: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{id}/stat"))
        .map_or(true, |stat| stat.rsplit_once(") ").is_some_and(|(_, rest)| rest.starts_with('Z')))
}

#[tokio::test(flavor = "multi_thread")]
async fn sigterm_ends_the_program_while_a_long_request_is_solved() {
    let folder = tempfile::tempdir().unwrap();
    let server = server(folder.path(), 600.0).await;
    // Far more work than the test waits for: seconds in the solver, layer by layer, and the writer.
    let (client, url, body) = (
        reqwest::Client::new(),
        format!("{}/api/v1/contour?format=gcode", server.base),
        long_contour(9000, 600, Some(1.0)),
    );
    let request = tokio::spawn(async move { client.post(url).json(&body).send().await });
    tokio::time::sleep(Duration::from_millis(1500)).await;
    assert!(!request.is_finished(), "the request is still being solved");
    let id = server.id();
    let signalled = Instant::now();
    let sent = std::process::Command::new("kill").arg("-TERM").arg(id.to_string()).status().unwrap();
    assert!(sent.success());
    // The shutdown deadline is the 30 s grace for open connections; cancelled at the signal,
    // the work ends in milliseconds, so the program is gone long before.
    while !ended(id) && signalled.elapsed() < Duration::from_secs(10) {
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    let took = signalled.elapsed();
    assert!(ended(id), "still running {took:?} after SIGTERM, its solver work not cancelled");
    drop(server);
    // The client got an answer or a closed connection, not a hang.
    let answered = tokio::time::timeout(Duration::from_secs(5), request).await;
    assert!(answered.is_ok(), "the request ended with the program");
}
