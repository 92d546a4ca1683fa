//! The measurements behind the capabilities' cost models (how a job's operation is cut
//! into parts; docs/guide/performance.md, "Split cost models"): core-seconds on one thread (CPU time, so a shared
//! machine's load matters less than to wall time) of the work a split request's parts and finish
//! step do. A measurement, not a test; run one section or all:
//!
//! ```sh
//! cargo run --release -p kerf-solver --example cost_model -- predict engagement
//! cargo run -p kerf-solver --example cost_model -- ratio contour deburr   # debug build
//! ```
//!
//! `ratio` times one predict case whose release figure docs/guide/performance.md gives (0.81 ms per pass,
//! sampling, N = 256, 4 passes per mm²), so figures measured in a debug build can be scaled to a
//! release build's: the contour and deburr constants were measured that way.

use kerf_cases::predict as support;
use kerf_cases::split::{
    Texts, context, contour_context, contour_request, deburr_context, deburr_request, engagement_request,
};
use kerf_solver::capability::{self, Capability, Control, OutputOptions, Part, Purpose, Resolved, Run, Sizing};
use kerf_solver::contour::ContourCapability;
use kerf_solver::deburr::DeburrCapability;
use kerf_solver::engagement::EngagementCapability;
use kerf_solver::predict::{Method, PredictCapability, PredictRequest};
use kerf_solver::tool::Tool;
use serde_json::json;

/// Process CPU time (user + system) in seconds, from /proc (0 where unavailable).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return 0.0 };
    let Some(rest) = stat.rsplit(')').next() else { return 0.0 };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// Runs `work` on one thread: its result and CPU seconds.
fn timed<T: Send>(pool: &rayon::ThreadPool, work: impl FnOnce() -> T + Send) -> (T, f64) {
    let cpu = cpu_seconds();
    let result = pool.install(work);
    (result, cpu_seconds() - cpu)
}

fn main() {
    let sections: Vec<String> = std::env::args().skip(1).collect();
    let wanted = |name: &str| sections.is_empty() || sections.iter().any(|s| s == name);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    if wanted("ratio") {
        ratio(&pool);
    }
    if wanted("predict") {
        predict(&pool);
    }
    if wanted("engagement") {
        engagement(&pool);
    }
    if wanted("contour") {
        contour(&pool);
    }
    if wanted("deburr") {
        deburr(&pool);
    }
}

/// Core-seconds of solving `request` with `pass_range` set.
fn predict_seconds(pool: &rayon::ThreadPool, request: &PredictRequest, tool: &Tool) -> f64 {
    timed(pool, || PredictCapability::solve(request, context(tool), &Run::default()).unwrap()).1
}

/// The debug/release ratio: predict's sampling pass at N = 256, pick 0.5 mm, whose release
/// figure is 0.81 ms (docs/guide/performance.md), on a smaller raster (the passes around each one are as many).
fn ratio(pool: &rayon::ThreadPool) {
    let (mut request, tool, moves) = support::raster_request(40.0, 0.5, 0.5, Method::Sampling, 256);
    let (middle, slice) = (moves / 2, 200);
    request.pass_range = Some([middle, middle]);
    let setup = predict_seconds(pool, &request, &tool);
    request.pass_range = Some([middle, middle + slice]);
    let total = predict_seconds(pool, &request, &tool);
    let per_pass = (total - setup) / slice as f64;
    eprintln!(
        "ratio: {per_pass:.3e} core-s per pass here, 0.81e-3 in release: this build is {:.1}× slower",
        per_pass / 0.81e-3
    );
}

/// Predict's cost model (`solver/src/predict/capability.rs`): the setup every part repeats (per
/// pass of the path), a predicted pass by method, N and with or without the force model, and the
/// finish step (per pass), on one thread of the patent's 103 041-pass raster.
fn predict(pool: &rayon::ThreadPool) {
    let slice = 2000;
    // The patent's job is the same raster at a 0.29963 mm pick and step (286 225 passes): three
    // times the passes around each one.
    for (method, resolution, cutting, pick) in [
        (Method::Sampling, 256, true, 0.5),
        (Method::Sampling, 256, false, 0.5),
        (Method::Sampling, 128, true, 0.5),
        (Method::Sampling, 512, true, 0.5),
        (Method::DepthBuffer, 256, true, 0.5),
        (Method::DepthBuffer, 128, true, 0.5),
        (Method::Sampling, 256, true, 0.29963),
        (Method::Sampling, 256, true, 1.0),
        (Method::DepthBuffer, 256, true, 0.29963),
    ] {
        let (mut request, tool, moves) = support::raster_request(160.0, pick, pick, method, resolution);
        if !cutting {
            request.cutting = None;
        }
        let middle = moves / 2;
        request.pass_range = Some([middle, middle]);
        let setup = predict_seconds(pool, &request, &tool);
        request.pass_range = Some([middle, middle + slice]);
        let total = predict_seconds(pool, &request, &tool);
        eprintln!(
            "predict {method:?} N = {resolution}, force {cutting}, pick {pick}: setup {:.3e} core-s per pass of {moves}, \
             {:.3e} per predicted pass",
            setup / moves as f64,
            (total - setup) / slice as f64
        );
    }
    // The finish step: the whole path's passes merged, corrected and written as a program.
    let (request, tool, moves) = support::raster_request(160.0, 0.5, 0.5, Method::Sampling, 64);
    let mut texts = Texts::default();
    let part = Part { units: 0..moves, seconds: 0.0 };
    pool.install(|| PredictCapability::solve_part(&request, context(&tool), &part, &Run::default(), &mut texts))
        .unwrap();
    let ((answer, program), cpu) = timed(pool, || {
        let answer = PredictCapability::finish(&request, context(&tool), &mut texts, &Run::default()).unwrap();
        let program =
            capability::program::<PredictCapability>(&request, &answer, &OutputOptions::default(), Control::default())
                .unwrap();
        (serde_json::to_vec(&answer).unwrap().len(), program.len())
    });
    eprintln!(
        "predict finish, {moves} passes: {:.3e} core-s per pass; answer {} MB, program {} MB",
        cpu / moves as f64,
        answer / 1_000_000,
        program / 1_000_000
    );
}

