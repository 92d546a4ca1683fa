//! Benchmarks for `solver::contour`:
//!
//! * contour vertices per second for a 100 000-vertex contour with 50 layers (the full answer,
//!   every move of every layer), and for one layer's 2-D plan;
//! * the simple-polygon check of `planar` on the same 100 000 vertices;
//! * the two cases measured against Clipper2 (offset once, copied to every layer): a star of 50
//!   tips with 100 layers, and a 20 000-vertex wavy outline with 8 layers, each solved as the
//!   endpoint solves it and its answer written as the endpoint writes its JSON;
//! * printed once before timing: the material left and over-cut at every corner of the three
//!   reference cases with and without loops, ideal and under the control models M1/M2.
//!
//! Run: `cargo bench -p kerf-solver --bench contour -- --warm-up-time 1 --measurement-time 5`.

use std::hint::black_box;

use criterion::BatchSize;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kerf_solver::capability::{Capability, Resolved, Run};
use kerf_solver::contour::{self, ContourCapability, ContourRequest, ControllerModel, LoopStyle};
use kerf_solver::planar::{Vec2, find_self_intersection};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

const VERTICES: usize = 100_000;
const LAYERS: usize = 50;

/// A castellated ring: 100 000 points on a circle of radius 300 mm, every 500 points stepping
/// 3 mm out or back in, so 200 sharp corners (100 convex with loops, 100 inside) between long
/// finely tessellated arcs.
fn castellated_ring() -> Vec<[f64; 2]> {
    (0..VERTICES)
        .map(|i| {
            let angle = std::f64::consts::TAU * i as f64 / VERTICES as f64;
            let radius = if (i / 500) % 2 == 0 { 300.0 } else { 303.0 };
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect()
}

fn big_request() -> ContourRequest {
    serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 1.0},
        "contour": castellated_ring(),
        "side": "outside",
        "depths": {"top": 0.0, "bottom": -50.0, "step": 1.0},
        "corner_loop": {"style": "arc"},
        "feed": 1200,
        "loop_feed": 4000
    }))
    .unwrap_or_else(|e| panic!("bench request: {e}"))
}

/// A star of 50 tips (radius 50 mm, valleys at 30 mm), outside, arc loops at the tips, 100 layers
/// of 1 mm, tool radius 3 mm.
fn star_request() -> ContourRequest {
    let contour: Vec<[f64; 2]> = (0..100)
        .map(|k| {
            let angle = std::f64::consts::TAU * f64::from(k) / 100.0;
            let radius = if k % 2 == 0 { 50.0 } else { 30.0 };
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect();
    serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 3.0},
        "contour": contour,
        "side": "outside",
        "depths": {"top": 0.0, "bottom": -100.0, "step": 1.0},
        "corner_loop": {"style": "arc"},
        "feed": 1200,
        "loop_feed": 4000
    }))
    .unwrap_or_else(|e| panic!("star request: {e}"))
}

/// A wavy outline of 20 000 vertices (radius 100 mm ± 2 mm, 20 waves), outside, 8 layers of
/// 1 mm, tool radius 3 mm.
fn wavy_request() -> ContourRequest {
    let contour: Vec<[f64; 2]> = (0..20_000)
        .map(|k| {
            let angle = std::f64::consts::TAU * f64::from(k) / 20_000.0;
            let radius = 100.0 + 2.0 * (20.0 * angle).sin();
            [radius * angle.cos(), radius * angle.sin()]
        })
        .collect();
    serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": 3.0},
        "contour": contour,
        "side": "outside",
        "depths": {"top": 0.0, "bottom": -8.0, "step": 1.0},
        "corner_loop": {"style": "arc"},
        "feed": 1200,
        "loop_feed": 4000
    }))
    .unwrap_or_else(|e| panic!("wavy request: {e}"))
}

fn resolved(tool: &Tool) -> Resolved<Tool> {
    Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() }
}

fn fixture_request(case: &Value, loops: bool, controller: Option<ControllerModel>) -> (ContourRequest, Tool) {
    let inputs = &case["inputs"];
    let radius = inputs["tool_radius"].as_f64().unwrap_or(1.0);
    let mut corner_loop = json!({"max_angle_deg": 179.0});
    let passes: Vec<Value> = inputs["passes"]
        .as_array()
        .map(Vec::as_slice)
        .unwrap_or_default()
        .iter()
        .map(|pass| match pass["join"].as_str().unwrap_or("") {
            "loop_arc" => {
                corner_loop["style"] = json!("arc");
                corner_loop["radius"] = pass["rho"].clone();
                json!({"allowance": pass["delta"], "loop": true})
            }
            "loop_par" => {
                corner_loop["style"] = json!("parallelogram");
                corner_loop["leg"] = pass["L"].clone();
                json!({"allowance": pass["delta"], "loop": true})
            }
            _ => json!({"allowance": pass["delta"], "loop": false, "join": "round"}),
        })
        .collect();
    let mut request: ContourRequest = serde_json::from_value(json!({
        "tool": {"kind": "flat", "radius": radius},
        "contour": inputs["contour"],
        "side": "outside",
        "direction": "conventional",
        "depths": {"top": 1.0, "bottom": 0.0, "step": 1.0},
        "corner_loop": corner_loop,
        "passes": passes,
        "feed": 600
    }))
    .unwrap_or_else(|e| panic!("fixture request: {e}"));
    if !loops {
        request.corner_loop.style = LoopStyle::None;
    }
    request.controller = controller;
    (request, Tool::new(ToolKind::Flat, radius))
}

