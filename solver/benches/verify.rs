//! Benchmark for solver::verify: a 3-axis finishing raster with a Ø6 ball over a 100 × 100 × 40
//! mm box stock, the ball following a dome (every move slopes, so every ray query searches its
//! move), cut at a dexel spacing of 0.1 mm (1 000 000 rays). Prints the blocks, the dexel
//! updates (ray queries) of one solve and, with criterion's time, the updates per second.
//!
//! Run: `cargo bench -p kerf-solver --bench verify -- --warm-up-time 1 --measurement-time 10`.
//! `KERF_BENCH_ROWS=n` sets the raster's rows (default 50, 1 mm apart over the middle 50 mm;
//! 200 steps of 0.5 mm per row, so 10 000 blocks), `KERF_BENCH_SPACING=h` the dexel spacing.

use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::capability::Run;
use kerf_solver::tool::{Tool, ToolKind};
use kerf_solver::verify::{self, VerifyRequest};
use serde_json::json;

/// The dome's height at (x, y): 5 mm at the centre of the stock, falling off to 0 at 50 mm.
fn dome(x: f64, y: f64) -> f64 {
    let r2 = ((x - 50.0).powi(2) + (y - 50.0).powi(2)) / 2500.0;
    5.0 * (1.0 - r2).max(0.0) - 6.0
}

fn raster(rows: usize) -> String {
    let mut program = String::from("G21 G90\nG0 X0 Y25 Z10\nF3000\n");
    for row in 0..rows {
        let y = 25.0 + 50.0 * row as f64 / rows.max(1) as f64;
        let forward = row % 2 == 0;
        for step in 0..=200 {
            let k = if forward { step } else { 200 - step };
            let x = 0.5 * k as f64;
            program.push_str(&format!("G1 X{x:.4} Y{y:.4} Z{:.4}\n", dome(x, y)));
        }
    }
    program.push_str("G0 Z50\nM30\n");
    program
}

fn bench(c: &mut Criterion) {
    let rows = std::env::var("KERF_BENCH_ROWS").ok().and_then(|v| v.parse().ok()).unwrap_or(50);
    let spacing: f64 = std::env::var("KERF_BENCH_SPACING").ok().and_then(|v| v.parse().ok()).unwrap_or(0.1);
    let request: VerifyRequest = serde_json::from_value(json!({
        "program": raster(rows),
        "tools": [{"kind": "ball", "radius": 3, "flute_length": 20, "stickout": 30}],
        "stock": {"kind": "box", "min": [0, 0, -40], "max": [100, 100, 0]},
        "resolution": spacing,
    }))
    .expect("a valid request");
    let tools = [Tool { flute_length: Some(20.0), stickout: Some(30.0), ..Tool::new(ToolKind::Ball, 3.0) }];
    let started = Instant::now();
    let cut = verify::verify(&request, &tools, verify::Found::default(), &Run::default()).expect("verified");
    let seconds = started.elapsed().as_secs_f64();
    println!(
        "verify raster: {} blocks, spacing {spacing} mm, {} rays, {} dexel updates, removed {:.1} mm³; one solve \
         {seconds:.2} s, {:.3e} updates/s",
        cut.moves,
        cut.rays[0] * cut.rays[1],
        cut.dexel_updates,
        cut.removed_volume_mm3,
        cut.dexel_updates as f64 / seconds
    );
    let mut group = c.benchmark_group("verify");
    group.sample_size(10);
    group.throughput(Throughput::Elements(cut.dexel_updates));
    group.bench_function("raster_ball_dome", |b| {
        b.iter(|| verify::verify(&request, &tools, verify::Found::default(), &Run::default()).expect("verified"))
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
