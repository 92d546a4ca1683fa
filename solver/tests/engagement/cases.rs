//! Every reference case of `solver/tests/fixtures/engagement.json` (copied to `tests/fixtures/`) to the
//! tolerances the fixture states: C1 (slot, then side milling), C2 part A (side-milling matrix)
//! and part B (inside corner, sharp and filleted), C3 (pair blocks and flute selection, also
//! with constant V_f); the exact engine everywhere, the dots engine where the fixture gives its
//! settings (C1, C3).

use kerf_cases::{case, close, fixture, number};
use std::collections::BTreeSet;

use kerf_solver::engagement::{
    self, EngagementRequest, EngagementSample, EngagementSolution, MillingMode, PathEngagement, SampleFlag,
};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

fn tool(diameter: f64) -> Tool {
    Tool::new(ToolKind::Flat, diameter / 2.0)
}

/// The API request for a fixture input block ([`kerf_cases::engagement::fixture_request`]; the
/// tool is passed to the solver apart).
fn request(stock: &Value, path: &Value, cutting: &Value, flutes: &Value, extra: Value) -> EngagementRequest {
    let body = kerf_cases::engagement::fixture_request(stock, path, cutting, flutes, 1.0);
    serde_json::from_value(kerf_cases::with(body, extra)).unwrap()
}

fn single(answer: EngagementSolution) -> PathEngagement {
    match answer {
        EngagementSolution::Single(result) => *result,
        EngagementSolution::Comparison(_) => panic!("expected a single-path answer"),
    }
}

fn solve(request: &EngagementRequest, diameter: f64) -> PathEngagement {
    single(engagement::solve(request, &tool(diameter)).unwrap())
}

fn sample_at(result: &PathEngagement, s: f64) -> &EngagementSample {
    result.samples.iter().find(|sample| (sample.s - s).abs() < 1e-6).unwrap_or_else(|| panic!("no sample at s = {s}"))
}

fn close_rel(what: &str, got: f64, expected: f64, relative: f64) {
    let tolerance = relative * expected.abs() + 1e-9;
    close(what, got, expected, tolerance);
}

fn mode_name(mode: MillingMode) -> &'static str {
    match mode {
        MillingMode::Slot => "full_slot",
        MillingMode::Climb => "down",
        MillingMode::Conventional => "up",
        MillingMode::Interior => "interior",
    }
}

fn flag_names(sample: &EngagementSample) -> BTreeSet<&'static str> {
    sample
        .flags
        .iter()
        .filter_map(|f| match f {
            SampleFlag::BurrRisk => Some("burr_risk"),
            SampleFlag::ChippingRisk => Some("chipping_risk"),
            _ => None,
        })
        .collect()
}

/// Exact-engine tolerances of the fixture.
struct Tolerances {
    angle: f64,
    ae: f64,
    h_rel: f64,
}

fn exact_tolerances() -> Tolerances {
    let t = &fixture("engagement")["tolerances"]["exact_engine"];
    Tolerances { angle: number(&t["angle_deg"]), ae: number(&t["ae_mm"]), h_rel: number(&t["H_rel"]) }
}

