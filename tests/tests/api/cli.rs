//! `kerf run`: runs each example job file locally and writes its results; a bad file fails with
//! the line and field.

use std::path::PathBuf;
use std::process::Command;

use crate::jobs::examples;

fn program() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_kerf-under-test"))
}

/// `kerf run EXAMPLE -o OUT` with no tool table (the examples define their tools).
fn run_locally(example: &std::path::Path, out: &std::path::Path) -> std::process::Output {
    Command::new(program())
        .arg("run")
        .arg(example)
        .arg("-o")
        .arg(out)
        .arg("--database")
        .arg(out.join("no-such.db"))
        .output()
        .unwrap()
}

#[test]
fn runs_each_example_locally() {
    for example in examples() {
        let out = tempfile::tempdir().unwrap();
        let output = run_locally(&example, out.path());
        assert!(output.status.success(), "{}: {}", example.display(), String::from_utf8_lossy(&output.stderr));
        let summary: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(out.path().join("job.json")).unwrap()).unwrap();
        let operations = summary["operations"].as_array().unwrap();
        assert!(!operations.is_empty());
        for (index, operation) in operations.iter().enumerate() {
            let name = operation["operation"].as_str().unwrap();
            let result: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(out.path().join(format!("{index:02}-{name}.json"))).unwrap(),
            )
            .unwrap();
            match name {
                "deburr" | "segment" => assert!(result["points"].as_array().unwrap().len() > 8),
                "contour" => assert!(!result["layers"].as_array().unwrap().is_empty()),
                "engagement" => assert!(
                    result["candidates"]
                        .as_array()
                        .unwrap()
                        .iter()
                        .all(|c| c["samples"].as_array().unwrap().len() > 100)
                ),
                "predict" => assert!(result["passes"].as_array().unwrap().len() > 8),
                _ => assert!(result.as_object().is_some_and(|o| !o.is_empty())),
            }
            let program = std::fs::read_to_string(out.path().join(format!("{index:02}-{name}.nc"))).unwrap();
            assert!(program.contains("M30"));
        }
        let listed = String::from_utf8_lossy(&output.stdout);
        assert!(listed.lines().count() > operations.len(), "lists the files written: {listed}");
    }
}

#[test]
fn bad_file_names_line_and_field() {
    let folder = tempfile::tempdir().unwrap();
    let file = folder.path().join("bad.toml");
    std::fs::write(
        &file,
        "[[operations]]\noperation = \"deburr\"\ntool = { kind = \"ball\", radius = 3 }\nedge = \"outer\"\ncut_amount = -1\n\
         workpiece = { kind = \"tube\", origin = [0, 0, 0], inner_radius = 15, outer_radius = 25 }\n\
         hole = { shape = \"round\", radius = \"5\" }\n",
    )
    .unwrap();
    let output =
        Command::new(program()).arg("run").arg(&file).arg("-o").arg(folder.path().join("out")).output().unwrap();
    assert!(!output.status.success());
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(message.contains("line 7") && message.contains("operations[0].hole.radius"), "{message}");

    std::fs::write(&file, std::fs::read_to_string(&file).unwrap().replace("radius = \"5\"", "radius = 5")).unwrap();
    let output =
        Command::new(program()).arg("run").arg(&file).arg("-o").arg(folder.path().join("out")).output().unwrap();
    assert!(!output.status.success());
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(message.contains("operations[0].cut_amount"), "a refused operation names its field: {message}");
    assert!(!folder.path().join("out").exists(), "nothing written for a failed job");
}

#[tokio::test(flavor = "multi_thread")]
async fn kerf_run_and_the_service_write_the_same_programs() {
    let app = kerf_tests::TestApp::spawn().await;
    for example in examples() {
        let out = tempfile::tempdir().unwrap();
        let output = run_locally(&example, out.path());
        assert!(output.status.success(), "{}: {}", example.display(), String::from_utf8_lossy(&output.stderr));
        let media =
            if example.extension().is_some_and(|e| e == "toml") { "application/toml" } else { "application/json" };
        let submitted = app
            .client
            .post(app.url("/api/v1/jobs"))
            .header("content-type", media)
            .body(std::fs::read(&example).unwrap())
            .send()
            .await
            .unwrap();
        let id = kerf_tests::json_with(submitted, 202).await["id"].as_i64().unwrap();
        let job = kerf_tests::poll_job(&app.client, &app.base, id, 120, kerf_tests::finished).await;
        assert_eq!(job["status"], "done", "{}: {job}", example.display());
        for (index, name) in job["operations"].as_array().unwrap().iter().enumerate() {
            let name = name.as_str().unwrap();
            let local = std::fs::read_to_string(out.path().join(format!("{index:02}-{name}.nc"))).unwrap();
            let served = app.get(&format!("/api/v1/jobs/{id}/gcode?operation={index}")).await.text().await.unwrap();
            assert_eq!(local, served, "{} operation {index}: kerf run and the service differ", example.display());
            let local = std::fs::read_to_string(out.path().join(format!("{index:02}-{name}.json"))).unwrap();
            let served: serde_json::Value = app.get(&format!("/api/v1/jobs/{id}")).await.json().await.unwrap();
            let served: serde_json::Value = served["results"][index]["result"].clone();
            let local: serde_json::Value = serde_json::from_str(&local).unwrap();
            // Timings are wall time: the only part that differs from run to run.
            let strip = |mut value: serde_json::Value| {
                value.as_object_mut().unwrap().remove("timings");
                value
            };
            assert_eq!(strip(local), strip(served), "{} operation {index}: results differ", example.display());
        }
    }
}

