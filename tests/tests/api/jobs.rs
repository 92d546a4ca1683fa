//! Jobs over HTTP: every example job file uploaded (multipart and raw) and run to the end, reuse
//! of identical jobs, failures with their field, cancellation, paging, bad uploads, the stored
//! job file read back and run again, and a server killed with SIGKILL in the middle of a job.

use std::path::{Path, PathBuf};
use std::time::Duration;

use kerf_server::state::Limits;
use kerf_tests::{ServerProcess, Store, TestApp, finished, json_with, poll_job, problem};
use reqwest::multipart::{Form, Part};
use serde_json::{Value, json};

pub fn examples() -> Vec<PathBuf> {
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let mut files: Vec<PathBuf> = std::fs::read_dir(folder)
        .expect("examples folder")
        .map(|entry| entry.expect("entry").path())
        .filter(|path| path.extension().is_some_and(|e| e == "json" || e == "toml"))
        .collect();
    files.sort();
    assert!(files.len() >= 2, "example job files");
    files
}

fn media_type(path: &Path) -> &'static str {
    if path.extension().is_some_and(|e| e == "toml") { "application/toml" } else { "application/json" }
}

async fn upload_multipart(app: &TestApp, path: &Path) -> reqwest::Response {
    let bytes = std::fs::read(path).unwrap();
    let name = path.file_name().unwrap().to_string_lossy().into_owned();
    let form = Form::new().part("file", Part::bytes(bytes).file_name(name));
    app.client.post(app.url("/api/v1/jobs")).multipart(form).send().await.unwrap()
}

async fn upload_raw(app: &TestApp, body: String, media_type: &str) -> reqwest::Response {
    app.client.post(app.url("/api/v1/jobs")).header("content-type", media_type).body(body).send().await.unwrap()
}

/// A job whose operations take a while: exact-width deburring at a tiny tolerance.
pub fn long_job(operations: usize) -> Value {
    let operation = kerf_cases::operation("deburr", kerf_cases::deburr::long_request());
    json!({"name": "long", "operations": vec![operation; operations]})
}

async fn example_jobs_run_to_the_end(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    for path in examples() {
        let operations = if path.extension().is_some_and(|e| e == "toml") {
            toml::from_str::<Value>(&std::fs::read_to_string(&path).unwrap()).unwrap()["operations"]
                .as_array()
                .unwrap()
                .len()
        } else {
            serde_json::from_str::<Value>(&std::fs::read_to_string(&path).unwrap()).unwrap()["operations"]
                .as_array()
                .unwrap()
                .len()
        };
        let response = upload_multipart(&app, &path).await;
        let location = response.headers()["location"].to_str().unwrap().to_owned();
        let submitted = json_with(response, 202).await;
        assert_eq!(submitted["status"], "queued");
        let id = submitted["id"].as_i64().unwrap();
        assert_eq!(location, format!("/api/v1/jobs/{id}"));
        let job = poll_job(&app.client, &app.base, id, 60, finished).await;
        assert_eq!(job["status"], "done", "{}: {job}", path.display());
        assert_eq!(job["progress"], 1.0);
        let results = job["results"].as_array().unwrap();
        assert_eq!(results.len(), operations);
        for (index, result) in results.iter().enumerate() {
            assert!(result["operation"].is_string());
            assert!(result["result"].as_object().is_some_and(|o| !o.is_empty()), "{result}");
            assert_eq!(result["gcode"], true, "{result}");
            let program = app.get_text(&format!("/api/v1/jobs/{id}/gcode?operation={index}"), 200).await;
            assert!(program.contains("M30"));
        }
        if operations > 1 {
            let answer = problem(app.get(&format!("/api/v1/jobs/{id}/gcode")).await, 422).await;
            assert_eq!(answer["errors"][0]["path"], "operation");
        }

        // The same file again, raw this time: an identical finished job is reused.
        let again =
            json_with(upload_raw(&app, std::fs::read_to_string(&path).unwrap(), media_type(&path)).await, 200).await;
        assert_eq!(again, json!({"id": id, "status": "done", "reused": true}));
    }
}

