//! The block-time rule in contours (docs/spec/segment.md): with `block_time_ms` every arc is
//! chorded so that each of its blocks lasts at least one block time at its feed, within the
//! `tolerance`; the arcs' half-length end segments join the straight moves they continue; the
//! summary counts the blocks; what the rule cannot fix is reported.

use kerf_solver::contour::{self, ContourMove, ContourSolution, MoveKind};
use kerf_solver::machine::BlockRule;
use kerf_solver::planar::{Vec2, vec2};
use kerf_solver::tool::{Tool, ToolKind};
use proptest::prelude::*;
use serde_json::{Value, json};

/// C1 (square island 20 × 20, r = 1, arc loops ρ = 1) in two layers with `extra` fields.
fn square(extra: Value) -> Value {
    let mut body = json!({
        "tool": {"kind": "flat", "radius": 1.0},
        "contour": [[0, 0], [20, 0], [20, 20], [0, 20]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -2, "step": 1},
        "corner_loop": {"style": "arc", "radius": 1.0},
        "feed": 800,
    });
    for (key, value) in extra.as_object().unwrap() {
        body[key] = value.clone();
    }
    body
}

fn solve(body: Value) -> ContourSolution {
    let radius = body["tool"]["radius"].as_f64().unwrap();
    contour::solve(&serde_json::from_value(body).unwrap(), &Tool::new(ToolKind::Flat, radius)).unwrap()
}

fn xy(step: &ContourMove) -> Vec2 {
    Vec2::new(step.to[0], step.to[1])
}

/// Horizontal feed moves of the first layer: (from, to, kind, feed).
fn level_moves(answer: &ContourSolution) -> Vec<(Vec2, Vec2, MoveKind, f64)> {
    let layer = &answer.layers[0];
    layer
        .moves
        .windows(2)
        .filter(|pair| pair[0].to[2] == layer.z && pair[1].to[2] == layer.z)
        .filter_map(|pair| pair[1].feed.map(|feed| (xy(&pair[0]), xy(&pair[1]), pair[1].kind, feed)))
        .collect()
}

fn codes(answer: &ContourSolution) -> Vec<&'static str> {
    answer.warnings.iter().map(|w| w.code).collect()
}

#[test]
fn loop_blocks_last_one_block_time_within_the_tolerance() {
    let tolerance = 0.01;
    let plain = solve(square(json!({})));
    let ruled = solve(square(json!({"block_time_ms": 4, "loop_feed": 1600})));
    let loop_rule = BlockRule::new(1600.0, 4.0).unwrap();
    let cut_rule = BlockRule::new(800.0, 4.0).unwrap();

    // Every block of a loop arc is at least one block long at the loop feed (1600 mm/min:
    // 0.1067 mm) and not much longer; the plain answer's arcs are coarser, with half-length ends.
    let loops: Vec<f64> =
        level_moves(&ruled).iter().filter(|m| m.2 == MoveKind::Loop).map(|(a, b, ..)| (b - a).norm()).collect();
    assert!(!loops.is_empty());
    let block = loop_rule.target_chord();
    assert!(
        loops.iter().all(|l| *l >= block * (1.0 - 1e-9)),
        "shortest {}",
        loops.iter().fold(f64::MAX, |m, l| m.min(*l))
    );
    assert!(loops.iter().all(|l| *l <= 1.05 * block), "longest {}", loops.iter().fold(0.0, |m: f64, l| m.max(*l)));
    let plain_loops = level_moves(&plain).iter().filter(|m| m.2 == MoveKind::Loop).count();
    assert!(loops.len() > 2 * plain_loops, "{} ruled vs {plain_loops} plain loop moves", loops.len());

    // The loop moves lie on the outside of the arc, within the rule's chord error band, never
    // beyond the tolerance: the plain chords stray up to the tolerance, the rule's about seven
    // times less, at no cost in short blocks.
    let (chord_error, _) = loop_rule.chord_error(1.0).unwrap();
    let deviations = |answer: &ContourSolution, centre: Vec2| -> Vec<f64> {
        level_moves(answer)
            .iter()
            .filter(|m| m.2 == MoveKind::Loop)
            .map(|(_, b, ..)| (b - centre).norm() - 1.0)
            .filter(|d| d.abs() < 0.5)
            .collect()
    };
    for (corner, plain_corner) in ruled.corners.iter().zip(&plain.corners) {
        let centre = vec2(corner.corner_loop.as_ref().unwrap().centre.unwrap());
        let near = deviations(&ruled, centre);
        assert!(near.iter().all(|d| *d >= -1e-12 && *d <= tolerance), "{near:?}");
        let deepest = near.iter().fold(0.0, |m: f64, d| m.max(*d));
        assert!(deepest >= chord_error * (1.0 - 1e-9) && deepest < 1.2 * chord_error, "{deepest} vs {chord_error}");
        let plain_centre = vec2(plain_corner.corner_loop.as_ref().unwrap().centre.unwrap());
        let plain_deepest = deviations(&plain, plain_centre).iter().fold(0.0, |m: f64, d| m.max(*d));
        assert!(plain_deepest > 5.0 * deepest && plain_deepest <= tolerance, "{plain_deepest}");
    }

    // The figures: every block counted, none short, the block-limited time at least the plain one.
    let blocks = ruled.summary.blocks.as_ref().unwrap();
    let feed_moves: usize = ruled.layers.iter().flat_map(|l| &l.moves).filter(|m| m.feed.is_some()).count();
    assert_eq!(blocks.blocks, feed_moves);
    assert_eq!(blocks.short_blocks, 0, "{:?}", ruled.warnings);
    assert!((blocks.block_length - cut_rule.block_length()).abs() < 1e-15);
    assert!(blocks.min_block_length >= block * (1.0 - 1e-9));
    assert!(blocks.estimated_time_s >= ruled.summary.estimated_time_s);
    assert!((blocks.finest_arc_tolerance.unwrap() - chord_error).abs() < 1e-15);
    assert!(plain.summary.blocks.is_none());
    assert!(!codes(&ruled).contains(&"W_BLOCK_TIME_VIOLATION"), "{:?}", ruled.warnings);
}

