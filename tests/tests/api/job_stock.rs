//! A finished job operation's cut stock over HTTP (`GET /api/v1/jobs/{id}/stock` and
//! `/stock/program`): resolved against the stored job file, so an operation on a machine given
//! only in the file (which `POST /api/v1/{name}/stock` cannot find) draws; the cut is the stored
//! result's verification (same removed volume and findings), playback up to a line removes less,
//! the program listed is the one whose lines the findings count (Fanuc, whatever the job's post;
//! verify's own program), on SQLite and PostgreSQL; an inch job's stock is in inches, and bad asks
//! get their problem.

use std::path::Path;

use kerf_tests::{Store, TestApp, finished, json_with, poll_job, problem};
use serde_json::{Value, json};

use crate::verify_mesh::chunks;

/// `examples/shop-job.toml`: a deburr and a contour on machine `vmc`, which only the file gives,
/// and a segment.
fn shop_job() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/shop-job.toml");
    toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Submits `job` and waits for it to end; its id and final state.
async fn run(app: &TestApp, job: &Value) -> (i64, Value) {
    let submitted = app.post_json("/api/v1/jobs", job).await;
    let id = json_with(submitted, 202).await["id"].as_i64().unwrap();
    (id, poll_job(&app.client, &app.base, id, 120, finished).await)
}

/// The GLB at `path`, as its glTF JSON.
async fn stock(app: &TestApp, path: &str) -> Value {
    let response = app.get(path).await;
    let status = response.status().as_u16();
    let kind = response.headers().get("content-type").map(|v| v.to_str().unwrap().to_owned());
    let bytes = response.bytes().await.unwrap();
    assert_eq!((status, kind.as_deref()), (200, Some("model/gltf-binary")), "{}", String::from_utf8_lossy(&bytes));
    chunks(&bytes).0
}

fn removed(verification: &Value) -> f64 {
    verification["removed_volume_mm3"].as_f64().unwrap_or(0.0)
}

kerf_tests::on_both_stores!(a_jobs_operation_is_cut_on_the_machine_its_file_gives);

async fn a_jobs_operation_is_cut_on_the_machine_its_file_gives(store: Store) {
    let app = TestApp::spawn_on(store, |_| {}).await.expect("a service on the store");
    let mut job = shop_job();
    job["output"]["dialect"] = json!("linuxcnc");
    let (id, state) = run(&app, &job).await;
    assert_eq!(state["status"], "done", "{state}");
    for (index, name) in [(0, "deburr"), (1, "contour")] {
        let result = &state["results"][index]["result"];
        let verification = &result["verification"];
        let json = stock(&app, &format!("/api/v1/jobs/{id}/stock?operation={index}")).await;
        let cut = &json["extras"]["verification"];
        assert_eq!(cut["removed_volume_mm3"], verification["removed_volume_mm3"], "{name}: {cut}");
        assert_eq!(cut["findings"], verification["findings"], "{name}");
        assert!(removed(cut) > 0.0, "{name}: {cut}");
        // The capability's own route cannot find the machine the file gives.
        let mut request = job["operations"][index].clone();
        request.as_object_mut().unwrap().remove("operation");
        let number = request["tool"].as_u64().unwrap();
        request["tool"] = job["tools"].as_array().unwrap().iter().find(|t| t["number"] == number).unwrap().clone();
        let unknown = problem(app.post_json(&format!("/api/v1/{name}/stock"), &request).await, 404).await;
        assert_eq!(unknown["errors"][0]["path"], "machine", "{unknown}");
        // The program listed is the Fanuc one the findings count, not the job's LinuxCNC post.
        let listed = app.get_text(&format!("/api/v1/jobs/{id}/stock/program?operation={index}"), 200).await;
        let posted = app.get_text(&format!("/api/v1/jobs/{id}/gcode?operation={index}"), 200).await;
        assert!(listed.starts_with('%') && !posted.starts_with('%'), "{name}:\n{listed:.200}\n---\n{posted:.200}");
        // Playback: up to the tenth line of that program the stock has lost less.
        let early = stock(&app, &format!("/api/v1/jobs/{id}/stock?operation={index}&upto_line=10")).await;
        assert!(removed(&early["extras"]["verification"]) < removed(cut), "{name}: {}", early["extras"]);
    }
    // A coarser spacing than the verification's is asked as the query says.
    let coarse = stock(&app, &format!("/api/v1/jobs/{id}/stock?operation=1&resolution=1")).await;
    assert_eq!(coarse["extras"]["verification"]["resolution"], 1.0, "{}", coarse["extras"]);
}

