//! Benchmark for solver::verify: a 3-axis finishing raster with a Ø6 ball over a 100 × 100 × 40
//! mm box stock, the ball following a dome (every move slopes, so every ray query searches its
//! move), cut at a dexel spacing of 0.1 mm (1 000 000 rays). Prints the blocks, the dexel
//! updates (ray queries) of one solve and, with criterion's time, the updates per second.
//!
//! Run: `cargo bench -p kerf-solver --bench verify -- --warm-up-time 1 --measurement-time 10`.
//! `KERF_BENCH_ROWS=n` sets the raster's rows (default 50, 1 mm apart over the middle 50 mm;
//! 200 steps of 0.5 mm per row, so 10 000 blocks; 500 rows 0.1 mm apart give the 100 502-block
//! finishing raster), `KERF_BENCH_SPACING=h` the dexel spacing, `KERF_BENCH_PROGRAM=file` a
//! G-code file to cut instead (tests/load/verify_numpy.py passes its own copy of the raster).
//!
//! Then, once, a deburr program cut at 0.01 mm (`KERF_BENCH_DEBURR_SPACING`): kerf's typical deburr
//! request (ball R3 chamfering 0.3 mm on the outer edge of a Ø20 hole in a tube of radii 40 and
//! 50 whose axis is y, the hole along z), its program cut in the tube's wall over the 28 × 28 mm
//! round the hole, given as a height field (the outer surface, the hole at the bottom).
//!
//! The one solve's time is printed as wall time and as the CPU time of the thread (from
//! /proc/thread-self/schedstat: on a shared machine the wall time counts other processes' turns).

use std::time::Instant;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::capability::Run;
use kerf_solver::deburr::{self, DeburrRequest};
use kerf_solver::gcode::{Arcs, Dialect, Post, Reference, ToolCall};
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

/// The CPU time this thread has run, s (Linux; none elsewhere).
fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(stat.split_whitespace().next()?.parse::<f64>().ok()? * 1e-9)
}

/// The deburr request, its verify request at `spacing` and the tools.
fn deburr_case(spacing: f64) -> (VerifyRequest, [Tool; 1]) {
    let request: DeburrRequest = serde_json::from_value(json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
        "hole": {"shape": "round", "radius": 10}, "edge": "outer", "cut_amount": 0.3, "tolerance": 0.01,
        "method": "tangent"
    }))
    .expect("a valid deburr request");
    let tool = Tool::new(ToolKind::Ball, 3.0);
    let answer = deburr::solve(&request, &tool).expect("deburred");
    let post = Post {
        dialect: Dialect::Fanuc,
        reference: Reference::Tip,
        tool: ToolCall::Table(1),
        arcs: Arcs::Chords,
        plunge_feed: None,
        units: kerf_solver::units::Units::Mm,
    };
    let program = deburr::program(&answer, &post).expect("a program");
    // The outer wall z = √(50² − x²) over [−14, 14]², sampled every 0.05 mm, the hole at the bottom.
    let (half, step) = (14.0, 0.05);
    let nodes = (2.0 * half / step) as usize + 1;
    let heights: Vec<Vec<f64>> = (0..nodes)
        .map(|j| {
            let y = -half + j as f64 * step;
            (0..nodes)
                .map(|i| {
                    let x = -half + i as f64 * step;
                    if x * x + y * y < 100.0 { 38.0 } else { (2500.0 - x * x).sqrt() }
                })
                .collect()
        })
        .collect();
    let verify: VerifyRequest = serde_json::from_value(json!({
        "program": program,
        "tools": [{"kind": "ball", "radius": 3, "number": 1}],
        "stock": {"kind": "grid", "origin": [-half, -half], "spacing": step, "heights": heights, "bottom": 38},
        "resolution": spacing,
    }))
    .expect("a valid verify request");
    (verify, [Tool { number: Some(1), ..tool }])
}

fn bench(c: &mut Criterion) {
    let rows = std::env::var("KERF_BENCH_ROWS").ok().and_then(|v| v.parse().ok()).unwrap_or(50);
    let spacing: f64 = std::env::var("KERF_BENCH_SPACING").ok().and_then(|v| v.parse().ok()).unwrap_or(0.1);
    let program = match std::env::var("KERF_BENCH_PROGRAM") {
        Ok(path) => std::fs::read_to_string(&path).expect("KERF_BENCH_PROGRAM names a readable G-code file"),
        Err(_) => raster(rows),
    };
    let request: VerifyRequest = serde_json::from_value(json!({
        "program": program,
        "tools": [{"kind": "ball", "radius": 3, "flute_length": 20, "stickout": 30}],
        "stock": {"kind": "box", "min": [0, 0, -40], "max": [100, 100, 0]},
        "resolution": spacing,
    }))
    .expect("a valid request");
    let tools = [Tool { flute_length: Some(20.0), stickout: Some(30.0), ..Tool::new(ToolKind::Ball, 3.0) }];
    let (started, cpu_started) = (Instant::now(), thread_cpu_seconds());
    let cut = verify::verify(&request, &tools, verify::Found::default(), &Run::default()).expect("verified");
    let seconds = started.elapsed().as_secs_f64();
    let cpu = thread_cpu_seconds().zip(cpu_started).map(|(end, start)| end - start);
    println!(
        "verify raster: {} blocks, spacing {spacing} mm, {} rays, {} dexel updates, removed {:.1} mm³; one solve \
         {seconds:.2} s, {:.3e} updates/s; CPU {} s, {} updates/s",
        cut.moves,
        cut.rays[0] * cut.rays[1],
        cut.dexel_updates,
        cut.removed_volume_mm3,
        cut.dexel_updates as f64 / seconds,
        cpu.map_or("-".into(), |cpu| format!("{cpu:.2}")),
        cpu.map_or("-".into(), |cpu| format!("{:.3e}", cut.dexel_updates as f64 / cpu)),
    );
    let deburr_spacing: f64 =
        std::env::var("KERF_BENCH_DEBURR_SPACING").ok().and_then(|v| v.parse().ok()).unwrap_or(0.01);
    let (deburr_request, deburr_tools) = deburr_case(deburr_spacing);
    let (started, cpu_started) = (Instant::now(), thread_cpu_seconds());
    let deburr_cut =
        verify::verify(&deburr_request, &deburr_tools, verify::Found::default(), &Run::default()).expect("verified");
    let seconds = started.elapsed().as_secs_f64();
    let cpu = thread_cpu_seconds().zip(cpu_started).map(|(end, start)| end - start);
    println!(
        "verify deburr: {} blocks, spacing {deburr_spacing} mm, {} rays, {} dexel updates, removed {:.3} mm³; one \
         solve {seconds:.3} s; CPU {} s",
        deburr_cut.moves,
        deburr_cut.rays[0] * deburr_cut.rays[1],
        deburr_cut.dexel_updates,
        deburr_cut.removed_volume_mm3,
        cpu.map_or("-".into(), |cpu| format!("{cpu:.3}")),
    );
    let mut group = c.benchmark_group("verify");
    group.sample_size(10);
    group.throughput(Throughput::Elements(cut.dexel_updates));
    group.bench_function("raster_ball_dome", |b| {
        b.iter(|| verify::verify(&request, &tools, verify::Found::default(), &Run::default()).expect("verified"))
    });
    group.bench_function("deburr_program", |b| {
        b.iter(|| {
            verify::verify(&deburr_request, &deburr_tools, verify::Found::default(), &Run::default()).expect("verified")
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