#[test]
fn arc_end_segments_join_their_straight_moves() {
    let ruled = solve(square(json!({"block_time_ms": 4})));
    let moves = level_moves(&ruled);
    // No turn anywhere but inside the arcs: consecutive moves never reverse and the loop's first
    // and last blocks continue the legs in a straight line.
    for corner in &ruled.corners {
        let shape = corner.corner_loop.as_ref().unwrap();
        let (a, b) = (vec2(shape.exit_end), vec2(shape.entry_start));
        // A and B are inside merged moves now, not move ends.
        assert!(moves.iter().all(|(_, to, ..)| (to - a).norm() > 1e-9 && (to - b).norm() > 1e-9));
        // P is still passed twice.
        let p = vec2(corner.cl_point);
        assert_eq!(moves.iter().filter(|(_, to, ..)| (to - p).norm() < 1e-12).count(), 2);
    }
    // The same path as without merging: the plain answer chorded at the same points would pass
    // the same corner points, and the layer is still closed.
    let layer = &ruled.layers[0];
    assert_eq!(layer.moves.last().unwrap().kind, MoveKind::Rapid);
}

#[test]
fn round_joins_follow_the_rule_at_the_cutting_feed() {
    let body = square(json!({
        "block_time_ms": 2,
        "passes": [{"allowance": 0.5, "join": "round"}, {"allowance": 0}],
        "tolerance": 0.005
    }));
    let answer = solve(body);
    let rule = BlockRule::new(800.0, 2.0).unwrap();
    let first_pass_cuts: Vec<f64> = level_moves(&answer)
        .iter()
        .skip_while(|m| m.2 == MoveKind::Link)
        .take_while(|m| m.2 != MoveKind::Link)
        .map(|(a, b, ..)| (b - a).norm())
        .collect();
    assert!(first_pass_cuts.len() > 20);
    assert!(first_pass_cuts.iter().all(|l| *l >= rule.target_chord() * (1.0 - 1e-9)), "{first_pass_cuts:?}");
    assert_eq!(answer.summary.blocks.as_ref().unwrap().short_blocks, 0, "{:?}", answer.warnings);
}

#[test]
fn what_the_rule_cannot_fix_is_reported() {
    // 10 000 mm/min on a 10 ms control wants 1.67 mm blocks: the 1 mm loop legs and leads are
    // shorter, and the loop arcs (ρ = 1) need a chord error of 0.45 mm, far above the tolerance.
    let fast = solve(square(json!({"feed": 10_000, "block_time_ms": 10})));
    let found = codes(&fast);
    assert!(found.contains(&"W_BLOCK_TIME_VIOLATION"), "{found:?}");
    assert!(found.contains(&"W_CHORD_ERROR_EXCEEDS_TOLERANCE"), "{found:?}");
    let blocks = fast.summary.blocks.as_ref().unwrap();
    assert!(blocks.short_blocks > 0 && blocks.min_block_length < blocks.block_length);
    // 20 000 mm/min: no chord as long as a block fits in a loop of radius 1 at all; the contour
    // is still made, at the tolerance, and the largest feasible feed is named.
    let faster = solve(square(json!({"feed": 20_000, "block_time_ms": 10})));
    let warning = faster.warnings.iter().find(|w| w.code == "W_INFEASIBLE_FEED_FOR_RADIUS").unwrap();
    assert!(warning.message.contains("12000 mm/min"), "{}", warning.message);
}

