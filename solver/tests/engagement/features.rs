//! The request forms and extras beyond the patent: docs/spec/api.md's example, candidate paths side by
//! side, stock left by an earlier cut, bitmap stock, rapids, the chip-thinning feed plan (it
//! never lets the chip exceed the target) and its G-code program, and determinism.

use kerf_solver::engagement::{
    self, EngagementRequest, EngagementSolution, FeedLimit, PathEngagement, SampleFlag, program,
};
use kerf_solver::gcode::Post;
use kerf_solver::gcode::{Dialect, Reference, ToolCall};
use kerf_solver::tool::{Tool, ToolKind};
use proptest::prelude::*;
use serde_json::{Value, json};

fn request(body: Value) -> EngagementRequest {
    serde_json::from_value(body).unwrap()
}

fn tool() -> Tool {
    Tool::new(ToolKind::Flat, 5.0)
}

fn single(body: Value) -> PathEngagement {
    match engagement::solve(&request(body), &tool()).unwrap() {
        EngagementSolution::Single(result) => *result,
        EngagementSolution::Comparison(_) => panic!("single path expected"),
    }
}

fn api_example() -> Value {
    json!({"tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0,0],[60,0],[60,40],[0,40]]},
     "path": [[-10,20],[70,20]], "spindle_rpm": 3000, "feed_per_tooth": 0.05,
     "flute_counts": [1,2,3,4,5,6,7,8], "thickness_limit": 0.075, "time_limit_s": 20})
}

#[test]
fn api_example_answers_with_the_api_fields() {
    let answer = engagement::solve(&request(api_example()), &tool()).unwrap();
    let text = serde_json::to_value(&answer).unwrap();
    for key in ["samples", "flutes", "recommended"] {
        assert!(text.get(key).is_some(), "missing {key}");
    }
    let sample = &text["samples"][100];
    for key in ["s", "t", "arcs", "engaged_deg", "radial_depth"] {
        assert!(sample.get(key).is_some(), "sample misses {key}");
    }
    for key in ["max_thickness", "mean_thickness", "min_thickness", "time_s", "recommended"] {
        assert!(text["flutes"][0].get(key).is_some(), "flute misses {key}");
    }
    // A full slot through a 60 mm block: H max is the slot table (§5.6); L = 80 mm, so
    // P_k = 32/k s: k = 1 is too slow, k ≥ 5 too thick.
    let result = answer.candidates()[0].clone();
    assert_eq!(result.recommended, vec![4, 3, 2]);
    assert!((result.flutes[3].max_thickness - 0.05 * std::f64::consts::SQRT_2).abs() < 1e-9);
    assert!((result.flutes[0].time_s - 60.0 * 80.0 / 150.0).abs() < 1e-9);
    // t at the tool's 2 flutes: V_f = 300 mm/min.
    let last = result.samples.last().unwrap();
    assert!((last.t - 60.0 * 80.0 / 300.0).abs() < 1e-9);
}

#[test]
fn same_request_same_bytes() {
    let first = serde_json::to_string(&engagement::solve(&request(api_example()), &tool()).unwrap()).unwrap();
    let second = serde_json::to_string(&engagement::solve(&request(api_example()), &tool()).unwrap()).unwrap();
    assert_eq!(first, second);
}

#[test]
fn candidates_side_by_side_equal_their_single_runs() {
    let straight = json!([[-10, 20], [70, 20]]);
    let bent = json!({"start": [-10, 20], "segments": [
        {"type": "line", "to": [30, 20]},
        {"type": "arc", "to": [40, 30], "center": [30, 30], "dir": "ccw"},
        {"type": "line", "to": [40, 50]}]});
    let mut body = api_example();
    body.as_object_mut().unwrap().remove("path");
    body["paths"] = json!([{"name": "straight", "path": straight}, {"name": "bent", "path": bent}]);
    let answer = engagement::solve(&request(body), &tool()).unwrap();
    let EngagementSolution::Comparison(comparison) = &answer else {
        panic!("comparison expected");
    };
    assert_eq!(comparison.candidates.len(), 2);
    let text = serde_json::to_value(&answer).unwrap();
    assert!(text.get("candidates").is_some() && text.get("samples").is_none());
    for (candidate, path) in comparison.candidates.iter().zip([straight, bent]) {
        let mut one = api_example();
        one["path"] = path;
        let mut alone = serde_json::to_value(single(one)).unwrap();
        alone["name"] = json!(candidate.name);
        assert_eq!(serde_json::to_value(candidate).unwrap(), alone);
    }
    assert!(comparison.candidates[1].feed_length < comparison.candidates[0].feed_length);
}

