//! Requests split into parts (issue 12: a job's chunks on different workers): solving the parts
//! apart, passing their outputs through JSON as the job store does, and finishing gives the
//! answer and program of solving the request whole, byte for byte.

#[path = "predict_support/mod.rs"]
mod support;

use kerf_solver::capability::{self, Capability, OutputOptions, PartSink, PartSource, Resolved, Run, Sizing, Split};
use kerf_solver::engagement::{EngagementCapability, EngagementRequest};
use kerf_solver::machine::MachineProfile;
use kerf_solver::predict::{CorrectionOptions, Method, PredictCapability, PredictRequest};
use kerf_solver::tool::Tool;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// Parts' outputs as JSON text, as the job store keeps them.
#[derive(Default)]
struct Texts(Vec<String>, usize);

impl PartSink for Texts {
    fn put<T: Serialize>(&mut self, value: &T) -> Result<(), kerf_solver::SolverError> {
        self.0.push(serde_json::to_string(value).unwrap());
        Ok(())
    }
}

impl PartSource for Texts {
    fn count(&self) -> usize {
        self.0.len()
    }

    fn next_part<T: DeserializeOwned>(&mut self) -> Option<Result<T, kerf_solver::SolverError>> {
        let text = self.0.get(self.1)?;
        self.1 += 1;
        Some(Ok(serde_json::from_str(text).unwrap()))
    }
}

fn context(tool: &Tool) -> Resolved<Tool> {
    Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() }
}

/// Splits into parts of `part_seconds`, solves them apart and finishes: the answer's JSON and
/// program, and how many parts there were.
fn split_and_finish(request: &PredictRequest, tool: &Tool, part_seconds: f64) -> Option<(String, String, usize)> {
    let sizing = Sizing { part_seconds, max_parts: 1000 };
    let Split { parts, .. } = PredictCapability::split(request, &context(tool), &sizing)?;
    let mut texts = Texts::default();
    for part in &parts {
        PredictCapability::solve_part(request, context(tool), part, &Run::default(), &mut texts).unwrap();
    }
    let answer = PredictCapability::finish(request, context(tool), &mut texts, &Run::default()).unwrap();
    let program = capability::program::<PredictCapability>(request, &answer, &OutputOptions::default()).unwrap();
    Some((serde_json::to_string(&answer).unwrap(), program, parts.len()))
}

fn whole(request: &PredictRequest, tool: &Tool) -> (String, String) {
    let answer = PredictCapability::solve(request, context(tool), &Run::default()).unwrap();
    let program = capability::program::<PredictCapability>(request, &answer, &OutputOptions::default()).unwrap();
    (serde_json::to_string(&answer).unwrap(), program)
}

#[test]
fn a_prediction_split_into_parts_is_the_whole_prediction() {
    // 21 × 21 passes over a 10 mm square: every part boundary falls inside a raster line, where
    // the corrections need the errors on both sides.
    let (request, tool, moves) = support::raster_request(10.0, 0.5, 0.5, Method::Sampling, 48);
    let (json, program) = whole(&request, &tool);
    for part_seconds in [1e-3, 0.02, 0.05] {
        let (split_json, split_program, parts) =
            split_and_finish(&request, &tool, part_seconds).expect("the prediction splits");
        assert!(parts >= 2, "{parts} parts of {moves} passes");
        assert!(split_json == json, "the merged answer differs from the whole one ({parts} parts)");
        assert!(split_program == program, "the merged program differs from the whole one ({parts} parts)");
    }
}

#[test]
fn a_range_of_passes_splits_within_it() {
    let (mut request, tool, _) = support::raster_request(10.0, 0.5, 0.5, Method::DepthBuffer, 32);
    request.pass_range = Some([100, 300]);
    request.exclusion_deg = Some(5.0);
    let (json, program) = whole(&request, &tool);
    let (split_json, split_program, parts) = split_and_finish(&request, &tool, 0.01).expect("splits");
    assert!(parts >= 2);
    assert!(split_json == json && split_program == program);
}

