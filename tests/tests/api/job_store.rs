//! The job store stays bounded: a quota that refuses what does not fit and writes
//! nothing of it, retention that prunes finished jobs on its own, `kerf jobs prune` on a real
//! database, and an SQLite file that stays small and shrinks again after pruning.

use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

use kerf_server::db::{self, Database, Db};
use kerf_server::store;
use kerf_tests::{Store, TestApp, finished, json_with, poll_job, problem};
use serde_json::{Value, json};

use crate::jobs::long_job;
use kerf_cases::contour::circle;

fn program() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_kerf-under-test"))
}

/// A segment job of an ellipse at a short block time: some 1 MB of JSON and program, named
/// `name` so that each is a new job.
fn segment_job(name: &str) -> Value {
    json!({"name": name, "operations": [{"operation": "segment",
        "curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [50, 25], "end_deg": 360},
        "feed": 1000, "block_time_ms": 4, "mode": "guarantee"}]})
}

/// A quick deburr job.
fn quick_job(name: &str) -> Value {
    json!({"name": name, "operations": [kerf_cases::operation("deburr", kerf_cases::deburr::case_1())]})
}

async fn submit(app: &TestApp, job: &Value) -> reqwest::Response {
    app.post_json("/api/v1/jobs", job).await
}

async fn submitted_id(app: &TestApp, job: &Value) -> i64 {
    json_with(submit(app, job).await, 202).await["id"].as_i64().unwrap()
}

/// The `--database` value of `app`'s store, as the command line takes it.
fn database_argument(app: &TestApp) -> String {
    match &app.config.database {
        Database::Sqlite(path) => path.to_string_lossy().into_owned(),
        Database::Postgres(url) => url.clone(),
    }
}

/// The file's size with its write-ahead log, bytes.
fn file_size(path: &std::path::Path) -> u64 {
    ["", "-wal"]
        .iter()
        .filter_map(|suffix| std::fs::metadata(format!("{}{suffix}", path.display())).ok())
        .map(|metadata| metadata.len())
        .sum()
}

async fn usage(db: &Db) -> (i64, u64) {
    let (jobs, bytes) = store::jobs::usage(db).await.unwrap();
    (jobs, bytes.unsigned_abs())
}

async fn the_store_stays_under_its_quota(store: Store) {
    let quota: u64 = 600 * 1024;
    let Some(app) = TestApp::spawn_on(store, |config| config.job_storage.quota_bytes = Some(quota)).await else {
        return;
    };
    let db = db::open(&app.config.database).await.unwrap();
    // Jobs of a few hundred kB of compressed results each, one after another, until one does not fit.
    let mut refused = None;
    for k in 0..20 {
        let id = submitted_id(&app, &segment_job(&format!("ellipse {k}"))).await;
        let job = poll_job(&app.client, &app.base, id, 60, finished).await;
        if job["status"] == "failed" {
            refused = Some(job);
            break;
        }
        assert_eq!(job["status"], "done", "{job}");
    }
    let refused = refused.expect("a job whose results do not fit in the quota fails");
    assert_eq!(refused["error"]["code"], "E_JOB_STORE_FULL", "{refused}");
    let detail = refused["error"]["detail"].as_str().unwrap();
    assert!(detail.contains("prune") && detail.contains("--job-store-quota-mb"), "{detail}");
    // Nothing of its results was written.
    assert!(refused.get("results").is_none(), "{refused}");
    problem(app.get(&format!("/api/v1/jobs/{}/gcode", refused["id"])).await, 409).await;
    let (jobs, used) = usage(&db).await;
    assert!(used <= quota, "{used} bytes stored over the quota of {quota}");

    // A job file larger than the room left is refused at submission, and nothing of it is stored.
    let room = usize::try_from(quota - used).unwrap();
    let big = json!({"name": "large contour", "operations": [{"operation": "contour",
        "tool": {"kind": "ball", "radius": 3}, "contour": circle(room / 30 + 100), "side": "outside",
        "depths": {"top": 0, "bottom": -1, "step": 1}, "feed": 800}]});
    assert!(big.to_string().len() > room);
    let answer = problem(submit(&app, &big).await, 429).await;
    assert_eq!(answer["code"], "E_JOB_STORE_FULL", "{answer}");
    let detail = answer["detail"].as_str().unwrap();
    assert!(detail.contains("prune") && detail.contains("--job-store-quota-mb"), "{detail}");
    assert_eq!(usage(&db).await, (jobs, used), "the refused job left nothing behind");
    let listed = json_with(app.get("/api/v1/jobs?limit=200").await, 200).await;
    assert_eq!(listed["jobs"].as_array().unwrap().len(), usize::try_from(jobs).unwrap());
    // A small job still fits in the room left.
    submitted_id(&app, &quick_job("small")).await;
}