async fn raw_uploads_run_and_refusals_name_the_field(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    for path in examples() {
        // A changed name makes a different job, so it runs instead of being reused.
        let text = std::fs::read_to_string(&path).unwrap().replacen("name = \"", "name = \"raw ", 1).replacen(
            "\"name\": \"",
            "\"name\": \"raw ",
            1,
        );
        let submitted = json_with(upload_raw(&app, text, media_type(&path)).await, 202).await;
        let job = poll_job(&app.client, &app.base, submitted["id"].as_i64().unwrap(), 60, finished).await;
        assert_eq!(job["status"], "done", "{job}");
    }
    // An operation the solver refuses fails the job with the field at fault.
    let mut bad = long_job(1);
    bad["operations"][0]["hole"]["radius"] = json!(60);
    bad["operations"][0]["tolerance"] = json!(0.01);
    let submitted = json_with(upload_raw(&app, bad.to_string(), "application/json").await, 202).await;
    let job = poll_job(&app.client, &app.base, submitted["id"].as_i64().unwrap(), 30, finished).await;
    assert_eq!(job["status"], "failed");
    assert!(job.get("results").is_none());
    // The job's error is the problem the endpoint answers for the same request, under its index.
    let mut request = bad["operations"][0].clone();
    request.as_object_mut().unwrap().remove("operation");
    let direct = kerf_tests::problem(app.post_json("/api/v1/deburr", &request).await, 422).await;
    let error = &job["error"];
    assert_eq!(error["code"], "E_HOLE_TOO_LARGE", "{job}");
    assert_eq!(error["code"], direct["code"]);
    assert_eq!(error["status"], 422);
    assert_eq!(error["detail"], direct["detail"]);
    assert_eq!(error["errors"][0]["path"], "operations[0].hole.radius");
    assert_eq!(error["errors"][0]["path"], format!("operations[0].{}", direct["errors"][0]["path"].as_str().unwrap()));
    // A failed job is removed on request.
    let failed_path = format!("/api/v1/jobs/{}", job["id"]);
    assert_eq!(app.delete(&failed_path).await.status(), 204, "a failed job is removed");
    problem(app.get(&failed_path).await, 404).await;
}

async fn bad_uploads(store: Store) {
    let limits = Limits { max_body_bytes: 64 * 1024, ..Limits::default() };
    let Some(app) = TestApp::spawn_on(store, |config| config.limits = limits).await else { return };
    app.register_tool(7, &json!({"kind": "ball", "radius": 3})).await;
    let good = "name = \"x\"\n[[operations]]\noperation = \"deburr\"\ntool = 7\nedge = \"outer\"\ncut_amount = 0.2\nworkpiece = { kind = \"tube\", origin = [0, 0, 0], inner_radius = 15, outer_radius = 25 }\nhole = { shape = \"round\", radius = 5 }\n";
    // (what, body, media type, status, field at fault, start of the detail)
    type Case = (&'static str, String, &'static str, u16, Option<&'static str>, Option<&'static str>);
    let cases: Vec<Case> = vec![
        (
            "TOML syntax",
            good.replace("edge = \"outer\"", "edge = outer"),
            "application/toml",
            400,
            Some("file"),
            Some("line 5,"),
        ),
        (
            "wrong type",
            good.replace("cut_amount = 0.2", "cut_amount = \"0.2\""),
            "application/toml",
            400,
            Some("operations[0].cut_amount"),
            Some("line 6,"),
        ),
        (
            "unknown operation",
            good.replace("operation = \"deburr\"", "operation = \"drill\""),
            "application/toml",
            400,
            Some("operations[0].operation"),
            Some("line 3,"),
        ),
        (
            "unknown field",
            good.replace("tool = 7", "tool = 7\ncolour = \"red\""),
            "application/toml",
            400,
            Some("operations[0].colour"),
            None,
        ),
        (
            "no operations",
            "name = \"x\"\noperations = []\n".to_owned(),
            "application/toml",
            400,
            Some("operations"),
            None,
        ),
        (
            "unknown tool",
            good.replace("tool = 7", "tool = 8"),
            "application/toml",
            404,
            Some("operations[0].tool"),
            None,
        ),
        ("JSON syntax", "{\"operations\": [".to_owned(), "application/json", 400, None, None),
        ("not text", String::from_utf8_lossy(&[0xff, 0xfe]).into_owned(), "application/toml", 400, None, None),
        ("wrong content type", good.to_owned(), "text/plain", 415, None, None),
        ("too large", format!("name = \"{}\"", "x".repeat(100_000)), "application/toml", 413, None, None),
        (
            "too deep",
            format!("x = {}{}", "[".repeat(100), "]".repeat(100)),
            "application/toml",
            400,
            Some("file"),
            None,
        ),
    ];
    for (what, body, media, status, field, line) in cases {
        let answer = problem(upload_raw(&app, body, media).await, status).await;
        if let Some(field) = field {
            assert_eq!(answer["errors"][0]["path"], field, "{what}: {answer}");
        }
        if let Some(line) = line {
            assert!(answer["detail"].as_str().unwrap().starts_with(line), "{what}: {answer}");
        }
    }
    let form = Form::new().part("other", Part::bytes(good.as_bytes().to_vec()));
    let response = app.client.post(app.url("/api/v1/jobs")).multipart(form).send().await.unwrap();
    assert_eq!(problem(response, 400).await["errors"][0]["path"], "file");
    let big = Form::new().part("file", Part::bytes(vec![b'#'; 100_000]).file_name("big.toml"));
    let response = app.client.post(app.url("/api/v1/jobs")).multipart(big).send().await.unwrap();
    problem(response, 413).await;
    assert_eq!(json_with(app.get("/api/v1/jobs").await, 200).await["jobs"], json!([]), "nothing stored");
    problem(app.get("/api/v1/jobs/999").await, 404).await;
    problem(app.delete("/api/v1/jobs/999").await, 404).await;
    problem(app.get("/api/v1/jobs/abc").await, 400).await;
    problem(app.get("/api/v1/jobs?limit=0").await, 400).await;
}