#[test]
fn what_is_not_split() {
    let (mut request, tool, _) = support::raster_request(10.0, 0.5, 0.5, Method::Sampling, 48);
    // Large parts: one would do.
    assert!(split_and_finish(&request, &tool, 1e6).is_none());
    // A second round predicts the path the first corrected: not split.
    request.correction = Some(CorrectionOptions { max_correction: None, iterations: Some(2) });
    assert!(split_and_finish(&request, &tool, 1e-3).is_none());
    // A refused request is solved whole, which reports why.
    request.correction = None;
    request.resolution = Some(1);
    assert!(split_and_finish(&request, &tool, 1e-3).is_none());
}

/// Three candidate paths through a 60 × 40 mm block, cut by a 4-flute Ø10 end mill at 2 mm a_p
/// with Kienzle forces, on a machine with a block time and accelerations (blocks, cycle time).
fn engagement_request(step: f64) -> (EngagementRequest, Tool, MachineProfile) {
    let request = serde_json::from_value(serde_json::json!({
        "tool": 1, "machine": "mill",
        "stock": {"polygon": [[0, 0], [60, 0], [60, 40], [0, 40]]},
        "paths": [
            {"name": "straight", "path": [[-10, 20], [70, 20]]},
            {"name": "zig-zag", "path": [[-10, 5], [70, 5], [70, 15], [-10, 15], [-10, 25], [70, 25]]},
            {"name": "deeper", "path": [[-10, 30], [35, 20], [70, 35]], "axial_depth": 3},
        ],
        "spindle_rpm": 8000, "feed_per_tooth": 0.05, "flute_counts": [2, 3, 4],
        "thickness_limit": 0.08, "step": step, "kienzle": {"kc11": 1800, "mc": 0.25}, "axial_depth": 2,
        "candidate": 1,
    }))
    .unwrap();
    let mut tool = Tool::new(kerf_solver::tool::ToolKind::Flat, 5.0);
    tool.flutes = 4;
    let machine = serde_json::from_value(serde_json::json!({
        "name": "mill", "block_time_ms": 4, "max_feed": 12000, "max_accel": 2000, "dialect": "linuxcnc"
    }))
    .unwrap();
    (request, tool, machine)
}

#[test]
fn engagement_candidates_split_into_parts_are_the_whole_comparison() {
    let (request, tool, machine) = engagement_request(0.05);
    let context =
        || Resolved { tool: tool.clone(), machine: Some(machine.clone()), material: None, other_tools: Vec::new() };
    let whole = EngagementCapability::solve(&request, context(), &Run::default()).unwrap();
    let output = OutputOptions::default();
    let whole_program = capability::program::<EngagementCapability>(&request, &whole, &output).unwrap();
    assert!(whole.cycle_time.is_some() && whole.result.candidates().iter().all(|c| c.blocks.is_some()));
    let Split { parts, .. } =
        EngagementCapability::split(&request, &context(), &Sizing { part_seconds: 1e-4, max_parts: 16 })
            .expect("three candidates split");
    assert_eq!(parts.len(), 3);
    let mut texts = Texts::default();
    for part in &parts {
        EngagementCapability::solve_part(&request, context(), part, &Run::default(), &mut texts).unwrap();
    }
    let merged = EngagementCapability::finish(&request, context(), &mut texts, &Run::default()).unwrap();
    assert!(serde_json::to_string(&merged).unwrap() == serde_json::to_string(&whole).unwrap());
    for candidate in 0..3 {
        let output = OutputOptions { candidate: Some(candidate), ..output };
        assert!(
            capability::program::<EngagementCapability>(&request, &merged, &output).unwrap()
                == capability::program::<EngagementCapability>(&request, &whole, &output).unwrap(),
            "candidate {candidate}'s program"
        );
    }
    assert!(
        capability::program::<EngagementCapability>(&request, &merged, &OutputOptions::default()).unwrap()
            == whole_program
    );
    // One path, or parts that one would hold, stay whole.
    assert!(EngagementCapability::split(&request, &context(), &Sizing { part_seconds: 1e6, max_parts: 16 }).is_none());
}

