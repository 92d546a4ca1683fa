//! Every reference case of `solver/tests/fixtures/segment.json` (copied to `tests/fixtures/`): cases A, B
//! and C through the public segment API (points to 1e-6 mm, counts exactly, figures to their
//! printed precision), the fixed-tolerance baselines, the edge cases E1–E5 and the surface table
//! through [`BlockRule`], and the G-code head of case A.

use kerf_cases::{case, close, fixture, number};
use kerf_solver::gcode::{Dialect, Post, ToolCall};
use kerf_solver::machine::{BlockRule, ChordStatus};
use kerf_solver::segment::{self, CommandPoint, SegmentRequest, SegmentSolution, WindowStatus};
use serde_json::{Value, json};

const POINT_TOLERANCE: f64 = 1e-6;

fn solve(request: Value) -> SegmentSolution {
    let request: SegmentRequest = serde_json::from_value(request).unwrap();
    segment::solve(&request, None).unwrap()
}

fn check_points(what: &str, got: &[CommandPoint], expected: &Value) {
    let expected = expected.as_array().unwrap();
    assert_eq!(got.len(), expected.len(), "{what}: count");
    for (index, (point, want)) in got.iter().zip(expected).enumerate() {
        for axis in 0..2 {
            close(&format!("{what}[{index}][{axis}]"), point[axis], number(&want[axis]), POINT_TOLERANCE);
        }
    }
}

fn check_ends(answer: &SegmentSolution, expected: &Value) {
    let first = expected["first_points"].as_array().unwrap().len();
    let last = expected["last_points"].as_array().unwrap().len();
    check_points("first points", &answer.points[..first], &expected["first_points"]);
    check_points("last points", &answer.points[answer.points.len() - last..], &expected["last_points"]);
}

fn block_lengths(answer: &SegmentSolution) -> Vec<f64> {
    answer.points.windows(2).map(|pair| (pair[1][0] - pair[0][0]).hypot(pair[1][1] - pair[0][1])).collect()
}

fn circle_a() -> Value {
    json!({"kind": "circle", "centre": [0, 0], "radius": 50})
}

fn ellipse_bc() -> Value {
    json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 50], "start_deg": 0, "end_deg": 90})
}

#[test]
fn case_a_reproduces_the_patent_experiment() {
    let case = case("segment", "A");
    let expected = &case["expected"];
    let answer = solve(json!({
        "curve": circle_a(), "feed": 10000, "block_time_ms": 4, "mode": "window",
        "margin": 1.0, "min_chord_error": 0.0
    }));
    close("C_ep", answer.chord_error, number(&expected["Cep_mm"]), 1e-13);
    assert!(answer.windows.iter().all(|w| w.status == WindowStatus::Ok));
    assert_eq!(answer.stats.blocks, 472);
    assert_eq!(answer.points.len(), number(&expected["summary"]["points"]) as usize);
    check_ends(&answer, expected);
    let lengths = block_lengths(&answer);
    for (index, length) in lengths[..lengths.len() - 1].iter().enumerate() {
        close(&format!("chord {index}"), *length, number(&expected["chord_length_mm"]), 1e-9);
    }
    close("last chord", answer.stats.last_block_length, number(&expected["last_chord_mm"]), 1e-6);
    close("max chord", answer.stats.max_block_length, number(&expected["summary"]["max_chord_mm"]), 1e-9);
    close(
        "block-limited time",
        answer.stats.estimated_time_s,
        number(&expected["summary"]["est_time_s_block_limited"]),
        1e-9,
    );
    close("path time", answer.stats.path_time_s, number(&expected["summary"]["path_time_s_at_F"]), 1e-6);
    // The fixture counts the final remainder among its short blocks (index 471).
    assert_eq!(answer.stats.short_blocks, 0);
    assert_eq!(answer.stats.short_end_blocks, 1);
    // The greedy chord may use the 1e-12 mm slack of docs/spec/segment.md §2.9.
    close("max deviation", answer.max_deviation, number(&expected["Cep_mm"]), 2e-12);
    close("feed limit", answer.feed_limit.unwrap(), 150_000.0 * 10.0, 1e-6);
    let codes: Vec<_> = answer.warnings.iter().map(|w| w.code).collect();
    assert_eq!(codes, ["W_SHORT_LAST_BLOCK"]);
    assert!(answer.warnings[0].message.contains("closed"));
}