async fn cancel_paging_and_conflicts(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    // Two long jobs on two workers, then a third waits in the queue.
    let mut ids = Vec::new();
    for n in 0..3 {
        let mut job = long_job(30);
        job["name"] = json!(format!("long {n}"));
        ids.push(
            json_with(upload_raw(&app, job.to_string(), "application/json").await, 202).await["id"].as_i64().unwrap(),
        );
    }
    let running = poll_job(&app.client, &app.base, ids[0], 30, |j| j["status"] == "running").await;
    assert_eq!(running["status"], "running");
    let queued = json_with(app.get(&format!("/api/v1/jobs/{}", ids[2])).await, 200).await;
    assert_eq!(queued["status"], "queued");

    // Cancel the queued one and a running one.
    let cancelled = json_with(app.delete(&format!("/api/v1/jobs/{}", ids[2])).await, 200).await;
    assert_eq!(cancelled["status"], "cancelled");
    let cancelled = json_with(app.delete(&format!("/api/v1/jobs/{}", ids[0])).await, 200).await;
    assert_eq!(cancelled["status"], "cancelled");
    // The worker lets go: a small job submitted now runs (on PostgreSQL behind the other long
    // job's remaining chunks, which the freed worker takes first).
    let small = json!({"name": "small", "operations": [kerf_cases::operation("deburr", kerf_cases::deburr::case_1())]});
    let small_id =
        json_with(upload_raw(&app, small.to_string(), "application/json").await, 202).await["id"].as_i64().unwrap();
    let small_job = poll_job(&app.client, &app.base, small_id, 30, finished).await;
    assert_eq!(small_job["status"], "done");
    tokio::time::sleep(Duration::from_millis(500)).await;
    let still = json_with(app.get(&format!("/api/v1/jobs/{}", ids[0])).await, 200).await;
    assert_eq!(still["status"], "cancelled", "a cancelled job never turns done");
    problem(app.get(&format!("/api/v1/jobs/{}/gcode", ids[2])).await, 409).await;
    // The other long job: cancelled while it runs, or removed if it ended meanwhile (PostgreSQL's
    // workers split it and may be done already).
    let ids_1 = ids[1];
    let removed = app.delete(&format!("/api/v1/jobs/{ids_1}")).await.status() == 204;
    let kept = |ids: &[i64]| -> Vec<i64> { ids.iter().copied().filter(|id| !(removed && *id == ids_1)).collect() };

    // Paging, newest first.
    let first = json_with(app.get("/api/v1/jobs?limit=2").await, 200).await;
    let page: Vec<i64> = first["jobs"].as_array().unwrap().iter().map(|j| j["id"].as_i64().unwrap()).collect();
    assert_eq!(page, [small_id, ids[2]]);
    let before = first["next_before"].as_i64().unwrap();
    let second = json_with(app.get(&format!("/api/v1/jobs?limit=2&before={before}")).await, 200).await;
    let page: Vec<i64> = second["jobs"].as_array().unwrap().iter().map(|j| j["id"].as_i64().unwrap()).collect();
    assert_eq!(page, kept(&[ids[1], ids[0]]));
    assert!(second.get("next_before").is_none());

    // An ended job is removed with what it stored: 204, then 404 wherever it was.
    let small_path = format!("/api/v1/jobs/{small_id}");
    assert_eq!(app.delete(&small_path).await.status(), 204, "a done job is removed");
    for path in [small_path.clone(), format!("{small_path}/gcode"), format!("{small_path}/program")] {
        problem(app.get(&path).await, 404).await;
    }
    problem(app.delete(&small_path).await, 404).await;
    let cancelled_path = format!("/api/v1/jobs/{}", ids[0]);
    assert_eq!(app.delete(&cancelled_path).await.status(), 204, "a cancelled job is removed");
    problem(app.get(&cancelled_path).await, 404).await;
    let left = json_with(app.get("/api/v1/jobs").await, 200).await;
    let left: Vec<i64> = left["jobs"].as_array().unwrap().iter().map(|j| j["id"].as_i64().unwrap()).collect();
    assert_eq!(left, kept(&[ids[2], ids[1]]));
    // The same files submitted again are new jobs, not the removed one's answer.
    let again =
        json_with(upload_raw(&app, small.to_string(), "application/json").await, 202).await["id"].as_i64().unwrap();
    assert!(again > small_id, "a removed job is not reused: {again}");
}