/// The with/without-loops material table, printed once: per corner of the final
/// pass, material left / over-cut (mm²) with loops, and without loops as miter or round joins,
/// ideal and under M1 (blend radius ρ_b: 1.5 mm for C1 as in docs/spec/contour.md §3.10, 1 mm for C2 as in
/// its case, 3 mm for C3) and M2 (servo T = 31.62 ms at 600 mm/min: Δ = 0.05 mm on a 1 mm arc).
fn material_table() {
    let fixture: Value = serde_json::from_str(include_str!("../tests/fixtures/contour.json")).unwrap_or(Value::Null);
    println!("material per corner, final pass: left area / over-cut area, mm²");
    for case in fixture["cases"].as_array().map(Vec::as_slice).unwrap_or_default() {
        let id = case["id"].as_str().unwrap_or("?");
        let blend = match id {
            "C1" => 1.5,
            "C2" => 1.0,
            _ => 3.0,
        };
        let models = [
            ("ideal", None),
            ("M1", Some(ControllerModel { blend_radius: Some(blend), servo_time_constant_ms: None })),
            ("M2", Some(ControllerModel { blend_radius: None, servo_time_constant_ms: Some(31.622_776_6) })),
        ];
        for (label, model) in &models {
            for variant in ["loops", "miter", "round"] {
                let (mut request, tool) = fixture_request(case, variant == "loops", model.clone());
                if variant != "loops"
                    && let Some(passes) = request.passes.as_mut()
                {
                    for pass in passes.iter_mut() {
                        pass.join = if variant == "round" { contour::Join::Round } else { contour::Join::Miter };
                    }
                }
                let Ok(answer) = contour::solve(&request, &tool) else {
                    continue;
                };
                let cells: Vec<String> = answer
                    .corners
                    .iter()
                    .map(|c| {
                        let m = c.predicted.unwrap_or(c.material);
                        format!("{:.0}°:{:.6}/{:.6}", c.angle_deg, m.left_area, m.overcut_area)
                    })
                    .collect();
                let name = if *label == "M1" { format!("M1 ρb={blend}") } else { (*label).to_owned() };
                println!("  {id} {name:<9} {variant:<6} {}", cells.join("  "));
            }
        }
    }
}

fn bench(c: &mut Criterion) {
    material_table();
    let request = big_request();
    let tool = Tool::new(ToolKind::Flat, 1.0);
    let answer = contour::solve(&request, &tool).unwrap_or_else(|e| panic!("{}", e.message()));
    println!(
        "100k ring: {} layers, {} moves, {} corners looped",
        answer.summary.layers,
        answer.summary.moves,
        answer.corners.iter().filter(|c| c.looped).count()
    );
    drop(answer);

    let mut group = c.benchmark_group("contour");
    group.sample_size(10);
    group.throughput(Throughput::Elements((VERTICES * LAYERS) as u64));
    group.bench_function("solve_100k_vertices_50_layers", |b| {
        b.iter(|| contour::solve(black_box(&request), &tool).map(|a| a.summary.moves))
    });
    group.throughput(Throughput::Elements(VERTICES as u64));
    group.bench_function("plan_100k_vertices_one_layer", |b| {
        b.iter(|| contour::plan(black_box(&request), &tool).map(|p| p.passes.len()))
    });
    let polygon: Vec<Vec2> = castellated_ring().into_iter().map(|[x, y]| Vec2::new(x, y)).collect();
    group.bench_function("simple_polygon_check_100k", |b| {
        b.iter(|| find_self_intersection(black_box(&polygon), kerf_solver::control::Control::default()))
    });
    group.finish();

    let mut group = c.benchmark_group("contour_peers");
    group.sample_size(20);
    let tool = Tool::new(ToolKind::Flat, 3.0);
    for (name, request) in [("star_50_tips_100_layers", star_request()), ("wavy_20k_vertices_8_layers", wavy_request())]
    {
        let answer = ContourCapability::solve(&request, resolved(&tool), &Run::default())
            .unwrap_or_else(|e| panic!("{name}: {}", e.message()));
        let json = ContourCapability::to_json(answer.clone()).map(|j| j.len()).unwrap_or(0);
        println!("{name}: {} moves, {json} bytes of JSON", answer.result.summary.moves);
        group.bench_function(format!("{name}/solve"), |b| {
            b.iter(|| {
                ContourCapability::solve(black_box(&request), resolved(&tool), &Run::default())
                    .map(|a| a.result.summary.moves)
            })
        });
        group.bench_function(format!("{name}/json"), |b| {
            b.iter_batched(|| answer.clone(), |a| ContourCapability::to_json(a).map(|j| j.len()), BatchSize::LargeInput)
        });
        group.bench_function(format!("{name}/request"), |b| {
            b.iter(|| {
                let answer = ContourCapability::solve(black_box(&request), resolved(&tool), &Run::default());
                answer.map(|a| ContourCapability::to_json(a).map(|j| j.len()))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
