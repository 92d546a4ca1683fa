//! Benchmarks for solver::predict: passes per second per core and on all cores for a realistic
//! finishing program (zig-zag raster over a curved surface, > 100 000 passes, ball Ø10, pixel
//! size 0.039 mm), as a ratio against the seed's 0.070 s per pass.
//!
//! Each sample predicts a slice of 1000 passes in the middle of the program (the whole program
//! still sweeps the stock), so a sample takes about a second; passes/s = 1000 / sample time.

use std::hint::black_box;
use std::time::Instant;

use criterion::{Criterion, criterion_group, criterion_main};
use kerf_solver::predict::{self, Method};

#[path = "../tests/predict_support/mod.rs"]
mod support;

/// The seed's time per pass (patent Fig. 21, GPU, 2009).
const SEED_SECONDS_PER_PASS: f64 = 0.070;
const SLICE: usize = 1000;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("predict");
    group.sample_size(10);
    for (method, resolution, name) in [
        (Method::Sampling, 256, "sampling_N256"),
        (Method::DepthBuffer, 256, "depth_buffer_N256"),
        (Method::Sampling, 512, "sampling_N512"),
    ] {
        let (mut request, tool, moves) =
            support::raster_request(160.0, 0.5, 0.5, method, resolution);
        let middle = moves / 2;
        request.pass_range = Some([middle, middle + SLICE]);
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let label = format!(
                "{name}_{threads}_thread{}_{SLICE}_of_{moves}_passes",
                if threads == 1 { "" } else { "s" }
            );
            let started = Instant::now();
            let answer = pool.install(|| predict::solve(&request, &tool, None).unwrap());
            let seconds = started.elapsed().as_secs_f64();
            let per_pass = seconds / SLICE as f64;
            eprintln!(
                "{label}: {:.3} ms/pass, {:.0} passes/s, {:.0}× the seed; predicted {} of the slice",
                per_pass * 1e3,
                1.0 / per_pass,
                SEED_SECONDS_PER_PASS / per_pass,
                answer.summary.predicted
            );
            group.bench_function(&label, |b| {
                b.iter(|| {
                    pool.install(|| black_box(predict::solve(&request, &tool, None).unwrap()))
                });
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
