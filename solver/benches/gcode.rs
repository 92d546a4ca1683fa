//! Benchmarks for the G-code writer: blocks per second written for a segment answer of about
//! 100 000 blocks (the whole-curve rule on an ellipse, G01 chords) and a contour answer (the arrow
//! island of `examples/contour-arrow.toml`, 40 layers, arcs as G02/G03), each beside the JSON
//! encoding of the same answer, so the cost of a G-code answer can be set against its JSON
//! answer (`solve` is the same for both and measured too).
//!
//! Run: `cargo bench -p kerf-solver --bench gcode -- --warm-up-time 1 --measurement-time 5`.
//! Criterion reports time per program or encoding and, from each answer's move count (printed
//! first), blocks per second (`thrpt`, in elements/s). `KERF_BENCH_ONLY=name` keeps the
//! configurations whose name contains it.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::capability::{self, Capability, Control, OutputOptions, Purpose, Resolved, Run};
use kerf_solver::contour::ContourCapability;
use kerf_solver::gcode::{Arcs, Dialect};
use kerf_solver::segment::SegmentCapability;
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::json;

/// Whether `KERF_BENCH_ONLY` keeps the configuration `name`.
fn wanted(name: &str) -> bool {
    std::env::var("KERF_BENCH_ONLY").ok().is_none_or(|filter| name.contains(&filter))
}

/// Benchmarks `C`'s solve of `request`, its JSON encoding and its program in `dialect`.
fn run<C: Capability>(
    group: &mut criterion::BenchmarkGroup<'_, criterion::measurement::WallTime>,
    name: &str,
    request: serde_json::Value,
    tool: C::Tool,
    output: OutputOptions,
) where
    C::Tool: Clone,
{
    let request: C::Request = serde_json::from_value(request).expect("the request reads");
    let context = || Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() };
    let solve = || C::solve(&request, context(), &Run { purpose: Purpose::Program, ..Run::default() });
    let answer = solve().expect("solve");
    let program = capability::program::<C>(&request, &answer, &output, Control::default()).expect("program");
    let json = serde_json::to_vec(&answer).expect("json");
    let blocks = program.lines().count() as u64;
    println!("{name}: {blocks} blocks, program {} bytes, JSON {} bytes", program.len(), json.len());
    group.throughput(Throughput::Elements(blocks));
    if wanted(&format!("{name}_solve")) {
        group.bench_function(format!("{name}_solve"), |b| b.iter(|| std::hint::black_box(solve())));
    }
    if wanted(&format!("{name}_json")) {
        group.bench_function(format!("{name}_json"), |b| {
            b.iter(|| serde_json::to_vec(std::hint::black_box(&answer)).expect("json"));
        });
    }
    if wanted(&format!("{name}_gcode")) {
        group.bench_function(format!("{name}_gcode"), |b| {
            b.iter(|| {
                capability::program::<C>(&request, std::hint::black_box(&answer), &output, Control::default())
                    .expect("program")
            });
        });
    }
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("gcode");
    group.sample_size(10);
    let fanuc = OutputOptions { dialect: Some(Dialect::Fanuc), ..OutputOptions::default() };
    run::<SegmentCapability>(
        &mut group,
        "segment_ellipse",
        json!({"curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [4000, 1500]}, "feed": 10000,
               "block_time_ms": 4, "mode": "curve", "tolerance": 0.0005}),
        None,
        fanuc,
    );
    let mut flat = Tool::new(ToolKind::Flat, 3.0);
    flat.number = Some(3);
    run::<ContourCapability>(
        &mut group,
        "contour_arrow",
        json!({"tool": 3, "contour": [[0, 10], [40, 10], [40, 0], [80, 25], [40, 50], [40, 40], [0, 40]],
               "side": "outside", "depths": {"top": 0, "bottom": -40, "step": 1},
               "corner_loop": {"style": "arc"}, "inside_corner_relief": "dogbone",
               "feed": 800, "loop_feed": 2000, "stock_allowance": 0.5, "spindle_rpm": 8000, "tolerance": 0.001,
               "passes": [{"allowance": 0.3, "join": "round"}, {"allowance": 0}]}),
        flat,
        OutputOptions { arcs: Some(Arcs::G2g3), ..fanuc },
    );
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