#[test]
fn case_a_in_every_curve_mode_gives_the_same_polygon() {
    let reference = solve(json!({"curve": circle_a(), "feed": 10000, "block_time_ms": 4}));
    for rule in ["max", "extremes"] {
        let answer = solve(json!({
            "curve": circle_a(), "feed": 10000, "block_time_ms": 4, "mode": "curve", "rule": rule
        }));
        assert_eq!(answer.stats.blocks, 472, "{rule}");
        assert_eq!(answer.windows.len(), 1);
        close(rule, answer.chord_error, reference.chord_error, 1e-15);
        check_points(rule, &answer.points, &serde_json::to_value(&reference.points).unwrap());
    }
}

#[test]
fn case_a_baselines() {
    let baselines = &case("segment", "A")["baselines"];
    for (key, tolerance) in [("fixed_0.01mm", 0.01), ("fixed_0.0005mm", 0.0005)] {
        let expected = &baselines[key];
        let answer = solve(json!({
            "curve": circle_a(), "feed": 10000, "block_time_ms": 4, "compare_tolerance": tolerance
        }));
        let comparison = answer.comparison.unwrap();
        assert_eq!(comparison.stats.blocks, number(&expected["blocks"]) as usize, "{key}");
        close(key, comparison.stats.max_block_length, number(&expected["chord_mm"]), 1e-9);
        close(
            key,
            comparison.stats.max_block_length / 10_000.0 * 60_000.0,
            number(&expected["time_per_block_ms"]),
            1e-6,
        );
        close(key, comparison.max_deviation, tolerance, 2e-12);
    }
    // 0.0005 mm starves the control on every block: the feed it can hold (E4), from the greedy
    // chord (which carries the 1e-12 mm slack) and from the closed form.
    let cap = number(&baselines["fixed_0.0005mm"]["feed_cap_by_block_time_mm_min"]);
    let answer = solve(json!({
        "curve": circle_a(), "feed": 10000, "block_time_ms": 4, "tolerance": 0.0005
    }));
    close("feed cap", answer.stats.max_block_length / 4.0 * 60_000.0, cap, 1e-6);
    close("tolerance feed", answer.tolerance_feed.unwrap(), cap, 1e-5);
    assert_eq!(answer.stats.blocks, 703);
    assert_eq!(answer.stats.short_blocks, 702);
    let codes: Vec<_> = answer.warnings.iter().map(|w| w.code).collect();
    assert!(codes.contains(&"W_CHORD_ERROR_EXCEEDS_TOLERANCE"), "{codes:?}");
    assert!(codes.contains(&"W_BLOCK_TIME_VIOLATION"), "{codes:?}");
    let advice = &answer.warnings.iter().find(|w| w.code == "W_CHORD_ERROR_EXCEEDS_TOLERANCE").unwrap().message;
    assert!(advice.contains("6708 mm/min"), "{advice}");
}