/// A database left by an older kerf: its migrations applied up to `version` only (0004: before
/// the materials library of 0006; 0002: before the machines registry of 0003).
async fn old_database(path: &std::path::Path, version: i64) {
    let options = sqlx::sqlite::SqliteConnectOptions::new().filename(path).create_if_missing(true);
    let pool = sqlx::sqlite::SqlitePoolOptions::new().max_connections(1).connect_with(options).await.unwrap();
    sqlx::migrate!("../migrations/sqlite").run_to(version, &pool).await.unwrap();
    pool.close().await;
}

/// An engagement job (a slot, with forces) whose operation names `material` and, if given,
/// `machine`; `materials` is the job file's own `[[materials]]` table (TOML).
fn material_job(folder: &std::path::Path, material: &str, machine: Option<&str>, materials: &str) -> PathBuf {
    let file = folder.join("job.toml");
    let machine = machine.map(|m| format!("machine = \"{m}\"\n")).unwrap_or_default();
    std::fs::write(
        &file,
        format!(
            "{materials}\n[[operations]]\noperation = \"engagement\"\ntool = {{ kind = \"flat\", radius = 5, flutes = 4 }}\n\
             spindle_rpm = 3000\nfeed_per_tooth = 0.05\naxial_depth = 2\nmaterial = \"{material}\"\n{machine}\
             path = [[-10, 0], [45, 0]]\nstock = {{ polygon = [[0, -20], [50, -20], [50, 20], [0, 20]] }}\n"
        ),
    )
    .unwrap();
    file
}

fn run_against(file: &std::path::Path, database: &std::path::Path, out: &std::path::Path) -> std::process::Output {
    Command::new(program()).arg("run").arg(file).arg("-o").arg(out).arg("--database").arg(database).output().unwrap()
}

#[tokio::test(flavor = "multi_thread")]
async fn a_database_from_before_the_materials_library_is_named_not_an_internal_error() {
    let folder = tempfile::tempdir().unwrap();
    let database = folder.path().join("old.db");
    old_database(&database, 4).await;
    let before = std::fs::read(&database).unwrap();

    // A library material: the database has no library to look it up in. Before the fix this
    // was "internal error; it has been logged (E_INTERNAL)".
    let file = material_job(folder.path(), "C45", None, "");
    let output = run_against(&file, &database, &folder.path().join("out"));
    assert!(!output.status.success());
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(!message.contains("E_INTERNAL") && !message.contains("internal error"), "{message}");
    assert!(message.contains("operations[0].material"), "names the field: {message}");
    assert!(message.contains("predates the materials library"), "says why: {message}");
    assert!(message.contains("kerf migrate"), "says how to upgrade: {message}");
    assert!(!folder.path().join("out").exists(), "nothing written for a failed job");
    assert_eq!(std::fs::read(&database).unwrap(), before, "kerf run leaves the database as it was");

    // A material the job file defines needs no library: the old database is fine.
    let file = material_job(folder.path(), "mine", None, "[[materials]]\nname = \"mine\"\nkc11 = 1500\nmc = 0.2\n");
    let output = run_against(&file, &database, &folder.path().join("out"));
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let result: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.path().join("out/00-engagement.json")).unwrap()).unwrap();
    assert_eq!(result["forces"]["kc11"], 1500.0);

    // `kerf migrate` upgrades it, after which the library material resolves.
    let migrated = Command::new(program()).arg("migrate").arg("--database").arg(&database).output().unwrap();
    assert!(migrated.status.success(), "{}", String::from_utf8_lossy(&migrated.stderr));
    let file = material_job(folder.path(), "C45", None, "");
    let output = run_against(&file, &database, &folder.path().join("out-c45"));
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let result: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(folder.path().join("out-c45/00-engagement.json")).unwrap())
            .unwrap();
    assert_eq!(result["forces"]["kc11"], 2220.0, "C45 from the seeded library");
}

#[tokio::test(flavor = "multi_thread")]
async fn a_database_from_before_the_machines_registry_is_named_too() {
    let folder = tempfile::tempdir().unwrap();
    let database = folder.path().join("older.db");
    old_database(&database, 2).await;
    let file =
        material_job(folder.path(), "mine", Some("mill"), "[[materials]]\nname = \"mine\"\nkc11 = 1500\nmc = 0.2\n");
    let output = run_against(&file, &database, &folder.path().join("out"));
    assert!(!output.status.success());
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(!message.contains("E_INTERNAL"), "{message}");
    assert!(
        message.contains("operations[0].machine") && message.contains("predates the machines registry"),
        "{message}"
    );
}