/// Compares one fixture checkpoint with the sample at its s.
fn check_point(label: &str, result: &PathEngagement, checkpoint: &Value, flutes: &[u32], tol: &Tolerances) {
    let s = number(&checkpoint["s"]);
    let sample = sample_at(result, s);
    let what = |field: &str| format!("{label} s={s} {field}");
    if let Some(pos) = checkpoint["pos"].as_array() {
        close(&what("x"), sample.position[0], number(&pos[0]), 1e-3);
        close(&what("y"), sample.position[1], number(&pos[1]), 1e-3);
    }
    let arcs = checkpoint["arcs"].as_array().unwrap();
    assert_eq!(sample.arcs.len(), arcs.len(), "{}: {:?}", what("arcs"), sample.arcs);
    for (got, expected) in sample.arcs.iter().zip(arcs) {
        close(&what("arc from"), got[0], number(&expected[0]), tol.angle);
        close(&what("arc to"), got[1], number(&expected[1]), tol.angle);
    }
    close(&what("engaged_deg"), sample.engaged_deg, number(&checkpoint["engaged_deg"]), 2.0 * tol.angle);
    close(&what("ae"), sample.radial_depth, number(&checkpoint["ae"]), tol.ae);
    let details = checkpoint["arc_details"].as_array().unwrap();
    assert_eq!(sample.arc_details.len(), details.len(), "{}", what("arc_details"));
    for (got, expected) in sample.arc_details.iter().zip(details) {
        close(&what("entry"), got.entry_deg, number(&expected["entry"]), tol.angle);
        close(&what("exit"), got.exit_deg, number(&expected["exit"]), tol.angle);
        close(&what("phi"), got.engage_deg, number(&expected["phi_engage"]), tol.angle);
        close(&what("psi"), got.disengage_deg, number(&expected["psi_disengage"]), tol.angle);
        // Ratios are printed to 4 decimals; 0.05° moves sin θ by at most 0.0009.
        close(&what("h_entry"), got.entry_thickness_ratio, number(&expected["h_entry_ratio"]), 1e-3);
        close(&what("h_exit"), got.exit_thickness_ratio, number(&expected["h_exit_ratio"]), 1e-3);
        assert_eq!(mode_name(got.mode), expected["mode"].as_str().unwrap(), "{}", what("mode"));
    }
    let flags: BTreeSet<&str> = checkpoint["flags"].as_array().unwrap().iter().map(|f| f.as_str().unwrap()).collect();
    assert_eq!(flag_names(sample), flags, "{}", what("flags"));
    for (column, k) in flutes.iter().enumerate() {
        let key = k.to_string();
        close_rel(
            &what(&format!("H k={k}")),
            sample.thickness[column],
            number(&checkpoint["H_mm_by_k"][&key]),
            tol.h_rel,
        );
        assert_eq!(
            u64::from(sample.teeth[column]),
            checkpoint["n_max_by_k"][&key].as_u64().unwrap(),
            "{}",
            what(&format!("n_max k={k}"))
        );
    }
}

fn flute_list(value: &Value) -> Vec<u32> {
    value.as_array().unwrap().iter().map(|k| u32::try_from(k.as_u64().unwrap()).unwrap()).collect()
}

fn recommended_set(result: &PathEngagement) -> BTreeSet<u32> {
    result.recommended.iter().copied().collect()
}

fn expected_set(value: &Value) -> BTreeSet<u32> {
    flute_list(value).into_iter().collect()
}

fn check_statistics(label: &str, result: &PathEngagement, expected: &Value, max_rel: f64, mean_rel: f64) {
    for flute in &result.flutes {
        let key = flute.flute_count.to_string();
        let row = &expected[&key];
        close_rel(&format!("{label} max k={key}"), flute.max_thickness, number(&row["max"]), max_rel);
        close_rel(&format!("{label} mean k={key}"), flute.mean_thickness, number(&row["mean"]), mean_rel);
        // Sampling-dependent: only the ordering is checked (fixture "min_and_median").
        assert!(flute.min_thickness <= flute.mean_thickness && flute.mean_thickness <= flute.max_thickness);
        assert!((flute.min_thickness..=flute.max_thickness).contains(&flute.median_thickness));
    }
}

fn check_intervals(label: &str, got: &[[f64; 2]], expected: &[[f64; 2]], tolerance: f64) {
    let tolerance = tolerance + 1e-9;
    assert_eq!(got.len(), expected.len(), "{label}: {got:?}");
    for (g, e) in got.iter().zip(expected) {
        close(&format!("{label} from"), g[0], e[0], tolerance);
        close(&format!("{label} to"), g[1], e[1], tolerance);
    }
}

// ---------------------------------------------------------------- C1