#[test]
fn case_a_gcode_head() {
    let answer = solve(json!({"curve": circle_a(), "feed": 10000, "block_time_ms": 4}));
    let program = segment::program(
        &answer,
        &Post {
            reference: kerf_solver::gcode::Reference::Tip,
            dialect: Dialect::Fanuc,
            tool: ToolCall::Table(1),
            arcs: kerf_solver::gcode::Arcs::Chords,
            plunge_feed: None,
            units: kerf_solver::units::Units::Mm,
        },
    )
    .unwrap();
    let case = case("segment", "A");
    let head: Vec<&str> =
        case["gcode_head_4_decimals"].as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    // The house post writes every line with its G word and Z; compare the coordinates.
    let lines: Vec<&str> = program.lines().collect();
    let start = lines.iter().position(|l| l.starts_with("G00 X50.0000 Y0.0000")).expect("rapid above the start");
    // The plunge to the start runs at half the feed (no plunge feed given); the first chord
    // carries the feed, as in the reference head.
    assert!(lines[start + 1].starts_with("G01 X50.0000 Y0.0000 Z0.0000 F5000"));
    assert_eq!(head[2], "G01 X49.9956 Y0.6667 F10000");
    assert_eq!(lines[start + 2], "G01 X49.9956 Y0.6667 Z0.0000 F10000");
    for (line, want) in lines[start + 3..].iter().zip(&head[3..]) {
        assert!(line.starts_with(&format!("G01 {want}")), "{line} vs {want}");
    }
    let feed_words = lines
        .iter()
        .filter(|l| {
            l.split(' ').any(|word| {
                word.strip_prefix('F')
                    .is_some_and(|value| !value.is_empty() && value.chars().all(|c| c.is_ascii_digit() || c == '.'))
            })
        })
        .count();
    assert_eq!(feed_words, 2);
    assert_eq!(lines.iter().filter(|l| l.starts_with("G01")).count(), 473);
}

#[test]
fn case_b_embodiment_4_on_the_quarter_ellipse() {
    let case = case("segment", "B");
    let expected = &case["expected"];
    let answer = solve(json!({
        "curve": ellipse_bc(), "feed": 10000, "block_time_ms": 4, "margin": 1.1,
        "mode": "curve", "rule": "extremes"
    }));
    close("C_ep", answer.chord_error, number(&expected["Cep_mm"]), 1e-13);
    close("r_min", answer.min_radius.unwrap(), number(&case["curve"]["r_min_mm"]), 1e-12);
    close("arc length", answer.curve_length, number(&case["curve"]["arc_length_mm"]), 1e-9);
    assert_eq!(answer.stats.blocks, number(&expected["blocks_total_greedy"]) as usize);
    check_ends(&answer, expected);
    let lengths = block_lengths(&answer);
    close("first chord", lengths[0], number(&expected["first_chord_mm"]), 1e-6);
    close(
        "shortest chord but the last",
        answer.stats.min_block_length,
        number(&expected["chord_min_mm_excluding_last"]),
        1e-6,
    );
    close("longest chord", answer.stats.max_block_length, number(&expected["chord_max_mm"]), 1e-6);
    close("last chord", answer.stats.last_block_length, number(&expected["last_chord_mm"]), 1e-6);
    close("max deviation", answer.max_deviation, number(&expected["max_deviation_mm"]), 1e-9);
    close("block-limited time", answer.stats.estimated_time_s, number(&expected["est_time_s_block_limited"]), 1e-9);
    assert_eq!(answer.stats.short_blocks, number(&expected["short_blocks_below_F_Tb"]) as usize);
    // The parameters t of the first points.
    for (point, t) in answer.points.iter().zip(expected["first_points_t_rad"].as_array().unwrap()) {
        let t = number(t);
        close("x(t)", point[0], 100.0 * t.cos(), 1e-6);
        close("y(t)", point[1], 50.0 * t.sin(), 1e-6);
    }
    // Eq. 15 variant.
    let eq15 = solve(json!({
        "curve": ellipse_bc(), "feed": 10000, "block_time_ms": 4, "margin": 1.1,
        "mode": "curve", "rule": "normal_accel"
    }));
    close("C_ep Eq. 15", eq15.chord_error, number(&expected["Cep_eq15_mm"]), 1e-13);
    // r_min read off the drawing gives the same value.
    let drawing = solve(json!({
        "curve": ellipse_bc(), "feed": 10000, "block_time_ms": 4, "margin": 1.1,
        "mode": "curve", "rule": "extremes", "min_radius": 25
    }));
    assert_eq!(drawing.points, answer.points);
}

