//! Engagement throughput: samples per second for 1 m of path at a 0.01 mm step
//! through a 200 × 200 mm pocket, for both engines, and the dot engine's memory at 0.01 mm;
//! with Kienzle torque and power at a 0.1 mm step, straight and helical flutes, and
//! for a ball end whose 16 height bands each take their own section's engagement.
//!
//! Run: `cargo bench -p kerf-solver --bench engagement -- --warm-up-time 1 --measurement-time 5`
//! (`KERF_BENCH_ONLY=ball` for the configurations whose name contains `ball`)
//!
//! For measuring CPU time on a shared machine (`perf stat -e task-clock`), and for checking
//! that a change leaves the answer alone: `KERF_BENCH_SOLVES=n` solves each chosen
//! configuration n more times instead of benchmarking it, and `KERF_BENCH_DUMP=dir` writes each
//! chosen configuration's answer JSON (the capability's own writer) to `dir/<name>.json`.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::capability::{Capability, Resolved, Run};
use kerf_solver::engagement::{self, EngagementCapability, EngagementRequest, EngagementSolution};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::json;

const STEP: f64 = 0.01;
const POCKET: f64 = 200.0;
const PATH_LENGTH: f64 = 1000.0;

/// A zig-zag clearing path with 50 % stepover (D = 10 mm), entering from outside the stock,
/// cut to exactly 1 m.
fn zigzag() -> Vec<[f64; 2]> {
    let mut points = vec![[-10.0, 5.0]];
    let mut length = 0.0;
    let mut row = 0;
    loop {
        let y = 5.0 + 5.0 * f64::from(row);
        let end_x = if row % 2 == 0 { POCKET - 5.0 } else { 5.0 };
        let [x0, _] = *points.last().unwrap();
        for target in [[x0, y], [end_x, y]] {
            let [px, py] = *points.last().unwrap();
            let piece = ((target[0] - px).powi(2) + (target[1] - py).powi(2)).sqrt();
            if piece == 0.0 {
                continue;
            }
            if length + piece >= PATH_LENGTH {
                let t = (PATH_LENGTH - length) / piece;
                points.push([px + t * (target[0] - px), py + t * (target[1] - py)]);
                return points;
            }
            length += piece;
            points.push(target);
        }
        row += 1;
    }
}

fn request(engine: &str) -> EngagementRequest {
    let mut body = json!({
        "tool": 1,
        "stock": {"polygon": [[0, 0], [POCKET, 0], [POCKET, POCKET], [0, POCKET]]},
        "path": zigzag(),
        "spindle_rpm": 8000, "feed_per_tooth": 0.05, "flute_counts": [2, 3, 4],
        "thickness_limit": 0.08, "time_limit_s": 600, "step": STEP,
    });
    if engine == "dots" {
        body["engine"] = json!("dots");
        body["grid"] = json!(0.01);
        body["contact_dots"] = json!(false);
    }
    if engine.starts_with("exact_kienzle") {
        // Torque and power for the three flute counts; a 10× coarser step keeps a run short.
        body["kienzle"] = json!({"kc11": 1800, "mc": 0.25});
        body["axial_depth"] = json!(2);
        body["step"] = json!(STEP * 10.0);
    }
    serde_json::from_value(body).unwrap()
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("engagement_1m_at_0.01mm");
    group.sample_size(10);
    // `KERF_BENCH_ONLY=name` runs the configurations whose name contains it (`name$`: that one
    // only), skipping the others' set-up too (each solves its request once to count samples).
    let filter = std::env::var("KERF_BENCH_ONLY").ok();
    for engine in
        ["exact", "dots", "exact_kienzle", "exact_kienzle_helix", "exact_kienzle_ball", "exact_kienzle_ball_helix"]
    {
        let wanted = filter.as_deref().is_none_or(|f| match f.strip_suffix('$') {
            Some(exact) => engine == exact,
            None => engine.contains(f),
        });
        if !wanted {
            continue;
        }
        let kind = if engine.contains("ball") { ToolKind::Ball } else { ToolKind::Flat };
        let mut tool = Tool::new(kind, 5.0);
        if engine.ends_with("helix") {
            tool.helix_deg = Some(30.0);
        }
        let request = request(engine);
        let answer = engagement::solve(&request, &tool).unwrap();
        let EngagementSolution::Single(result) = &answer else { unreachable!() };
        let samples = result.samples.len() as u64;
        if let Some(grid) = &result.grid {
            let full = (POCKET / 0.01) * (POCKET / 0.01);
            eprintln!(
                "dots grid for this path: {} × {} dots = {:.1} MB; the whole 200 × 200 mm pocket at 0.01 mm: {full:.0} dots = {:.1} MB",
                grid.width,
                grid.height,
                grid.bytes as f64 / 1e6,
                full / 8.0 / 1e6
            );
        }
        eprintln!("{engine}: {samples} samples, path {:.1} mm", result.path_length);
        if let Ok(dir) = std::env::var("KERF_BENCH_DUMP") {
            let context = Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() };
            let answer = EngagementCapability::solve(&request, context, &Run::default()).unwrap();
            let bytes = EngagementCapability::to_json(answer).unwrap();
            std::fs::write(format!("{dir}/{engine}.json"), bytes).unwrap();
        }
        if let Some(solves) = std::env::var("KERF_BENCH_SOLVES").ok().and_then(|n| n.parse::<usize>().ok()) {
            for _ in 0..solves {
                drop(std::hint::black_box(engagement::solve(&request, &tool).unwrap()));
            }
            continue;
        }
        group.throughput(Throughput::Elements(samples));
        group.bench_function(engine, |b| {
            b.iter(|| engagement::solve(&request, &tool).unwrap());
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