fn c1_request(engine: &str) -> (EngagementRequest, Value) {
    let c = case("engagement", "C1");
    let input = &c["input"];
    let sim = &input["simulation"];
    let extra = if engine == "dots" {
        json!({"engine": "dots", "grid": sim["dot_engine"]["grid"], "step": sim["dot_engine"]["ds"],
               "thickness_limit": input["evaluation"]["T1_mm"], "time_limit_s": input["evaluation"]["T2_s"]})
    } else {
        json!({"step": sim["ds"], "thickness_limit": input["evaluation"]["T1_mm"],
               "time_limit_s": input["evaluation"]["T2_s"]})
    };
    let request =
        request(&input["stock"], &input["path"], &input["cutting"], &input["tool"]["flute_candidates"], extra);
    (request, c)
}

#[test]
fn c1_exact_engine() {
    let (request, c) = c1_request("exact");
    let expected = &c["expected"];
    let result = solve(&request, 10.0);
    let flutes = flute_list(&c["input"]["tool"]["flute_candidates"]);
    close("path length", result.path_length, number(&expected["path_length"]), 1e-9);
    let tol = exact_tolerances();
    // s = 71.25 lies off the 0.1 mm grid: the checkpoints are read from a 0.05 mm run.
    let mut fine = request.clone();
    fine.step = Some(0.05);
    let fine_result = solve(&fine, 10.0);
    for checkpoint in expected["checkpoints"].as_array().unwrap() {
        check_point("C1", &fine_result, checkpoint, &flutes, &tol);
    }
    check_statistics("C1", &result, &expected["representative_mm"], 0.002, 0.01);
    for flute in &result.flutes {
        let key = flute.flute_count.to_string();
        close_rel(&format!("time k={key}"), flute.time_s, number(&expected["machining_time_s"][&key]), 1e-4);
    }
    assert_eq!(recommended_set(&result), expected_set(&expected["recommended_flutes"]));
    // Fastest first.
    assert_eq!(result.recommended, vec![4, 3]);
    let continuum: Vec<[f64; 2]> = expected["engaged_intervals_s_continuum_open"]
        .as_array()
        .unwrap()
        .iter()
        .map(|i| [number(&i[0]), number(&i[1])])
        .collect();
    check_intervals("C1 engaged", &result.engaged_intervals, &continuum, number(&c["input"]["simulation"]["ds"]));
    // The full-slot samples carry the closed-form table of §5.6.
    let slot = sample_at(&result, 30.0);
    for (column, k) in flutes.iter().enumerate() {
        close_rel(
            &format!("slot H/fz k={k}"),
            slot.thickness[column] / 0.05,
            number(&expected["slot_closed_form_H_over_fz"][k.to_string()]),
            1e-6,
        );
    }
    let codes: Vec<&str> = result.warnings.iter().map(|w| w.code).collect();
    assert!(codes.contains(&"W_FULL_IMMERSION") && codes.contains(&"W_MULTI_ARC"), "{codes:?}");
    assert!(!codes.contains(&"W_PLUNGE"), "{codes:?}");
}

/// a_e of C1 in closed form (the fixture's phase table), R = 5.
fn c1_radial_depth(s: f64) -> f64 {
    let r: f64 = 5.0;
    if s <= 70.0 {
        let x = s - 10.0;
        if !(-5.0..=50.0).contains(&x) {
            0.0
        } else if x < 0.0 {
            2.0 * (r * r - x * x).sqrt()
        } else if x <= 45.0 {
            10.0
        } else {
            2.0 * (r - (r * r - (50.0 - x).powi(2)).sqrt())
        }
    } else if s <= 72.5 {
        0.0
    } else {
        let x = 60.0 - (s - 72.5);
        // The return pass reaches the wall side at X = 50 + R·cos 30°.
        let entry_end = 50.0 + r * 30.0_f64.to_radians().cos();
        let exit_start = r * 30.0_f64.to_radians().cos();
        if x > entry_end || x < 0.0 {
            0.0
        } else if x >= 50.0 {
            r * (((x - 50.0) / r).asin().cos() - 0.5)
        } else if x >= exit_start {
            2.5
        } else {
            r - (r * r - x * x).sqrt()
        }
    }
}