async fn a_job_over_the_per_job_cap_fails_naming_its_operation(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |config| config.job_storage.job_max_bytes = 100 * 1024).await else {
        return;
    };
    let mut job = quick_job("two operations");
    job["operations"] = json!([quick_job("")["operations"][0], segment_job("")["operations"][0]]);
    let id = submitted_id(&app, &job).await;
    let job = poll_job(&app.client, &app.base, id, 60, finished).await;
    assert_eq!(job["status"], "failed", "{job}");
    assert_eq!(job["error"]["code"], "E_RESULT_TOO_LARGE", "{job}");
    assert_eq!(job["error"]["errors"][0]["path"], "operations[1]", "{job}");
    assert!(job["error"]["detail"].as_str().unwrap().contains("--job-result-max-mb"), "{job}");
    // Nothing of it stays stored, not even the result of the operation that fitted (on
    // PostgreSQL its chunk may have finished first).
    let db = db::open(&app.config.database).await.unwrap();
    let rows: (i64,) = match &db {
        Db::Sqlite(pool) => sqlx::query_as("SELECT COUNT(*) FROM job_results").fetch_one(pool).await.unwrap(),
        Db::Postgres(pool) => sqlx::query_as("SELECT COUNT(*) FROM job_results").fetch_one(pool).await.unwrap(),
    };
    assert_eq!(rows.0, 0, "results of a failed job");
    assert!(usage(&db).await.1 < 4096, "the failed job takes only its job file");
}

/// `kerf jobs prune ARGUMENTS` on `app`'s store; its standard output.
fn prune_command(app: &TestApp, arguments: &[&str]) -> String {
    let output = Command::new(program())
        .args(["jobs", "prune", "--database", &database_argument(app)])
        .args(arguments)
        .env("RUST_LOG", "warn")
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(output.status.success(), "kerf jobs prune failed: {stdout}{}", String::from_utf8_lossy(&output.stderr));
    stdout
}

async fn prune_removes_finished_jobs_only(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |config| {
        config.job_workers = 1;
        config.solver_slots = 1;
        config.job_storage.retention = None;
    })
    .await
    else {
        return;
    };
    // Finished jobs of every kind: done, failed, cancelled.
    let done = submitted_id(&app, &quick_job("done")).await;
    assert_eq!(poll_job(&app.client, &app.base, done, 60, finished).await["status"], "done");
    let mut bad = quick_job("failed");
    bad["operations"][0]["hole"]["radius"] = json!(60);
    let failed = submitted_id(&app, &bad).await;
    assert_eq!(poll_job(&app.client, &app.base, failed, 60, finished).await["status"], "failed");
    // One running, one queued behind it (one worker), one cancelled while queued.
    let running = submitted_id(&app, &long_job(30)).await;
    assert_eq!(poll_job(&app.client, &app.base, running, 60, |j| j["status"] != "queued").await["status"], "running");
    let mut second = long_job(30);
    second["name"] = json!("queued");
    let queued = submitted_id(&app, &second).await;
    let mut third = long_job(30);
    third["name"] = json!("cancelled");
    let cancelled = submitted_id(&app, &third).await;
    json_with(app.delete(&format!("/api/v1/jobs/{cancelled}")).await, 200).await;

    // Nothing finished more than a day ago.
    let output = prune_command(&app, &["--older-than-days", "1"]);
    assert!(output.contains("removed 0 finished job"), "{output}");
    assert_eq!(app.get(&format!("/api/v1/jobs/{done}")).await.status(), 200);

    let output = prune_command(&app, &["--older-than-days", "0"]);
    assert!(
        output.contains(&format!("removed 3 finished job(s) older than 0 day(s) (ids {done}, {failed}, {cancelled})")),
        "{output}"
    );
    for id in [done, failed, cancelled] {
        problem(app.get(&format!("/api/v1/jobs/{id}")).await, 404).await;
    }
    let still = json_with(app.get(&format!("/api/v1/jobs/{running}")).await, 200).await;
    assert_eq!(still["status"], "running", "{still}");
    let still = json_with(app.get(&format!("/api/v1/jobs/{queued}")).await, 200).await;
    assert_eq!(still["status"], "queued", "{still}");
    assert!(output.contains("the store holds 2 job(s)"), "{output}");
    for id in [running, queued] {
        app.delete(&format!("/api/v1/jobs/{id}")).await;
    }
}

