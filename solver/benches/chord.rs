//! Benchmarks for solver::chord (issue 3, "Measure and report"): segments per second for a
//! B-spline of about 100 000 blocks (window mode, the patent's per-window rule, and the
//! whole-curve rule), and the R50 circle of the patent's experiment as the baseline.
//!
//! Run: `cargo bench -p kerf-solver --bench chord -- --warm-up-time 1 --measurement-time 5`.
//! Criterion reports time per solve; the block count of each input is printed first, so
//! segments per second = blocks / time.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::chord::{self, SegmentRequest};
use serde_json::{Value, json};

/// A cubic B-spline through an Archimedean spiral (pitch 12 mm, radius 50 to 520 mm) with a
/// 0.5 mm wave in z, control points about 10 mm apart: about 70 m of curve, 100 000 blocks at
/// 10 000 mm/min with a 4 ms block time.
fn spiral() -> Value {
    let mut control = Vec::new();
    let mut angle: f64 = 0.0;
    loop {
        let radius = 50.0 + 12.0 * angle / std::f64::consts::TAU;
        if radius > 520.0 {
            break;
        }
        control.push([radius * angle.cos(), radius * angle.sin(), 0.5 * (3.0 * angle).sin()]);
        angle += 10.0 / radius;
    }
    json!({"kind": "bspline", "degree": 3, "control_points": control})
}

fn request(curve: &Value, mode: &str) -> SegmentRequest {
    serde_json::from_value(json!({
        "curve": curve, "feed": 10000, "block_time_ms": 4, "margin": 1.05, "mode": mode
    }))
    .expect("bench request")
}

fn bench(c: &mut Criterion) {
    let spline = spiral();
    let mut group = c.benchmark_group("chord");
    group.sample_size(10);
    for mode in ["window", "curve"] {
        let request = request(&spline, mode);
        let blocks = chord::solve(&request, None).expect("solve").stats.blocks;
        println!("bspline {mode}: {blocks} blocks");
        group.throughput(Throughput::Elements(blocks as u64));
        group.bench_function(format!("bspline_{mode}"), |b| {
            b.iter(|| chord::solve(std::hint::black_box(&request), None))
        });
    }
    let circle = request(&json!({"kind": "circle", "centre": [0, 0], "radius": 50}), "window");
    let blocks = chord::solve(&circle, None).expect("solve").stats.blocks;
    println!("circle R50: {blocks} blocks");
    group.throughput(Throughput::Elements(blocks as u64));
    group.bench_function("circle_r50", |b| b.iter(|| chord::solve(std::hint::black_box(&circle), None)));
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