#[test]
fn c1_dots_engine() {
    let (request, c) = c1_request("dots");
    let expected = &c["expected"];
    let result = solve(&request, 10.0);
    let dots = &fixture("engagement")["tolerances"]["dot_engine"];
    let grid = number(&c["input"]["simulation"]["dot_engine"]["grid"]);
    let step = number(&c["input"]["simulation"]["dot_engine"]["ds"]);
    check_statistics(
        "C1 dots",
        &result,
        &expected["representative_mm"],
        number(&dots["representative_max_rel"]),
        number(&dots["representative_mean_rel"]),
    );
    assert_eq!(recommended_set(&result), expected_set(&expected["recommended_flutes"]));
    // a_e within 2g of the continuum somewhere in [s − Δs − g, s + g] (one step of lag).
    let ae_tolerance = 2.0 * grid;
    for sample in result.samples.iter().skip(1) {
        let window = (0..=200).map(|i| sample.s - step - grid + (step + 2.0 * grid) * f64::from(i) / 200.0);
        let best = window.map(|s| (c1_radial_depth(s) - sample.radial_depth).abs()).fold(f64::INFINITY, f64::min);
        assert!(best <= ae_tolerance, "dots a_e at s = {}: {} (off by {best})", sample.s, sample.radial_depth);
    }
    // Steady phases: H within the dots engine's H tolerance.
    let h_rel = number(&dots["H_rel"]);
    let flutes = flute_list(&c["input"]["tool"]["flute_candidates"]);
    for checkpoint in expected["checkpoints"].as_array().unwrap() {
        let s = number(&checkpoint["s"]);
        if ![30.0, 100.0].contains(&s) {
            continue;
        }
        let sample = sample_at(&result, s);
        for (column, k) in flutes.iter().enumerate() {
            close_rel(
                &format!("dots s={s} H k={k}"),
                sample.thickness[column],
                number(&checkpoint["H_mm_by_k"][k.to_string()]),
                h_rel,
            );
        }
    }
    let grid_info = result.grid.as_ref().unwrap();
    assert!((grid_info.cell - grid).abs() < 1e-12);
    assert!(!result.contact_dots.as_ref().unwrap().is_empty());
}

// ---------------------------------------------------------------- C2

#[test]
fn c2_part_a_side_milling_matrix() {
    let c = case("engagement", "C2");
    let part = &c["part_A"];
    let input = &part["input"];
    let flutes = flute_list(&input["tool"]["flute_candidates"]);
    let tol = exact_tolerances();
    for row in part["rows"].as_array().unwrap() {
        let request = request(
            &input["stock"],
            &row["path"],
            &input["cutting"],
            &input["tool"]["flute_candidates"],
            json!({"step": input["simulation"]["ds"]}),
        );
        let result = solve(&request, 10.0);
        let label = format!("C2A ae={} {}", row["ae"], row["side"].as_str().unwrap());
        let mut checkpoint = row.clone();
        checkpoint["s"] = row["checkpoint_s"].clone();
        checkpoint["ae"] = row["ae_measured"].clone();
        checkpoint["arc_details"] = json!([{
            "entry": row["entry"], "exit": row["exit"], "phi_engage": row["phi_engage"],
            "psi_disengage": row["psi_disengage"], "h_entry_ratio": row["h_entry_ratio"],
            "h_exit_ratio": row["h_exit_ratio"], "mode": row["mode"]
        }]);
        check_point(&label, &result, &checkpoint, &flutes, &tol);
        let sample = sample_at(&result, number(&row["checkpoint_s"]));
        close_rel(
            &format!("{label} mean chip thickness"),
            sample.mean_chip_thickness,
            number(&row["mean_chip_thickness_mm"]),
            1e-3,
        );
    }
}