/// Engagement: core-seconds per sample of the exact engine, per flute count.
fn engagement(pool: &rayon::ThreadPool) {
    for counts in [vec![2], vec![2, 3, 4]] {
        let (mut request, tool, machine) = engagement_request(0.005);
        request.flute_counts = Some(counts.clone());
        let context = Resolved { tool: tool.clone(), machine: Some(machine), material: None, other_tools: Vec::new() };
        let (answer, cpu) = timed(pool, || EngagementCapability::solve(&request, context, &Run::default()).unwrap());
        let samples: usize = answer.result.candidates().iter().map(|c| c.samples.len()).sum();
        eprintln!(
            "engagement, exact, {} flute counts: {samples} samples, {:.3e} core-s per sample and flute count",
            counts.len(),
            cpu / (samples * counts.len()) as f64
        );
    }
}

fn job_run() -> Run<'static> {
    Run { purpose: Purpose::Job, ..Run::default() }
}

/// Core-seconds of the parts of `request` (one part of every unit) and of its finish step (with
/// the answer serialised and the program written, as a worker stores them).
fn parts_and_finish<C: Capability>(
    pool: &rayon::ThreadPool,
    request: &C::Request,
    context: &Resolved<C::Tool>,
    units: usize,
) -> (f64, f64, C::Answer)
where
    Resolved<C::Tool>: Clone + Send + Sync,
    C::Request: Sync,
{
    let mut texts = Texts::default();
    let part = Part { units: 0..units, seconds: 0.0 };
    let ((), parts) = timed(pool, || C::solve_part(request, context.clone(), &part, &job_run(), &mut texts).unwrap());
    let (answer, finish) = timed(pool, || {
        let answer = C::finish(request, context.clone(), &mut texts, &job_run()).unwrap();
        let _ = capability::program::<C>(request, &answer, &OutputOptions::default(), Control::default());
        let _ = serde_json::to_vec(&answer).unwrap();
        answer
    });
    (parts, finish, answer)
}

/// Contour (`solver/src/contour/parts.rs`): a star of `corners` corners (radius `corners` mm,
/// every other corner 3 mm in), two passes; untilted the
/// layers repeat the first layer's plan (per move), tilted every layer is planned (per corner and
/// pass).
fn contour(pool: &rayon::ThreadPool) {
    let star = |corners: usize| -> serde_json::Value {
        json!(
            (0..corners)
                .map(|k| {
                    let angle = std::f64::consts::TAU * k as f64 / corners as f64;
                    let radius = corners as f64 - if k % 2 == 0 { 0.0 } else { 3.0 };
                    [radius * angle.cos(), radius * angle.sin()]
                })
                .collect::<Vec<_>>()
        )
    };
    for corners in [100, 400] {
        let passes = 2;
        for (layers, tilt) in [(1, false), (100, false), (20, true)] {
            let extra = if tilt {
                json!({"contour": star(corners), "inside_corner_relief": "none", "tilt_deg": 2})
            } else {
                json!({"contour": star(corners), "inside_corner_relief": "none"})
            };
            let request = contour_request(layers, extra);
            let context = contour_context(false);
            let (parts, finish, answer) = parts_and_finish::<ContourCapability>(pool, &request, &context, layers);
            let moves = answer.result.summary.moves;
            eprintln!(
                "contour, {corners} corners, {passes} passes, {layers} layers, tilted {tilt}: {moves} moves; parts \
                 {parts:.3} core-s, finish {finish:.3}; per corner and pass and layer {:.3e}; per move {:.3e} (parts), \
                 {:.3e} (finish)",
                parts / (corners * passes * layers) as f64,
                parts / moves as f64,
                finish / moves as f64,
            );
        }
    }
    let (request, context) = (contour_request(40, json!({"tilt_deg": 2})), contour_context(false));
    let split = ContourCapability::split(&request, &context, &Sizing { part_seconds: 1e-3, max_parts: 1000 });
    eprintln!("(the tilted arrow, 40 layers, at 1 ms parts: {:?} parts)", split.map(|s| s.parts.len()));
}

/// Deburr (`solver/src/deburr/parts.rs`): core-seconds per loop and per point by method, from
/// loops of two sizes at two tolerances.
fn deburr(pool: &rayon::ThreadPool) {
    for method in ["tangent", "exact"] {
        for (radius, tolerance) in [(3.0, 0.01), (6.0, 0.01), (5.0, 0.001)] {
            let holes: Vec<(f64, f64, f64)> =
                (0..60).map(|i| (radius, 60.0 * (i % 6) as f64, 20.0 * i as f64)).collect();
            let request = deburr_request(&holes, "outer", json!({"method": method, "tolerance": tolerance}));
            let context = deburr_context(None, false);
            let (parts, finish, answer) = parts_and_finish::<DeburrCapability>(pool, &request, &context, holes.len());
            let points: usize = answer.holes.iter().flatten().map(|hole| hole.result.summary.count).sum();
            eprintln!(
                "deburr {method}, R {radius}, TA {tolerance}: {} loops, {points} points; {:.3e} core-s per loop, {:.3e} \
                 per point; finish {finish:.3e}",
                holes.len(),
                parts / holes.len() as f64,
                parts / points as f64
            );
        }
    }
}
