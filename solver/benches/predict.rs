//! Benchmarks for solver::predict: passes per second per core and on both cores for a realistic
//! finishing program, as a ratio against the patent's 0.070 s per pass (patent Fig. 21).
//!
//! The program (kerf_cases::predict): a ball end mill Ø10 finishing a double-wave surface
//! (slopes up to 26°) by a zig-zag raster, pick 0.5 mm, 0.5 mm segments, 103 041 feed passes,
//! f_t = 0.1 mm at 6000 rpm, force model with modal stiffness; stock = surface + 0.2 mm as a
//! height grid. Resolution N = 256 gives the patent's pixel size 0.039 mm; N = 512 is twice as fine.
//!
//! Each criterion sample predicts a slice of 1000 passes in the middle of the program (the whole
//! program still sweeps the stock): ms per pass = sample time / 1000. Before each group the bench
//! prints one measured slice with wall and process CPU time (the machine is shared, so CPU time
//! per pass is the per-core figure), and once the whole program on all threads.
//!
//! Environment: `KERF_BENCH_SLICES=n` measures the slice n times per group (old and new builds
//! run alternately give ranges on a shared machine); `KERF_BENCH_ONLY=name` keeps the groups whose
//! name contains it; `KERF_BENCH_WHOLE=0` skips the whole-program run (4 min on 2 cores);
//! `KERF_BENCH_DUMP=dir` writes each group's slice answer to `dir/<group>.json` (to compare the
//! answers of two builds field by field); `KERF_BENCH_THREADS=n` measures on n threads only (1
//! for instruction counts under callgrind, whose toggles are global across threads).

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use kerf_solver::predict::{self, Method};

use kerf_cases::predict as support;

/// The patent's time per pass (patent Fig. 21, GPU, 2009).
const PATENT_SECONDS_PER_PASS: f64 = 0.070;
/// Passes per criterion sample.
const SLICE: usize = 1000;

/// Process CPU time (user + system) in seconds, from /proc (0 where unavailable).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    let Some(rest) = stat.rsplit(')').next() else {
        return 0.0;
    };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

fn report(label: &str, passes: usize, wall: f64, cpu: f64) {
    let per_pass = wall / passes as f64;
    let cpu_per_pass = cpu / passes as f64;
    eprintln!(
        "{label}: {passes} passes, wall {:.3} ms/pass ({:.0} passes/s, {:.0}× the patent), CPU {:.3} ms/pass per core ({:.0}× the patent per core)",
        per_pass * 1e3,
        1.0 / per_pass,
        PATENT_SECONDS_PER_PASS / per_pass,
        cpu_per_pass * 1e3,
        PATENT_SECONDS_PER_PASS / cpu_per_pass,
    );
}

fn bench(c: &mut Criterion) {
    let slices: usize = std::env::var("KERF_BENCH_SLICES").ok().and_then(|v| v.parse().ok()).unwrap_or(1);
    let only = std::env::var("KERF_BENCH_ONLY").unwrap_or_default();
    let thread_counts: Vec<usize> = match std::env::var("KERF_BENCH_THREADS").ok().and_then(|v| v.parse().ok()) {
        Some(threads) => vec![threads],
        None => vec![1, 2],
    };
    let mut group = c.benchmark_group("predict");
    group.sample_size(10);
    for (method, resolution, name) in [
        (Method::Sampling, 256, "sampling_N256"),
        (Method::DepthBuffer, 256, "depth_buffer_N256"),
        (Method::Sampling, 512, "sampling_N512"),
    ] {
        if !name.contains(only.as_str()) {
            continue;
        }
        let (mut request, tool, moves) = support::raster_request(160.0, 0.5, 0.5, method, resolution);
        let middle = moves / 2;
        for &threads in &thread_counts {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let label = format!("{name}_{threads}_threads");
            // Setup alone (reading 103 041 lines, the grids), then the slice.
            request.pass_range = Some([middle, middle]);
            let (started, cpu) = (Instant::now(), cpu_seconds());
            pool.install(|| predict::solve(&request, &tool, None).unwrap());
            let (setup_wall, setup_cpu) = (started.elapsed().as_secs_f64(), cpu_seconds() - cpu);
            request.pass_range = Some([middle, middle + SLICE]);
            eprintln!("{label}: setup {setup_wall:.3} s wall, {setup_cpu:.2} s CPU for {moves} passes");
            for _ in 0..slices {
                let (started, cpu) = (Instant::now(), cpu_seconds());
                let answer = pool.install(|| predict::solve(&request, &tool, None).unwrap());
                let (wall, cpu) = (started.elapsed().as_secs_f64(), cpu_seconds() - cpu);
                assert_eq!(answer.summary.predicted + answer.summary.no_cut + answer.summary.no_surface, SLICE);
                report(&label, SLICE, wall - setup_wall, cpu - setup_cpu);
                if let Ok(dir) = std::env::var("KERF_BENCH_DUMP") {
                    let text = serde_json::to_string_pretty(&answer).unwrap();
                    std::fs::write(format!("{dir}/{label}.json"), text).unwrap();
                }
            }
            group.bench_function(format!("{label}_{SLICE}_of_{moves}_passes"), |b| {
                b.iter(|| pool.install(|| black_box(predict::solve(&request, &tool, None).unwrap())));
            });
        }
    }
    group.finish();
    if std::env::var("KERF_BENCH_WHOLE").is_ok_and(|v| v == "0") {
        return;
    }
    // The whole program once, on all threads.
    let (mut request, tool, moves) = support::raster_request(160.0, 0.5, 0.5, Method::Sampling, 256);
    request.pass_range = None;
    let (started, cpu) = (Instant::now(), cpu_seconds());
    let answer = predict::solve(&request, &tool, None).unwrap();
    let (wall, cpu) = (started.elapsed().as_secs_f64(), cpu_seconds() - cpu);
    eprintln!(
        "whole program, sampling N = 256, {} threads: {moves} passes in {wall:.1} s wall, {cpu:.1} s CPU; predicted {}, no_cut {}, no_surface {}, max |e| {:.4} mm",
        rayon::current_num_threads(),
        answer.summary.predicted,
        answer.summary.no_cut,
        answer.summary.no_surface,
        answer.summary.max_error.unwrap_or(0.0).abs().max(answer.summary.min_error.unwrap_or(0.0).abs()),
    );
    report("whole program", moves, wall, cpu);
}

criterion_group!(benches, bench);
criterion_main!(benches);
