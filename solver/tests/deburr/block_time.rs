//! Deburring with the block-time rule: with a block time and the feed, every block of
//! the loop is at least feed × block time long unless a warning says why (the tolerance, a radius
//! too small for the feed, a piece shorter than one block), and the deviation stays within both
//! the tolerance and the rule's chord error; without a block time nothing changes.

use kerf_solver::deburr::{self, Deburr, DeburrRequest};
use kerf_solver::gcode::Dialect;
use kerf_solver::machine::{BlockRule, MachineProfile};
use kerf_solver::tool::{Tool, ToolKind};
use proptest::prelude::*;
use serde_json::{Value, json};

fn ball(radius: f64) -> Tool {
    Tool::new(ToolKind::Ball, radius)
}

fn request(mut body: Value) -> DeburrRequest {
    if body.get("tool").is_none() {
        body["tool"] = json!({"kind": "ball", "radius": 3});
    }
    serde_json::from_value(body).expect("valid request")
}

/// The outer edge of an R8 hole in an R25 tube (like `examples/deburr-tube.toml`) with `extra`.
fn tube(extra: Value) -> Value {
    let mut body = json!({
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 15, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 8}, "edge": "outer", "cut_amount": 0.3
    });
    for (key, value) in extra.as_object().unwrap() {
        body[key] = value.clone();
    }
    body
}

fn lengths(result: &Deburr) -> Vec<f64> {
    result
        .points
        .windows(2)
        .map(|pair| {
            let (a, b) = (pair[0].centre, pair[1].centre);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
        })
        .collect()
}

fn codes(result: &Deburr) -> Vec<&'static str> {
    result.warnings.iter().map(|w| w.code).collect()
}