#[test]
fn case_b_and_c_baselines() {
    for (id, feed) in [("B", 10_000.0), ("C", 12_000.0)] {
        let baselines = &case("segment", id)["baselines"];
        for (key, tolerance) in [("fixed_0.01mm", 0.01), ("fixed_0.001mm", 0.001)] {
            let expected = &baselines[key];
            let answer = solve(json!({
                "curve": ellipse_bc(), "feed": feed, "block_time_ms": 4, "compare_tolerance": tolerance
            }));
            let what = format!("{id} {key}");
            let stats = answer.comparison.unwrap().stats;
            assert_eq!(stats.blocks, number(&expected["blocks"]) as usize, "{what}");
            close(&what, stats.min_block_length, number(&expected["min_chord_mm"]), 1e-6);
            assert_eq!(stats.short_blocks, number(&expected["short_blocks_below_F_Tb"]) as usize, "{what}");
            if let Some(time) = expected.get("est_time_s_block_limited") {
                close(&what, stats.estimated_time_s, number(time), 1e-9);
            }
        }
    }
}

#[test]
fn case_c_adaptive_windows() {
    let case = case("segment", "C");
    let expected = &case["expected"];
    let answer = solve(json!({
        "curve": ellipse_bc(), "feed": 12000, "block_time_ms": 4, "margin": 1.05,
        "min_chord_error": 0.001, "mode": "window", "window": 5
    }));
    assert_eq!(answer.windows.len(), number(&expected["windows"]) as usize);
    let clamped = answer.windows.iter().filter(|w| w.status == WindowStatus::ClampedToMinChordError).count();
    assert_eq!(clamped, number(&expected["windows_clamped_to_Cemin"]) as usize);
    for (window, want) in answer.windows.iter().zip(expected["first_windows"].as_array().unwrap()) {
        close("s0", window.s_start, number(&want["s0"]), 1e-8);
        close("s1", window.s_end, number(&want["s1"]), 1e-8);
        close("r", window.radius.unwrap(), number(&want["r"]), 1e-8);
        close("cep", window.chord_error, number(&want["cep"]), 1e-9);
        assert_eq!(window.status, WindowStatus::Ok);
    }
    assert_eq!(answer.stats.blocks, number(&expected["blocks_total"]) as usize);
    check_ends(&answer, expected);
    for (s, want) in answer.s.iter().zip(expected["first_points_s_mm"].as_array().unwrap()) {
        close("s", *s, number(want), 1e-6);
    }
    close(
        "shortest chord but the last",
        answer.stats.min_block_length,
        number(&expected["chord_min_mm_excluding_last"]),
        1e-6,
    );
    close("longest chord", answer.stats.max_block_length, number(&expected["chord_max_mm"]), 1e-6);
    close("last chord", answer.stats.last_block_length, number(&expected["last_chord_mm"]), 1e-6);
    close("max deviation", answer.max_deviation, number(&expected["max_deviation_mm"]), 1e-9);
    assert_eq!(answer.stats.short_blocks, number(&expected["blocks_below_F_Tb_excluding_last"]) as usize);
    close("block-limited time", answer.stats.estimated_time_s, number(&expected["est_time_s_block_limited"]), 1e-9);
    close("block length", answer.stats.block_length, number(&expected["L_min_plain_mm"]), 1e-12);
    // Derived values of the case.
    let rule = BlockRule::new(12_000.0, 4.0).unwrap().with_margin(1.05);
    close("h", rule.half_chord(), number(&expected["half_chord_h_mm"]), 1e-15);
    close("L_min k_f", rule.target_chord(), number(&expected["L_min_kf_mm"]), 1e-15);
    close("C_e(25)", rule.chord_error(25.0).unwrap().0, number(&expected["Ce_at_r25_mm"]), 1e-15);
    close("C_e(200)", rule.chord_error(200.0).unwrap().0, number(&expected["Ce_at_r200_mm"]), 1e-15);
}

