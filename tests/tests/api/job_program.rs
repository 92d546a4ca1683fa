//! One program per job: `GET /api/v1/jobs/{id}/program` joins every
//! operation's program into one with one program number, a tool change per operation and one
//! end; `outputs.zip` holds every output; `kerf run` writes the same program; both dialects pass
//! `rs274`; bad requests get their problem.

use std::io::Read;
use std::path::Path;

use kerf_tests::{TestApp, finished, json_with, poll_job, problem, rs274_moves};
use serde_json::{Value, json};

fn shop_job() -> Value {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/shop-job.toml");
    toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

async fn run_job(app: &TestApp, job: &Value) -> i64 {
    let submitted = app.post_json("/api/v1/jobs", job).await;
    let id = json_with(submitted, 202).await["id"].as_i64().unwrap();
    let state = poll_job(&app.client, &app.base, id, 120, finished).await;
    assert_eq!(state["status"], "done", "{state}");
    id
}

/// The feed moves (`STRAIGHT_FEED`, `ARC_FEED`) rs274 interprets, in order.
fn feed_moves(program: &str, folder: &Path, name: &str) -> Option<Vec<[f64; 3]>> {
    Some(rs274_moves(program, folder, name)?.into_iter().filter(|(feed, _)| *feed).map(|(_, to)| to).collect())
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn a_job_runs_as_one_program_in_both_dialects() {
    let app = TestApp::spawn().await;
    let folder = tempfile::tempdir().unwrap();
    for dialect in ["fanuc", "linuxcnc"] {
        let mut job = shop_job();
        job["output"]["dialect"] = json!(dialect);
        let id = run_job(&app, &job).await;
        let response = app.get(&format!("/api/v1/jobs/{id}/program")).await;
        assert_eq!(response.status(), 200);
        assert!(response.headers()["content-type"].to_str().unwrap().starts_with("text/x-gcode"));
        let program = response.text().await.unwrap();
        let lines: Vec<&str> = program.lines().collect();
        assert_eq!((lines[0], lines[lines.len() - 1]), ("%", "%"), "{dialect}: % at both ends");
        assert_eq!(lines.iter().filter(|l| **l == "%").count(), 2, "{dialect}");
        // deburr (T7), contour (T3), segment (T10): three tool changes, each with its offset.
        let changes: Vec<&str> = lines.iter().copied().filter(|l| l.contains("M06")).collect();
        assert_eq!(changes, ["T7 M06", "T3 M06", "T10 M06"], "{dialect}");
        for n in [7, 3, 10] {
            assert_eq!(program.matches(&format!("G43 H{n} ")).count(), 1, "{dialect}: H{n}");
        }
        assert_eq!(lines.iter().filter(|l| l.starts_with("M30") || l.starts_with("M2")).count(), 1, "{dialect}");
        assert_eq!(lines.iter().filter(|l| **l == "M08").count(), 3, "{dialect}: coolant per operation");
        assert_eq!(lines.iter().filter(|l| **l == "M09").count(), 3, "{dialect}");
        let numbers: Vec<&str> = lines.iter().copied().filter(|l| l.starts_with('O')).collect();
        match dialect {
            "fanuc" => assert_eq!(numbers.len(), 1, "one O word: {numbers:?}"),
            _ => assert!(numbers.is_empty(), "LinuxCNC reads O words as subroutines: {numbers:?}"),
        }
        assert!(program.contains("O4711"), "{dialect}: the file's program number");
        assert!(program.contains("(3 OPERATIONS, 3 IN THIS PROGRAM, TOOLS T3 T7 T10, ESTIMATED"), "{program}");

        // Every operation's cutting moves are in it, in order, unchanged.
        let Some(joined) = feed_moves(&program, folder.path(), &format!("job-{dialect}")) else { return };
        let mut expected = Vec::new();
        for index in 0..3 {
            let single = app.get(&format!("/api/v1/jobs/{id}/gcode?operation={index}")).await.text().await.unwrap();
            expected.extend(feed_moves(&single, folder.path(), &format!("op-{dialect}-{index}")).unwrap());
        }
        assert_eq!(joined, expected, "{dialect}: the joined program's feed moves are the operations'");
        // Between operations the tool is at the job's clearance height before it moves across.
        let traverses = rs274_moves(&program, folder.path(), "traverses").unwrap();
        let clearance = 30.0;
        for change in program.split("M06").skip(2) {
            assert!(change.contains(&format!("Z{clearance:.4}")), "{dialect}: retract before the change");
        }
        assert!(traverses.iter().any(|(feed, to)| !feed && (to[2] - clearance).abs() < 1e-6));
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn the_zip_holds_every_output_and_kerf_run_writes_the_same_program() {
    let app = TestApp::spawn().await;
    let id = run_job(&app, &shop_job()).await;
    let response = app.get(&format!("/api/v1/jobs/{id}/outputs.zip")).await;
    assert_eq!(response.status(), 200);
    assert_eq!(response.headers()["content-type"], "application/zip");
    let bytes = response.bytes().await.unwrap();
    let mut archive = zip::ZipArchive::new(std::io::Cursor::new(bytes.to_vec())).expect("a zip archive");
    let mut names: Vec<String> =
        (0..archive.len()).map(|index| archive.by_index(index).unwrap().name().unwrap().into_owned()).collect();
    names.sort();
    assert_eq!(
        names,
        [
            "00-deburr.json",
            "00-deburr.nc",
            "01-contour.json",
            "01-contour.nc",
            "02-segment.json",
            "02-segment.nc",
            "job.json",
            "program.nc"
        ]
    );
    let (mut stored, mut packed) = (0, 0);
    for index in 0..archive.len() {
        let entry = archive.by_index(index).unwrap();
        assert_eq!(entry.compression(), zip::CompressionMethod::Deflated, "{:?}", entry.name());
        (stored, packed) = (stored + entry.size(), packed + entry.compressed_size());
    }
    assert!(packed * 3 < stored, "G-code and JSON deflate to under a third: {packed} of {stored} bytes");
    let mut read = |name: &str| {
        let mut text = String::new();
        archive.by_name(name).unwrap().read_to_string(&mut text).expect("the CRC and size check out");
        text
    };
    let program = app.get(&format!("/api/v1/jobs/{id}/program")).await.text().await.unwrap();
    assert_eq!(read("program.nc"), program);
    let single = app.get(&format!("/api/v1/jobs/{id}/gcode?operation=1")).await.text().await.unwrap();
    assert_eq!(read("01-contour.nc"), single);

    let out = tempfile::tempdir().unwrap();
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/shop-job.toml");
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_kerf-under-test"))
        .arg("run")
        .arg(&example)
        .arg("-o")
        .arg(out.path())
        .arg("--database")
        .arg(out.path().join("none.db"))
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    assert_eq!(std::fs::read_to_string(out.path().join("program.nc")).unwrap(), program);
}

/// Python's `zipfile` (not the crate that wrote it) opens the archive, finds every entry deflated
/// with its CRC right (`testzip`), and reads the same texts the API answers.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_python3), ignore = "python3 not found: apt-get install python3")]
async fn pythons_zipfile_reads_the_deflated_outputs() {
    let app = TestApp::spawn().await;
    let id = run_job(&app, &shop_job()).await;
    let bytes = app.get(&format!("/api/v1/jobs/{id}/outputs.zip")).await.bytes().await.unwrap();
    let folder = tempfile::tempdir().unwrap();
    let path = folder.path().join("outputs.zip");
    std::fs::write(&path, &bytes).unwrap();
    let script = "import json, sys, zipfile\n\
        with zipfile.ZipFile(sys.argv[1]) as archive:\n\
        \x20   assert archive.testzip() is None, archive.testzip()\n\
        \x20   print(json.dumps({i.filename: [i.compress_type == zipfile.ZIP_DEFLATED, archive.read(i).decode()]\n\
        \x20                     for i in archive.infolist()}))\n";
    let output = std::process::Command::new("python3").args(["-c", script]).arg(&path).output().expect("python3 runs");
    assert!(output.status.success(), "zipfile refused it: {}", String::from_utf8_lossy(&output.stderr));
    let entries: Value = serde_json::from_slice(&output.stdout).unwrap();
    let entries = entries.as_object().unwrap();
    assert_eq!(entries.len(), 8, "{:?}", entries.keys());
    for (name, entry) in entries {
        assert_eq!(entry[0], true, "{name} is deflated");
    }
    let program = app.get(&format!("/api/v1/jobs/{id}/program")).await.text().await.unwrap();
    assert_eq!(entries["program.nc"][1], program.as_str());
    let contour = app.get(&format!("/api/v1/jobs/{id}/gcode?operation=1")).await.text().await.unwrap();
    assert_eq!(entries["01-contour.nc"][1], contour.as_str());
    let job = app.get(&format!("/api/v1/jobs/{id}")).await;
    let answer = json_with(job, 200).await["results"][1]["result"].clone();
    let zipped: Value = serde_json::from_str(entries["01-contour.json"][1].as_str().unwrap()).unwrap();
    assert_eq!(zipped, answer);
}

#[tokio::test(flavor = "multi_thread")]
async fn program_numbers_follow_the_job_unless_the_file_sets_one() {
    let app = TestApp::spawn().await;
    let mut job = shop_job();
    job["output"].as_object_mut().unwrap().remove("program_number");
    let id = run_job(&app, &job).await;
    let program = app.get(&format!("/api/v1/jobs/{id}/program")).await.text().await.unwrap();
    assert!(program.starts_with(&format!("%\nO{} (KERF JOB", 2000 + id - 1)), "{}", &program[..40]);
    // A second job gets the next number.
    job["name"] = json!("another bracket");
    let second = run_job(&app, &job).await;
    let other = app.get(&format!("/api/v1/jobs/{second}/program")).await.text().await.unwrap();
    assert!(other.starts_with(&format!("%\nO{} (KERF JOB", 2000 + second - 1)));
    assert_ne!(second, id);
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_program_requests_get_their_problem() {
    let app = TestApp::spawn().await;
    for path in ["/api/v1/jobs/999/program", "/api/v1/jobs/999/outputs.zip"] {
        problem(app.get(path).await, 404).await;
    }
    for number in [0, 8000, 123_456] {
        let mut job = shop_job();
        job["output"]["program_number"] = json!(number);
        let body = problem(app.post_json("/api/v1/jobs", &job).await, 422).await;
        assert_eq!(body["errors"][0]["path"], "output.program_number", "{body}");
    }
    // A job still running: 409, like its other outputs.
    let long = crate::jobs::long_job(2);
    let id = json_with(app.post_json("/api/v1/jobs", &long).await, 202).await["id"].as_i64().unwrap();
    for path in [format!("/api/v1/jobs/{id}/program"), format!("/api/v1/jobs/{id}/outputs.zip")] {
        problem(app.get(&path).await, 409).await;
    }
    assert_eq!(app.delete(&format!("/api/v1/jobs/{id}")).await.status(), 200);
    // A job whose only operation has no program: 422 E_NO_PROGRAM (a tilted contour).
    let tilted = json!({"operations": [{"operation": "contour", "tool": {"kind": "flat", "radius": 3},
        "contour": [[0, 0], [60, 0], [60, 40], [0, 40]], "side": "outside",
        "depths": {"top": 0, "bottom": -2, "step": 2}, "feed": 800, "tilt_deg": 5}]});
    let id = run_job(&app, &tilted).await;
    let body = problem(app.get(&format!("/api/v1/jobs/{id}/program")).await, 422).await;
    assert_eq!(body["code"], "E_NO_PROGRAM", "{body}");
}

#[tokio::test(flavor = "multi_thread")]
async fn job_downloads_are_named_by_their_post_and_haas_smoothing_is_set_once() {
    let app = TestApp::spawn().await;
    for (dialect, extension) in [("sinumerik", "mpf"), ("heidenhain_iso", "i"), ("haas", "nc")] {
        let mut job = shop_job();
        job["output"]["dialect"] = json!(dialect);
        job["machines"][0]["haas_smoothing"] = json!(2);
        let id = run_job(&app, &job).await;
        let response = app.get(&format!("/api/v1/jobs/{id}/program")).await;
        assert_eq!(response.status(), 200, "{dialect}");
        let disposition = response.headers()["content-disposition"].to_str().unwrap().to_owned();
        assert_eq!(disposition, format!("attachment; filename=\"kerf-job-{id}.{extension}\""), "{dialect}");
        let program = response.text().await.unwrap();
        let response = app.get(&format!("/api/v1/jobs/{id}/gcode?operation=1")).await;
        assert_eq!(response.status(), 200, "{dialect}");
        let disposition = response.headers()["content-disposition"].to_str().unwrap().to_owned();
        assert_eq!(disposition, format!("attachment; filename=\"kerf-job-{id}-1.{extension}\""), "{dialect}");
        let operation = response.text().await.unwrap();
        if dialect == "haas" {
            // The machine's smoothing once, after the safety block, in the job's program as in each
            // operation's.
            assert_eq!(program.matches("G187").count(), 1, "{program}");
            assert!(program.contains("\nG21 G17 G90 G40 G49 G80 G94\nG187 P2\n(OPERATION 1 "), "{program}");
            assert!(operation.contains("\nG21 G17 G90 G40 G49 G80 G94\nG187 P2\n"), "{operation}");
            let mut plain = shop_job();
            plain["output"]["dialect"] = json!("haas");
            let id = run_job(&app, &plain).await;
            let program = app.get(&format!("/api/v1/jobs/{id}/program")).await.text().await.unwrap();
            assert!(!program.contains("G187") && program.contains("O04711"), "{program}");
        } else {
            assert!(!program.contains("G187") && !operation.contains("G187"), "{dialect}: {program}");
        }
    }
}

/// A job file in inch (`units` at the top, or an operation's own) joins into one inch program:
/// G20, the tools' radii in inches, the
/// rapids timed at the machine's mm/min, every operation's feed moves as rs274 reads them in its
/// own program; an operation in mm is left out, and the header says why.
#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn an_inch_job_joins_into_one_inch_program_and_leaves_an_mm_operation_out() {
    let app = TestApp::spawn().await;
    let folder = tempfile::tempdir().unwrap();
    let mut job = shop_job();
    let mut deburr_in_mm = job["operations"][0].clone();
    deburr_in_mm["units"] = json!("mm");
    // The file's units for an operation that says none; one that says its own keeps them.
    job["units"] = json!("inch");
    job["operations"] = json!([
        {"operation": "contour", "tool": 3, "machine": "vmc",
         "contour": [[0, 0], [2.4, 0], [2.4, 1.6], [0, 1.6]], "side": "outside",
         "depths": {"top": 0, "bottom": -0.16, "step": 0.08}, "feed": 30, "spindle_rpm": 8000},
        {"operation": "segment", "tool": 10, "machine": "vmc", "units": "inch",
         "curve": {"kind": "circle", "centre": [1.2, 0.8, -0.08], "radius": 0.8}, "feed": 45},
        deburr_in_mm,
    ]);
    let id = run_job(&app, &job).await;
    let state = json_with(app.get(&format!("/api/v1/jobs/{id}")).await, 200).await;
    let units: Vec<&str> = (0..3).map(|i| state["results"][i]["result"]["units"].as_str().unwrap()).collect();
    assert_eq!(units, ["inch", "inch", "mm"], "{state}");
    let response = app.get(&format!("/api/v1/jobs/{id}/program")).await;
    assert_eq!(response.status(), 200);
    let program = response.text().await.unwrap();
    assert_eq!(program.matches("\nG20 G17 G90 G40 G49 G80 G94\n").count(), 1, "{program}");
    assert!(!program.contains("G21"), "{program}");
    assert!(program.contains("(3 OPERATIONS, 2 IN THIS PROGRAM, TOOLS T3 T10, ESTIMATED"), "{program}");
    assert!(program.contains("(1 CONTOUR: T3 FLAT RADIUS 0.11811 IN D6 FLAT END MILL,"), "{program}");
    assert!(
        program.contains("(3 DEBURR: NOT IN THIS PROGRAM: ITS PROGRAM IS IN MM, THIS PROGRAM IN INCH"),
        "{program}"
    );
    assert_eq!(program.matches("M06").count(), 2, "{program}");

    let Some(joined) = feed_moves(&program, folder.path(), "inch-job") else { return };
    let mut expected = Vec::new();
    for index in 0..2 {
        let single = app.get(&format!("/api/v1/jobs/{id}/gcode?operation={index}")).await.text().await.unwrap();
        assert!(single.contains("\nG20 "), "{single}");
        expected.extend(feed_moves(&single, folder.path(), &format!("inch-op-{index}")).unwrap());
    }
    assert_eq!(joined, expected, "the joined program's feed moves are the inch operations'");
}