/// Smallest circumradius of three consecutive centres: the tightest turn of the path.
fn smallest_radius(result: &Deburr) -> f64 {
    let centre = |i: usize| result.points[i].centre;
    (0..result.points.len() - 2)
        .map(|i| {
            let (a, b, c) = (centre(i), centre(i + 1), centre(i + 2));
            let side = |p: [f64; 3], q: [f64; 3]| {
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
            };
            let (x, y, z) = (side(a, b), side(b, c), side(a, c));
            let s = 0.5 * (x + y + z);
            let area = (s * (s - x) * (s - y) * (s - z)).max(0.0).sqrt();
            if area > 0.0 { x * y * z / (4.0 * area) } else { f64::INFINITY }
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn without_a_block_time_nothing_changes() {
    let body = kerf_cases::with(kerf_cases::deburr::case_1(), json!({"tolerance": 0.01}));
    let plain = deburr::solve(&request(body.clone()), &ball(3.0)).unwrap();
    assert_eq!(plain.summary.count, 92, "reference case 1");
    assert_eq!(deburr::solve_with(&request(body), &ball(3.0), None).unwrap(), plain);
    let summary = serde_json::to_value(&plain.summary).unwrap();
    for key in ["blocks", "min_block_length", "short_blocks", "block_time_ms", "block_length"] {
        assert!(summary.get(key).is_none(), "{key} only with a block time");
    }
    assert!((plain.summary.estimated_time_s - 0.0).abs() > 0.0);
}

#[test]
fn blocks_are_at_least_one_block_time_long() {
    let tool = ball(3.0);
    for (feed, block_time, tolerance) in
        [(300.0, 4.0, 0.01), (3000.0, 4.0, 0.01), (1500.0, 1.0, 0.01), (10000.0, 4.0, 0.05)]
    {
        let body = tube(json!({"feed": feed, "block_time_ms": block_time, "tolerance": tolerance}));
        let fixed = deburr::solve(&request(tube(json!({"feed": feed, "tolerance": tolerance}))), &tool).unwrap();
        let result = deburr::solve(&request(body), &tool).unwrap();
        let summary = &result.summary;
        let block = feed * block_time / 60_000.0;
        let what = format!("F{feed} T{block_time} TA{tolerance}");
        assert_eq!(summary.short_blocks, Some(0), "{what}: {:?}", codes(&result));
        assert_eq!(summary.blocks, Some(result.points.len() - 1), "{what}");
        assert!(lengths(&result).iter().all(|l| *l >= block), "{what}");
        assert!(summary.min_block_length.unwrap() >= block && summary.block_length == Some(block), "{what}");
        // Within both: the tolerance and the rule's chord error (aimed at 2.1 block lengths, the
        // bisection's reach) on the tightest turn of the path.
        assert!(summary.max_deviation <= tolerance, "{what}");
        let reach = BlockRule::new(feed, block_time).unwrap().with_margin(2.1);
        let bound = reach.tolerance_for(smallest_radius(&result), Some(tolerance)).unwrap();
        assert!(summary.max_deviation <= bound * 1.05, "{what}: {} > {bound}", summary.max_deviation);
        // The block-limited time: every block at least T_b.
        assert!(summary.estimated_time_s >= summary.blocks.unwrap() as f64 * block_time / 1000.0, "{what}");
        assert!(result.warnings.iter().all(|w| !w.code.contains("BLOCK_TIME")), "{what}");
        // The rule is finer than the plain tolerance where that would allow longer chords.
        if feed <= 3000.0 {
            assert!(summary.count > fixed.summary.count, "{what}: {} vs {}", summary.count, fixed.summary.count);
            assert!(summary.max_deviation < fixed.summary.max_deviation, "{what}");
        }
    }
}

#[test]
fn every_hole_shape_on_both_edges() {
    let tool = ball(2.0);
    let holes = [
        json!({"shape": "round", "radius": 6, "eccentricity": 3, "penetration_angle_deg": 10}),
        json!({"shape": "slot", "radius": 5, "centre_distance": 16}),
        json!({"shape": "rounded_rect", "radius": 3, "centre_distance": [10, 14]}),
    ];
    for hole in &holes {
        for (edge, method) in [("outer", "tangent"), ("inner", "exact")] {
            let body = json!({
                "tool": {"kind": "ball", "radius": 2},
                "workpiece": {"kind": "tube", "origin": [5, 0, 0], "arrangement_angle_deg": 30, "inner_radius": 20, "outer_radius": 30},
                "hole": hole, "edge": edge, "cut_amount": 0.2, "method": method,
                "feed": 1200, "block_time_ms": 2, "tolerance": 0.02
            });
            let result = deburr::solve(&request(body), &tool).unwrap();
            let what = format!("{hole} {edge}");
            assert_eq!(result.summary.short_blocks, Some(0), "{what}: {:?}", result.warnings);
            assert!(result.summary.max_deviation <= 0.02, "{what}");
        }
    }
}

#[test]
fn a_tolerance_that_forbids_long_blocks_is_reported() {
    // At 10 m/min a 4 ms block is 0.667 mm; on the R5.3 centre path 0.01 mm allows less.
    let result =
        deburr::solve(&request(tube(json!({"feed": 10000, "block_time_ms": 4, "tolerance": 0.01}))), &ball(3.0))
            .unwrap();
    assert!(result.summary.short_blocks.unwrap() > 0);
    assert!(result.summary.max_deviation <= 0.01, "the tolerance still wins");
    let found = codes(&result);
    assert!(
        found.contains(&"W_CHORD_ERROR_EXCEEDS_TOLERANCE") && found.contains(&"W_BLOCK_TIME_VIOLATION"),
        "{found:?}"
    );
    let advice = &result.warnings.iter().find(|w| w.code == "W_CHORD_ERROR_EXCEEDS_TOLERANCE").unwrap().message;
    let feed: f64 = advice.split("At most ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
    // At the advised feed both are met.
    let slower =
        deburr::solve(&request(tube(json!({"feed": feed, "block_time_ms": 4, "tolerance": 0.01}))), &ball(3.0))
            .unwrap();
    assert_eq!(slower.summary.short_blocks, Some(0), "{feed}: {:?}", slower.warnings);
}

#[test]
fn a_radius_too_small_for_the_feed_is_reported() {
    // A 1 mm hole deburred with a 0.5 mm ball at 20 m/min and 8 ms: blocks of 2.7 mm on a loop
    // a few mm round.
    let body = json!({
        "tool": {"kind": "ball", "radius": 0.5},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 8, "outer_radius": 10},
        "hole": {"shape": "round", "radius": 1}, "edge": "outer", "cut_amount": 0.05,
        "feed": 20000, "block_time_ms": 8, "tolerance": 1
    });
    let result = deburr::solve(&request(body), &ball(0.5)).unwrap();
    assert!(result.summary.short_blocks.unwrap() > 0);
    let found = codes(&result);
    assert!(found.contains(&"W_FEED_TOO_HIGH_FOR_RADIUS") && found.contains(&"W_BLOCK_TIME_VIOLATION"), "{found:?}");
}

#[test]
fn machine_values_and_bad_block_times() {
    let machine = MachineProfile {
        arcs: None,
        plunge_feed: None,
        max_accel: None,
        max_jerk: None,
        rapid_feed: None,
        tool_change_s: None,
        haas_smoothing: None,
        name: Some("hsc".to_owned()),
        block_time_ms: 4.0,
        max_feed: 2000.0,
        dialect: Dialect::Linuxcnc,
        margin: Some(1.2),
        min_chord_error: Some(0.002),
        description: None,
        mode: None,
        spindle_power_kw: None,
        spindle_torque_nm: None,
        max_spindle_rpm: None,
        spindle_power_curve: None,
        units: None,
    };
    let tool = ball(3.0);
    // The machine's block time applies at the request's feed, capped by the machine's max feed
    // (deburr keeps its own feed otherwise: the machine never raises it).
    let named = request(tube(json!({"machine": "hsc", "feed": 3000})));
    let result = deburr::solve_with(&named, &tool, Some(&machine)).unwrap();
    assert_eq!(result.summary.block_time_ms, Some(4.0));
    assert_eq!(result.summary.feed, machine.max_feed);
    assert_eq!(result.summary.short_blocks, Some(0));
    let capped = result.warnings.iter().find(|w| w.code == "W_FEED_ABOVE_MACHINE_MAX").expect("the feed is capped");
    assert!(capped.message.contains("capped from 3000 mm/min to 2000"), "{}", capped.message);
    let slower = deburr::solve_with(&request(tube(json!({"machine": "hsc", "feed": 1500}))), &tool, Some(&machine));
    assert_eq!(slower.unwrap().summary.feed, 1500.0, "a feed below the machine's is kept");
    // min_chord_error 0.002: no interval is cut finer than that where the rule asks for less.
    assert!(result.summary.max_deviation >= 0.001, "{}", result.summary.max_deviation);
    // The request's block time overrides the machine's.
    let own = request(tube(json!({"machine": "hsc", "feed": 1000, "block_time_ms": 2})));
    assert_eq!(deburr::solve_with(&own, &tool, Some(&machine)).unwrap().summary.block_time_ms, Some(2.0));
    // Resolution is the caller's (capability::resolve): a name without its profile applies no
    // machine. And bad block times.
    assert_eq!(deburr::solve(&named, &tool).unwrap().summary.block_time_ms, None);
    for bad in [0.0, -4.0, f64::NAN, f64::INFINITY] {
        let mut body = request(tube(json!({"feed": 1000})));
        body.block_time_ms = Some(bad);
        let error = deburr::solve(&body, &tool).unwrap_err();
        assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("block_time_ms")), "{bad}");
    }
    // The program header records the rule.
    let post = kerf_solver::gcode::Post {
        dialect: Dialect::Fanuc,
        reference: kerf_solver::gcode::Reference::Tip,
        tool: kerf_solver::gcode::ToolCall::Table(7),
        arcs: kerf_solver::gcode::Arcs::Chords,
        plunge_feed: None,
        units: kerf_solver::units::Units::Mm,
    };
    let program = deburr::program(&result, &post).unwrap();
    assert!(program.contains("(BLOCK TIME 4 MS MARGIN 1.2:"), "{program}");
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn short_blocks_only_with_a_reason(
        hole_radius in 2.0..12.0_f64,
        shape in 0_usize..3,
        feed in 100.0..12000.0_f64,
        block_time in 0.5..10.0_f64,
        tolerance in 0.002..0.1_f64,
        inner in any::<bool>(),
    ) {
        let hole = match shape {
            0 => json!({"shape": "round", "radius": hole_radius}),
            1 => json!({"shape": "slot", "radius": hole_radius * 0.6, "centre_distance": hole_radius}),
            _ => json!({"shape": "rounded_rect", "radius": hole_radius * 0.4, "centre_distance": [hole_radius, hole_radius * 0.8]}),
        };
        let body = json!({
            "tool": {"kind": "ball", "radius": 1.5},
            "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 30, "outer_radius": 40},
            "hole": hole, "edge": if inner { "inner" } else { "outer" }, "cut_amount": 0.2,
            "feed": feed, "block_time_ms": block_time, "tolerance": tolerance
        });
        let result = match deburr::solve(&request(body), &ball(1.5)) {
            Ok(result) => result,
            Err(error) => {
                prop_assert!(["E_FAR_GOUGE", "E_TOO_MANY_POINTS"].contains(&error.code().as_str()), "{}", error.message());
                return Ok(());
            }
        };
        let summary = &result.summary;
        let block = feed * block_time / 60_000.0;
        prop_assert!(summary.max_deviation <= tolerance);
        let short = lengths(&result).iter().filter(|l| **l < block * (1.0 - 1e-9)).count();
        prop_assert_eq!(Some(short), summary.short_blocks);
        let found = codes(&result);
        if short > 0 {
            prop_assert!(found.contains(&"W_BLOCK_TIME_VIOLATION"), "{found:?}");
        } else {
            prop_assert!(!found.contains(&"W_BLOCK_TIME_VIOLATION"), "{found:?}");
        }
        // Short blocks come from the tolerance, a tight radius, or pieces of the profile that
        // are shorter than one block (straight sides, or a whole arc).
        let has_reason = found.contains(&"W_CHORD_ERROR_EXCEEDS_TOLERANCE") || found.contains(&"W_FEED_TOO_HIGH_FOR_RADIUS");
        if short > 0 && !has_reason {
            prop_assert!(shape != 0, "a round hole has no straight sides: {found:?} {:?}", result.warnings);
        }
    }
}