#[tokio::test(flavor = "multi_thread")]
async fn killed_server_loses_no_job() {
    let program = PathBuf::from(env!("CARGO_BIN_EXE_kerf-under-test"));
    let folder = tempfile::tempdir().unwrap();
    let database = folder.path().join("kerf.db");
    let client = reqwest::Client::new();

    // Killed once while running: re-run after the restart and finished.
    let server = ServerProcess::start(&program, &database).await;
    let submit = |base: String, body: Value| {
        let client = client.clone();
        async move {
            let response = client.post(format!("{base}/api/v1/jobs")).json(&body).send().await.unwrap();
            json_with(response, 202).await["id"].as_i64().unwrap()
        }
    };
    let first = submit(server.base.clone(), long_job(12)).await;
    let running = poll_job(&client, &server.base, first, 30, |j| j["status"] == "running").await;
    assert_eq!(running["status"], "running");
    server.kill();
    let server = ServerProcess::start(&program, &database).await;
    let after = json_with(client.get(format!("{}/api/v1/jobs/{first}", server.base)).send().await.unwrap(), 200).await;
    assert!(matches!(after["status"].as_str(), Some("queued" | "running")), "re-queued after the kill: {after}");
    let done = poll_job(&client, &server.base, first, 120, finished).await;
    assert_eq!(done["status"], "done", "{done}");
    assert_eq!(done["attempts"], 2);

    // Killed on both attempts: failed with the reason, never stuck in running.
    let mut second_job = long_job(40);
    second_job["name"] = json!("killed twice");
    let second = submit(server.base.clone(), second_job).await;
    poll_job(&client, &server.base, second, 30, |j| j["status"] == "running").await;
    server.kill();
    let server = ServerProcess::start(&program, &database).await;
    poll_job(&client, &server.base, second, 30, |j| j["status"] == "running" && j["attempts"] == 2).await;
    server.kill();
    let server = ServerProcess::start(&program, &database).await;
    let failed =
        json_with(client.get(format!("{}/api/v1/jobs/{second}", server.base)).send().await.unwrap(), 200).await;
    assert_eq!(failed["status"], "failed", "{failed}");
    assert_eq!(failed["error"]["code"], "E_INTERRUPTED", "{failed}");
    assert!(failed["error"]["detail"].as_str().unwrap().contains("interrupted"), "{failed}");
    drop(server);
}