#[test]
fn stock_left_by_an_earlier_cut() {
    // C1's first pass as an earlier cut; the return pass alone then side-mills a_e = R/2.
    let body = json!({
        "tool": 1, "spindle_rpm": 3000, "feed_per_tooth": 0.05, "flute_counts": [4], "step": 0.1,
        "stock": {"polygon": [[0, -20], [50, -20], [50, 20], [0, 20]],
                  "previous_cuts": [{"path": [[-10, 0], [60, 0]], "radius": 5}]},
        "path": [[60, 2.5], [-10, 2.5]],
    });
    for engine in ["exact", "dots"] {
        let mut body = body.clone();
        if engine == "dots" {
            body["engine"] = json!("dots");
            body["grid"] = json!(0.025);
        }
        let result = single(body);
        // Steady at X = 32.5 (s = 27.5): arc [0, 60], a_e = 2.5 (C1 checkpoint s = 100).
        let sample = result.samples.iter().find(|s| (s.s - 27.5).abs() < 1e-9).unwrap();
        let tolerance = if engine == "exact" { 1e-6 } else { 0.05 };
        assert!((sample.radial_depth - 2.5).abs() < tolerance, "{engine}: {}", sample.radial_depth);
        if engine == "exact" {
            assert_eq!(sample.arcs.len(), 1);
            assert!(sample.arcs[0][0].abs() < 1e-6 && (sample.arcs[0][1] - 60.0).abs() < 1e-6);
        }
    }
}

fn bitmap_of_block(
    cell: f64,
    origin: [f64; 2],
    width: usize,
    height: usize,
    inside: impl Fn(f64, f64) -> bool,
) -> Value {
    let mut bytes = vec![0_u8; (width * height).div_ceil(8)];
    for row in 0..height {
        for column in 0..width {
            let x = origin[0] + (column as f64 + 0.5) * cell;
            let y = origin[1] + (row as f64 + 0.5) * cell;
            if inside(x, y) {
                let bit = row * width + column;
                bytes[bit / 8] |= 0x80 >> (bit % 8);
            }
        }
    }
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut text = String::new();
    for chunk in bytes.chunks(3) {
        let value = (u32::from(chunk[0]) << 16)
            | (u32::from(*chunk.get(1).unwrap_or(&0)) << 8)
            | u32::from(*chunk.get(2).unwrap_or(&0));
        for i in 0..4 {
            if i <= chunk.len() {
                text.push(ALPHABET[((value >> (18 - 6 * i)) & 63) as usize] as char);
            } else {
                text.push('=');
            }
        }
    }
    json!({"bitmap": {"origin": origin, "cell": cell, "width": width, "height": height, "data": text}})
}

#[test]
fn bitmap_stock_matches_the_polygon_it_rasterises() {
    // The block [0, 60] × [0, 40] on 0.5 mm cells: the cell edges are the polygon's edges.
    let stock =
        bitmap_of_block(0.5, [-5.0, -5.0], 140, 100, |x, y| (0.0..60.0).contains(&x) && (0.0..40.0).contains(&y));
    let mut body = api_example();
    body["path"] = json!([[-10, 3], [70, 3]]);
    let polygon = single(body.clone());
    body["stock"] = stock;
    let bitmap = single(body.clone());
    assert_eq!(polygon.samples.len(), bitmap.samples.len());
    for (a, b) in polygon.samples.iter().zip(&bitmap.samples) {
        assert_eq!(a.arcs.len(), b.arcs.len(), "s = {}", a.s);
        for (p, q) in a.arcs.iter().zip(&b.arcs) {
            assert!((p[0] - q[0]).abs() < 1e-6 && (p[1] - q[1]).abs() < 1e-6, "s = {}: {p:?} vs {q:?}", a.s);
        }
    }
    // The dots engine takes the bitmap's cells as its dots by default.
    body["engine"] = json!("dots");
    let dots = single(body);
    let grid = dots.grid.unwrap();
    assert_eq!(grid.cell, 0.5);
    for (origin, anchor) in grid.origin.iter().zip([-5.0, -5.0]) {
        let cells = (origin - anchor) / 0.5;
        assert!((cells - cells.round()).abs() < 1e-9, "dots line up with the bitmap cells");
    }
    let exact_max = polygon.flutes[3].max_thickness;
    assert!((dots.flutes[3].max_thickness - exact_max).abs() <= 0.02 * exact_max);
}