#[test]
fn case_derived_constants() {
    for (id, margin) in [("A", 1.0), ("B", 1.1)] {
        let expected = &case("segment", id)["expected"];
        let rule = BlockRule::new(10_000.0, 4.0).unwrap().with_margin(margin);
        close("alpha", rule.alpha(), number(&expected["alpha_min2"]), 1e-22);
        close("h", rule.half_chord(), number(&expected["half_chord_h_mm"]), 1e-15);
    }
    let expected = &case("segment", "A")["expected"];
    let rule = BlockRule::new(10_000.0, 4.0).unwrap();
    let cep = rule.chord_error(50.0).unwrap().0;
    let chord = kerf_solver::machine::chord_length(50.0, cep);
    // The fixture's chord is the greedy one, 1e-12 mm of slack on the chord error longer.
    close("chord", chord, number(&expected["chord_length_mm"]), 1e-9);
    let angle = 2.0 * (chord / 100.0).asin();
    close("angle", angle.to_degrees(), number(&expected["chord_angle_deg"]), 1e-9);
    close("sides", std::f64::consts::TAU / angle, number(&expected["sides_exact"]), 1e-6);
}

#[test]
fn edge_cases_e1_to_e5() {
    for case in fixture("segment")["edge_cases"].as_array().unwrap() {
        let label = case["label"].as_str().unwrap();
        let radius = case["r_mm"].as_f64().unwrap_or(f64::INFINITY);
        let rule = BlockRule::new(number(&case["F"]), number(&case["Tb_ms"]))
            .unwrap()
            .with_margin(number(&case["kf"]))
            .with_min_chord_error(number(&case["Ce_min"]));
        let limit = rule.feed_limit(radius);
        match case["F_limit_chord_eq_diameter_mm_min"].as_f64() {
            Some(expected) => close(label, limit, expected, 1e-6 * expected),
            None => assert!(limit.is_infinite(), "{label}"),
        }
        match (rule.chord_error(radius), case["status"].as_str().unwrap()) {
            (Err(infeasible), "INFEASIBLE_FEED_FOR_RADIUS") => {
                assert!(case["Cep_mm"].is_null());
                close(label, infeasible.feed_limit, limit, 0.0);
            }
            (Ok((cep, status)), expected_status) => {
                let expected_cep = number(&case["Cep_mm"]);
                close(label, cep, expected_cep, 1e-15 * expected_cep.max(1e-3));
                let expected = if expected_status == "CLAMPED_TO_CEMIN" {
                    ChordStatus::ClampedToMin
                } else {
                    ChordStatus::Surface
                };
                assert_eq!(status, expected, "{label}");
            }
            (other, status) => panic!("{label}: {other:?} but the fixture says {status}"),
        }
    }
}

#[test]
fn surface_table_in_micrometres() {
    let table = &fixture("segment")["surface_table_um_Tb4"];
    let radii: Vec<f64> = table["r_mm"].as_array().unwrap().iter().map(number).collect();
    for (feed, row) in table["rows"].as_object().unwrap() {
        let rule = BlockRule::new(feed.parse().unwrap(), 4.0).unwrap();
        for (radius, value) in radii.iter().zip(row.as_array().unwrap()) {
            let micrometres = rule.chord_error(*radius).unwrap().0 * 1000.0;
            close(&format!("F {feed} r {radius}"), micrometres, number(value), 5.01e-7);
        }
    }
}

