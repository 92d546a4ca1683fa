//! Deburr throughput: ball centres per second for a ~10 000-point job (single core), for the
//! seed's tangent method and the exact method, and a typical 92-point job (reference case 1).
//!
//! `cargo bench -p kerf-solver --bench deburr`

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::deburr::{self, DeburrRequest};
use kerf_solver::tool::{Tool, ToolKind};

fn request(tolerance: f64, method: &str) -> DeburrRequest {
    serde_json::from_value(serde_json::json!({
        "tool": {"kind": "ball", "radius": 3},
        "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
        "hole": {"shape": "round", "radius": 10},
        "edge": "outer", "cut_amount": 0.5, "tolerance": tolerance, "method": method
    }))
    .expect("valid request")
}

fn bench(c: &mut Criterion) {
    let tool = Tool::new(ToolKind::Ball, 3.0);
    let mut group = c.benchmark_group("deburr");
    for (name, tolerance, method) in [
        ("typical_case1_tangent", 0.01, "tangent"),
        ("10k_points_tangent", 1e-6, "tangent"),
        ("10k_points_exact", 1e-6, "exact"),
    ] {
        let job = request(tolerance, method);
        let count = deburr::solve(&job, &tool).expect("solves").summary.count;
        eprintln!("{name}: {count} points");
        group.throughput(Throughput::Elements(count as u64));
        group.bench_function(name, |b| b.iter(|| deburr::solve(std::hint::black_box(&job), &tool).expect("solves")));
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