#[test]
fn rapids_do_not_cut_and_collisions_are_reported() {
    let body = json!({
        "tool": 1, "spindle_rpm": 3000, "feed_per_tooth": 0.05, "flute_counts": [2], "step": 0.5,
        "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "path": {"start": [-10, 5], "segments": [
            {"type": "line", "to": [70, 5]},
            {"type": "line", "to": [70, 30], "rapid": true},
            {"type": "line", "to": [30, 30], "rapid": true},
            {"type": "line", "to": [-10, 30]}]},
    });
    let result = single(body);
    assert!((result.path_length - 185.0).abs() < 1e-9);
    assert!((result.feed_length - 120.0).abs() < 1e-9);
    let codes: Vec<&str> = result.warnings.iter().map(|w| w.code).collect();
    assert!(codes.contains(&"W_RAPID_COLLISION"), "{codes:?}");
    assert!(codes.contains(&"W_PLUNGE"), "the feed after the rapid starts in material: {codes:?}");
    let rapid = result.samples.iter().find(|s| (s.s - 130.0).abs() < 1e-9).unwrap();
    assert!(rapid.flags.contains(&SampleFlag::Rapid) && rapid.flags.contains(&SampleFlag::Collision));
    assert!(rapid.arcs.is_empty());
    // Time stands still on rapids.
    let before = result.samples.iter().find(|s| (s.s - 80.0).abs() < 1e-9).unwrap();
    let after = result.samples.iter().find(|s| (s.s - 145.0).abs() < 1e-9).unwrap();
    assert!((after.t - before.t).abs() < 1e-9);
    // The rapid at cutting depth removed nothing: the last pass cuts a full slot.
    let slot = result.samples.iter().find(|s| (s.s - 160.0).abs() < 1e-9).unwrap();
    assert!((slot.engaged_deg - 180.0).abs() < 1e-6);
}

/// Peak chip ratio max(0, sin θ) over a sample's arcs, computed here independently.
fn peak_ratio(arcs: &[[f64; 2]]) -> f64 {
    arcs.iter()
        .map(|[a, b]| {
            let steps = 2000;
            (0..=steps)
                .map(|i| (a + (b - a) * f64::from(i) / f64::from(steps)).to_radians().sin())
                .chain([if *a <= 90.0 && 90.0 <= *b { 1.0 } else { 0.0 }])
                .fold(0.0_f64, f64::max)
        })
        .fold(0.0, f64::max)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

    #[test]
    fn feed_plan_never_exceeds_the_target(
        target in 0.02_f64..0.1,
        max_feed in 1000.0_f64..8000.0,
        offset in -8.0_f64..8.0,
        corner in 10.0_f64..50.0,
    ) {
        let body = json!({
            "tool": 1, "spindle_rpm": 4000, "feed_per_tooth": 0.05, "flute_counts": [3], "step": 0.2,
            "stock": {"polygon": [[0, -20], [60, -20], [60, 20], [0, 20]]},
            "path": [[-10, offset], [corner, offset], [corner, 30]],
            "feed_plan": {"target_thickness": target, "max_feed": max_feed, "flute_count": 3},
            "axial_depth": 2,
        });
        let result = single(body);
        let plan = result.feed_plan.clone().unwrap();
        prop_assert!(!plan.blocks.is_empty());
        let mut covered = 0.0;
        for block in &plan.blocks {
            covered += block.to_s - block.from_s;
            let feed = block.feed.unwrap();
            prop_assert!(feed <= max_feed && feed >= 1.0 && feed.fract() == 0.0);
            // Every sample touching the block: the chip there stays at or below the target.
            for sample in result.samples.iter().filter(|s| s.s >= block.from_s - 1e-9 && s.s <= block.to_s + 1e-9) {
                let chip = feed / (3.0 * 4000.0) * peak_ratio(&sample.arcs);
                prop_assert!(chip <= target * (1.0 + 1e-6), "s = {}: chip {} > {}", sample.s, chip, target);
            }
            if block.limited_by == Some(FeedLimit::Machine) {
                prop_assert!(feed >= max_feed.floor() - 1.0);
            }
        }
        prop_assert!((covered - result.path_length).abs() < 1e-6);
        let timed: f64 = plan.blocks.iter().map(|b| 60.0 * (b.to_s - b.from_s) / b.feed.unwrap()).sum();
        prop_assert!((timed - plan.time_s).abs() < 1e-9 * timed.max(1.0));
    }
}

