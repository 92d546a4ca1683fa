//! Benchmarks for solver::segment: blocks per second for
//! a B-spline of about 100 000 blocks, a large ellipse and a polyline of 100 000 points, in the
//! patent's per-window mode, the whole-curve rule and the no-short-blocks `guarantee` mode
//! (docs/spec/segment.md §2.9a), with the R50 circle of the patent's experiment as the baseline.
//!
//! Run: `cargo bench -p kerf-solver --bench segment -- --warm-up-time 1 --measurement-time 5`.
//! Criterion reports time per solve and, from the block count of each input (printed first),
//! blocks per second (`thrpt`, in elements/s).
//!
//! On a shared machine, and to check that a change leaves the answers alone (as the engagement
//! bench): `KERF_BENCH_ONLY=name` keeps the configurations whose name (`bspline_window`,
//! `circle_r50`, ...) contains it (`name$`: that one only); `KERF_BENCH_SOLVES=n` solves each
//! kept configuration n more times instead of benchmarking it (CPU time under `perf stat -e
//! task-clock`, instructions under callgrind); `KERF_BENCH_DUMP=dir` writes each kept
//! configuration's answer JSON to `dir/<name>.json` (to `cmp` two builds).
//!
//! `KERF_BENCH_SPANS=n` instead times, n rounds each (the least wall time printed), where a request of `tests/load/peers.py` spends its time: reading its JSON, solving
//! it, writing the answer's JSON (the endpoint's writer and serde's), for the B-spline of 5 000
//! poles at 0.001 mm and the ellipse 30 000 × 15 000 at 1e-5 mm (about 100 000 points each).

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::capability::{Capability, Resolved, Run};
use kerf_solver::segment::{self, SegmentCapability, SegmentRequest};
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

/// A full ellipse 400 × 150 mm: about 1 800 mm of curve with radii from 56 to 1 067 mm.
fn ellipse() -> Value {
    json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [400, 150]})
}