#[test]
fn c2_part_b_inside_corner() {
    let c = case("engagement", "C2");
    let part = &c["part_B"];
    let input = &part["input"];
    let flutes = flute_list(&input["tool"]["flute_candidates"]);
    let step = number(&input["simulation"]["ds"]);
    let tol = exact_tolerances();
    for name in ["sharp", "fillet3"] {
        let expected = &part["expected"][name];
        let request = request(
            &input["stock"],
            &input["paths"][name],
            &input["cutting"],
            &input["tool"]["flute_candidates"],
            json!({"step": step, "spike_threshold_deg": 5.0}),
        );
        let result = solve(&request, 10.0);
        let label = format!("C2B {name}");
        close(&format!("{label} length"), result.path_length, number(&expected["path_length"]), 1e-4);
        for checkpoint in expected["checkpoints"].as_array().unwrap() {
            check_point(&label, &result, checkpoint, &flutes, &tol);
        }
        close(
            &format!("{label} max engaged"),
            result.max_engaged_deg,
            number(&expected["max_engaged_deg"]),
            2.0 * tol.angle,
        );
        let at = expected.get("max_engaged_at_s").or_else(|| expected.get("max_engaged_at_s_approx")).unwrap();
        close(&format!("{label} max engaged at"), result.max_engaged_at_s, number(at), 0.1 + step);
        if let Some(max_ae) = expected.get("max_ae") {
            close(&format!("{label} max ae"), result.max_radial_depth, number(max_ae), tol.ae);
        } else {
            let at_peak = sample_at(&result, result.max_engaged_at_s).radial_depth;
            close(&format!("{label} ae at max engagement"), at_peak, number(&expected["max_ae_at_that_s"]), tol.ae);
        }
        for flute in &result.flutes {
            let key = flute.flute_count.to_string();
            close_rel(
                &format!("{label} H max k={key}"),
                flute.max_thickness,
                number(&expected["H_max_mm_by_k_over_path"][&key]),
                tol.h_rel,
            );
        }
        let codes: Vec<&str> = result.warnings.iter().map(|w| w.code).collect();
        if name == "sharp" {
            assert!(codes.contains(&"W_VERTEX") && codes.contains(&"W_ENGAGEMENT_SPIKE"), "{codes:?}");
        }
    }
}

// ---------------------------------------------------------------- C3

fn c3_request(cutting: &Value, limits: Value, engine: Option<(f64, f64)>) -> (EngagementRequest, Value) {
    let c = case("engagement", "C3");
    let input = &c["input"];
    let mut extra = limits;
    match engine {
        Some((grid, step)) => {
            extra["engine"] = json!("dots");
            extra["grid"] = json!(grid);
            extra["step"] = json!(step);
        }
        None => extra["step"] = input["simulation"]["ds"].clone(),
    }
    let request = request(&input["stock"], &input["path"], cutting, &input["tool"]["flute_candidates"], extra);
    (request, c)
}

#[test]
fn c3_exact_engine_constant_fz() {
    let c = case("engagement", "C3");
    let input = &c["input"];
    let expected = &c["expected"];
    let limits = json!({"thickness_limit": input["evaluation"]["T1_mm"], "time_limit_s": input["evaluation"]["T2_s"]});
    let (request, _) = c3_request(&input["cutting"], limits, None);
    let result = solve(&request, 20.0);
    let flutes = flute_list(&input["tool"]["flute_candidates"]);
    let tol = exact_tolerances();
    close("C3 length", result.path_length, number(&expected["path_length"]), 1e-9);
    for checkpoint in expected["checkpoints"].as_array().unwrap() {
        check_point("C3", &result, checkpoint, &flutes, &tol);
    }
    let fz = number(&input["cutting"]["fz"]);
    for flute in &result.flutes {
        let key = flute.flute_count.to_string();
        close_rel(
            &format!("C3 H/fz k={key}"),
            flute.max_thickness / fz,
            number(&expected["H_over_fz_max_by_k"][&key]),
            tol.h_rel,
        );
        assert_eq!(
            u64::from(flute.max_teeth),
            expected["n_max_by_k_over_path"][&key].as_u64().unwrap(),
            "C3 n_max k={key}"
        );
        close_rel(
            &format!("C3 time k={key}"),
            flute.time_s,
            number(&expected["machining_time_s_constant_fz"][&key]),
            1e-4,
        );
    }
    check_statistics("C3", &result, &expected["representative_mm_constant_fz"], 0.002, 0.01);
    assert_eq!(recommended_set(&result), expected_set(&expected["recommended_flutes_constant_fz"]));
    let mut continuum: Vec<[f64; 2]> = expected["engaged_intervals_s_continuum"]
        .as_object()
        .unwrap()
        .values()
        .map(|i| [number(&i[0]), number(&i[1])])
        .collect();
    continuum.sort_by(|a, b| a[0].total_cmp(&b[0]));
    check_intervals("C3 engaged", &result.engaged_intervals, &continuum, number(&input["simulation"]["ds"]));
    // Simultaneous cutting: k = 4 and 8 on b, 6 on c, 5/8/10 on a.
    for k in [4_u32, 5, 6, 8, 10] {
        let flute = result.flutes.iter().find(|f| f.flute_count == k).unwrap();
        assert!(!flute.multi_tooth_intervals.is_empty(), "k = {k}");
    }
}