async fn retention_prunes_finished_jobs_on_its_own(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |config| {
        config.job_workers = 1;
        config.solver_slots = 1;
        config.job_storage.retention = Some(Duration::from_millis(500));
        config.job_storage.prune_every = Duration::from_millis(100);
    })
    .await
    else {
        return;
    };
    let done = submitted_id(&app, &quick_job("done")).await;
    assert_eq!(poll_job(&app.client, &app.base, done, 60, finished).await["status"], "done");
    // A running job and a queued one, older than the retention, stay.
    let running = submitted_id(&app, &long_job(30)).await;
    let mut second = long_job(30);
    second["name"] = json!("queued");
    let queued = submitted_id(&app, &second).await;
    let mut gone = false;
    for _ in 0..600 {
        if app.get(&format!("/api/v1/jobs/{done}")).await.status() == 404 {
            gone = true;
            break;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert!(gone, "the finished job past its retention was pruned");
    tokio::time::sleep(Duration::from_millis(800)).await;
    let running_job = json_with(app.get(&format!("/api/v1/jobs/{running}")).await, 200).await;
    assert!(matches!(running_job["status"].as_str(), Some("running" | "done")), "{running_job}");
    let queued_job = json_with(app.get(&format!("/api/v1/jobs/{queued}")).await, 200).await;
    assert!(matches!(queued_job["status"].as_str(), Some("queued" | "running" | "done")), "{queued_job}");
    for id in [running, queued] {
        app.delete(&format!("/api/v1/jobs/{id}")).await;
    }
}

kerf_tests::on_both_stores!(
    the_store_stays_under_its_quota,
    a_job_over_the_per_job_cap_fails_naming_its_operation,
    prune_removes_finished_jobs_only,
    retention_prunes_finished_jobs_on_its_own
);

#[tokio::test(flavor = "multi_thread")]
async fn the_sqlite_file_stays_bounded_and_shrinks_after_pruning() {
    // 24 jobs of about 1 MB of JSON and program each, into a 3 MiB quota.
    let quota: u64 = 3 * 1024 * 1024;
    let mut app = TestApp::spawn_configured(|config| {
        config.job_storage.quota_bytes = Some(quota);
        config.job_storage.retention = None;
    })
    .await;
    let (mut done, mut stored) = (0, 0);
    for k in 0..24 {
        let response = submit(&app, &segment_job(&format!("ellipse {k}"))).await;
        if response.status() == 429 {
            continue;
        }
        let id = json_with(response, 202).await["id"].as_i64().unwrap();
        stored += 1;
        if poll_job(&app.client, &app.base, id, 60, finished).await["status"] == "done" {
            done += 1;
        }
    }
    let full = file_size(&app.database);
    eprintln!("{done} of 24 jobs stored; database file with its log: {full} bytes (quota {quota})");
    assert!(done >= 3, "{done} jobs stored");
    // The quota bounds the file: what it holds, the schema's pages, and a write-ahead log cut
    // back at checkpoints.
    assert!(full <= quota + 6 * 1024 * 1024, "{full} bytes on disk with a quota of {quota}");
    app.shutdown().await;
    let output = prune_command(&app, &["--older-than-days", "0"]);
    let pruned = file_size(&app.database);
    eprintln!("{output}after pruning: {pruned} bytes");
    assert!(output.contains(&format!("removed {stored} finished job(s)")), "{output}");
    assert!(pruned * 4 < full, "the file gave the pruned jobs' space back: {full} → {pruned} bytes");
}

#[tokio::test(flavor = "multi_thread")]
async fn results_stored_before_compression_are_still_served() {
    // A row as the schema before migration 0004 stored it: plain text, no compressed columns.
    let app = TestApp::spawn_configured(|config| config.job_workers = 0).await;
    let db = db::open(&app.config.database).await.unwrap();
    let Db::Sqlite(pool) = &db else { unreachable!("an SQLite test app") };
    let job = serde_json::to_string(&quick_job("old")).unwrap();
    let (id,): (i64,) = sqlx::query_as(
        "INSERT INTO jobs (name, status, content_hash, job_json, operations, finished_at)
         VALUES ('old', 'done', 'h', $1, '[\"deburr\"]', '2020-01-01T00:00:00.000Z') RETURNING id",
    )
    .bind(&job)
    .fetch_one(pool)
    .await
    .unwrap();
    sqlx::query(
        "INSERT INTO job_results (job_id, position, operation, result_json, gcode) VALUES ($1, 0, 'deburr', $2, $3)",
    )
    .bind(id)
    .bind(r#"{"points": [[1.5, 2.5, 3.5]]}"#)
    .bind("%\nO1000\nG00 X1.5000\nM30\n%\n")
    .execute(pool)
    .await
    .unwrap();
    let shown = json_with(app.get(&format!("/api/v1/jobs/{id}")).await, 200).await;
    assert_eq!(shown["results"][0]["result"], json!({"points": [[1.5, 2.5, 3.5]]}), "{shown}");
    assert_eq!(shown["results"][0]["gcode"], true);
    let program = app.get_text(&format!("/api/v1/jobs/{id}/gcode"), 200).await;
    assert_eq!(program, "%\nO1000\nG00 X1.5000\nM30\n%\n");
    // And it is pruned like any other finished job.
    let output = prune_command(&app, &["--older-than-days", "30"]);
    assert!(output.contains(&format!("removed 1 finished job(s) older than 30 day(s) (ids {id})")), "{output}");
}