#[tokio::test(flavor = "multi_thread")]
async fn an_inch_jobs_stock_and_program_are_in_inches() {
    let app = TestApp::spawn().await;
    let job = json!({
        "units": "inch",
        "tools": [{"number": 3, "kind": "flat", "radius": 0.125}],
        "operations": [{
            "operation": "contour",
            "tool": 3,
            "contour": [[0, 0], [1.5, 0], [1.5, 1.25], [0, 1.25]],
            "side": "outside",
            "depths": {"top": 0, "bottom": -0.125, "step": 0.0625},
            "feed": 24,
        }],
    });
    let (id, state) = run(&app, &job).await;
    assert_eq!(state["status"], "done", "{state}");
    let json = stock(&app, &format!("/api/v1/jobs/{id}/stock?operation=0")).await;
    assert_eq!(json["extras"]["units"], "inch", "{}", json["extras"]);
    let index = json["meshes"][0]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize;
    let widest = json["accessors"][index]["max"][0].as_f64().unwrap();
    // The outline is 1.5 in wide, cut outside by a 0.25 in cutter: the stock about it is a few
    // inches across, not tens of millimetres.
    assert!(widest > 1.5 && widest < 4.0, "{widest}");
    let listed = app.get_text(&format!("/api/v1/jobs/{id}/stock/program?operation=0"), 200).await;
    assert!(listed.contains("G20"), "{listed:.300}");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_verify_operation_cuts_and_lists_its_own_program() {
    let app = TestApp::spawn().await;
    let program = "T1 M6\nG0 X-10 Y0 Z5\nG1 Z-1 F500\nG1 X10\nG1 X12 Z-1.2\nG1 X14 Z-1\nG1 X30\nG0 Z50\nM30";
    let job = json!({
        "operations": [{
            "operation": "verify",
            "program": program,
            "tools": [{"number": 1, "kind": "flat", "radius": 5}],
            "stock": {"kind": "box", "min": [-5, -4, -10], "max": [25, 30, 0]},
            "part": {"kind": "box", "min": [-5, -4, -10], "max": [25, 30, -1]},
            "resolution": 0.25,
        }],
    });
    let (id, state) = run(&app, &job).await;
    assert_eq!(state["status"], "done", "{state}");
    let result = &state["results"][0]["result"];
    let json = stock(&app, &format!("/api/v1/jobs/{id}/stock?operation=0")).await;
    let cut = &json["extras"]["verify"];
    assert_eq!(cut["removed_volume_mm3"], result["removed_volume_mm3"], "{cut}");
    assert_eq!(cut["findings"], result["findings"]);
    assert_eq!(app.get_text(&format!("/api/v1/jobs/{id}/stock/program?operation=0"), 200).await, program);
    let early = stock(&app, &format!("/api/v1/jobs/{id}/stock?operation=0&upto_line=4")).await;
    assert!(removed(&early["extras"]["verify"]) < removed(cut), "{}", early["extras"]);
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_asks_of_a_jobs_stock_name_their_field() {
    let app = TestApp::spawn().await;
    let mut job = shop_job();
    job["operations"][1]["verification"] = json!({"enabled": false});
    let (id, state) = run(&app, &job).await;
    assert_eq!(state["status"], "done", "{state}");
    let at = |problem: &Value| problem["errors"][0]["path"].as_str().unwrap_or_default().to_owned();
    for (query, status, field) in [
        ("operation=3", 400, "operation"),
        ("", 400, "operation"),
        ("operation=0&resolution=-1", 400, "resolution"),
        ("operation=0&resolution=0.00001", 422, "resolution"),
        ("operation=0&upto_line=x", 400, "upto_line"),
        ("operation=1", 422, "operations[1].verification"),
        ("operation=2", 422, "operations[2].verification"),
    ] {
        let refused = problem(app.get(&format!("/api/v1/jobs/{id}/stock?{query}")).await, status).await;
        assert_eq!(at(&refused), field, "{query}: {refused}");
    }
    let unknown = problem(app.get("/api/v1/jobs/999999/stock?operation=0").await, 404).await;
    assert!(unknown["detail"].as_str().unwrap().contains("999999"), "{unknown}");
    let segment = problem(app.get(&format!("/api/v1/jobs/{id}/stock/program?operation=9")).await, 400).await;
    assert_eq!(at(&segment), "operation", "{segment}");
    // A job that failed has no stock to draw.
    let mut failing = shop_job();
    failing["operations"][1]["depths"] = json!({"top": 0, "bottom": -4, "step": 0});
    let (failed, state) = run(&app, &failing).await;
    assert_eq!(state["status"], "failed", "{state}");
    problem(app.get(&format!("/api/v1/jobs/{failed}/stock?operation=0")).await, 409).await;
    problem(app.get(&format!("/api/v1/jobs/{failed}/stock/program?operation=0")).await, 409).await;
}