#[test]
fn c3_exact_engine_constant_vf() {
    let c = case("engagement", "C3");
    let input = &c["input"];
    let expected = &c["expected"]["constant_vf_variant"];
    for (variant, key) in input["evaluation_variant_constant_vf"]
        .as_array()
        .unwrap()
        .iter()
        .zip(["recommended_T2_30", "recommended_T2_20"])
    {
        let limits = json!({"thickness_limit": variant["T1_mm"], "time_limit_s": variant["T2_s"]});
        let (request, _) = c3_request(&input["cutting_variant_constant_vf"], limits, None);
        let result = solve(&request, 20.0);
        for flute in &result.flutes {
            let k = flute.flute_count.to_string();
            let row = &expected["representative_mm"][&k];
            close_rel(&format!("vf fz k={k}"), flute.feed_per_tooth, number(&row["fz"]), 1e-5);
            close_rel(&format!("vf max k={k}"), flute.max_thickness, number(&row["max"]), 0.002);
            close_rel(&format!("vf mean k={k}"), flute.mean_thickness, number(&row["mean"]), 0.01);
            close_rel(&format!("vf time k={k}"), flute.time_s, number(&expected["machining_time_s_all_k"]), 1e-9);
        }
        assert_eq!(recommended_set(&result), expected_set(&expected[key]), "{key}");
        let no_recommendation = result.warnings.iter().find(|w| w.code == "W_NO_RECOMMENDATION");
        if key == "recommended_T2_20" {
            let message = &no_recommendation.expect("W_NO_RECOMMENDATION").message;
            assert!(message.contains("time 24") && message.contains("> 20 s"), "{message}");
        } else {
            assert!(no_recommendation.is_none());
        }
    }
}

#[test]
fn c3_dots_engine() {
    let c = case("engagement", "C3");
    let input = &c["input"];
    let expected = &c["expected"];
    let dots = &fixture("engagement")["tolerances"]["dot_engine"];
    let limits = json!({"thickness_limit": input["evaluation"]["T1_mm"], "time_limit_s": input["evaluation"]["T2_s"]});
    let settings = &input["simulation"]["dot_engine"];
    let (request, _) =
        c3_request(&input["cutting"], limits, Some((number(&settings["grid"]), number(&settings["ds"]))));
    let result = solve(&request, 20.0);
    check_statistics(
        "C3 dots",
        &result,
        &expected["representative_mm_constant_fz"],
        number(&dots["representative_max_rel"]),
        number(&dots["representative_mean_rel"]),
    );
    assert_eq!(recommended_set(&result), expected_set(&expected["recommended_flutes_constant_fz"]));
    let tolerance = number(&settings["ds"]) + number(&settings["grid"]);
    let mut continuum: Vec<[f64; 2]> = expected["engaged_intervals_s_continuum"]
        .as_object()
        .unwrap()
        .values()
        .map(|i| [number(&i[0]), number(&i[1])])
        .collect();
    continuum.sort_by(|a, b| a[0].total_cmp(&b[0]));
    check_intervals("C3 dots engaged", &result.engaged_intervals, &continuum, tolerance + number(&settings["ds"]));
}