/// The raw text of every operation's `result` in a job's JSON answer, as served.
fn raw_results(job_text: &str) -> Vec<String> {
    use std::collections::BTreeMap;

    use serde_json::value::RawValue;
    let job: BTreeMap<String, Box<RawValue>> = serde_json::from_str(job_text).unwrap();
    let results: Vec<BTreeMap<String, Box<RawValue>>> = serde_json::from_str(job["results"].get()).unwrap();
    results.iter().map(|result| result["result"].get().to_owned()).collect()
}

async fn jobs_answer_as_the_endpoints_do(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    let machine = json!({"block_time_ms": 4, "max_feed": 12000, "dialect": "linuxcnc"});
    json_with(app.put_json("/api/v1/machines/lcnc", &machine).await, 201).await;
    let deburr = json!({
        "tool": {"kind": "ball", "radius": 3, "number": 7}, "machine": "lcnc",
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 5}, "edge": "outer", "cut_amount": 0.2, "feed": 300.7
    });
    let engagement = json!({
        "tool": {"kind": "flat", "radius": 5, "flutes": 4, "number": 5}, "spindle_rpm": 8000,
        "feed_per_tooth": 0.04, "flute_counts": [2, 4], "axial_depth": 3, "candidate": 1,
        "stock": {"polygon": [[0, 0], [100, 0], [100, 80], [0, 80]]},
        "paths": [
            {"name": "a", "path": [[-10, 20], [110, 20]]},
            {"name": "b", "path": [[-10, 40], [110, 40], [110, 50]]}
        ]
    });
    let mut operations = Vec::new();
    for (name, request) in [("deburr", &deburr), ("engagement", &engagement)] {
        let mut operation = json!({"operation": name});
        operation.as_object_mut().unwrap().extend(request.as_object().unwrap().clone());
        operations.push(operation);
    }
    // No [output] dialect: each program takes its machine's (deburr: LinuxCNC), else Fanuc.
    let submitted = json_with(app.post_json("/api/v1/jobs", &json!({"operations": operations})).await, 202).await;
    let id = submitted["id"].as_i64().unwrap();
    let job = poll_job(&app.client, &app.base, id, 60, finished).await;
    assert_eq!(job["status"], "done", "{job}");
    let job_text = app.get(&format!("/api/v1/jobs/{id}")).await.text().await.unwrap();
    let stored = raw_results(&job_text);

    for (index, (name, request)) in [("deburr", &deburr), ("engagement", &engagement)].into_iter().enumerate() {
        let answer = app.post_text(&format!("/api/v1/{name}"), request, 200).await;
        assert_eq!(stored[index], answer, "{name}: the stored result is the endpoint's answer byte for byte");
        let direct = app
            .client
            .post(app.url(&format!("/api/v1/{name}")))
            .header("accept", "text/x-gcode")
            .json(request)
            .send()
            .await
            .unwrap()
            .text()
            .await
            .unwrap();
        let from_job = app.get(&format!("/api/v1/jobs/{id}/gcode?operation={index}")).await.text().await.unwrap();
        assert_eq!(from_job, direct, "{name}: the job's program is the endpoint's");
    }
    let deburr_program = app.get(&format!("/api/v1/jobs/{id}/gcode?operation=0")).await.text().await.unwrap();
    assert!(deburr_program.contains("G64 P"), "a LinuxCNC program: {deburr_program}");
    let engagement_program = app.get(&format!("/api/v1/jobs/{id}/gcode?operation=1")).await.text().await.unwrap();
    assert!(engagement_program.contains("Y40.0000"), "the second candidate's path: {engagement_program}");
    assert!(!engagement_program.contains("Y20.0000"), "not the first candidate's path");
}

/// Submits `text`, waits for the job to end and answers its id and its results' raw text.
async fn run_to_the_end(app: &TestApp, text: String, media_type: &str) -> (i64, Value, Vec<String>) {
    let submitted = json_with(upload_raw(app, text, media_type).await, 202).await;
    let id = submitted["id"].as_i64().unwrap();
    let job = poll_job(&app.client, &app.base, id, 60, finished).await;
    let results = if job["status"] == "done" {
        raw_results(&app.get(&format!("/api/v1/jobs/{id}")).await.text().await.unwrap())
    } else {
        Vec::new()
    };
    (id, job, results)
}