/// docs/spec/segment.md §2.9a (revision 2): on the quarter ellipse at 10 000 mm/min and 4 ms the
/// patent's window rule leaves blocks shorter than feed × block time where a window's radius
/// is looser than the curve inside it; mode `guarantee` leaves none but the final remainder,
/// and every chord stays within the error of the smallest radius along it.
#[test]
fn guarantee_mode_leaves_no_short_blocks_on_the_quarter_ellipse() {
    let request = |mode: &str| json!({"curve": ellipse_bc(), "feed": 10000, "block_time_ms": 4, "mode": mode});
    let window = solve(request("window"));
    assert!(window.stats.short_blocks > 0, "the window rule should show the problem it has");
    let guarantee = solve(request("guarantee"));
    assert_eq!(guarantee.stats.short_blocks, 0);
    let lengths = block_lengths(&guarantee);
    let block = guarantee.stats.block_length;
    for (index, length) in lengths[..lengths.len() - 1].iter().enumerate() {
        assert!(*length >= block * (1.0 - 1e-9), "block {index}: {length} < {block}");
    }
    // One window per chord, with the chord error of its smallest radius: on this ellipse the
    // radius grows from t = 0, so it is the radius at the chord's start.
    assert_eq!(guarantee.windows.len(), guarantee.stats.blocks);
    for window in &guarantee.windows {
        let t = guarantee_parameter(window.s_start);
        let radius = (100.0 * t.sin()).hypot(50.0 * t.cos()).powi(3) / 5000.0;
        close("window radius", window.radius.unwrap(), radius, 1e-6 * radius);
    }
    assert!(guarantee.max_deviation <= guarantee.chord_error + 1e-12);
    // Backwards (t from 90° down to 0) the radius shrinks along every chord: the smallest is
    // at its end, not its start.
    let backwards = solve(json!({
        "curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 50], "start_deg": 90, "end_deg": 0,
                  "direction": "cw"},
        "feed": 10000, "block_time_ms": 4, "mode": "guarantee"
    }));
    assert_eq!(backwards.stats.short_blocks, 0);
    // Only slightly more blocks than the window rule: the chords are still about one block.
    assert!(guarantee.stats.blocks <= window.stats.blocks + window.stats.blocks / 10);
    // On a circle every radius is the same: case A's polygon.
    let circle = solve(json!({"curve": circle_a(), "feed": 10000, "block_time_ms": 4, "mode": "guarantee"}));
    let case_a = solve(json!({"curve": circle_a(), "feed": 10000, "block_time_ms": 4}));
    assert_eq!(circle.stats.blocks, 472);
    for (a, b) in circle.points.iter().zip(&case_a.points) {
        close("case A point", (a[0] - b[0]).hypot(a[1] - b[1]), 0.0, 1e-9);
    }
}

/// The ellipse parameter t at arc length `s` of the quarter ellipse 100 × 50 (bisection on a
/// fine Simpson sum; slow and simple on purpose).
fn guarantee_parameter(s: f64) -> f64 {
    let length = |t: f64| {
        let n = 2000;
        let h = t / f64::from(n);
        let speed = |x: f64| (100.0 * x.sin()).hypot(50.0 * x.cos());
        let mut sum = speed(0.0) + speed(t);
        for k in 1..n {
            sum += speed(h * f64::from(k)) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        sum * h / 3.0
    };
    let (mut lo, mut hi) = (0.0_f64, std::f64::consts::FRAC_PI_2);
    for _ in 0..60 {
        let middle = 0.5 * (lo + hi);
        if length(middle) < s {
            lo = middle;
        } else {
            hi = middle;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn guarantee_mode_refuses_window_options() {
    for (field, value) in [("window", json!(5)), ("rule", json!("max")), ("radius_estimate", json!("minimum"))] {
        let mut request = json!({"curve": circle_a(), "feed": 10000, "block_time_ms": 4, "mode": "guarantee"});
        request[field] = value;
        let parsed: SegmentRequest = serde_json::from_value(request).unwrap();
        let error = segment::solve(&parsed, None).unwrap_err();
        assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some(field)));
    }
}