#[test]
fn bad_block_times_name_the_field() {
    for value in [json!(0), json!(-4)] {
        let request = serde_json::from_value(square(json!({"block_time_ms": value}))).unwrap();
        let error = contour::solve(&request, &Tool::new(ToolKind::Flat, 1.0)).unwrap_err();
        assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("block_time_ms")));
    }
}

fn star(points: &[(f64, f64)]) -> Vec<[f64; 2]> {
    let total: f64 = points.iter().map(|p| p.0).sum();
    let mut angle = 0.0;
    points
        .iter()
        .map(|(gap, radius)| {
            let point = [radius * f64::cos(angle), radius * f64::sin(angle)];
            angle += std::f64::consts::TAU * gap / total;
            point
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The figures agree with a recount of the moves: every feed move is a block, a block is
    /// short when it is shorter than its feed × block time, and the last block before a rapid
    /// ends a span.
    #[test]
    fn block_figures_match_a_recount(
        shape in prop::collection::vec((0.3f64..1.0, 4.0f64..10.0), 4..10),
        block_time in 0.5f64..12.0,
        feed in 200.0f64..6000.0,
        loop_feed in 200.0f64..8000.0,
        style in prop::sample::select(vec!["arc", "triangle", "parallelogram"]),
    ) {
        let body = json!({
            "tool": {"kind": "flat", "radius": 0.3},
            "contour": star(&shape),
            "side": "outside",
            "depths": {"top": 0, "bottom": -1, "step": 0.5},
            "corner_loop": {"style": style},
            "feed": feed, "loop_feed": loop_feed, "block_time_ms": block_time,
            "passes": [{"allowance": 0.1, "join": "round"}, {"allowance": 0}]
        });
        let request = serde_json::from_value(body).unwrap();
        let Ok(answer) = contour::solve(&request, &Tool::new(ToolKind::Flat, 0.3)) else { return Ok(()) };
        let blocks = answer.summary.blocks.clone().unwrap();
        let (mut count, mut short, mut short_end) = (0, 0, 0);
        let all: Vec<&ContourMove> = answer.layers.iter().flat_map(|l| &l.moves).collect();
        for (i, step) in all.iter().enumerate().skip(1) {
            let Some(step_feed) = step.feed else { continue };
            count += 1;
            let length = ((step.to[0] - all[i - 1].to[0]).powi(2) + (step.to[1] - all[i - 1].to[1]).powi(2)
                + (step.to[2] - all[i - 1].to[2]).powi(2)).sqrt();
            let ends_span = all.get(i + 1).is_none_or(|next| next.feed.is_none());
            if length < step_feed * block_time / 60_000.0 * (1.0 - 1e-9) {
                if ends_span { short_end += 1 } else { short += 1 }
            }
        }
        prop_assert_eq!(blocks.blocks, count);
        prop_assert_eq!(blocks.short_blocks, short);
        prop_assert_eq!(blocks.short_end_blocks, short_end);
        prop_assert!(blocks.estimated_time_s >= answer.summary.estimated_time_s * (1.0 - 1e-12));
        // Loop arcs never make short blocks unless the rule reported why: only the straight
        // segments of triangle (1) and parallelogram (2) loops may be short.
        let reported = answer.warnings.iter().any(|w| {
            matches!(w.code, "W_INFEASIBLE_FEED_FOR_RADIUS" | "W_CHORD_ERROR_EXCEEDS_TOLERANCE")
        });
        if !reported {
            let loop_block = feed.max(loop_feed) * block_time / 60_000.0;
            let short_loops = level_moves(&answer)
                .iter()
                .filter(|(a, b, kind, _)| *kind == MoveKind::Loop && (b - a).norm() < loop_block * (1.0 - 1e-9))
                .count();
            let straight: usize = answer
                .corners
                .iter()
                .filter_map(|c| c.corner_loop.as_ref())
                .map(|l| match l.style {
                    contour::LoopStyle::Triangle => 1,
                    contour::LoopStyle::Parallelogram => 2,
                    _ => 0,
                })
                .sum();
            prop_assert!(short_loops <= straight, "{short_loops} short loop blocks, {straight} straight loop segments");
        }
    }
}
