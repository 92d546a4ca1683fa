//! Deburr throughput: ball centres per second for a ~10 000-point job (single core) and a typical
//! 92-point job (reference case 1), for the patent's tangent method and the exact method (centres
//! whose swept chamfer is W wide). The cost per centre is one over the throughput.
//!
//! `cargo bench -p kerf-solver --bench deburr`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::deburr::{self, DeburrRequest};
use kerf_solver::tool::{Tool, ToolKind};

fn request(tolerance: f64, method: &str) -> DeburrRequest {
    request_with_cut(0.5, tolerance, method)
}

fn request_with_cut(cut_amount: f64, tolerance: f64, method: &str) -> DeburrRequest {
    serde_json::from_value(serde_json::json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
        "hole": {"shape": "round", "radius": 10},
        "edge": "outer", "cut_amount": cut_amount, "tolerance": tolerance, "method": method
    }))
    .expect("valid request")
}

/// The request of tests/load/deburr-distinct.lua: case 1 with a cut amount
/// around 0.3 (one of the values that script sends), tolerance 0.01, the default (tangent) method.
const DISTINCT_LOAD_NAME: &str = "typical_distinct_load_cut0.300123_tangent";
const DISTINCT_LOAD_CUT: f64 = 0.300123;

fn bench(c: &mut Criterion) {
    let tool = &Tool::new(ToolKind::Ball, 3.0);
    let mut group = c.benchmark_group("deburr");
    for (name, tolerance, method) in [
        ("typical_case1_tangent", 0.01, "tangent"),
        (DISTINCT_LOAD_NAME, 0.01, "tangent"),
        ("typical_case1_exact", 0.01, "exact"),
        ("10k_points_tangent", 1e-6, "tangent"),
        ("10k_points_exact", 1e-6, "exact"),
    ] {
        let job = if name == DISTINCT_LOAD_NAME {
            request_with_cut(DISTINCT_LOAD_CUT, tolerance, method)
        } else {
            request(tolerance, method)
        };
        let run = |job: &DeburrRequest| deburr::solve(job, tool);
        let count = run(&job).expect("solves").summary.count;
        eprintln!("{name}: {count} points");
        group.throughput(Throughput::Elements(count as u64));
        group.bench_function(name, |b| b.iter(|| run(std::hint::black_box(&job)).expect("solves")));
    }
    group.finish();
    // The distinct-load request again, timed by the thread's CPU time instead of the wall clock:
    // on a shared machine the wall clock also counts the time other processes hold the core.
    let mut cpu = c.benchmark_group("deburr_cpu_time");
    let job = request_with_cut(DISTINCT_LOAD_CUT, 0.01, "tangent");
    cpu.bench_function(DISTINCT_LOAD_NAME, |b| {
        b.iter_custom(|iterations| {
            let start = thread_cpu_time();
            for _ in 0..iterations {
                deburr::solve(std::hint::black_box(&job), tool).expect("solves");
            }
            thread_cpu_time().saturating_sub(start)
        });
    });
    cpu.finish();
}

/// CPU time of this thread so far: the first field of /proc/thread-self/schedstat, in ns (Linux).
fn thread_cpu_time() -> std::time::Duration {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux schedstat");
    let nanoseconds = text.split_whitespace().next().and_then(|field| field.parse().ok()).expect("CPU time in ns");
    std::time::Duration::from_nanos(nanoseconds)
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
