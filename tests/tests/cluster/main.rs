//! Past one machine, on a throw-away PostgreSQL server and real processes on loopback:
//! one `kerf serve --job-workers 0` and two `kerf worker`s share the queue; one worker is killed
//! with SIGKILL in the middle of a job; every job ends done with the results of a one-process
//! SQLite run of the same files. A large prediction is split into parts that both workers run at
//! once, one killed in the middle of a part, and its merged result and program are a one-process
//! run's byte for byte, as are those of an engagement comparison, a contour and a deburring split
//! into parts, and a verification split into strips of rows answers as `POST /api/v1/verify`; a
//! refused part fails its job with its problem. Two API nodes on one
//! database see each other's tools, machines and jobs, and a cancel through one reaches the job
//! running on the other within two seconds.
//! Each test skips, printing why, when PostgreSQL is not installed (fails under
//! `KERF_REQUIRE_EXTERNAL=1`). The deployment files are checked against the same binary and the
//! locked packages (`deploy`); `tls` connects to PostgreSQL over TLS.

mod deploy;
mod tls;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use kerf_tests::{PgServer, ServerProcess, Store, TestApp, finished, json_with, poll_job};
use reqwest::Client;
use serde_json::{Value, json};

fn program() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_kerf-under-test"))
}

/// The example job files, as JSON values.
fn examples() -> Vec<Value> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .expect("examples folder")
        .map(|entry| entry.expect("entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "json" || e == "toml"))
        .collect();
    files.sort();
    files
        .iter()
        .map(|path| {
            let text = std::fs::read_to_string(path).unwrap();
            if path.extension().is_some_and(|e| e == "toml") {
                toml::from_str(&text).unwrap()
            } else {
                serde_json::from_str(&text).unwrap()
            }
        })
        .collect()
}

/// A job whose operations take a while: exact-width deburring at a tiny tolerance.
fn long_job(name: &str, operations: usize) -> Value {
    let operation = kerf_cases::operation("deburr", kerf_cases::deburr::long_request());
    json!({"name": name, "operations": vec![operation; operations]})
}

/// A prediction job: a ball end mill finishing a double-wave surface by a zig-zag raster
/// (`tests/load/predict-job.py` at a smaller size), `size` mm square, `pick` mm between lines,
/// sampling at `resolution`.
fn predict_job(size: f64, pick: f64, resolution: u32) -> Value {
    let radius = 5.0;
    let surface = |x: f64, y: f64| {
        let (amplitude, k) = (25.0, std::f64::consts::PI / 160.0);
        let z = amplitude * (k * x).sin() * (k * y).sin();
        let dx = amplitude * k * (k * x).cos() * (k * y).sin();
        let dy = amplitude * k * (k * x).sin() * (k * y).cos();
        let length = (dx * dx + dy * dy + 1.0).sqrt();
        (z, [-dx / length, -dy / length, 1.0 / length])
    };
    let lines = (size / pick).round() as usize + 1;
    let mut program = vec!["%".to_owned(), "O1000 (RASTER)".to_owned(), "G21 G90 G17".to_owned(), "T1 M06".to_owned()];
    program.push("S6000 M03".to_owned());
    for line in 0..lines {
        for k in 0..lines {
            let i = if line % 2 == 0 { k } else { lines - 1 - k };
            let (x, y) = (i as f64 * pick, line as f64 * pick);
            let (z, n) = surface(x, y);
            let tip = [x + radius * n[0], y + radius * n[1], z + radius * n[2] - radius];
            if line == 0 && k == 0 {
                program.push(format!("G0 X{:.4} Y{:.4} Z60.0", tip[0], tip[1]));
                program.push(format!("G1 Z{:.4} F1200", tip[2]));
            } else {
                program.push(format!("X{:.4} Y{:.4} Z{:.4}", tip[0], tip[1], tip[2]));
            }
        }
    }
    program.extend(["G0 Z60.0", "M05", "M30", "%"].map(str::to_owned));
    let (margin, spacing) = (2.0 * radius, 0.5);
    let count = ((size + 2.0 * margin) / spacing).round() as usize + 1;
    let heights: Vec<Vec<f64>> = (0..count)
        .map(|j| {
            (0..count)
                .map(|i| {
                    let (z, n) = surface(-margin + i as f64 * spacing, -margin + j as f64 * spacing);
                    ((z + 0.2 / n[2]) * 1e6).round() / 1e6
                })
                .collect()
        })
        .collect();
    let mode = json!({"stiffness": 5000, "frequency_hz": 1370, "damping_ratio": 0.05});
    let shape_error: Vec<Value> = (0..10)
        .map(|k| json!({"angle_deg": 10 * k, "error": 0.003 + 0.004 * f64::from(10 * k).to_radians().sin()}))
        .collect();
    let tool = json!({"number": 1, "kind": "ball", "radius": radius, "shape_error": shape_error,
        "stiffness": {"kind": "modal", "x": [mode], "y": [mode]}});
    json!({
        "name": format!("raster {size} mm, {} passes, N = {resolution}", lines * lines),
        "tools": [tool],
        "operations": [{"operation": "predict", "tool": 1,
            "stock": {"kind": "grid", "origin": [-margin, -margin], "spacing": spacing, "heights": heights, "bottom": -100.0},
            "path": {"kind": "gcode", "program": program.join("\n") + "\n"},
            "cutting": {"ktc": 2000, "krc": 800, "kac": 300}, "method": "sampling", "resolution": resolution}]
    })
}

/// The mixed jobs: the examples, renamed so no two are identical (identical jobs are reused).
fn mixed_jobs(count: usize) -> Vec<Value> {
    let examples = examples();
    (0..count)
        .map(|n| {
            let mut job = examples[n % examples.len()].clone();
            job["name"] = json!(format!("mixed {n}"));
            job
        })
        .collect()
}

async fn submit(client: &Client, base: &str, job: &Value) -> i64 {
    let response = client.post(format!("{base}/api/v1/jobs")).json(job).send().await.unwrap();
    json_with(response, 202).await["id"].as_i64().unwrap()
}

/// A finished job's results and programs, as served (the raw text of each `result`, and each
/// operation's G-code).
async fn outputs(client: &Client, base: &str, id: i64) -> Vec<(String, String)> {
    use std::collections::BTreeMap;

    use serde_json::value::RawValue;
    let text = client.get(format!("{base}/api/v1/jobs/{id}")).send().await.unwrap().text().await.unwrap();
    let job: BTreeMap<String, Box<RawValue>> = serde_json::from_str(&text).unwrap();
    let results: Vec<BTreeMap<String, Box<RawValue>>> = serde_json::from_str(job["results"].get()).unwrap();
    let mut outputs = Vec::new();
    for (index, result) in results.iter().enumerate() {
        let gcode = client
            .get(format!("{base}/api/v1/jobs/{id}/gcode?operation={index}"))
            .send()
            .await
            .unwrap()
            .text()
            .await
            .unwrap();
        outputs.push((result["result"].get().to_owned(), gcode));
    }
    outputs
}

/// The worker processes running chunks of job `id` now, from the chunks' `worker` column
/// (host:pid:start).
async fn running_workers(postgres: &PgServer, id: i64) -> Vec<u32> {
    let pool = sqlx::PgPool::connect(&postgres.url()).await.unwrap();
    let rows: Vec<(String,)> = sqlx::query_as(
        "SELECT DISTINCT worker FROM job_chunks WHERE job_id = $1 AND status = 'running' AND worker IS NOT NULL",
    )
    .bind(id)
    .fetch_all(&pool)
    .await
    .unwrap();
    pool.close().await;
    rows.iter().filter_map(|(worker,)| worker.split(':').nth(1)?.parse().ok()).collect()
}

/// A result without the time it took (prediction results in jobs carry their `timings`).
fn without_timings(result: &str) -> Value {
    let mut value: Value = serde_json::from_str(result).unwrap();
    if let Some(object) = value.as_object_mut() {
        object.remove("timings");
    }
    value
}

async fn metric(client: &Client, base: &str, name: &str) -> Option<f64> {
    let text = client.get(format!("{base}/metrics")).send().await.unwrap().text().await.unwrap();
    text.lines().find(|line| line.starts_with(name)).and_then(|line| line.rsplit(' ').next()?.parse().ok())
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn workers_share_the_queue_and_survive_a_kill() {
    let Some(postgres) = PgServer::start() else { return };
    let url = postgres.url();
    let client = Client::builder().timeout(Duration::from_secs(60)).build().unwrap();
    let api = ServerProcess::start_with(&program(), &["serve", "--database", &url, "--job-workers", "0"]).await;
    let worker_arguments = ["worker", "--database", &url, "--job-workers", "1", "--job-lease-s", "3"];
    let mut workers = Vec::new();
    for _ in 0..2 {
        workers.push(Some(ServerProcess::start_with(&program(), &worker_arguments).await));
    }
    assert_eq!(
        json_with(client.get(format!("{}/readyz", api.base)).send().await.unwrap(), 200).await["status"],
        "ready"
    );

    // The long job first, so a worker takes it at once; then the rest.
    // Four prediction operations of a few seconds each: four chunks.
    let mut long = predict_job(40.0, 0.5, 96);
    let operation = long["operations"][0].clone();
    long["name"] = json!("long, killed");
    long["operations"] = json!(vec![operation; 4]);
    let mut jobs = vec![long, predict_job(20.0, 0.5, 96)];
    jobs.extend(mixed_jobs(20));
    let mut ids = Vec::new();
    for job in &jobs {
        ids.push(submit(&client, &api.base, job).await);
    }

    // The long job's chunks (one per operation) run on both workers at once; kill one of them
    // once the job is well under way.
    let long = ids[0];
    let deadline = Instant::now() + Duration::from_secs(60);
    let pids = loop {
        let pids = running_workers(&postgres, long).await;
        if pids.len() == 2 || Instant::now() > deadline {
            break pids;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    };
    assert_eq!(pids.len(), 2, "both workers run chunks of the long job at once: {pids:?}");
    let index = workers.iter().position(|w| w.as_ref().is_some_and(|w| w.id() == pids[0])).expect("one of ours");
    workers[index].take().unwrap().kill();

    let started = Instant::now();
    for (&id, job) in ids.iter().zip(&jobs) {
        let done = poll_job(&client, &api.base, id, 300, finished).await;
        assert_eq!(done["status"], "done", "{}: {}", job["name"], done["error"]);
        assert_eq!(done["progress"], 1.0);
    }
    let long_done = json_with(client.get(format!("{}/api/v1/jobs/{long}", api.base)).send().await.unwrap(), 200).await;
    assert_eq!(long_done["attempts"], 2, "the killed chunk was claimed again once");
    eprintln!("all {} jobs done {:.1} s after the kill", ids.len(), started.elapsed().as_secs_f64());

    // Nothing is left running or queued.
    let page = json_with(client.get(format!("{}/api/v1/jobs?limit=200", api.base)).send().await.unwrap(), 200).await;
    assert!(page["jobs"].as_array().unwrap().iter().all(|j| j["status"] == "done"), "every job done");

    // The surviving worker's metrics: it claimed jobs, and its database answers.
    let survivor = workers.iter().flatten().next().unwrap();
    let claimed = metric(&client, &survivor.base, "kerf_job_chunks_claimed_total").await.unwrap();
    assert!(claimed >= 1.0, "claims counted: {claimed}");
    assert_eq!(client.get(format!("{}/readyz", survivor.base)).send().await.unwrap().status(), 200);
    let done = metric(&client, &api.base, "kerf_jobs{state=\"done\"}").await.unwrap();
    assert_eq!(done, jobs.len() as f64);

    // The same files through one SQLite process give the same results and programs, byte for byte.
    let local = TestApp::spawn_on(Store::Sqlite, |_| {}).await.unwrap();
    let mut local_ids = Vec::new();
    for job in &jobs {
        local_ids.push(submit(&local.client, &local.base, job).await);
    }
    for ((&id, &local_id), job) in ids.iter().zip(&local_ids).zip(&jobs) {
        let local_done = poll_job(&local.client, &local.base, local_id, 300, finished).await;
        assert_eq!(local_done["status"], "done", "{}", local_done["error"]);
        let shared = outputs(&client, &api.base, id).await;
        let alone = outputs(&local.client, &local.base, local_id).await;
        assert_eq!(shared.len(), alone.len(), "{}", job["name"]);
        for (index, (a, b)) in shared.iter().zip(&alone).enumerate() {
            assert!(
                without_timings(&a.0) == without_timings(&b.0),
                "{}: operation {index}'s result differs from the one-process run",
                job["name"]
            );
            assert!(a.1 == b.1, "{}: operation {index}'s program differs from the one-process run", job["name"]);
        }
    }
    for worker in workers.into_iter().flatten() {
        worker.terminate();
    }
    api.terminate();
}

/// A result's text without the time it took (`"timings": {...}`, the last member of a prediction
/// answer; flat), so the rest can be compared byte for byte.
fn strip_timings(result: &str) -> String {
    match result.find(",\"timings\":{") {
        Some(start) => {
            let end = result[start..].find('}').map_or(result.len(), |end| start + end + 1);
            format!("{}{}", &result[..start], &result[end..])
        }
        None => result.to_owned(),
    }
}

async fn connect(postgres: &PgServer) -> sqlx::PgPool {
    sqlx::PgPool::connect(&postgres.url()).await.unwrap()
}

/// Chunks of job `id` running on the worker process `pid` now: (position, kind).
async fn chunks_of(pool: &sqlx::PgPool, id: i64, pid: u32) -> Vec<(i64, String)> {
    sqlx::query_as(
        "SELECT position, kind FROM job_chunks
         WHERE job_id = $1 AND status = 'running' AND split_part(worker, ':', 2) = $2",
    )
    .bind(id)
    .bind(pid.to_string())
    .fetch_all(pool)
    .await
    .unwrap()
}

/// The job's progress and the weighted sum of its chunks' progress, read in one snapshot, and
/// the chunks' weights together.
async fn progress_and_sum(pool: &sqlx::PgPool, id: i64) -> (f64, f64, f64) {
    sqlx::query_as(
        "SELECT j.progress, COALESCE(SUM(c.weight * c.progress) / NULLIF(SUM(c.weight), 0), 0), SUM(c.weight)
         FROM jobs j JOIN job_chunks c ON c.job_id = j.id WHERE j.id = $1 GROUP BY j.progress",
    )
    .bind(id)
    .fetch_one(pool)
    .await
    .unwrap()
}

fn signal(pid: u32, name: &str) {
    let status = std::process::Command::new("kill").arg(format!("-{name}")).arg(pid.to_string()).status().unwrap();
    assert!(status.success(), "kill -{name} {pid}");
}

/// The prediction job of the split tests: 10 201 passes (a 30 mm raster at 0.3 mm) sampled at
/// N = 96, with a fixed program number so the job's one program does not depend on its id.
fn large_prediction() -> Value {
    let mut job = predict_job(30.0, 0.3, 96);
    job["output"] = json!({"program_number": 4242});
    job
}

/// An engagement comparison of three candidate paths through a 60 × 40 mm block, fine enough
/// (0.003 mm steps, 140 000 samples) to be split into parts of [`PART_SECONDS`]; on a machine with a
/// block time and accelerations (blocks, cycle time), programming the second candidate.
fn engagement_comparison() -> Value {
    json!({
        "name": "engagement, three candidates",
        "tools": [{"number": 2, "kind": "flat", "radius": 5, "flutes": 4}],
        "machines": [{"name": "mill", "block_time_ms": 4, "max_feed": 12000, "max_accel": 2000, "dialect": "linuxcnc"}],
        "output": {"program_number": 4343},
        "operations": [{
            "operation": "engagement", "tool": 2, "machine": "mill",
            "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
            "paths": [
                {"name": "straight", "path": [[-10, 20], [70, 20]]},
                {"name": "zig-zag", "path": [[-10, 5], [70, 5], [70, 15], [-10, 15], [-10, 25], [70, 25]]},
                {"name": "deeper", "path": [[-10, 30], [35, 20], [70, 35]], "axial_depth": 3}
            ],
            "spindle_rpm": 8000, "feed_per_tooth": 0.05, "flute_counts": [2, 3, 4], "thickness_limit": 0.08,
            "step": 0.003, "kienzle": {"kc11": 1800, "mc": 0.25}, "axial_depth": 2, "candidate": 1
        }]
    })
}

/// A contour of many layers: a star of 100 corners (radius 100 mm, every other corner 3 mm in), two
/// passes with arc loops, 120 layers (240 000 moves, about 0.6 core-s by the cost model) to be
/// split into parts of [`PART_SECONDS`]; on a machine with a block time and accelerations.
fn contour_layers() -> Value {
    let star: Vec<[f64; 2]> = (0..100)
        .map(|k| {
            let angle = std::f64::consts::TAU * f64::from(k) / 100.0;
            let radius = if k % 2 == 0 { 100.0 } else { 97.0 };
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect();
    json!({
        "name": "contour, a star of 120 layers",
        "tools": [{"number": 3, "kind": "flat", "radius": 3}],
        "machines": [{"name": "mill", "block_time_ms": 2, "max_feed": 12000, "max_accel": 2000}],
        "output": {"program_number": 4444},
        "operations": [{
            "operation": "contour", "tool": 3, "machine": "mill", "contour": star, "side": "outside",
            "depths": {"top": 0, "bottom": -12, "step": 0.1}, "corner_loop": {"style": "arc"},
            "feed": 800, "loop_feed": 2000, "stock_allowance": 0.5, "spindle_rpm": 8000,
            "passes": [{"allowance": 0.3, "join": "round"}, {"allowance": 0}]
        }]
    })
}

/// A deburring of 40 holes along a tube, both edges (80 loops, the inside ridges with another
/// tool), holes pointing up, sideways and down (turned: `M00`), exact width at a fine tolerance
/// (about 0.6 core-s by the cost model) to be split into parts of [`PART_SECONDS`].
fn deburr_holes() -> Value {
    let holes: Vec<Value> = (0..40)
        .map(|i| {
            let angle = [0.0, 180.0, 90.0, 170.0][i % 4];
            json!({"shape": "round", "radius": 5, "penetration_angle_deg": angle, "axial_position": 20 * ((i * 7) % 40)})
        })
        .collect();
    json!({
        "name": "deburr, 40 holes, both edges",
        "tools": [{"number": 7, "kind": "ball", "radius": 3}, {"number": 8, "kind": "ball", "radius": 2}],
        "output": {"program_number": 4545},
        "operations": [{
            "operation": "deburr", "tool": 7, "inner_tool": 8, "edge": "both", "cut_amount": 0.3,
            "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
            "holes": holes, "method": "exact", "tolerance": 1e-4
        }]
    })
}

/// A verification of a finishing raster (the verify bench's: a Ø6 ball over a dome, 100 rows of
/// 201 moves, 20 000 blocks) over a 100 × 100 × 40 mm box, against a part whose top the dome dips
/// under (gouges past the cap of 1000 findings, material left beside the raster), at 0.06 mm
/// dexels (1 667 rows, 53 strips; about 1 core-s by the cost model) to be split into strips of
/// rows at [`PART_SECONDS`].
fn verify_raster() -> Value {
    let dome = |x: f64, y: f64| {
        let r2 = ((x - 50.0).powi(2) + (y - 50.0).powi(2)) / 2500.0;
        5.0 * (1.0 - r2).max(0.0) - 6.0
    };
    let mut program = String::from("G21 G90\nG0 X0 Y25 Z10\nF3000\n");
    for row in 0..100 {
        let y = 25.0 + 0.5 * f64::from(row);
        for step in 0..=200 {
            let k = if row % 2 == 0 { step } else { 200 - step };
            let x = 0.5 * f64::from(k);
            program.push_str(&format!("G1 X{x:.4} Y{y:.4} Z{:.4}\n", dome(x, y)));
        }
    }
    program.push_str("G0 Z50\nM30\n");
    json!({
        "name": "verify, a finishing raster",
        "operations": [{
            "operation": "verify", "program": program,
            "tools": [{"kind": "ball", "radius": 3, "number": 1, "flute_length": 20, "stickout": 30}],
            "stock": {"kind": "box", "min": [0, 0, -40], "max": [100, 100, 0]},
            "part": {"kind": "box", "min": [0, 0, -40], "max": [100, 100, -3]},
            "resolution": 0.06
        }]
    })
}

/// Workers that split work into parts of this many core-seconds (`KERF_JOB_PART_S`; the default
/// 8 would leave this test's operations whole).
const PART_SECONDS: &str = "0.25";

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn a_prediction_splits_across_workers_and_survives_a_kill() {
    let Some(postgres) = PgServer::start() else { return };
    let url = postgres.url();
    let client = Client::builder().timeout(Duration::from_secs(60)).build().unwrap();
    let api = ServerProcess::start_with(&program(), &["serve", "--database", &url, "--job-workers", "0"]).await;
    let worker_arguments = ["worker", "--database", &url, "--job-workers", "1", "--job-lease-s", "3"];
    let mut workers = Vec::new();
    for _ in 0..2 {
        let worker =
            ServerProcess::start_with_env(&program(), &worker_arguments, &[("KERF_JOB_PART_S", PART_SECONDS)]).await;
        workers.push(Some(worker));
    }
    let pool = connect(&postgres).await;
    let job = large_prediction();
    let id = submit(&client, &api.base, &job).await;
    let engagement = engagement_comparison();
    let engagement_id = submit(&client, &api.base, &engagement).await;
    let contour = contour_layers();
    let contour_id = submit(&client, &api.base, &contour).await;
    let deburr = deburr_holes();
    let deburr_id = submit(&client, &api.base, &deburr).await;

    // The one operation is split, and both workers run parts of it at once.
    let deadline = Instant::now() + Duration::from_secs(300);
    let pids = loop {
        let pids = running_workers(&postgres, id).await;
        if pids.len() == 2 || Instant::now() > deadline {
            break pids;
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    assert_eq!(pids.len(), 2, "both workers run parts of the one prediction at once: {pids:?}");
    let (parts,): (i64,) =
        sqlx::query_as("SELECT COUNT(*) FROM job_chunks WHERE job_id = $1 AND kind = 'part' AND operation = 0")
            .bind(id)
            .fetch_one(&pool)
            .await
            .unwrap();
    assert!(parts >= 3, "the prediction is split into parts: {parts}");

    // The job's progress is the sum of its chunks' (weighted by their work; one operation's
    // weights make 1), in every snapshot.
    for _ in 0..10 {
        let (progress, sum, weights) = progress_and_sum(&pool, id).await;
        assert!((progress - sum).abs() < 1e-9, "job progress {progress}, chunks' sum {sum}");
        assert!((weights - 1.0).abs() < 1e-9, "one operation's chunks weigh {weights}");
        tokio::time::sleep(Duration::from_millis(100)).await;
    }

    // Kill one worker in the middle of a part: stopped first (SIGSTOP), so the part it runs is
    // surely unfinished when it is killed (SIGKILL); if it had none running, let it go on and
    // look again.
    let (victim, killed) = loop {
        assert!(Instant::now() < deadline, "no worker ran a part to kill");
        let pid = running_workers(&postgres, id).await.first().copied();
        let Some(pid) = pid else {
            tokio::time::sleep(Duration::from_millis(20)).await;
            continue;
        };
        signal(pid, "STOP");
        match chunks_of(&pool, id, pid).await.as_slice() {
            [(position, kind), ..] if kind == "part" => break (pid, *position),
            _ => signal(pid, "CONT"),
        }
    };
    let index = workers.iter().position(|w| w.as_ref().is_some_and(|w| w.id() == victim)).expect("one of ours");
    workers[index].take().unwrap().kill();

    let done = poll_job(&client, &api.base, id, 900, finished).await;
    assert_eq!(done["status"], "done", "{}", done["error"]);
    assert_eq!(done["progress"], 1.0);
    let (attempts,): (i64,) = sqlx::query_as("SELECT attempts FROM job_chunks WHERE job_id = $1 AND position = $2")
        .bind(id)
        .bind(killed)
        .fetch_one(&pool)
        .await
        .unwrap();
    assert_eq!(attempts, 2, "the killed part was claimed again");
    let (left, stored, expected): (i64, i64, i64) = sqlx::query_as(
        "SELECT (SELECT COUNT(*) FROM job_chunks WHERE job_id = $1 AND (output_gz IS NOT NULL OR status <> 'done')),
                stored_bytes,
                octet_length(job_json) + (SELECT SUM(octet_length(result_gz) + COALESCE(octet_length(gcode_gz), 0))
                                          FROM job_results WHERE job_id = $1)
         FROM jobs WHERE id = $1",
    )
    .bind(id)
    .fetch_one(&pool)
    .await
    .unwrap();
    assert_eq!(left, 0, "every chunk done, and the parts' outputs dropped once merged");
    assert_eq!(stored, expected, "the job takes its file and its result");

    // The engagement comparison, the contour's layers and the deburring's loops were split into
    // parts too, and are done.
    for (other, what) in
        [(engagement_id, "engagement candidates"), (contour_id, "contour layers"), (deburr_id, "deburr loops")]
    {
        let other_done = poll_job(&client, &api.base, other, 900, finished).await;
        assert_eq!(other_done["status"], "done", "{what}: {}", other_done["error"]);
        assert_eq!(other_done["progress"], 1.0, "{what}");
        let (parts,): (i64,) =
            sqlx::query_as("SELECT COUNT(*) FROM job_chunks WHERE job_id = $1 AND kind = 'part' AND status = 'done'")
                .bind(other)
                .fetch_one(&pool)
                .await
                .unwrap();
        assert!(parts >= 2, "the {what} are split: {parts} parts");
        eprintln!("{what}: {parts} parts");
    }

    // One SQLite process runs the same files whole: the same results (but for the time a
    // prediction took) and programs, byte for byte.
    let local = TestApp::spawn_on(Store::Sqlite, |_| {}).await.unwrap();
    let job_program = |base: &str, id: i64| {
        let client = client.clone();
        let url = format!("{base}/api/v1/jobs/{id}/program");
        async move { client.get(url).send().await.unwrap().text().await.unwrap() }
    };
    for (shared_id, file) in [(id, &job), (engagement_id, &engagement), (contour_id, &contour), (deburr_id, &deburr)] {
        let local_id = submit(&local.client, &local.base, file).await;
        let local_done = poll_job(&local.client, &local.base, local_id, 900, finished).await;
        assert_eq!(local_done["status"], "done", "{}", local_done["error"]);
        let shared = outputs(&client, &api.base, shared_id).await;
        let alone = outputs(&local.client, &local.base, local_id).await;
        let name = &file["name"];
        assert_eq!(shared.len(), 1);
        assert!(
            strip_timings(&shared[0].0) == strip_timings(&alone[0].0),
            "{name}: the merged result differs from the one-process run"
        );
        assert!(shared[0].1 == alone[0].1, "{name}: the merged program differs from the one-process run");
        assert!(
            job_program(&api.base, shared_id).await == job_program(&local.base, local_id).await,
            "{name}: the job's one program differs from the one-process run"
        );
    }
    let shared = outputs(&client, &api.base, id).await;
    assert!(shared[0].0.contains("\"timings\":{"), "the merged prediction reports its time");
    pool.close().await;
    for worker in workers.into_iter().flatten() {
        worker.terminate();
    }
    api.terminate();
}

/// A verification job is split into strips of the dexel grid's rows that both workers cut, and
/// its stored answer is `POST /api/v1/verify`'s for the same request, byte for byte.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn a_verification_splits_into_strips_across_workers() {
    let Some(postgres) = PgServer::start() else { return };
    let url = postgres.url();
    let client = Client::builder().timeout(Duration::from_secs(120)).build().unwrap();
    let api = ServerProcess::start_with(&program(), &["serve", "--database", &url, "--job-workers", "0"]).await;
    let worker_arguments = ["worker", "--database", &url, "--job-workers", "1"];
    let mut workers = Vec::new();
    for _ in 0..2 {
        workers.push(
            ServerProcess::start_with_env(&program(), &worker_arguments, &[("KERF_JOB_PART_S", PART_SECONDS)]).await,
        );
    }
    let pool = connect(&postgres).await;
    let job = verify_raster();
    let id = submit(&client, &api.base, &job).await;
    let done = poll_job(&client, &api.base, id, 900, finished).await;
    assert_eq!(done["status"], "done", "{}", done["error"]);
    assert_eq!(done["progress"], 1.0);
    let (parts, cut_by): (i64, i64) = sqlx::query_as(
        "SELECT COUNT(*), COUNT(DISTINCT split_part(worker, ':', 2)) FROM job_chunks
         WHERE job_id = $1 AND kind = 'part' AND status = 'done'",
    )
    .bind(id)
    .fetch_one(&pool)
    .await
    .unwrap();
    assert!(parts >= 2, "the verification is split into strips: {parts} parts");
    eprintln!("verification: {parts} parts, cut by {cut_by} workers");

    let mut request = job["operations"][0].clone();
    request.as_object_mut().unwrap().remove("operation");
    let response = client.post(format!("{}/api/v1/verify", api.base)).json(&request).send().await.unwrap();
    assert_eq!(response.status(), 200);
    let answer = response.text().await.unwrap();
    let stored = outputs(&client, &api.base, id).await;
    assert_eq!(stored.len(), 1);
    assert!(stored[0].0 == answer, "the merged verification differs from the endpoint's answer");
    let answer: Value = serde_json::from_str(&answer).unwrap();
    assert_eq!(answer["findings"].as_array().unwrap().len(), 1000, "findings past the cap");
    assert!(answer["findings_left_off"].as_u64().unwrap() > 0);
    assert_eq!(answer["findings"][999]["kind"], "gouge");
    pool.close().await;
    for worker in workers {
        worker.terminate();
    }
    api.terminate();
}

/// Two workers' heartbeats at once keep the job's progress at its chunks' sum: the second one
/// waits for the first's lock on the job and must add up the chunks after the first commits (it
/// used to sum them from the snapshot it took before waiting, and left the job behind; the
/// prediction test above saw that once). The first heartbeat is held open by hand between its
/// chunk's update and its commit, so the interleaving is certain.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn heartbeats_at_once_keep_the_job_at_its_chunks_sum() {
    use kerf_server::jobs::file::{self, Format};
    use kerf_server::store::jobs::{self as store, Claimant};
    let Some(postgres) = PgServer::start() else { return };
    let db = kerf_server::db::open(&postgres.database()).await.unwrap();
    let deburr = kerf_cases::operation("deburr", kerf_cases::deburr::case_1());
    let job = json!({"name": "two chunks", "operations": [deburr, deburr]});
    let id = store::insert(&db, &file::parse(&job.to_string(), Format::Json).unwrap(), "two chunks", u64::MAX)
        .await
        .unwrap();
    let claimant = |worker: &str| Claimant { worker: worker.into(), lease: Duration::from_secs(60) };
    let (first, second) = (claimant("first"), claimant("second"));
    let first_work = store::claim(&db, &first).await.unwrap().expect("a chunk for the first worker").work;
    let second_work = store::claim(&db, &second).await.unwrap().expect("a chunk for the second worker").work;
    assert_eq!((first_work.id, second_work.id), (id, id));
    assert_ne!(first_work.chunk, second_work.chunk);

    // The first heartbeat: its chunk at 0.5 and the job's row locked, not committed yet.
    let pool = connect(&postgres).await;
    let mut held = pool.begin().await.unwrap();
    let position = i64::try_from(first_work.chunk.unwrap()).unwrap();
    sqlx::query("UPDATE job_chunks SET progress = 0.5 WHERE job_id = $1 AND position = $2")
        .bind(id)
        .bind(position)
        .execute(&mut *held)
        .await
        .unwrap();
    sqlx::query("SELECT id FROM jobs WHERE id = $1 FOR UPDATE").bind(id).execute(&mut *held).await.unwrap();

    let second_beat = tokio::spawn({
        let db = db.clone();
        async move { store::heartbeat(&db, second_work, &second, 0.25).await }
    });
    tokio::time::sleep(Duration::from_millis(500)).await;
    assert!(!second_beat.is_finished(), "the second heartbeat waits for the first's lock on the job");
    held.commit().await.unwrap();
    assert!(second_beat.await.unwrap().unwrap(), "the second heartbeat keeps its chunk");

    let (progress, sum, _) = progress_and_sum(&pool, id).await;
    assert!((sum - 0.375).abs() < 1e-9, "the chunks at 0.5 and 0.25 weigh alike: {sum}");
    assert!((progress - sum).abs() < 1e-9, "job progress {progress}, chunks' sum {sum}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn a_refused_part_fails_its_job_with_its_problem() {
    let Some(postgres) = PgServer::start() else { return };
    let url = postgres.url();
    let client = Client::builder().timeout(Duration::from_secs(60)).build().unwrap();
    let api = ServerProcess::start_with(&program(), &["serve", "--database", &url, "--job-workers", "0"]).await;
    // Results of at most 1 MiB per job: the parts' outputs together are more.
    let worker = ServerProcess::start_with_env(
        &program(),
        &["worker", "--database", &url, "--job-workers", "1", "--job-result-max-mb", "1"],
        &[("KERF_JOB_PART_S", PART_SECONDS)],
    )
    .await;
    let pool = connect(&postgres).await;
    let id = submit(&client, &api.base, &large_prediction()).await;
    let failed = poll_job(&client, &api.base, id, 900, finished).await;
    assert_eq!(failed["status"], "failed", "{failed}");
    let error = &failed["error"];
    assert_eq!(error["code"], "E_RESULT_TOO_LARGE", "{error}");
    assert_eq!(error["status"], 422);
    assert_eq!(error["errors"][0]["path"], "operations[0]", "{error}");
    // The chunk refused was one of the operation's parts (or its finish step), and nothing the
    // others stored is left.
    let (kind,): (String,) = sqlx::query_as("SELECT kind FROM job_chunks WHERE job_id = $1 AND status = 'failed'")
        .bind(id)
        .fetch_one(&pool)
        .await
        .unwrap();
    assert!(kind == "part" || kind == "finish", "the refused chunk is a {kind}");
    eprintln!("the refused chunk: a {kind}");
    let (outputs, stored, file): (i64, i64, i64) = sqlx::query_as(
        "SELECT (SELECT COUNT(*) FROM job_chunks WHERE job_id = $1 AND output_gz IS NOT NULL), stored_bytes,
                octet_length(job_json)::BIGINT
         FROM jobs WHERE id = $1",
    )
    .bind(id)
    .fetch_one(&pool)
    .await
    .unwrap();
    assert_eq!((outputs, stored), (0, file), "a failed job keeps only its file");
    pool.close().await;
    worker.terminate();
    api.terminate();
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn two_api_nodes_share_the_registry_and_cancel_reaches_the_other() {
    let Some(first) = TestApp::spawn_on(Store::Postgres, |config| config.job_workers = 1).await else { return };
    // The second node runs no jobs: whatever runs, runs on the first.
    let second = first.spawn_beside(|config| config.job_workers = 0).await;

    let tool = json!({"kind": "ball", "radius": 3, "name": "shared"});
    json_with(first.put_json("/api/v1/tools/7", &tool).await, 201).await;
    assert_eq!(json_with(second.get("/api/v1/tools/7").await, 200).await["name"], "shared");
    let machine = json!({"block_time_ms": 4, "max_feed": 12000, "dialect": "linuxcnc"});
    json_with(second.put_json("/api/v1/machines/lcnc", &machine).await, 201).await;
    assert_eq!(json_with(first.get("/api/v1/machines").await, 200).await.as_array().unwrap().len(), 1);
    // A replace through one is a replace for the other (200, not 201).
    json_with(second.put_json("/api/v1/tools/7", &json!({"kind": "ball", "radius": 2})).await, 200).await;
    assert_eq!(json_with(first.get("/api/v1/tools/7").await, 200).await["radius"], 2.0);

    // A long job submitted through the second node runs on the first node's worker; a short one
    // waits behind it. Cancelled through the second node, the long one stops on the first at
    // once (NOTIFY), and the short one runs.
    let long = submit(&second.client, &second.base, &long_job("long, cancelled", 40)).await;
    let running = poll_job(&second.client, &second.base, long, 60, |j| j["status"] == "running").await;
    assert_eq!(running["status"], "running");
    let mut short = mixed_jobs(1).remove(0);
    short["name"] = json!("behind the long one");
    let short = submit(&second.client, &second.base, &short).await;
    tokio::time::sleep(Duration::from_millis(500)).await;
    assert_eq!(json_with(second.get(&format!("/api/v1/jobs/{short}")).await, 200).await["status"], "queued");
    // Measured and printed, not asserted: the short job starting before the long one could end is
    // what shows the cancel reached the other node's worker.
    let cancelled_at = Instant::now();
    json_with(second.delete(&format!("/api/v1/jobs/{long}")).await, 200).await;
    let after = poll_job(&first.client, &first.base, short, 30, |j| j["status"] != "queued").await;
    let reached = cancelled_at.elapsed();
    assert_ne!(after["status"], "queued", "{after}");
    eprintln!("cancel reached the other node's worker in {:.0} ms", reached.as_secs_f64() * 1e3);
    let short_done = poll_job(&first.client, &first.base, short, 60, finished).await;
    assert_eq!(short_done["status"], "done", "{short_done}");
    assert_eq!(json_with(first.get(&format!("/api/v1/jobs/{long}")).await, 200).await["status"], "cancelled");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn readiness_follows_the_database() {
    let Some(app) = TestApp::spawn_on(Store::Postgres, |_| {}).await else { return };
    assert_eq!(json_with(app.get("/readyz").await, 200).await["database"], "postgres");
    app.postgres.as_ref().unwrap().stop();
    let answer = app.get("/readyz").await;
    assert_eq!(answer.status(), 503);
    assert_eq!(answer.headers()["content-type"], "application/problem+json");
    assert!(answer.headers().contains_key("retry-after"), "a load balancer is told when to look again");
    // The process itself is up: its page still answers.
    assert_eq!(app.get("/").await.status(), 200);
    drop(app);
}

/// One database route's answer while PostgreSQL is down: 503 `E_UNAVAILABLE` with `Retry-After`;
/// how long it took (printed, not asserted: the acquire timeout bounds it).
async fn unavailable(request: reqwest::RequestBuilder, what: &str) -> f64 {
    let started = Instant::now();
    let answer = request.send().await.unwrap();
    let seconds = started.elapsed().as_secs_f64();
    assert!(answer.headers().contains_key("retry-after"), "{what}: no Retry-After ({})", answer.status());
    let problem = kerf_tests::problem(answer, 503).await;
    assert_eq!(problem["code"], "E_UNAVAILABLE", "{what}: {problem}");
    eprintln!("{what}: 503 after {seconds:.2} s");
    seconds
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_postgres), ignore = "PostgreSQL not found: apt-get install postgresql")]
async fn a_database_outage_mid_job_loses_no_finished_result() {
    let Some(postgres) = PgServer::start() else { return };
    let url = postgres.url();
    let client = Client::builder().timeout(Duration::from_secs(60)).build().unwrap();
    let timeout = [("KERF_DATABASE_TIMEOUT_S", "2")];
    let api =
        ServerProcess::start_with_env(&program(), &["serve", "--database", &url, "--job-workers", "0"], &timeout).await;
    // A lease longer than the outage: the chunks stay their worker's while it is down.
    let worker_arguments = ["worker", "--database", &url, "--job-workers", "2", "--job-lease-s", "40"];
    let worker = ServerProcess::start_with_env(&program(), &worker_arguments, &timeout).await;
    let mut ids = Vec::new();
    for n in 0..6 {
        let mut job = predict_job(20.0, 0.5, 96);
        job["name"] = json!(format!("outage {n}"));
        ids.push(submit(&client, &api.base, &job).await);
    }
    let deadline = Instant::now() + Duration::from_secs(60);
    while json_with(client.get(format!("{}/api/v1/jobs/{}", api.base, ids[0])).send().await.unwrap(), 200).await["status"]
        != "running"
    {
        assert!(Instant::now() < deadline, "the first job never started");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }

    // PostgreSQL stops while both workers compute; the work goes on.
    postgres.stop_fast();
    let stopped = Instant::now();
    let mut slowest: f64 = 0.0;
    slowest = slowest.max(unavailable(client.get(format!("{}/api/v1/tools", api.base)), "GET /api/v1/tools").await);
    let job = format!("{}/api/v1/jobs/{}", api.base, ids[0]);
    slowest = slowest.max(unavailable(client.get(&job), "GET /api/v1/jobs/{id}").await);
    let tool = json!({"kind": "flat", "radius": 3});
    let put = client.put(format!("{}/api/v1/tools/5", api.base)).json(&tool);
    slowest = slowest.max(unavailable(put, "PUT /api/v1/tools/5").await);
    let submitted = client.post(format!("{}/api/v1/jobs", api.base)).json(&predict_job(10.0, 0.5, 32));
    slowest = slowest.max(unavailable(submitted, "POST /api/v1/jobs").await);
    slowest = slowest.max(unavailable(client.get(format!("{}/readyz", api.base)), "GET /readyz (API)").await);
    slowest = slowest.max(unavailable(client.get(format!("{}/readyz", worker.base)), "GET /readyz (worker)").await);
    eprintln!("slowest 503 during the outage: {slowest:.2} s");
    // Down long enough that running work finishes meanwhile and has to keep its result.
    tokio::time::sleep(Duration::from_secs(8).saturating_sub(stopped.elapsed())).await;
    postgres.start_again();
    eprintln!("PostgreSQL down {:.1} s", stopped.elapsed().as_secs_f64());

    // Every job ends done, run once: no finished result was dropped and computed again.
    for &id in &ids {
        let done = poll_job(&client, &api.base, id, 300, finished).await;
        assert_eq!(done["status"], "done", "job {id}: {}", done["error"]);
        assert_eq!(done["attempts"], 1, "job {id} was run again: a finished result was lost");
    }
    assert!(tool_absent(&client, &api.base).await, "the refused PUT stored nothing");
    worker.terminate();
    api.terminate();
}

async fn tool_absent(client: &Client, base: &str) -> bool {
    client.get(format!("{base}/api/v1/tools/5")).send().await.unwrap().status() == 404
}

#[tokio::test(flavor = "multi_thread")]
async fn a_worker_needs_postgres() {
    let folder = tempfile::tempdir().unwrap();
    let database = folder.path().join("kerf.db");
    let output = std::process::Command::new(program()).args(["worker", "--database"]).arg(&database).output().unwrap();
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("PostgreSQL"), "{stderr}");
}