/// Process CPU time (user + system) in seconds, from /proc (0 where unavailable).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else { return 0.0 };
    let Some(rest) = stat.rsplit(')').next() else { return 0.0 };
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// The measurements behind predict's cost model (`solver/src/predict/capability.rs`, README "More
/// than one machine"): core-seconds of the setup every part repeats (per pass of the path), of a
/// predicted pass by method, N and with or without the force model, and of the finish step (per
/// pass), on one thread of the seed's 103 041-pass raster. CPU time, so a shared machine's load
/// matters less than to wall time.
///
/// `cargo test --release -p kerf-solver --test split_parts -- --ignored --nocapture cost_model`
#[test]
#[ignore = "a measurement, minutes long: run it in release builds"]
fn cost_model() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    let slice = 2000;
    let measure = |label: &str, request: &PredictRequest, tool: &Tool, count: usize| {
        let (started, cpu) = (std::time::Instant::now(), cpu_seconds());
        pool.install(|| PredictCapability::solve(request, context(tool), &Run::default()).unwrap());
        let (wall, cpu) = (started.elapsed().as_secs_f64(), cpu_seconds() - cpu);
        eprintln!("{label}: {cpu:.3} s CPU ({wall:.3} s wall), {:.3e} core-s per unit of {count}", cpu / count as f64);
        cpu
    };
    // The seed's job is the same raster at a 0.29963 mm pick and step (286 225 passes): three
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
        let setup = measure(&format!("setup, {moves} passes"), &request, &tool, moves);
        request.pass_range = Some([middle, middle + slice]);
        let total =
            measure(&format!("{method:?} N = {resolution}, force {cutting}, pick {pick}"), &request, &tool, slice);
        eprintln!("  per pass without the setup: {:.3e} core-s", (total - setup) / slice as f64);
    }
    // Engagement: core-seconds per sample of the exact engine, per flute count.
    for counts in [vec![2], vec![2, 3, 4]] {
        let (mut request, tool, machine) = engagement_request(0.005);
        request.flute_counts = Some(counts.clone());
        let context = Resolved { tool: tool.clone(), machine: Some(machine), material: None, other_tools: Vec::new() };
        let (started, cpu) = (std::time::Instant::now(), cpu_seconds());
        let answer = pool.install(|| EngagementCapability::solve(&request, context, &Run::default()).unwrap());
        let cpu = cpu_seconds() - cpu;
        let samples: usize = answer.result.candidates().iter().map(|c| c.samples.len()).sum();
        eprintln!(
            "engagement, exact, {} flute counts: {samples} samples, {cpu:.3} s CPU ({:.3} s wall), {:.3e} core-s per \
             sample and flute count",
            counts.len(),
            started.elapsed().as_secs_f64(),
            cpu / (samples * counts.len()) as f64
        );
    }
    // The finish step: the whole path's passes merged (all `not_predicted` but one slice, which
    // costs the same to merge), corrected and written as a program.
    let (request, tool, moves) = support::raster_request(160.0, 0.5, 0.5, Method::Sampling, 64);
    let parts = PredictCapability::split(&request, &context(&tool), &Sizing { part_seconds: 1e9, max_parts: 2 })
        .map_or(0, |split| split.parts.len());
    eprintln!("(sizing at one part: {parts} parts)");
    let mut texts = Texts::default();
    let part = kerf_solver::capability::Part { units: 0..moves, seconds: 0.0 };
    pool.install(|| PredictCapability::solve_part(&request, context(&tool), &part, &Run::default(), &mut texts))
        .unwrap();
    let (started, cpu) = (std::time::Instant::now(), cpu_seconds());
    let answer = pool.install(|| {
        let answer = PredictCapability::finish(&request, context(&tool), &mut texts, &Run::default()).unwrap();
        let program = capability::program::<PredictCapability>(&request, &answer, &OutputOptions::default()).unwrap();
        (serde_json::to_vec(&answer).unwrap().len(), program.len())
    });
    let cpu = cpu_seconds() - cpu;
    eprintln!(
        "finish, {moves} passes: {cpu:.3} s CPU ({:.3} s wall), {:.3e} core-s per pass; answer {} MB, program {} MB",
        started.elapsed().as_secs_f64(),
        cpu / moves as f64,
        answer.0 / 1_000_000,
        answer.1 / 1_000_000
    );
}