/// The stored job file read back: JSON with every operation in order, for TOML and JSON uploads
/// and for failed jobs; submitted again it runs the same job; 404 once the job is removed.
async fn job_file_round_trips(store: Store) {
    let Some(app) = TestApp::spawn_on(store, |_| {}).await else { return };
    problem(app.get("/api/v1/jobs/999999/file").await, 404).await;
    for path in examples()
        .into_iter()
        .filter(|path| path.file_name().is_some_and(|n| n.to_string_lossy().starts_with("deburr")))
    {
        let text = std::fs::read_to_string(&path).unwrap().replacen("name = \"", "name = \"file ", 1).replacen(
            "\"name\": \"",
            "\"name\": \"file ",
            1,
        );
        let (id, job, results) = run_to_the_end(&app, text, media_type(&path)).await;
        assert_eq!(job["status"], "done", "{}: {job}", path.display());
        let response = app.get(&format!("/api/v1/jobs/{id}/file")).await;
        assert_eq!(response.status(), 200, "{}", path.display());
        assert_eq!(response.headers()["content-type"], "application/json");
        let file_text = response.text().await.unwrap();
        let file: Value = serde_json::from_str(&file_text).unwrap();
        let names: Vec<&str> =
            file["operations"].as_array().unwrap().iter().map(|o| o["operation"].as_str().unwrap()).collect();
        assert_eq!(json!(names), job["operations"], "{}: every operation, in order", path.display());
        assert!(file["name"].as_str().unwrap().starts_with("file "), "{file}");
        assert!(!file["tools"].as_array().unwrap().is_empty(), "the tools the operations name: {file}");
        // Submitted again while the job is there, it is that job.
        let again = json_with(upload_raw(&app, file_text.clone(), "application/json").await, 200).await;
        assert_eq!(again, json!({"id": id, "status": "done", "reused": true}), "{}", path.display());
        // Removed, the job has no file; the file read back runs as a new job to the same results.
        assert_eq!(app.delete(&format!("/api/v1/jobs/{id}")).await.status(), 204);
        problem(app.get(&format!("/api/v1/jobs/{id}/file")).await, 404).await;
        let (rerun, job, rerun_results) = run_to_the_end(&app, file_text, "application/json").await;
        assert_ne!(rerun, id);
        assert_eq!(job["status"], "done", "{job}");
        assert_eq!(rerun_results, results, "{}: the re-submitted file gives the same results", path.display());
    }
    // A failed job's file is kept, and submitted again it fails the same way.
    let mut bad = long_job(1);
    bad["name"] = json!("file refused");
    bad["operations"][0]["hole"]["radius"] = json!(60);
    let (id, job, _) = run_to_the_end(&app, bad.to_string(), "application/json").await;
    assert_eq!(job["status"], "failed", "{job}");
    let file_text = app.get_text(&format!("/api/v1/jobs/{id}/file"), 200).await;
    let file: Value = serde_json::from_str(&file_text).unwrap();
    // The request as parsed: what was sent, with the defaults it ran with written out.
    let operation = &file["operations"][0];
    assert_eq!(operation["operation"], "deburr", "{file}");
    assert_eq!(operation["tool"]["kind"], "ball", "an inline tool stays inline: {file}");
    assert_eq!(operation["hole"]["radius"], 60.0, "{file}");
    assert_eq!(operation["workpiece"]["outer_radius"], 50.0, "{file}");
    let (rerun, again, _) = run_to_the_end(&app, file_text, "application/json").await;
    assert_ne!(rerun, id, "a failed job is not reused");
    assert_eq!(again["status"], "failed", "{again}");
    assert_eq!(again["error"], job["error"]);
}

kerf_tests::on_both_stores!(
    example_jobs_run_to_the_end,
    raw_uploads_run_and_refusals_name_the_field,
    bad_uploads,
    cancel_paging_and_conflicts,
    jobs_answer_as_the_endpoints_do,
    job_file_round_trips
);
