//! `POST /api/v1/engagement` over HTTP: the docs/spec/api.md example, the reference cases C1–C3 of
//! `solver/tests/fixtures/engagement.json` to their tolerances (C2 part B as two candidate paths side by
//! side), the dots engine, G-code of the feed plan in both dialects through LinuxCNC's `rs274`
//! (moves equal to the JSON positions within 1e-4, F words equal to the plan's feeds), and a
//! table of bad requests answered with the field at fault and the database unchanged.

use kerf_cases::{case, close, number};
use std::collections::BTreeSet;

use kerf_tests::{TestApp, assert_moves_match, external_program, finished, json_with, poll_job, problem, rs274_moves};
use serde_json::{Value, json};

const URL: &str = "/api/v1/engagement";

/// The docs/spec/api.md example.
pub fn api_example() -> Value {
    json!({
        "tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0,0],[60,0],[60,40],[0,40]]},
        "path": [[-10,20],[70,20]], "spindle_rpm": 3000, "feed_per_tooth": 0.05,
        "flute_counts": [1,2,3,4,5,6,7,8], "thickness_limit": 0.075, "time_limit_s": 20
    })
}

fn close_rel(what: &str, got: f64, expected: f64, relative: f64) {
    close(what, got, expected, relative * expected.abs() + 1e-9);
}

/// The request body for a fixture input block ([`kerf_cases::engagement::fixture_request`]) with
/// a tool of `diameter` and `extra` fields.
fn fixture_request(stock: &Value, path: &Value, cutting: &Value, flutes: &Value, diameter: f64, extra: Value) -> Value {
    kerf_cases::with(kerf_cases::engagement::fixture_request(stock, path, cutting, flutes, diameter / 2.0), extra)
}

fn sample_at(result: &Value, s: f64) -> &Value {
    result["samples"]
        .as_array()
        .unwrap()
        .iter()
        .find(|sample| (number(&sample["s"]) - s).abs() < 1e-6)
        .unwrap_or_else(|| panic!("no sample at s = {s}"))
}

fn flute_list(value: &Value) -> Vec<u64> {
    value.as_array().unwrap().iter().map(|k| k.as_u64().unwrap()).collect()
}

fn recommended(result: &Value) -> Vec<u64> {
    flute_list(&result["recommended"])
}

/// One fixture checkpoint against the sample at its s (exact-engine tolerances).
fn check_point(label: &str, result: &Value, checkpoint: &Value, flutes: &[u64]) {
    let s = number(&checkpoint["s"]);
    let sample = sample_at(result, s);
    let what = |field: &str| format!("{label} s={s} {field}");
    let arcs = checkpoint["arcs"].as_array().unwrap();
    let got = sample["arcs"].as_array().unwrap();
    assert_eq!(got.len(), arcs.len(), "{}: {got:?}", what("arcs"));
    for (g, e) in got.iter().zip(arcs) {
        close(&what("arc from"), number(&g[0]), number(&e[0]), 0.05);
        close(&what("arc to"), number(&g[1]), number(&e[1]), 0.05);
    }
    close(&what("engaged_deg"), number(&sample["engaged_deg"]), number(&checkpoint["engaged_deg"]), 0.1);
    close(&what("radial_depth"), number(&sample["radial_depth"]), number(&checkpoint["ae"]), 0.005);
    for (column, k) in flutes.iter().enumerate() {
        let key = k.to_string();
        close_rel(
            &what(&format!("H k={k}")),
            number(&sample["thickness"][column]),
            number(&checkpoint["H_mm_by_k"][&key]),
            0.002,
        );
        assert_eq!(sample["teeth"][column], checkpoint["n_max_by_k"][&key], "{}", what(&format!("n k={k}")));
    }
}