#[test]
fn program_carries_the_planned_feeds() {
    let body = json!({
        "tool": 1, "spindle_rpm": 4000, "feed_per_tooth": 0.05, "flute_counts": [3, 4], "step": 0.1,
        "stock": {"polygon": [[0, -20], [60, -20], [60, 20], [0, 20]]},
        "path": {"start": [-10, 2], "segments": [
            {"type": "line", "to": [30, 2]},
            {"type": "arc", "to": [40, 12], "center": [30, 12], "dir": "ccw"},
            {"type": "line", "to": [40, 30]}]},
        "feed_plan": {"target_thickness": 0.04, "max_feed": 6000, "flute_count": 3},
        "axial_depth": 3, "stock_top_z": 10,
    });
    let answer = engagement::solve(&request(body), &tool()).unwrap();
    let result = &answer.candidates()[0];
    let plan = result.feed_plan.as_ref().unwrap();
    let post = Post {
        dialect: Dialect::Linuxcnc,
        reference: Reference::Tip,
        tool: ToolCall::Table(4),
        arcs: kerf_solver::gcode::Arcs::Chords,
        plunge_feed: None,
        units: kerf_solver::units::Units::Mm,
    };
    let text = program(&answer, 0, &post).unwrap();
    assert!(text.contains("T4 M06") && text.contains("S4000 M03") && text.ends_with("M30\n"));
    // Cutting at Z = 10 − 3, clearance at 15.
    assert!(text.contains("Z7.0000") && text.contains("Z15.0000"));
    let feeds: Vec<f64> = text
        .lines()
        .filter(|l| l.starts_with("G01"))
        .filter_map(|l| l.split_whitespace().find_map(|w| w.strip_prefix('F')))
        .map(|f| f.parse().unwrap())
        .collect();
    let planned: std::collections::BTreeSet<u64> = plan.blocks.iter().map(|b| b.feed.unwrap() as u64).collect();
    assert!(feeds.len() >= 2, "{feeds:?}");
    // The descent into the cut runs at half the nominal feed of the plan's 3 flutes
    // (3 × 0.05 × 4000 = 600) at most: the plunge without a plunge feed.
    assert_eq!(result.program_flute_count, 3);
    for feed in &feeds {
        assert!(planned.contains(&(*feed as u64)) || *feed == 300.0, "F{feed} not in the plan {planned:?}");
    }
    // The arc's chord points lie on the arc, within the chord tolerance.
    let mut on_arc = 0;
    for line in text.lines().filter(|l| l.starts_with("G01")) {
        let coordinate = |axis: char| -> Option<f64> {
            line.split_whitespace().find_map(|w| w.strip_prefix(axis)).and_then(|v| v.parse().ok())
        };
        let (Some(x), Some(y)) = (coordinate('X'), coordinate('Y')) else {
            continue;
        };
        if x > 30.0 + 1e-9 && y < 12.0 - 1e-9 {
            on_arc += 1;
            let radius = ((x - 30.0).powi(2) + (y - 12.0).powi(2)).sqrt();
            assert!((radius - 10.0).abs() < 1e-4, "{line}");
        }
    }
    assert!(on_arc > 10);
    assert!(text.contains("X40.0000 Y30.0000"));
    // The nominal program (no plan) uses one feed, 2 flutes × 0.05 × 4000, after the plunge at
    // half of it.
    let body = json!({
        "tool": 1, "spindle_rpm": 4000, "feed_per_tooth": 0.05, "step": 0.5,
        "stock": {"polygon": [[0, -20], [60, -20], [60, 20], [0, 20]]},
        "path": [[-10, 2], [70, 2]], "axial_depth": 1,
    });
    let answer = engagement::solve(&request(body), &tool()).unwrap();
    let text = program(&answer, 0, &post).unwrap();
    let feed_words = text.lines().filter(|l| l.starts_with("G01") && l.contains(" F")).count();
    assert_eq!(feed_words, 2, "{text}");
    assert!(text.contains(" F200\n") && text.contains(" F400\n"), "{text}");
}
