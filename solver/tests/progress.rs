//! Every capability reports its progress while it runs:
//! through the seam's `Control`, a job's bar moves within one operation, not only 0 → 100 %.

use std::sync::Mutex;

use kerf_solver::capability::{Capability, Control, Resolved, Run, resolve};
use kerf_solver::contour::ContourCapability;
use kerf_solver::deburr::DeburrCapability;
use kerf_solver::engagement::EngagementCapability;
use kerf_solver::segment::SegmentCapability;
use serde_json::{Value, json};

use crate::inline::Inline;

/// The fractions `C` reports while solving `body`.
fn reported<C: Capability>(body: Value) -> Vec<f64> {
    let request: C::Request = serde_json::from_value(body).expect("a valid request");
    let context: Resolved<C::Tool> = resolve(C::refs(&request), &Inline).expect("inline tool");
    let seen = Mutex::new(Vec::new());
    let record = |fraction: f64| seen.lock().unwrap().push(fraction);
    let run = Run { control: Control { progress: Some(&record), cancel: None }, ..Run::default() };
    C::solve(&request, context, &run).expect("it solves");
    seen.into_inner().unwrap()
}

/// Within 0–1, never going back, and with values inside the run, not only at its ends.
fn moves(what: &str, fractions: &[f64]) {
    assert!(fractions.iter().all(|f| (0.0..=1.0).contains(f)), "{what}: {fractions:?}");
    assert!(fractions.windows(2).all(|w| w[0] <= w[1]), "{what} goes back: {fractions:?}");
    let inside = fractions.iter().filter(|f| **f > 0.05 && **f < 0.95).count();
    assert!(inside >= 2, "{what} reports no progress inside the run: {fractions:?}");
}

#[test]
fn contour_reports_per_layer() {
    let fractions = reported::<ContourCapability>(json!({
        "tool": {"kind": "flat", "radius": 3},
        "contour": [[0, 10], [40, 10], [40, 0], [80, 25], [40, 50], [40, 40], [0, 40]],
        "side": "outside", "depths": {"top": 0, "bottom": -9, "step": 1}, "feed": 800,
    }));
    moves("contour", &fractions);
}

#[test]
fn engagement_reports_per_sample_across_its_paths() {
    let fractions = reported::<EngagementCapability>(json!({
        "tool": {"kind": "flat", "radius": 5}, "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "paths": [{"path": [[-10, 20], [70, 20]]}, {"path": [[-10, 35], [70, 35]]}],
        "spindle_rpm": 3000, "feed_per_tooth": 0.05, "flute_counts": [2],
    }));
    moves("engagement", &fractions);
    // The second path continues where the first ended.
    assert!(fractions.iter().any(|f| *f > 0.5 && *f < 0.95), "{fractions:?}");
}

#[test]
fn segment_reports_along_the_curve() {
    let fractions = reported::<SegmentCapability>(json!({
        "curve": {"kind": "circle", "centre": [0, 0], "radius": 50},
        "feed": 1000, "block_time_ms": 4,
    }));
    moves("segment", &fractions);
}

#[test]
fn deburr_reports_its_stages() {
    let fractions = reported::<DeburrCapability>(json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 20, "outer_radius": 25},
        "hole": {"shape": "round", "radius": 5}, "edge": "outer", "cut_amount": 0.5,
    }));
    moves("deburr", &fractions);
}