/// 100 000 points 0.05 mm apart on a wavy closed curve (radius 60 ± 8 mm, 7 waves): a dense
/// polyline of about 5 m taken as the true curve.
fn polyline() -> Value {
    let count = 100_000;
    let points: Vec<[f64; 2]> = (0..count)
        .map(|k| {
            let angle = std::f64::consts::TAU * f64::from(k) / f64::from(count) * 13.0;
            let radius = 60.0 + 8.0 * (7.0 * angle / 13.0).sin();
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect();
    json!({"kind": "polyline", "points": points, "corner_angle_deg": 60})
}

fn request(curve: &Value, mode: &str) -> Option<SegmentRequest> {
    serde_json::from_value(json!({
        "curve": curve, "feed": 10000, "block_time_ms": 4, "margin": 1.05, "mode": mode
    }))
    .ok()
}

/// Whether `KERF_BENCH_ONLY` keeps the configuration `name`.
fn wanted(name: &str) -> bool {
    std::env::var("KERF_BENCH_ONLY").ok().is_none_or(|filter| match filter.strip_suffix('$') {
        Some(exact) => name == exact,
        None => name.contains(&filter),
    })
}

/// Solves `request` once to print its block count, writes its answer for `KERF_BENCH_DUMP`,
/// and solves it `KERF_BENCH_SOLVES` times or benchmarks it.
fn run(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    request: &SegmentRequest,
) {
    let answer = segment::solve(request, None).expect("solve");
    let blocks = answer.stats.blocks;
    println!("{name}: {blocks} blocks");
    if let Ok(dir) = std::env::var("KERF_BENCH_DUMP") {
        std::fs::write(format!("{dir}/{name}.json"), serde_json::to_vec(&answer).expect("json")).expect("dump");
    }
    if let Some(solves) = std::env::var("KERF_BENCH_SOLVES").ok().and_then(|n| n.parse::<usize>().ok()) {
        for _ in 0..solves {
            drop(std::hint::black_box(segment::solve(std::hint::black_box(request), None)));
        }
        return;
    }
    group.throughput(Throughput::Elements(blocks as u64));
    group.bench_function(name, |b| b.iter(|| segment::solve(std::hint::black_box(request), None)));
}

/// The B-spline of `tests/load/peers.py`: 5 000 poles 20 mm apart along a spiral from radius
/// 10 mm, 2 mm pitch, a 0.5 mm wave in z.
fn peers_spiral() -> Value {
    let mut control = Vec::new();
    let mut angle: f64 = 0.0;
    for _ in 0..5000 {
        let radius = 10.0 + 2.0 * angle / std::f64::consts::TAU;
        control.push([radius * angle.cos(), radius * angle.sin(), 0.5 * (3.0 * angle).sin()]);
        angle += 20.0 / radius;
    }
    json!({"kind": "bspline", "degree": 3, "control_points": control})
}

/// A request of `tests/load/peers.py`: the curve cut at the fixed chord error `tolerance`.
fn peers_request(curve: Value, tolerance: f64) -> Vec<u8> {
    serde_json::to_vec(&json!({"curve": curve, "mode": "curve", "feed": 1000, "block_time_ms": 1,
        "min_chord_error": tolerance, "tolerance": tolerance}))
    .expect("request")
}

/// The least wall time of `rounds` calls of `work`, s (on a loaded machine the least of many
/// rounds is the one that ran alone).
fn least(rounds: usize, mut work: impl FnMut()) -> f64 {
    (0..rounds)
        .map(|_| {
            let started = std::time::Instant::now();
            work();
            started.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// Where the peers' segment requests spend their time (`KERF_BENCH_SPANS`).
fn spans(rounds: usize) {
    let cases = [
        ("bspline 5000 poles, 0.001 mm", peers_request(peers_spiral(), 0.001)),
        (
            "ellipse 30000 x 15000, 1e-5 mm",
            peers_request(json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [30000, 15000]}), 1e-5),
        ),
    ];
    let context = || Resolved { tool: None, machine: None, material: None, other_tools: Vec::new() };
    for (name, body) in cases {
        let request: SegmentRequest = serde_json::from_slice(&body).expect("request");
        let answer = SegmentCapability::solve(&request, context(), &Run::default()).expect("solve");
        let json = SegmentCapability::to_json(answer.clone()).expect("json");
        let parse = least(rounds, || drop(std::hint::black_box(serde_json::from_slice::<SegmentRequest>(&body))));
        let solve = least(rounds, || {
            drop(std::hint::black_box(SegmentCapability::solve(&request, context(), &Run::default())))
        });
        let clone = least(rounds, || drop(std::hint::black_box(answer.clone())));
        let writer =
            least(rounds, || drop(std::hint::black_box(SegmentCapability::to_json(answer.clone()).map(|j| j.len()))));
        let serde = least(rounds, || drop(std::hint::black_box(serde_json::to_vec(&answer).map(|j| j.len()))));
        let ms = |seconds: f64| seconds * 1e3;
        println!(
            "{name}: {} points, {} bytes of JSON; least of {rounds}: parse {:.2} ms, solve {:.2} ms, \
             JSON {:.2} ms by the endpoint's writer, {:.2} ms by serde",
            answer.result.points.len(),
            json.len(),
            ms(parse),
            ms(solve),
            ms(writer - clone),
            ms(serde),
        );
    }
}

fn bench(c: &mut Criterion) {
    if let Some(rounds) = std::env::var("KERF_BENCH_SPANS").ok().and_then(|n| n.parse::<usize>().ok()) {
        spans(rounds.max(1));
        return;
    }
    let mut group = c.benchmark_group("segment");
    group.sample_size(10);
    let curves = [("bspline", spiral()), ("ellipse", ellipse()), ("polyline", polyline())];
    for (name, curve) in &curves {
        for mode in ["window", "guarantee", "curve"] {
            let name = format!("{name}_{mode}");
            if !wanted(&name) {
                continue;
            }
            // A mode the solver does not know (before guarantee existed) is skipped.
            let Some(request) = request(curve, mode) else {
                println!("{name}: mode not available");
                continue;
            };
            run(&mut group, &name, &request);
        }
    }
    if wanted("circle_r50") {
        let circle = request(&json!({"kind": "circle", "centre": [0, 0], "radius": 50}), "window").expect("circle");
        run(&mut group, "circle_r50", &circle);
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
