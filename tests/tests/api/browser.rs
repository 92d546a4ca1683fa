//! The page in real headless Chromium (Debian's `chromium`, driven by playwright-core from
//! `tests/browser/`): it loads, submits the sample job with its button, and plots (the engagement
//! view also with a material of the library, checked against the API); the workbench
//! keeps state, honours machines, reports errors at the field and never scrolls sideways; jobs
//! show the progress the service reports and no more. Every scenario also fails on a console
//! error or a request that leaves 127.0.0.1.

use std::path::Path;
use std::process::Command;

use kerf_tests::{TestApp, external_program};

/// Runs `tests/browser/run.mjs <scenario>` against `app`. Always `Some`: a missing tool fails the
/// test, which carries `#[cfg_attr(not(kerf_has_chromium), ignore = …)]` to be ignored without it.
pub fn run_scenario(app: &TestApp, scenario: &str, extra: &[&str]) -> Option<serde_json::Value> {
    let node = external_program("node", "the browser test")?;
    external_program("chromium", "the browser test")?;
    let folder = kerf_tests::external::browser_folder();
    let driver = "playwright-core not installed (npm ci --prefix tests/browser)";
    assert!(kerf_tests::external::browser_driver(), "{}", kerf_tests::missing_message(driver, "the browser test"));
    let screenshot = app.directory().join(format!("{scenario}.png"));
    let output = Command::new(node)
        .current_dir(&folder)
        .arg("run.mjs")
        .arg(scenario)
        .arg(&app.base)
        .arg(&screenshot)
        .args(extra)
        .output()
        .expect("node runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "browser scenario {scenario} failed: {stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let line = stdout.lines().last().unwrap_or_default();
    Some(serde_json::from_str(line).unwrap_or_else(|_| panic!("scenario output: {stdout}")))
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn deburr_page_plots_the_sample_job() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "deburr", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["segments"].as_u64().unwrap() >= 10, "{result}");
    let objects = result["objects"].as_array().unwrap();
    assert!(objects.contains(&"tube".into()) && objects.contains(&"tool".into()), "{result}");
    eprintln!("load to first deburr plot: {} s", result["firstPlot"]);
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn segment_page_cuts_the_sample_and_uses_a_registered_machine() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "segment", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["segments"], 472, "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn workbench_keeps_state_honours_the_machine_and_fits_the_window() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "workbench", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["placeholder"], "2 (machine)", "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn jobs_page_runs_an_uploaded_example() {
    let app = TestApp::spawn().await;
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/deburr-tube.toml");
    let Some(result) = run_scenario(&app, "jobs", &[example.to_str().unwrap()]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["plots"], 2, "one plot per operation: {result}");
    eprintln!("upload to result on the page: {} s", result["seconds"]);
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn contour_page_plots_the_sample_and_downloads_gcode() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "contour", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["segments"].as_u64().unwrap() >= 50, "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn jobs_page_shows_the_contour_example() {
    let app = TestApp::spawn().await;
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/contour-arrow.toml");
    let Some(result) = run_scenario(&app, "jobs", &[example.to_str().unwrap()]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["plots"], 1, "one plot for the one operation: {result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn engagement_page_compares_the_sample_paths() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "engagement", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["columns"], 3, "three candidate paths, one shown at a time: {result}");
    // Plan, contact, a_e, chip thickness, torque and power, feed plan, and two per flute count.
    assert_eq!(result["charts"], 8, "the charts of the path shown, no more: {result}");
    assert!(result["recommendation"].as_str().unwrap().contains("Recommended flute counts"), "{result}");
    assert_eq!(result["file"], "engagement-1-fanuc.nc");
    // The answer's verification of the program of the path chosen for G-code (the first, named),
    // with its stock drawn (`engagementCut`), not explained away.
    let verification = result["verification"].as_str().unwrap();
    assert!(
        verification.contains("the program of straight cut on its own model") && verification.contains("mm³"),
        "{result}"
    );
    assert!(verification.contains("part: none") && !verification.contains("not drawn here"), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn engagement_page_computes_with_a_library_material() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "engagementMaterial", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["rows"].as_u64().unwrap() >= 1, "{result}");
    eprintln!("C45 on the page: {} N·m, {} kW", result["torque"], result["power"]);
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn jobs_page_shows_an_engagement_job() {
    let app = TestApp::spawn().await;
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/engagement-pocket.toml");
    let Some(result) = run_scenario(&app, "jobs", &[example.to_str().unwrap()]) else { return };
    assert_eq!(result["ok"], true);
    // The first path's plan, contact, a_e, chip thickness, feed plan and two per flute count
    // (the example gives no Kienzle values, so no torque); the other paths are drawn when shown.
    assert_eq!(result["plots"], 7, "the charts of the path shown: {result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn jobs_page_shows_only_the_progress_the_service_reports() {
    // One worker, so the jobs behind the long prediction wait their turn.
    let app = TestApp::spawn_configured(|config| config.job_workers = 1).await;
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples");
    let predict = examples.join("predict-raster.toml");
    let deburr = examples.join("deburr-tube.toml");
    let Some(result) = run_scenario(&app, "progress", &[predict.to_str().unwrap(), deburr.to_str().unwrap()]) else {
        return;
    };
    assert_eq!(result["ok"], true);
    assert!(result["moving"].as_str().is_some_and(|label| label.starts_with("engagement: ")), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn predict_page_colours_the_path_by_error() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "predict", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["colours"].as_u64().unwrap() >= 4, "{result}");
    assert_eq!(result["worst"], 20, "{result}");
    let verification = result["verification"].as_str().unwrap();
    assert!(verification.contains("the program cut on its own model") && verification.contains("mm³"), "{result}");
    assert!(verification.contains("part: none") && !verification.contains("not drawn here"), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn jobs_page_shows_a_prediction_job() {
    let app = TestApp::spawn().await;
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/predict-raster.toml");
    let Some(result) = run_scenario(&app, "jobs", &[example.to_str().unwrap()]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["plots"], 3, "path, colour scale and histogram: {result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn jobs_page_downloads_every_output_as_a_zip() {
    let app = TestApp::spawn().await;
    let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/shop-job.toml");
    let Some(result) = run_scenario(&app, "jobzip", &[example.to_str().unwrap()]) else { return };
    assert_eq!(result["ok"], true);
    let id = result["id"].as_i64().unwrap();
    assert_eq!(result["file"], format!("job-{id}.zip"));
    let entries: Vec<&str> = result["entries"].as_array().unwrap().iter().map(|e| e.as_str().unwrap()).collect();
    assert_eq!(
        entries,
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
    // The page saved the service's bytes unchanged.
    let served = app.get(&format!("/api/v1/jobs/{id}/outputs.zip")).await.bytes().await.unwrap();
    assert_eq!(result["size"].as_u64().unwrap(), served.len() as u64);
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn saving_an_existing_tool_number_asks_first_and_keeps_the_old_tool() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "toolOverwrite", &[]) else { return };
    assert_eq!(result["ok"], true);
    let stored = app.client.get(format!("{}/api/v1/tools/7", app.base)).send().await.unwrap();
    let stored: serde_json::Value = stored.json().await.unwrap();
    assert_eq!((stored["kind"].as_str(), stored["radius"].as_f64()), (Some("flat"), Some(5.0)), "{stored}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn a_decimal_comma_is_a_decimal_separator_never_dropped() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "decimalComma", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["language"], "de-DE", "{result}");
    // 6,5 is 6.5 (radius 3.25), or refused at the field; never 65.
    assert!(result["radius"] == 3.25 || result["marked"] == serde_json::json!(["size"]), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn deburr_by_od_id_and_diameter_gives_the_path_of_the_radii() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "deburrDiameters", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["points"].as_u64().unwrap() > 10, "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn segment_defaults_to_no_short_blocks_and_its_advice_names_the_page_controls() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "segmentDefault", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["short"], 0, "{result}");
    eprintln!("ellipse: per-window mode {} short blocks; advice {}", result["windowShort"], result["advice"]);
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn a_failed_job_reads_in_words_and_can_be_resubmitted_and_deleted() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "jobsFailed", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["again"].as_array().unwrap().iter().any(|id| id.as_i64() > result["id"].as_i64()), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn predict_draws_an_uploaded_stl_stock() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "predictStl", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["triangles"], 12, "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn an_opened_deburr_job_draws_its_tube_and_hole() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "jobDeburrSolids", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert_eq!(result["refused"], "false", "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn saving_an_existing_machine_or_material_asks_first_and_keeps_it() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "registryOverwrite", &[]) else { return };
    assert_eq!(result["ok"], true);
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn engagement_page_stars_no_flute_count_over_the_machines_torque() {
    let app = TestApp::spawn().await;
    // The form's example needs 2.6 N·m with 4 flutes, 5.3 N·m with 8.
    let machine = serde_json::json!({"block_time_ms": 4, "max_feed": 12000, "spindle_torque_nm": 2});
    let response = app.put_json("/api/v1/machines/vmc-2nm", &machine).await;
    assert_eq!(response.status(), 201);
    let Some(result) = run_scenario(&app, "engagementMachineLimits", &[]) else { return };
    assert_eq!(result["ok"], true, "{result}");
    assert!(!result["over"].as_array().unwrap().is_empty(), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn verify_page_lists_findings_at_their_lines() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "verify", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["findings"].as_u64().unwrap() >= 2, "{result}");
    assert!(
        result["red"].as_u64().unwrap() >= 500 && result["plunged"].as_f64() < result["removed"].as_f64(),
        "{result}"
    );
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn the_units_switch_sends_inch_and_labels_plots_and_readouts_in_inches() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "units", &[]) else { return };
    assert_eq!(result["flipped"], "0.23622", "{result}");
    assert_eq!(result["feedHint"], "5000 mm/min (machine)", "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn the_predict_view_follows_the_units_switch_with_errors_in_tenths() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "unitsPredict", &[]) else { return };
    assert_eq!(result["flipped"], "0.23622", "{result}");
    assert_eq!(result["back"], "6", "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn the_verify_view_follows_the_units_switch_and_reads_an_stl_part_in_mm() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "unitsVerify", &[]) else { return };
    assert_eq!(result["flipped"], "0.19685", "{result}");
    assert_eq!(result["back"], "5", "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn deburr_page_draws_the_cut_tube_with_its_chamfer() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "deburrCut", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["green"].as_u64().unwrap() >= 300 && result["tube"].as_u64().unwrap() >= 20000, "{result}");
    assert!(result["partly"].as_f64() < result["removed"].as_f64(), "{result}");
    eprintln!("compute to cut tube drawn: {} s, {} vertices", result["seconds"], result["vertices"]);
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn the_machine_form_lists_every_post_and_saves_haas_smoothing() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "machinePosts", &[]) else { return };
    assert_eq!(result["stored"]["haas_smoothing"], 2, "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn contour_page_draws_its_cut_stock() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "contourCut", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["partly"].as_f64() < result["removed"].as_f64(), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn predict_page_draws_the_stock_its_corrected_program_cuts() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "predictCut", &[]) else { return };
    assert_eq!(result["ok"], true);
    eprintln!("{result}");
    assert!(result["partly"].as_f64() < result["removed"].as_f64(), "{result}");
    assert!(result["partly"].as_f64() > Some(0.0), "playback cut some of the stock: {result}");
    assert!(result["green"].as_u64() > Some(0) && result["listed"].as_u64() > Some(10), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn engagement_page_draws_the_stock_its_program_cuts() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "engagementCut", &[]) else { return };
    assert_eq!(result["ok"], true);
    eprintln!("{result}");
    assert!(result["partly"].as_f64() < result["removed"].as_f64(), "{result}");
    assert!(result["green"].as_u64() > Some(0), "{result}");
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(
    not(kerf_has_chromium),
    ignore = "chromium or its driver not found: apt-get install chromium npm; npm ci --prefix tests/browser"
)]
async fn an_opened_job_draws_an_operations_cut_stock_when_asked() {
    let app = TestApp::spawn().await;
    let Some(result) = run_scenario(&app, "jobCut", &[]) else { return };
    assert_eq!(result["ok"], true);
    assert!(result["partly"].as_f64() < result["removed"].as_f64(), "{result}");
    assert!(result["deepest"].as_f64() < Some(-0.1), "{result}");
}