fn check_statistics(label: &str, result: &Value, expected: &Value, max_rel: f64, mean_rel: f64) {
    for flute in result["flutes"].as_array().unwrap() {
        let key = flute["flute_count"].to_string();
        close_rel(
            &format!("{label} max k={key}"),
            number(&flute["max_thickness"]),
            number(&expected[&key]["max"]),
            max_rel,
        );
        close_rel(
            &format!("{label} mean k={key}"),
            number(&flute["mean_thickness"]),
            number(&expected[&key]["mean"]),
            mean_rel,
        );
        let (low, mean, high) =
            (number(&flute["min_thickness"]), number(&flute["mean_thickness"]), number(&flute["max_thickness"]));
        assert!(low <= mean && mean <= high, "{label} k={key}: min ≤ mean ≤ max");
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn api_example_over_http() {
    let app = TestApp::spawn().await;
    let body = api_example();
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    assert_eq!(answer["tool"]["radius"], 5.0);
    assert_eq!(
        answer["stock"],
        json!({"polygon": [[0.0, 0.0], [60.0, 0.0], [60.0, 40.0], [0.0, 40.0]]}),
        "the stock is echoed"
    );
    assert_eq!(answer["thickness_limit"], 0.075);
    assert_eq!(answer["time_limit_s"], 20.0);
    // L = 80 mm: P_k = 60·80/(k·0.05·3000) = 32/k s; the slot's H_k/f_z is 1, 1, 1, √2, 1.618, ...
    close("path length", number(&answer["path_length"]), 80.0, 1e-9);
    // Full slot (docs/spec/engagement.md §5.6): H_k/f_z = 1 for k = 1, 1/sin(π/k) for even k,
    // 1/(2 sin(π/2k)) for odd k ≥ 3.
    let slot_ratio = |k: f64| {
        let pi = std::f64::consts::PI;
        if k == 1.0 {
            1.0
        } else if k % 2.0 == 0.0 {
            1.0 / (pi / k).sin()
        } else {
            1.0 / (2.0 * (pi / (2.0 * k)).sin())
        }
    };
    for (index, flute) in answer["flutes"].as_array().unwrap().iter().enumerate() {
        let k = (index + 1) as f64;
        assert_eq!(flute["flute_count"], index + 1);
        close("time", number(&flute["time_s"]), 32.0 / k, 1e-9);
        close_rel("max H", number(&flute["max_thickness"]), 0.05 * slot_ratio(k), 1e-9);
        let meets = number(&flute["max_thickness"]) <= 0.075 && number(&flute["time_s"]) <= 20.0;
        assert_eq!(flute["recommended"], meets, "k = {k}");
    }
    // T1 = 0.075 keeps k ≤ 4, T2 = 20 s needs k ≥ 2: fastest first.
    assert_eq!(recommended(&answer), vec![4, 3, 2]);
    let slot = sample_at(&answer, 30.0);
    assert_eq!(slot["arcs"], json!([[0.0, 180.0]]));
    assert_eq!(slot["engaged_deg"], 180.0);
    assert_eq!(slot["radial_depth"], 10.0);
    close("t at s = 30", number(&slot["t"]), 60.0 * 30.0 / 300.0, 1e-9);
    assert_eq!(sample_at(&answer, 0.0)["arcs"], json!([]));
    // Determinism: byte-identical answers.
    let once = app.client.post(app.url(URL)).json(&body).send().await.unwrap().bytes().await.unwrap();
    let again = app.client.post(app.url(URL)).json(&body).send().await.unwrap().bytes().await.unwrap();
    assert_eq!(once, again);
    // A registered tool by number gives the same numbers.
    app.register_tool(3, &json!({"kind": "flat", "radius": 5, "flutes": 4})).await;
    let mut by_number = body.clone();
    by_number["tool"] = json!(3);
    let numbered = json_with(app.post_json(URL, &by_number).await, 200).await;
    assert_eq!(numbered["tool"]["number"], 3);
    assert_eq!(numbered["flutes"], answer["flutes"]);
    assert_eq!(numbered["time_flute_count"], 4);
}

#[tokio::test(flavor = "multi_thread")]
async fn c1_slot_then_side_milling() {
    let app = TestApp::spawn().await;
    let c = case("engagement", "C1");
    let input = &c["input"];
    let expected = &c["expected"];
    let flutes = flute_list(&input["tool"]["flute_candidates"]);
    let limits = json!({"thickness_limit": input["evaluation"]["T1_mm"], "time_limit_s": input["evaluation"]["T2_s"]});
    let body = |extra: Value| {
        let mut extra_all = limits.clone();
        for (key, value) in extra.as_object().unwrap() {
            extra_all[key] = value.clone();
        }
        fixture_request(
            &input["stock"],
            &input["path"],
            &input["cutting"],
            &input["tool"]["flute_candidates"],
            10.0,
            extra_all,
        )
    };
    let ds = number(&input["simulation"]["ds"]);
    let started = std::time::Instant::now();
    let result = json_with(app.post_json(URL, &body(json!({"step": ds}))).await, 200).await;
    eprintln!(
        "C1 exact at Δs = {ds}: {} samples in {:?}",
        result["samples"].as_array().unwrap().len(),
        started.elapsed()
    );
    close("path length", number(&result["path_length"]), 142.5, 1e-9);
    check_statistics("C1", &result, &expected["representative_mm"], 0.002, 0.01);
    for flute in result["flutes"].as_array().unwrap() {
        let key = flute["flute_count"].to_string();
        close_rel(
            &format!("time k={key}"),
            number(&flute["time_s"]),
            number(&expected["machining_time_s"][&key]),
            1e-4,
        );
    }
    let set: BTreeSet<u64> = recommended(&result).into_iter().collect();
    assert_eq!(set, flute_list(&expected["recommended_flutes"]).into_iter().collect());
    assert_eq!(recommended(&result), vec![4, 3], "fastest first");
    let intervals = result["engaged_intervals"].as_array().unwrap();
    let continuum = expected["engaged_intervals_s_continuum_open"].as_array().unwrap();
    assert_eq!(intervals.len(), continuum.len(), "{intervals:?}");
    for (got, want) in intervals.iter().zip(continuum) {
        close("interval from", number(&got[0]), number(&want[0]), ds);
        close("interval to", number(&got[1]), number(&want[1]), ds);
    }
    // Checkpoints (s = 71.25 lies off the 0.1 mm grid: read them from a 0.05 mm run).
    let fine = json_with(app.post_json(URL, &body(json!({"step": 0.05}))).await, 200).await;
    for checkpoint in expected["checkpoints"].as_array().unwrap() {
        check_point("C1", &fine, checkpoint, &flutes);
    }

    // The dots engine over HTTP, at the fixture's grid and step: the patent's contact dots and
    // the representative values within its tolerances.
    let dots_settings = &input["simulation"]["dot_engine"];
    let dots = json_with(
        app.post_json(
            URL,
            &body(json!({"engine": "dots", "grid": dots_settings["grid"], "step": dots_settings["ds"]})),
        )
        .await,
        200,
    )
    .await;
    assert_eq!(dots["engine"], "dots");
    assert_eq!(dots["grid"]["cell"], dots_settings["grid"]);
    assert!(dots["contact_dots"].as_array().is_some_and(|d| d.len() > 1000), "contact dots for the scatter");
    check_statistics("C1 dots", &dots, &expected["representative_mm"], 0.01, 0.02);
    let set: BTreeSet<u64> = recommended(&dots).into_iter().collect();
    assert_eq!(set, flute_list(&expected["recommended_flutes"]).into_iter().collect());
}

#[tokio::test(flavor = "multi_thread")]
async fn c2_side_milling_and_inside_corner_side_by_side() {
    let app = TestApp::spawn().await;
    let c = case("engagement", "C2");
    // Part A: each row a straight pass at a known radial depth, checked at its checkpoint.
    let part_a = &c["part_A"];
    let input = &part_a["input"];
    let flutes = flute_list(&input["tool"]["flute_candidates"]);
    for row in part_a["rows"].as_array().unwrap() {
        let body = fixture_request(
            &input["stock"],
            &row["path"],
            &input["cutting"],
            &input["tool"]["flute_candidates"],
            10.0,
            json!({"step": input["simulation"]["ds"]}),
        );
        let result = json_with(app.post_json(URL, &body).await, 200).await;
        let label = format!("C2A a_e={} {}", row["ae"], row["side"]);
        let checkpoint = json!({"s": row["checkpoint_s"], "arcs": row["arcs"], "engaged_deg": row["engaged_deg"],
            "ae": row["ae_measured"], "H_mm_by_k": row["H_mm_by_k"], "n_max_by_k": row["n_max_by_k"]});
        check_point(&label, &result, &checkpoint, &flutes);
        let sample = sample_at(&result, number(&row["checkpoint_s"]));
        close(&label, number(&sample["mean_chip_thickness"]), number(&row["mean_chip_thickness_mm"]), 1e-5);
        let mode = sample["arc_details"][0]["mode"].as_str().unwrap();
        let expected_mode = match row["mode"].as_str().unwrap() {
            "down" => "climb",
            "up" => "conventional",
            other => other,
        };
        assert_eq!(mode, expected_mode, "{label}");
    }

    // Part B: the sharp corner and the 3 mm fillet as two candidate paths of one request.
    let part_b = &c["part_B"];
    let input = &part_b["input"];
    let mut body = fixture_request(
        &input["stock"],
        &Value::Null,
        &input["cutting"],
        &input["tool"]["flute_candidates"],
        10.0,
        json!({"step": input["simulation"]["ds"]}),
    );
    body.as_object_mut().unwrap().remove("path");
    body["paths"] = json!([
        {"name": "sharp", "path": input["paths"]["sharp"]},
        {"name": "fillet 3", "path": input["paths"]["fillet3"]},
    ]);
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    let candidates = answer["candidates"].as_array().unwrap();
    assert_eq!(candidates.len(), 2);
    assert_eq!(candidates[0]["name"], "sharp");
    assert_eq!(candidates[1]["name"], "fillet 3");
    let expected = &part_b["expected"];
    let sharp = &expected["sharp"];
    close("sharp length", number(&candidates[0]["path_length"]), number(&sharp["path_length"]), 1e-9);
    close("sharp max Φ", number(&candidates[0]["max_engaged_deg"]), number(&sharp["max_engaged_deg"]), 0.1);
    close("sharp max Φ at", number(&candidates[0]["max_engaged_at_s"]), number(&sharp["max_engaged_at_s"]), 1e-6);
    close("sharp max a_e", number(&candidates[0]["max_radial_depth"]), number(&sharp["max_ae"]), 0.005);
    let fillet = &expected["fillet3"];
    close("fillet length", number(&candidates[1]["path_length"]), number(&fillet["path_length"]), 1e-3);
    close("fillet max Φ", number(&candidates[1]["max_engaged_deg"]), number(&fillet["max_engaged_deg"]), 0.1);
    for (candidate, expected) in candidates.iter().zip([sharp, fillet]) {
        for flute in candidate["flutes"].as_array().unwrap() {
            let key = flute["flute_count"].to_string();
            close_rel(
                &format!("{} H max k={key}", candidate["name"]),
                number(&flute["max_thickness"]),
                number(&expected["H_max_mm_by_k_over_path"][&key]),
                0.002,
            );
        }
        for checkpoint in expected["checkpoints"].as_array().unwrap() {
            check_point(candidate["name"].as_str().unwrap(), candidate, checkpoint, &flutes);
        }
    }
}

#[tokio::test(flavor = "multi_thread")]
async fn c3_pair_blocks_and_flute_selection() {
    let app = TestApp::spawn().await;
    let c = case("engagement", "C3");
    let input = &c["input"];
    let expected = &c["expected"];
    let flutes = flute_list(&input["tool"]["flute_candidates"]);
    let evaluation = &input["evaluation"];
    let body = fixture_request(
        &input["stock"],
        &input["path"],
        &input["cutting"],
        &input["tool"]["flute_candidates"],
        20.0,
        json!({"step": input["simulation"]["ds"], "thickness_limit": evaluation["T1_mm"], "time_limit_s": evaluation["T2_s"]}),
    );
    let result = json_with(app.post_json(URL, &body).await, 200).await;
    for flute in result["flutes"].as_array().unwrap() {
        let key = flute["flute_count"].to_string();
        close_rel(
            &format!("H/fz k={key}"),
            number(&flute["max_thickness"]) / 0.1,
            number(&expected["H_over_fz_max_by_k"][&key]),
            0.002,
        );
        assert_eq!(flute["max_teeth"], expected["n_max_by_k_over_path"][&key], "n_max k={key}");
        close_rel(
            &format!("time k={key}"),
            number(&flute["time_s"]),
            number(&expected["machining_time_s_constant_fz"][&key]),
            1e-4,
        );
    }
    check_statistics("C3", &result, &expected["representative_mm_constant_fz"], 0.002, 0.01);
    let set: BTreeSet<u64> = recommended(&result).into_iter().collect();
    assert_eq!(set, flute_list(&expected["recommended_flutes_constant_fz"]).into_iter().collect());
    assert_eq!(recommended(&result), vec![10, 9, 7, 5], "fastest first");
    for checkpoint in expected["checkpoints"].as_array().unwrap() {
        check_point("C3", &result, checkpoint, &flutes);
    }

    // Constant V_f: 24 s for every k; T2 = 30 s admits k = 5…10, T2 = 20 s none.
    let variant = &expected["constant_vf_variant"];
    for (limits, want) in input["evaluation_variant_constant_vf"]
        .as_array()
        .unwrap()
        .iter()
        .zip([flute_list(&variant["recommended_T2_30"]), flute_list(&variant["recommended_T2_20"])])
    {
        let body = fixture_request(
            &input["stock"],
            &input["path"],
            &input["cutting_variant_constant_vf"],
            &input["tool"]["flute_candidates"],
            20.0,
            json!({"step": input["simulation"]["ds"], "thickness_limit": limits["T1_mm"], "time_limit_s": limits["T2_s"]}),
        );
        let result = json_with(app.post_json(URL, &body).await, 200).await;
        for flute in result["flutes"].as_array().unwrap() {
            close("constant V_f time", number(&flute["time_s"]), 24.0, 1e-9);
        }
        let got: BTreeSet<u64> = recommended(&result).into_iter().collect();
        assert_eq!(got, want.into_iter().collect(), "T2 = {}", limits["T2_s"]);
        if got.is_empty() {
            assert!(result["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "W_NO_RECOMMENDATION"));
        }
    }
}

/// A path that never touches the stock is not an error (docs/spec/engagement.md §9 `W_NO_CONTACT`): all
/// series zero, T1 trivially met, and the answer says so.
#[tokio::test(flavor = "multi_thread")]
async fn a_path_that_never_touches_the_stock_is_a_warning() {
    let app = TestApp::spawn().await;
    let mut body = api_example();
    body["path"] = json!([[-10, 60], [70, 60]]);
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    let warning =
        answer["warnings"].as_array().unwrap().iter().find(|w| w["code"] == "W_NO_CONTACT").expect("W_NO_CONTACT");
    assert!(warning["message"].as_str().unwrap().contains("never touches"), "{warning}");
    assert!(answer["samples"].as_array().unwrap().iter().all(|s| s["arcs"] == json!([]) && s["radial_depth"] == 0.0));
    assert!(answer["flutes"].as_array().unwrap().iter().all(|f| f["max_thickness"] == 0.0));
    assert_eq!(answer["engaged_intervals"], json!([]));
    // L = 80 mm: P_k = 32/k s, so T2 = 20 s admits k ≥ 2; T1 is met by every k.
    assert_eq!(recommended(&answer), vec![8, 7, 6, 5, 4, 3, 2], "only T2 decides");
}

/// A request naming a machine takes its `max_feed` as the feed plan's cap and its dialect for
/// G-code; a cap above the machine's is kept with a warning; an unknown machine is 404.
#[tokio::test(flavor = "multi_thread")]
async fn a_named_machine_caps_the_feed_plan_and_sets_the_dialect() {
    let app = TestApp::spawn().await;
    let mut body = api_example();
    body["machine"] = json!("vmc-1");
    body["feed_plan"] = json!({"target_thickness": 0.05});
    let unknown = problem(app.post_json(URL, &body).await, 404).await;
    assert_eq!(unknown["errors"][0]["path"], "machine");

    let machine = json!({"block_time_ms": 4, "max_feed": 900, "dialect": "linuxcnc"});
    json_with(app.put_json("/api/v1/machines/vmc-1", &machine).await, 201).await;
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    assert_eq!(answer["machine"]["max_feed"], 900.0);
    assert_eq!(answer["feed_plan"]["max_feed"], 900.0, "{}", answer["feed_plan"]);
    let feeds: Vec<f64> =
        answer["feed_plan"]["blocks"].as_array().unwrap().iter().map(|block| number(&block["feed"])).collect();
    assert!(!feeds.is_empty() && feeds.iter().all(|&feed| feed <= 900.0 + 1e-9), "{feeds:?}");

    body["axial_depth"] = json!(2);
    let program = app.post_text(&format!("{URL}?format=gcode"), &body, 200).await;
    assert!(!program.starts_with('%') && program.contains("G64"), "linuxcnc from the machine:\n{program}");

    // The machine caps a larger max feed, and says so; it never raises a smaller one.
    body["feed_plan"]["max_feed"] = json!(5000);
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    assert_eq!(answer["feed_plan"]["max_feed"], 900.0);
    assert!(answer["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "W_FEED_ABOVE_MACHINE_MAX"));
    body["feed_plan"]["max_feed"] = json!(400);
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    assert_eq!(answer["feed_plan"]["max_feed"], 400.0);
}

/// The program starts the spindle the way the analysis assumed: M03 for `cw`, M04 for `ccw`.
#[tokio::test(flavor = "multi_thread")]
async fn the_program_turns_the_spindle_as_analysed() {
    let app = TestApp::spawn().await;
    let mut body = api_example();
    body["axial_depth"] = json!(2);
    for (direction, code, other) in [("cw", "S3000 M03", "M04"), ("ccw", "S3000 M04", "M03")] {
        body["spindle_direction"] = json!(direction);
        let program = app.post_text(&format!("{URL}?format=gcode"), &body, 200).await;
        assert!(program.contains(code) && !program.contains(other), "{direction}:\n{program}");
    }
}

/// With a block time the program's arcs are chorded into blocks of one block time at their
/// feed, and the answer reports the program's blocks; an arc too tight for one block is
/// reported, not refused.
#[tokio::test(flavor = "multi_thread")]
async fn block_time_chords_the_program_and_reports_its_blocks() {
    let app = TestApp::spawn().await;
    let mut body = api_example();
    body["path"] = json!({"start": [-10, 20], "segments": [
        {"type": "line", "to": [30, 20]},
        {"type": "arc", "to": [40, 30], "center": [30, 30], "dir": "ccw"},
        {"type": "line", "to": [40, 60]}]});
    body["axial_depth"] = json!(2);
    // The tool's own 2 flutes, so the program is for them.
    body["flute_counts"] = json!([2]);
    let gcode_moves = |program: &str| program.lines().filter(|l| l.starts_with("G01")).count();
    let program_of = |body: Value| {
        let request = app.client.post(app.url(&format!("{URL}?format=gcode"))).json(&body);
        async move { request.send().await.unwrap().text().await.unwrap() }
    };
    let plain = json_with(app.post_json(URL, &body).await, 200).await;
    assert!(plain.get("blocks").is_none(), "no block figures without a block time");
    let plain_moves = gcode_moves(&program_of(body.clone()).await);

    body["block_time_ms"] = json!(4);
    let ruled = json_with(app.post_json(URL, &body).await, 200).await;
    let blocks = &ruled["blocks"];
    assert_eq!(blocks["block_time_ms"], 4.0);
    // 2 flutes × 0.05 mm × 3000 rpm = 300 mm/min: blocks of 0.02 mm on a 4 ms control.
    let block_length = 300.0 * 4.0 / 60_000.0;
    assert!((number(&blocks["block_length"]) - block_length).abs() < 1e-12, "{blocks}");
    assert_eq!(blocks["short_blocks"], 0, "{}", ruled["warnings"]);
    assert!(number(&blocks["min_block_length"]) >= block_length * (1.0 - 1e-9), "{blocks}");
    let program = program_of(body.clone()).await;
    assert_eq!(gcode_moves(&program), blocks["blocks"].as_u64().unwrap() as usize, "every feed block is a G01");
    // The R10 quarter arc (15.7 mm) in chords of one 0.02 mm block instead of 0.28 mm ones.
    assert!(gcode_moves(&program) > plain_moves + 700, "{} vs {plain_moves}", gcode_moves(&program));
    assert_eq!(ruled["samples"], plain["samples"], "the analysis does not change");

    // 20 m/min on a 10 ms control wants 3.3 mm blocks: an R1 arc cannot hold one.
    body["feed_per_tooth"] = Value::Null;
    body["feed"] = json!(20_000);
    body["block_time_ms"] = json!(10);
    body["path"]["segments"][1] = json!({"type": "arc", "to": [31, 21], "center": [30, 21], "dir": "ccw"});
    body["path"]["segments"][2] = json!({"type": "line", "to": [31, 60]});
    let tight = json_with(app.post_json(URL, &body).await, 200).await;
    let codes: Vec<&str> = tight["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"W_INFEASIBLE_FEED_FOR_RADIUS") && codes.contains(&"W_BLOCK_TIME_VIOLATION"), "{codes:?}");
    assert!(tight["blocks"]["short_blocks"].as_u64().unwrap() > 0);

    body["block_time_ms"] = json!(0);
    let refused = problem(app.post_json(URL, &body).await, 422).await;
    assert_eq!(refused["errors"][0]["path"], "block_time_ms");
}

/// The example job's engagement operation gives exactly the endpoint's answer for the same
/// request, and its program is the endpoint's for the first path in the job's output options.
#[tokio::test(flavor = "multi_thread")]
async fn a_job_answers_like_the_endpoint() {
    let app = TestApp::spawn().await;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/engagement-pocket.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let file: Value = toml::from_str(&text).unwrap();
    let response = app
        .client
        .post(app.url("/api/v1/jobs"))
        .header("content-type", "application/toml")
        .body(text)
        .send()
        .await
        .unwrap();
    let id = json_with(response, 202).await["id"].as_i64().unwrap();
    let job = poll_job(&app.client, &app.base, id, 60, finished).await;
    assert_eq!(job["status"], "done", "{job}");
    let mut request = file["operations"][0].clone();
    request.as_object_mut().unwrap().remove("operation");
    request["tool"] = file["tools"][0].clone();
    let answer = json_with(app.post_json(URL, &request).await, 200).await;
    assert_eq!(job["results"][0]["operation"], "engagement");
    assert_eq!(job["results"][0]["result"], answer, "the job's result is the endpoint's answer");
    let candidates = answer["candidates"].as_array().unwrap();
    assert_eq!(candidates.len(), 3);
    assert!(candidates.iter().all(|c| c["flutes"].as_array().unwrap().len() == 8));
    let from_job = app.get(&format!("/api/v1/jobs/{id}/gcode")).await.text().await.unwrap();
    let url = app.url(&format!("{URL}?format=gcode&dialect=linuxcnc&candidate=0"));
    let from_endpoint = app.client.post(url).json(&request).send().await.unwrap().text().await.unwrap();
    assert_eq!(from_job, from_endpoint);
    assert!(from_job.contains("G64 P") && from_job.contains("T5 M06"));
}

/// A bad value in an engagement job file names its line and field (400); an operation the solver
/// refuses fails the job with the field at fault.
#[tokio::test(flavor = "multi_thread")]
async fn engagement_job_errors_name_the_line_and_field() {
    let app = TestApp::spawn().await;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/engagement-pocket.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let upload = |body: String| {
        app.client.post(app.url("/api/v1/jobs")).header("content-type", "application/toml").body(body).send()
    };
    let bad_type = text.replace("thickness_limit = 0.06", "thickness_limit = \"thin\"");
    let line = bad_type.lines().position(|l| l.starts_with("thickness_limit")).unwrap() + 1;
    let answer = problem(upload(bad_type).await.unwrap(), 400).await;
    assert_eq!(answer["errors"][0]["path"], "operations[0].thickness_limit");
    assert!(answer["detail"].as_str().unwrap().starts_with(&format!("line {line},")), "{answer}");
    let refused = text.replace("flute_counts = [1, 2, 3, 4, 5, 6, 7, 8]", "flute_counts = [1, 2, 40]");
    let id = json_with(upload(refused).await.unwrap(), 202).await["id"].as_i64().unwrap();
    let job = poll_job(&app.client, &app.base, id, 60, finished).await;
    assert_eq!(job["status"], "failed", "{job}");
    assert_eq!(job["error"]["errors"][0]["path"], "operations[0].flute_counts[2]");
    assert_eq!(job["error"]["code"], "E_INPUT", "{job}");
}

// ---------------------------------------------------------------- G-code

/// The moves the JSON answer describes after the tool change, with their feeds: rapid above the
/// start, feed down to the cutting depth, then one feed move to the end of every plan block (the
/// block ends are sample positions; the paths here are straight lines).
fn expected_moves(result: &Value, cut_z: f64, safe_z: f64) -> Vec<(bool, [f64; 3], Option<f64>)> {
    let samples = result["samples"].as_array().unwrap();
    let position = |s: f64| {
        let sample =
            samples.iter().find(|sample| (number(&sample["s"]) - s).abs() < 1e-9).expect("block end at a sample");
        [number(&sample["position"][0]), number(&sample["position"][1])]
    };
    let start = position(0.0);
    let blocks = result["feed_plan"]["blocks"].as_array().unwrap();
    // The plunge runs no faster than the nominal feed of the program's flutes (f_z = 0.05,
    // N = 3000), halved (no plunge feed given).
    let nominal = number(&result["program_flute_count"]) * 0.05 * 3000.0;
    let first_feed = number(&blocks[0]["feed"]);
    let mut moves = vec![
        (false, [start[0], start[1], safe_z], None),
        (true, [start[0], start[1], cut_z], Some(first_feed.min(nominal) * 0.5)),
    ];
    for block in blocks {
        let end = position(number(&block["to_s"]));
        moves.push((true, [end[0], end[1], cut_z], Some(number(&block["feed"]))));
    }
    moves
}

/// The modal feed of every G00/G01 line of `program`, in order (`None` for rapids).
fn program_feeds(program: &str) -> Vec<Option<f64>> {
    let mut modal = None;
    program
        .lines()
        .filter(|line| line.starts_with("G00 X") || line.starts_with("G01 "))
        .map(|line| {
            if let Some(word) = line.split_whitespace().find(|w| w.starts_with('F')) {
                modal = word[1..].parse::<f64>().ok();
            }
            line.starts_with("G01").then_some(modal).flatten()
        })
        .collect()
}

#[tokio::test(flavor = "multi_thread")]
#[cfg_attr(not(kerf_has_rs274), ignore = "rs274 not found: apt-get install linuxcnc-uspace")]
async fn gcode_of_the_feed_plan_in_both_dialects() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 5, "flutes": 3})).await;
    app.register_tool(6, &json!({"kind": "ball", "radius": 5, "flutes": 2})).await;
    let mut body = api_example();
    body["tool"] = json!(3);
    body.as_object_mut().unwrap().remove("path");
    // A slot, a side cut at a_e = 2.5 (climb) and a pass through the air: the chip-thinning
    // plan raises the feed where the engagement is thin.
    body["paths"] = json!([
        {"name": "slot then side", "path": [[-10, 20], [70, 20], [70, 27.5], [-10, 27.5]]},
        {"name": "side only", "path": [[70, 42.5], [-10, 42.5]]},
    ]);
    body["axial_depth"] = json!(3);
    body["stock_top_z"] = json!(1);
    body["feed_plan"] = json!({"target_thickness": 0.05, "max_feed": 1500});
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    let external = external_program("rs274", "the LinuxCNC G-code check").is_some();
    for (tool, reference, lift) in [(3, "tip", 0.0), (3, "centre", 0.0), (6, "centre", 5.0)] {
        let mut body = body.clone();
        body["tool"] = json!(tool);
        let answer = if tool == 3 { answer.clone() } else { json_with(app.post_json(URL, &body).await, 200).await };
        for (candidate, result) in answer["candidates"].as_array().unwrap().iter().enumerate() {
            let plan = &result["feed_plan"];
            let feeds: BTreeSet<u64> =
                plan["blocks"].as_array().unwrap().iter().map(|b| number(&b["feed"]) as u64).collect();
            assert!(feeds.len() >= 2, "the plan changes the feed: {feeds:?}");
            // Through the air at the nominal feed of the plan's flute count, not at the max feed.
            let nominal = (number(&plan["flute_count"]) * 0.05 * 3000.0).min(1500.0);
            let air: Vec<&Value> =
                plan["blocks"].as_array().unwrap().iter().filter(|b| b["limited_by"] == "air").collect();
            assert!(!air.is_empty() && air.iter().all(|b| number(&b["feed"]) == nominal), "{air:?}");
            for dialect in ["fanuc", "linuxcnc"] {
                let url = app
                    .url(&format!("{URL}?format=gcode&dialect={dialect}&reference={reference}&candidate={candidate}"));
                let response = app.client.post(url).json(&body).send().await.unwrap();
                assert_eq!(response.status(), 200);
                assert!(response.headers()["content-type"].to_str().unwrap().starts_with("text/x-gcode"));
                let program = response.text().await.unwrap();
                assert!(program.contains(&format!("T{tool} M06")), "{program}");
                if dialect == "fanuc" {
                    assert!(program.starts_with("%\n") && program.contains("O1000"));
                } else {
                    assert!(program.contains("G64 P"));
                }
                let expected = expected_moves(result, 1.0 - 3.0 + lift, 1.0 + 5.0 + lift);
                let feeds = program_feeds(&program);
                assert_eq!(feeds.len(), expected.len(), "{program}");
                for (index, (got, want)) in feeds.iter().zip(&expected).enumerate() {
                    // F words carry at most one decimal (the nominal feed k·f_z·N may not be whole).
                    let same = match (got, want.2) {
                        (Some(g), Some(w)) => (g - w).abs() <= 0.05,
                        (g, w) => *g == w,
                    };
                    assert!(same, "F word of move {index}: {got:?} vs {:?}\n{program}", want.2);
                }
                let label = format!("engagement_{tool}_{reference}_{candidate}_{dialect}");
                let Some(mut interpreted) = rs274_moves(&program, app.directory(), &label) else {
                    assert!(!external);
                    continue;
                };
                // The first traverse is the length-offset block; the last the final retract.
                let first_rapid = interpreted.iter().position(|m| !m.0).unwrap();
                interpreted.drain(..=first_rapid);
                interpreted.pop();
                let ends: Vec<(bool, [f64; 3])> = expected.iter().map(|m| (m.0, m.1)).collect();
                assert_moves_match(&label, &interpreted, &ends);
            }
        }
    }

    // Without a feed plan every cutting move runs at the nominal feed of the program's flutes
    // (here the tool's 2, the only count compared), the plunge (the first feed move) at half of it.
    let mut nominal = api_example();
    nominal["axial_depth"] = json!(2);
    nominal["flute_counts"] = json!([2]);
    let program = app
        .client
        .post(app.url(&format!("{URL}?format=gcode")))
        .json(&nominal)
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    let feeds: Vec<f64> = program_feeds(&program).into_iter().flatten().collect();
    assert!((feeds[0] - 150.0).abs() <= 0.05, "{program}");
    assert!(feeds[1..].iter().all(|f| (*f - 300.0).abs() <= 0.05), "{program}");
    if let Some(moves) = rs274_moves(&program, app.directory(), "engagement_nominal") {
        assert!(moves.iter().any(|m| m.0 && (m.1[0] - 70.0).abs() < 1e-9 && (m.1[2] + 2.0).abs() < 1e-9));
    }
    // An arc path is written as chords the interpreter accepts; Accept: text/x-gcode works too.
    let mut arc = api_example();
    arc["path"] = json!({"start": [-10, 20], "segments": [
        {"type": "line", "to": [20, 20]},
        {"type": "arc", "to": [40, 20], "center": [30, 20], "dir": "cw"},
        {"type": "line", "to": [70, 20]}]});
    arc["axial_depth"] = json!(2);
    let response = app.client.post(app.url(URL)).header("accept", "text/x-gcode").json(&arc).send().await.unwrap();
    assert_eq!(response.status(), 200);
    let program = response.text().await.unwrap();
    if let Some(moves) = rs274_moves(&program, app.directory(), "engagement_arc") {
        assert!(moves.len() > 20, "the arc as chords");
    }
}

// ---------------------------------------------------------------- bad requests

fn with(changes: Value) -> Value {
    let mut body = api_example();
    for (key, value) in changes.as_object().unwrap() {
        if value.is_null() {
            body.as_object_mut().unwrap().remove(key);
        } else {
            body[key] = value.clone();
        }
    }
    body
}

/// (what, body, query, expected status, expected field path, expected code)
fn bad_cases() -> Vec<(&'static str, Value, &'static str, u16, &'static str, &'static str)> {
    vec![
        (
            "self-intersecting stock",
            with(json!({"stock": {"polygon": [[0, 0], [60, 40], [60, 0], [0, 40]]}})),
            "",
            422,
            "stock.polygon[0]",
            "E_STOCK",
        ),
        (
            "overlapping stock regions",
            with(json!({"stock": {"polygons": [
                {"outer": [[0, 0], [30, 0], [30, 30], [0, 30]]}, {"outer": [[20, 20], [50, 20], [50, 50], [20, 50]]}]}})),
            "",
            422,
            "stock.polygons[0].outer[1]",
            "E_STOCK",
        ),
        (
            "flat stock ring",
            with(json!({"stock": {"polygon": [[0, 0], [1, 1], [2, 2]]}})),
            "",
            422,
            "stock.polygon[0]",
            "E_STOCK",
        ),
        (
            "stock with two points",
            with(json!({"stock": {"polygon": [[0, 0], [1, 1]]}})),
            "",
            422,
            "stock.polygon",
            "E_STOCK",
        ),
        ("no stock shape", with(json!({"stock": {}})), "", 422, "stock", "E_INPUT"),
        ("empty path", with(json!({"path": []})), "", 422, "path", "E_PATH"),
        ("one-point path", with(json!({"path": [[1, 1]]})), "", 422, "path", "E_PATH"),
        ("zero-length path", with(json!({"path": [[1, 1], [1, 1]]})), "", 422, "path", "E_PATH"),
        ("path without segments", with(json!({"path": {"start": [0, 0], "segments": []}})), "", 422, "path", "E_PATH"),
        ("no path at all", with(json!({"path": null})), "", 422, "path", "E_PATH"),
        (
            "arc centre not equidistant",
            with(
                json!({"path": {"start": [0, 0], "segments": [{"type": "arc", "to": [10, 0], "center": [4, 1], "dir": "ccw"}]}}),
            ),
            "",
            422,
            "path.segments[0].center",
            "E_PATH",
        ),
        ("zero feed per tooth", with(json!({"feed_per_tooth": 0})), "", 422, "feed_per_tooth", "E_INPUT"),
        ("negative feed per tooth", with(json!({"feed_per_tooth": -0.05})), "", 422, "feed_per_tooth", "E_INPUT"),
        ("no feed", with(json!({"feed_per_tooth": null})), "", 422, "feed_per_tooth", "E_INPUT"),
        ("both feeds", with(json!({"feed": 600})), "", 422, "feed", "E_INPUT"),
        ("zero spindle", with(json!({"spindle_rpm": 0})), "", 422, "spindle_rpm", "E_INPUT"),
        ("flute count zero", with(json!({"flute_counts": [1, 0]})), "", 422, "flute_counts[1]", "E_INPUT"),
        ("flute count 33", with(json!({"flute_counts": [33]})), "", 422, "flute_counts[0]", "E_INPUT"),
        ("flute count twice", with(json!({"flute_counts": [2, 4, 2]})), "", 422, "flute_counts[2]", "E_INPUT"),
        ("no flute counts", with(json!({"flute_counts": []})), "", 422, "flute_counts", "E_INPUT"),
        ("negative flute count", with(json!({"flute_counts": [-1]})), "", 400, "flute_counts[0]", "E_JSON"),
        ("zero thickness limit", with(json!({"thickness_limit": 0})), "", 422, "thickness_limit", "E_INPUT"),
        ("coordinates beyond 1 km", with(json!({"path": [[0, 0], [2e6, 0]]})), "", 422, "path[1][0]", "E_INPUT"),
        ("grid with the exact engine", with(json!({"grid": 0.1})), "", 422, "grid", "E_INPUT"),
        ("step zero", with(json!({"step": 0})), "", 422, "step", "E_INPUT"),
        ("too many samples", with(json!({"step": 1e-4})), "", 422, "step", "E_TOO_MANY_SAMPLES"),
        (
            "grid over the memory limit",
            with(json!({"engine": "dots", "grid": 0.0005})),
            "",
            422,
            "grid",
            "E_GRID_MEMORY",
        ),
        ("path and paths", with(json!({"paths": [{"path": [[0, 0], [5, 0]]}]})), "", 422, "paths", "E_INPUT"),
        (
            "empty candidate path",
            with(json!({"path": null, "paths": [{"path": [[0, 0], [5, 0]]}, {"path": [[3, 3]]}]})),
            "",
            422,
            "paths[1].path",
            "E_PATH",
        ),
        (
            "17 candidate paths",
            with(json!({"path": null, "paths": vec![json!({"path": [[0, 0], [5, 0]]}); 17]})),
            "",
            422,
            "paths",
            "E_TOO_LARGE",
        ),
        (
            "bitmap of the wrong size",
            with(json!({"stock": {"bitmap": {"origin": [0, 0], "cell": 1, "width": 4, "height": 4, "data": "/w=="}}})),
            "",
            422,
            "stock.bitmap.data",
            "E_STOCK",
        ),
        (
            "feed plan without max feed",
            with(json!({"feed_plan": {"target_thickness": 0.05}})),
            "",
            422,
            "feed_plan.max_feed",
            "E_INPUT",
        ),
        ("unknown machine", with(json!({"machine": "vmc-1"})), "", 404, "machine", "E_NOT_FOUND"),
        ("unknown tool", with(json!({"tool": 4242})), "", 404, "tool", "E_NOT_FOUND"),
        (
            "inline tool of radius zero",
            with(json!({"tool": {"kind": "flat", "radius": 0}})),
            "",
            422,
            "tool.radius",
            "E_INPUT",
        ),
        ("unknown field", with(json!({"colour": "red"})), "", 400, "colour", "E_JSON"),
        ("point with three coordinates", with(json!({"path": [[0, 0, 0], [5, 0, 0]]})), "", 400, "path[0]", "E_JSON"),
        ("unknown engine", with(json!({"engine": "voxels"})), "", 400, "engine", "E_JSON"),
        (
            "unknown segment type",
            with(json!({"path": {"start": [0, 0], "segments": [{"type": "spline", "to": [1, 0]}]}})),
            "",
            400,
            "path.segments[0].type",
            "E_JSON",
        ),
        ("G-code without axial depth", api_example(), "?format=gcode", 422, "axial_depth", "E_INPUT"),
        (
            "G-code of a missing candidate",
            with(json!({"axial_depth": 2})),
            "?format=gcode&candidate=1",
            422,
            "candidate",
            "E_INPUT",
        ),
        ("candidate not a number", api_example(), "?format=gcode&candidate=first", 400, "candidate", "E_QUERY"),
        ("unknown query parameter", api_example(), "?colour=red", 400, "colour", "E_QUERY"),
        ("bad dialect", api_example(), "?format=gcode&dialect=mazak", 400, "dialect", "E_QUERY"),
    ]
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_engagement_requests() {
    let app = TestApp::spawn().await;
    app.register_tool(3, &json!({"kind": "flat", "radius": 5})).await;
    let tools_before = json_with(app.get("/api/v1/tools").await, 200).await;
    let jobs_before = json_with(app.get("/api/v1/jobs").await, 200).await;
    let mut mismatches = Vec::new();
    for (what, body, query, status, field, code) in bad_cases() {
        let response = app.client.post(app.url(&format!("{URL}{query}"))).json(&body).send().await.unwrap();
        let answer = problem(response, status).await;
        if answer["code"] != code || answer["errors"][0]["path"] != field {
            mismatches.push(format!("{what}: expected {code} at {field}, got {answer}"));
        }
        if what == "grid over the memory limit" {
            let detail = answer["detail"].as_str().unwrap();
            assert!(detail.contains("the limit is 1000000000 dots"), "the limit is named: {detail}");
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
    assert_eq!(json_with(app.get("/api/v1/tools").await, 200).await, tools_before, "tools unchanged");
    assert_eq!(json_with(app.get("/api/v1/jobs").await, 200).await, jobs_before, "no job created");
}

#[tokio::test(flavor = "multi_thread")]
async fn path_given_as_gcode_text() {
    let app = kerf_tests::TestApp::spawn().await;
    let mut body = serde_json::json!({
        "tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "path": {"gcode": "G21 G90 G17\nG0 X-10 Y20\nG1 X70 F600\nM30\n"},
        "spindle_rpm": 3000, "feed_per_tooth": 0.05, "flute_counts": [2, 4]});
    let answer = kerf_tests::json_with(app.post_json("/api/v1/engagement", &body).await, 200).await;
    let straight = answer["samples"].as_array().unwrap();
    assert!(straight.iter().any(|s| s["engaged_deg"].as_f64().unwrap() > 179.0), "a full slot through the block");
    assert!(straight.iter().all(|s| s["segment"] == 3), "samples name the program line");
    body["path"] = serde_json::json!({"gcode": "G21 G90\nG0 X-10 Y20\nG1 X70 Y# F600\n"});
    let problem = kerf_tests::problem(app.post_json("/api/v1/engagement", &body).await, 422).await;
    assert_eq!(problem["errors"][0]["path"], "path.gcode");
    assert!(problem["detail"].as_str().unwrap().contains("line 3"), "{problem}");
}

// ---------------------------------------------------------------- cutting physics

#[tokio::test(flavor = "multi_thread")]
async fn kienzle_torque_and_power_against_the_machines_spindle() {
    let app = TestApp::spawn().await;
    let machine = json!({"block_time_ms": 4, "max_feed": 12000, "spindle_power_kw": 0.05, "spindle_torque_nm": 100});
    json_with(app.put_json("/api/v1/machines/small-spindle", &machine).await, 201).await;
    let request = json!({
        "tool": {"kind": "flat", "radius": 5, "flutes": 4}, "spindle_rpm": 8000, "feed_per_tooth": 0.05,
        "flute_counts": [2, 4], "axial_depth": 2, "kienzle": {"kc11": 1800, "mc": 0.25},
        "machine": "small-spindle",
        "stock": {"polygon": [[0, 0], [100, 0], [100, 80], [0, 80]]},
        "path": [[-10, 40], [110, 40]]
    });
    let answer = json_with(app.post_json("/api/v1/engagement", &request).await, 200).await;
    let flutes = answer["flutes"].as_array().unwrap();
    for entry in flutes {
        let torque = entry["mean_torque_nm"].as_f64().expect("mean torque");
        let power = entry["mean_power_kw"].as_f64().expect("mean power");
        assert!(torque > 0.0);
        // P = 2πNM/60, in kW.
        let expected = 2.0 * std::f64::consts::PI * 8000.0 * torque / 60.0 / 1000.0;
        assert!((power - expected).abs() <= 1e-9 * expected.max(1.0), "{power} vs {expected}");
    }
    let codes: Vec<&str> = answer["warnings"].as_array().unwrap().iter().map(|w| w["code"].as_str().unwrap()).collect();
    assert!(codes.contains(&"W_SPINDLE_POWER"), "the 0.05 kW spindle is exceeded: {codes:?}");
    // Without the machine no limit applies; a bad limit on a machine is refused at its field.
    let mut unlimited = request.clone();
    unlimited.as_object_mut().unwrap().remove("machine");
    let answer = json_with(app.post_json("/api/v1/engagement", &unlimited).await, 200).await;
    assert!(!answer["warnings"].to_string().contains("W_SPINDLE_POWER"));
    let bad = json!({"block_time_ms": 4, "max_feed": 12000, "spindle_power_kw": -1});
    let problem = problem(app.put_json("/api/v1/machines/bad-spindle", &bad).await, 422).await;
    assert_eq!(problem["errors"][0]["path"], "spindle_power_kw");
}

/// Candidate paths at different depths: each answer and program uses its own a_p.
#[tokio::test(flavor = "multi_thread")]
async fn each_candidate_path_may_give_its_own_axial_depth() {
    let app = TestApp::spawn().await;
    let request = json!({
        "tool": {"kind": "flat", "radius": 5, "flutes": 4}, "spindle_rpm": 8000, "feed_per_tooth": 0.05,
        "flute_counts": [4], "axial_depth": 2, "kienzle": {"kc11": 1800, "mc": 0.25},
        "stock": {"polygon": [[0, 0], [100, 0], [100, 80], [0, 80]]},
        "paths": [
            {"name": "full depth in one pass", "path": [[-10, 40], [110, 40]], "axial_depth": 6},
            {"name": "the request's depth", "path": [[-10, 40], [110, 40]]}
        ]
    });
    let answer = json_with(app.post_json(URL, &request).await, 200).await;
    let candidates = answer["candidates"].as_array().unwrap();
    let torque = |c: &Value| c["flutes"][0]["mean_torque_nm"].as_f64().unwrap();
    assert_eq!(candidates[0]["forces"]["axial_depth"], 6.0);
    assert_eq!(candidates[1]["forces"]["axial_depth"], 2.0);
    close_rel(
        "three times the depth, three times the torque",
        torque(&candidates[0]),
        3.0 * torque(&candidates[1]),
        1e-12,
    );
    for (candidate, z) in [(0, "Z-6.0000"), (1, "Z-2.0000")] {
        let url = app.url(&format!("{URL}?format=gcode&candidate={candidate}"));
        let program = app.client.post(url).json(&request).send().await.unwrap().text().await.unwrap();
        assert!(program.contains(z), "candidate {candidate} cuts at {z}: {program}");
    }
    let mut bad = request.clone();
    bad["paths"][0]["axial_depth"] = json!(-6);
    let problem = problem(app.post_json(URL, &bad).await, 422).await;
    assert_eq!(problem["errors"][0]["path"], "paths[0].axial_depth");
}

/// A machine's power curve: at a low spindle speed the power it gives there, not its rating,
/// limits the cut, and the capped feed plan brings the path's power under it.
#[tokio::test(flavor = "multi_thread")]
async fn the_power_curve_limits_the_cut_at_its_speed() {
    let app = TestApp::spawn().await;
    // 0.5 kW at standstill rising to 8 kW at 4000 rpm: 1.4375 kW available at 500 rpm.
    let machine = json!({"block_time_ms": 4, "max_feed": 20000, "spindle_power_kw": 8,
                         "spindle_power_curve": [[0, 0.5], [4000, 8.0], [12000, 8.0]]});
    json_with(app.put_json("/api/v1/machines/s1-curve", &machine).await, 201).await;
    let request = json!({
        "tool": {"kind": "flat", "radius": 8, "flutes": 4}, "spindle_rpm": 500, "feed_per_tooth": 0.3,
        "flute_counts": [4], "axial_depth": 10, "material": "42CrMo4", "machine": "s1-curve",
        "stock": {"polygon": [[0, 0], [100, 0], [100, 80], [0, 80]]},
        "path": [[-10, 40], [110, 40]],
        "feed_plan": {"target_thickness": 1.0, "max_feed": 20000, "flute_count": 4}
    });
    let answer = json_with(app.post_json(URL, &request).await, 200).await;
    let available = 0.5 + 7.5 * 500.0 / 4000.0;
    close_rel("power available at 500 rpm", answer["forces"]["spindle_power_kw"].as_f64().unwrap(), available, 1e-12);
    let power = answer["flutes"][0]["mean_power_kw"].as_f64().unwrap();
    assert!(power > available && power < 8.0, "over the curve, under the rating: {power} kW");
    assert!(answer["warnings"].to_string().contains("W_SPINDLE_POWER"), "{}", answer["warnings"]);
    let blocks = answer["feed_plan"]["blocks"].as_array().unwrap();
    let cutting: Vec<&Value> = blocks.iter().filter(|b| b["limited_by"] == "power").collect();
    assert!(!cutting.is_empty(), "{blocks:?}");
    // The slowest power-limited feed, run as a constant feed, stays under the curve's power.
    let feed = cutting.iter().map(|b| b["feed"].as_f64().unwrap()).fold(f64::INFINITY, f64::min);
    let mut capped = request.clone();
    let body = capped.as_object_mut().unwrap();
    body.remove("feed_per_tooth");
    body.remove("feed_plan");
    body.insert("feed".to_owned(), json!(feed));
    let answer = json_with(app.post_json(URL, &capped).await, 200).await;
    // The highest phase-mean power of any sample (the path's mean is lower: entry and exit).
    let samples = answer["samples"].as_array().unwrap();
    let power = samples.iter().filter_map(|s| s["power_kw"][0].as_f64()).fold(0.0, f64::max);
    assert!(power <= available && power > 0.99 * available, "capped: {power} kW of {available}");
    assert!(!answer["warnings"].to_string().contains("W_SPINDLE_POWER"));

    let bad = json!({"block_time_ms": 4, "max_feed": 12000, "spindle_power_curve": [[0, 1], [5000, 4], [4000, 5]]});
    let problem = problem(app.put_json("/api/v1/machines/bad-curve", &bad).await, 422).await;
    assert_eq!(problem["errors"][0]["path"], "spindle_power_curve[2][0]");
}

/// Each straight feed move of `program` (G01, modal coordinates and feed) as its start, end and
/// feed (the engagement programs here write arcs as chords).
fn feed_moves(program: &str) -> Vec<([f64; 3], [f64; 3], f64)> {
    let (mut at, mut feed, mut moves) = ([0.0; 3], 0.0, Vec::new());
    for line in program.lines() {
        let from = at;
        let words: Vec<&str> = line.split_whitespace().collect();
        let Some(&motion) = words.first() else { continue };
        for word in &words[1..] {
            let (axis, value) = word.split_at(1);
            let Ok(value) = value.parse::<f64>() else { continue };
            match axis {
                "X" => at[0] = value,
                "Y" => at[1] = value,
                "Z" => at[2] = value,
                "F" => feed = value,
                _ => {}
            }
        }
        assert!(!["G02", "G03"].contains(&motion), "{line}");
        if motion == "G01" {
            moves.push((from, at, feed));
        }
    }
    moves
}

/// Distance in the plan from `p` to the rectangle `[x0, x1] × [y0, y1]` (0 inside).
fn rectangle_distance(p: [f64; 3], [x0, y0, x1, y1]: [f64; 4]) -> f64 {
    let dx = (x0 - p[0]).max(p[0] - x1).max(0.0);
    let dy = (y0 - p[1]).max(p[1] - y1).max(0.0);
    dx.hypot(dy)
}

/// Distance in the plan from the move `from → to` to the rectangle (sampled every 0.01 mm).
fn move_distance(from: [f64; 3], to: [f64; 3], rectangle: [f64; 4]) -> f64 {
    let length = (to[0] - from[0]).hypot(to[1] - from[1]);
    let steps = (length / 0.01).ceil().max(1.0) as usize;
    (0..=steps)
        .map(|i| {
            let t = i as f64 / steps as f64;
            let p = [from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1]), 0.0];
            rectangle_distance(p, rectangle)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The largest feed of any program move that comes within the tool radius of the stock (ends
/// there or passes there) is the planned cutting feed: air moves run at the programmed feed, not
/// at the machine's maximum up to where the cutter touches; with a machine of 12 000 mm/min and a
/// 10 N·m spindle, with and without a feed plan.
#[tokio::test(flavor = "multi_thread")]
async fn no_move_reaches_the_stock_faster_than_the_planned_feed() {
    let app = TestApp::spawn().await;
    let machine = json!({"block_time_ms": 4, "max_feed": 12000, "spindle_torque_nm": 10});
    json_with(app.put_json("/api/v1/machines/vmc-12k", &machine).await, 201).await;
    let stock = [0.0, 0.0, 60.0, 40.0];
    let radius = 5.0;
    let mut body = api_example();
    body["axial_depth"] = json!(2);
    body["kienzle"] = json!({"kc11": 1800, "mc": 0.25});
    body["machine"] = json!("vmc-12k");
    body["feed_plan"] = json!({"target_thickness": 0.05});
    for plan in [true, false] {
        if !plan {
            body.as_object_mut().unwrap().remove("feed_plan");
        }
        let answer = json_with(app.post_json(URL, &body).await, 200).await;
        let samples = answer["samples"].as_array().unwrap();
        let in_contact = |from: f64, to: f64| {
            samples.iter().any(|sample| {
                let s = number(&sample["s"]);
                s > from && s <= to && !sample["arcs"].as_array().unwrap().is_empty()
            })
        };
        let planned = if plan {
            let blocks = answer["feed_plan"]["blocks"].as_array().unwrap();
            blocks
                .iter()
                .filter(|b| in_contact(number(&b["from_s"]), number(&b["to_s"])))
                .map(|b| number(&b["feed"]))
                .fold(0.0, f64::max)
        } else {
            number(&answer["program_flute_count"]) * 0.05 * 3000.0
        };
        let program = app.post_text(&format!("{URL}?format=gcode"), &body, 200).await;
        let near: Vec<([f64; 3], f64)> = feed_moves(&program)
            .into_iter()
            .filter(|(from, to, _)| move_distance(*from, *to, stock) <= radius * (1.0 + 1e-9))
            .map(|(_, to, feed)| (to, feed))
            .collect();
        assert!(!near.is_empty(), "{program}");
        let (end, fastest) = near.iter().copied().fold(([0.0; 3], 0.0), |a, b| if b.1 > a.1 { b } else { a });
        assert!(
            (fastest - planned).abs() < 1.0,
            "feed plan {plan}: a move to {end:?} runs at F{fastest}, the planned cutting feed is {planned}:\n{program}"
        );
        // The program is for the recommended flute count, which holds the machine's torque.
        let recommended = answer["recommended"].as_array().unwrap();
        let flutes = answer["flutes"].as_array().unwrap();
        for k in recommended {
            let flute = flutes.iter().find(|f| f["flute_count"] == *k).unwrap();
            assert!(flute.get("over_limits").is_none(), "{flute}");
        }
        if let Some(best) = recommended.first() {
            assert_eq!(answer["program_flute_count"], *best);
            assert!(program.to_lowercase().contains(&format!("feeds for {best} flutes")), "{program}");
        }
    }
}

/// The docs/spec/api.md example cut 2 deep, with `tool`.
fn slot_request(tool: Value) -> Value {
    json!({"tool": tool, "stock": {"polygon": [[0,0],[60,0],[60,40],[0,40]]}, "path": [[-10,20],[70,20]],
           "spindle_rpm": 3000, "feed_per_tooth": 0.05, "axial_depth": 2})
}

#[tokio::test(flavor = "multi_thread")]
async fn the_program_is_cut_on_the_stock_extruded_and_a_holder_in_it_found_at_its_lines() {
    let app = TestApp::spawn().await;
    let answer = json_with(app.post_json(URL, &slot_request(json!({"kind": "flat", "radius": 5}))).await, 200).await;
    let verification = &answer["verification"];
    assert_eq!(verification["ok"], true, "{verification}");
    close_rel("removed volume", number(&verification["removed_volume_mm3"]), 1200.0, 0.03);

    // The holder 1.5 mm above the tip, 2 deep: in the stock on the plunge, the cut and the retract.
    let body = slot_request(json!({"kind": "flat", "radius": 5, "stickout": 1.5}));
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    let verification = &answer["verification"];
    assert_eq!(verification["ok"], false);
    let findings = verification["findings"].as_array().unwrap();
    assert!(!findings.is_empty() && findings.iter().all(|f| f["kind"] == "holder_contact"), "{verification}");
    assert!(answer["warnings"].as_array().unwrap().iter().any(|w| w["code"] == "W_VERIFY_HOLDER_CONTACT"));
    let program = app.post_text(&format!("{URL}?format=gcode&dialect=fanuc"), &body, 200).await;
    let lines: Vec<&str> = program.lines().collect();
    assert!(program.contains("(WARNING VERIFICATION FOUND"), "{program}");
    for finding in findings {
        let line = finding["line"].as_u64().unwrap() as usize;
        assert!(program.contains(&format!("(WARNING HOLDER CONTACT AT LINE {line}: ")), "{program}");
        assert!(lines[line - 1].starts_with("G0"), "line {line}: {program}");
    }
    // The tool gives its stickout but not its holder's diameter: the contact is said to be found
    // with an assumed holder (three shank diameters), in the answer, its warning and the header.
    let assumed = "the tool: the holder 30.000 mm across assumed (the tool gives no holder_diameter)";
    assert_eq!(verification["assumed"], json!([assumed]), "{verification}");
    let warning =
        answer["warnings"].as_array().unwrap().iter().find(|w| w["code"] == "W_VERIFY_HOLDER_CONTACT").unwrap();
    assert!(warning["message"].as_str().unwrap().ends_with(&format!("; {assumed}")), "{warning}");
    assert!(program.contains("(WARNING THE TOOL: THE HOLDER 30.000 MM ACROSS ASSUMED "), "{program}");
    let mut given = body.clone();
    given["tool"]["holder_diameter"] = json!(30);
    let answer = json_with(app.post_json(URL, &given).await, 200).await;
    assert!(answer["verification"].get("assumed").is_none(), "{}", answer["verification"]);
    // The same contacts, one line earlier: the header has no line on the holder.
    let positions = |findings: &Value| -> Vec<(Value, u64)> {
        findings.as_array().unwrap().iter().map(|f| (f["position"].clone(), f["line"].as_u64().unwrap())).collect()
    };
    let earlier: Vec<(Value, u64)> =
        positions(&verification["findings"]).into_iter().map(|(p, l)| (p, l - 1)).collect();
    assert_eq!(positions(&answer["verification"]["findings"]), earlier);
    let program = app.post_text(&format!("{URL}?format=gcode&dialect=fanuc"), &given, 200).await;
    assert!(program.contains("(WARNING VERIFICATION FOUND") && !program.contains("ASSUMED"), "{program}");
    // Without either, both are said; a tool that gives no lengths cutting in the open says it
    // assumed them, but no warning does.
    let open = json_with(app.post_json(URL, &slot_request(json!({"kind": "flat", "radius": 5}))).await, 200).await;
    assert_eq!(
        open["verification"]["assumed"],
        json!([
            "the tool: the holder face 40.000 mm above the tip and the holder 30.000 mm across assumed (the tool gives no stickout or holder_diameter)"
        ])
    );
    assert!(!open["warnings"].to_string().contains("assumed"), "{}", open["warnings"]);

    let mut fine = body.clone();
    fine["verification"] = json!({"resolution": 0.0005});
    let refused = problem(app.post_json(URL, &fine).await, 422).await;
    assert_eq!(refused["code"], "E_GRID_MEMORY");
    assert_eq!(refused["errors"][0]["path"], "verification.resolution");
}

/// The candidate a program is asked for is the one cut: of two paths, the deep one puts the
/// holder in the stock, and its program says so whichever candidate the request itself names.
#[tokio::test(flavor = "multi_thread")]
async fn the_candidate_programmed_is_the_candidate_verified() {
    let app = TestApp::spawn().await;
    let mut body = slot_request(json!({"kind": "flat", "radius": 5, "stickout": 4}));
    body.as_object_mut().unwrap().remove("path");
    body["paths"] = json!([
        {"name": "2 deep", "path": [[-10, 20], [70, 20]]},
        {"name": "6 deep", "path": [[-10, 20], [70, 20]], "axial_depth": 6},
    ]);
    let answer = json_with(app.post_json(URL, &body).await, 200).await;
    assert_eq!(answer["verification"]["ok"], true, "candidate 0 is the one verified: {}", answer["verification"]);
    let shallow = app.post_text(&format!("{URL}?format=gcode&candidate=0"), &body, 200).await;
    assert!(!shallow.contains("WARNING") && shallow.contains("Z-2.0000"), "{shallow}");

    let deep = app.post_text(&format!("{URL}?format=gcode&candidate=1"), &body, 200).await;
    assert!(deep.contains("Z-6.0000"), "{deep}");
    assert!(deep.contains("(WARNING VERIFICATION FOUND"), "the deep path's holder contact: {deep}");
    let lines: Vec<&str> = deep.lines().collect();
    let mut named = body.clone();
    named["candidate"] = json!(1);
    let answer = json_with(app.post_json(URL, &named).await, 200).await;
    let findings = answer["verification"]["findings"].as_array().unwrap();
    assert!(!findings.is_empty() && findings.iter().all(|f| f["kind"] == "holder_contact"), "{answer}");
    for finding in findings {
        let line = finding["line"].as_u64().unwrap() as usize;
        assert!(deep.contains(&format!("(WARNING HOLDER CONTACT AT LINE {line}: ")), "{deep}");
        assert!(lines[line - 1].contains("Z-6.0000") || lines[line - 1].starts_with("G0"), "line {line}: {deep}");
    }
    // The same program from the request naming the candidate, from the program route, and for
    // candidate 0 from a request naming 1.
    assert_eq!(app.post_text(&format!("{URL}?format=gcode"), &named, 200).await, deep);
    assert_eq!(app.post_text(&format!("{URL}/program?candidate=1"), &body, 200).await, deep);
    assert_eq!(app.post_text(&format!("{URL}?format=gcode&candidate=0"), &named, 200).await, shallow);

    // A candidate past the last path, in the request or the query, is refused before any work.
    for (request, query) in [(json!(2), ""), (json!(0), "?format=gcode&candidate=2")] {
        let mut missing = body.clone();
        missing["candidate"] = request;
        let refused = problem(app.post_json(&format!("{URL}{query}"), &missing).await, 422).await;
        assert_eq!(refused["code"], "E_INPUT");
        assert_eq!(refused["errors"][0]["path"], "candidate", "{refused}");
    }
}
