//! Requests split into parts (a job's chunks on different workers): solving the parts
//! apart, passing their outputs through JSON as the job store does, and finishing gives the
//! answer and program of solving the request whole, byte for byte.

use kerf_cases::predict;
use kerf_cases::split::{
    Texts, context, contour_context, contour_request, deburr_context, deburr_request, engagement_request,
};
use kerf_solver::capability::{self, Capability, Control, OutputOptions, Part, Purpose, Resolved, Run, Sizing, Split};
use kerf_solver::contour::ContourCapability;
use kerf_solver::deburr::DeburrCapability;
use kerf_solver::engagement::EngagementCapability;
use kerf_solver::predict::{CorrectionOptions, Method, PredictCapability, PredictRequest};
use kerf_solver::tool::Tool;
use proptest::prelude::*;
use serde_json::json;

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
    let program =
        capability::program::<PredictCapability>(request, &answer, &OutputOptions::default(), Control::default())
            .unwrap();
    Some((serde_json::to_string(&answer).unwrap(), program, parts.len()))
}

fn whole(request: &PredictRequest, tool: &Tool) -> (String, String) {
    let answer = PredictCapability::solve(request, context(tool), &Run::default()).unwrap();
    let program =
        capability::program::<PredictCapability>(request, &answer, &OutputOptions::default(), Control::default())
            .unwrap();
    (serde_json::to_string(&answer).unwrap(), program)
}

#[test]
fn a_prediction_split_into_parts_is_the_whole_prediction() {
    // 21 × 21 passes over a 10 mm square: every part boundary falls inside a raster line, where
    // the corrections need the errors on both sides.
    let (request, tool, moves) = predict::raster_request(10.0, 0.5, 0.5, Method::Sampling, 48);
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
    let (mut request, tool, _) = predict::raster_request(10.0, 0.5, 0.5, Method::DepthBuffer, 32);
    request.pass_range = Some([100, 300]);
    request.exclusion_deg = Some(5.0);
    let (json, program) = whole(&request, &tool);
    let (split_json, split_program, parts) = split_and_finish(&request, &tool, 0.01).expect("splits");
    assert!(parts >= 2);
    assert!(split_json == json && split_program == program);
}

#[test]
fn what_is_not_split() {
    let (mut request, tool, _) = predict::raster_request(10.0, 0.5, 0.5, Method::Sampling, 48);
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

#[test]
fn engagement_candidates_split_into_parts_are_the_whole_comparison() {
    let (request, tool, machine) = engagement_request(0.05);
    let context =
        || Resolved { tool: tool.clone(), machine: Some(machine.clone()), material: None, other_tools: Vec::new() };
    let whole = EngagementCapability::solve(&request, context(), &Run::default()).unwrap();
    let output = OutputOptions::default();
    let whole_program =
        capability::program::<EngagementCapability>(&request, &whole, &output, Control::default()).unwrap();
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
            capability::program::<EngagementCapability>(&request, &merged, &output, Control::default()).unwrap()
                == capability::program::<EngagementCapability>(&request, &whole, &output, Control::default()).unwrap(),
            "candidate {candidate}'s program"
        );
    }
    assert!(
        capability::program::<EngagementCapability>(&request, &merged, &OutputOptions::default(), Control::default())
            .unwrap()
            == whole_program
    );
    // One path, or parts that one would hold, stay whole.
    assert!(EngagementCapability::split(&request, &context(), &Sizing { part_seconds: 1e6, max_parts: 16 }).is_none());
}

/// A job's run: what a worker solves with.
fn job_run() -> Run<'static> {
    Run { purpose: Purpose::Job, ..Run::default() }
}

/// The program of `answer`, or why there is none (a tilted wall's contour has none: only its
/// JSON answer carries the axes).
fn program_of<C: Capability>(request: &C::Request, answer: &C::Answer) -> String {
    capability::program::<C>(request, answer, &OutputOptions::default(), Control::default())
        .unwrap_or_else(|error| format!("{error:?}"))
}

/// The answer's JSON and program of solving `request` whole, as one process runs a job.
fn whole_of<C: Capability>(request: &C::Request, context: &Resolved<C::Tool>) -> (String, String)
where
    Resolved<C::Tool>: Clone,
{
    let answer = C::solve(request, context.clone(), &job_run()).unwrap();
    (serde_json::to_string(&answer).unwrap(), program_of::<C>(request, &answer))
}

/// The answer's JSON and program of solving `parts` of `request` apart (their outputs through
/// JSON, as the job store passes them on through CBOR) and finishing.
fn parts_of<C: Capability>(request: &C::Request, context: &Resolved<C::Tool>, parts: &[Part]) -> (String, String)
where
    Resolved<C::Tool>: Clone,
{
    let mut texts = Texts::default();
    for part in parts {
        C::solve_part(request, context.clone(), part, &job_run(), &mut texts).unwrap();
    }
    let answer = C::finish(request, context.clone(), &mut texts, &job_run()).unwrap();
    (serde_json::to_string(&answer).unwrap(), program_of::<C>(request, &answer))
}

/// Splits at `part_seconds` and asserts the merged answer and program are the whole ones; the
/// number of parts.
fn assert_split_is_whole<C: Capability>(
    label: &str,
    request: &C::Request,
    context: &Resolved<C::Tool>,
    part_seconds: f64,
) -> usize
where
    Resolved<C::Tool>: Clone,
{
    let Split { parts, finish_seconds } = C::split(request, context, &Sizing { part_seconds, max_parts: 1000 })
        .unwrap_or_else(|| panic!("{label}: splits at {part_seconds} core-s"));
    assert!(parts.len() >= 2 && finish_seconds > 0.0, "{label}: {} parts", parts.len());
    assert!(parts.windows(2).all(|pair| pair[0].units.end == pair[1].units.start), "{label}: consecutive parts");
    let (json, program) = whole_of::<C>(request, context);
    let (split_json, split_program) = parts_of::<C>(request, context, &parts);
    assert!(split_json == json, "{label}: the merged answer differs from the whole one ({} parts)", parts.len());
    assert!(split_program == program, "{label}: the merged program differs from the whole one");
    parts.len()
}

/// `units` cut at the sorted, distinct `cuts` (each within it) into consecutive parts.
fn cut(units: usize, cuts: &[usize]) -> Vec<Part> {
    let mut bounds: Vec<usize> = cuts.iter().map(|c| c % units.max(1)).filter(|&c| c > 0).collect();
    bounds.sort_unstable();
    bounds.dedup();
    bounds.insert(0, 0);
    bounds.push(units);
    bounds.windows(2).map(|pair| Part { units: pair[0]..pair[1], seconds: 1.0 }).collect()
}

#[test]
fn contour_layers_split_into_parts_are_the_whole_contour() {
    let cases = [
        // Layers repeat the first one's plan: only many split, into parts ten times the plan.
        ("arrow", contour_request(1, json!({"depths": {"top": 0, "bottom": -9, "step": 0.02}})), false),
        ("tilted walls", contour_request(9, json!({"tilt_deg": 3})), false),
        ("ramped, on a machine", contour_request(10, json!({"machine": "mill", "ramp_angle_deg": 3})), true),
        (
            "lead shortened",
            contour_request(
                1,
                json!({"side": "inside", "lead": 100, "depths": {"top": 0, "bottom": -6, "step": 0.02}}),
            ),
            false,
        ),
    ];
    for (label, request, machine) in cases {
        let context = contour_context(machine);
        for part_seconds in [1e-6, 1e-3] {
            assert_split_is_whole::<ContourCapability>(label, &request, &context, part_seconds);
        }
        let answer = ContourCapability::solve(&request, context.clone(), &job_run()).unwrap();
        let shortened = answer.result.warnings.iter().any(|w| w.code == "W_LEAD_SHORTENED");
        assert_eq!(shortened, label == "lead shortened", "{label}");
        assert!(ContourCapability::split(&request, &context, &Sizing { part_seconds: 1e6, max_parts: 1000 }).is_none());
    }
    // A refused contour is solved whole, which reports why.
    let refused = contour_request(5, json!({"feed": -1}));
    assert!(
        ContourCapability::split(&refused, &contour_context(false), &Sizing { part_seconds: 1e-9, max_parts: 9 })
            .is_none()
    );
}

#[test]
fn deburr_loops_split_into_parts_are_the_whole_deburring() {
    // Holes up, down (turned, M00) and sideways, out of order along the tube.
    let holes = [(5.0, 0.0, 0.0), (4.0, 180.0, 40.0), (5.0, 90.0, 80.0), (3.0, 170.0, 10.0), (4.0, 10.0, 120.0)];
    let cases = [
        ("outer edges", deburr_request(&holes, "outer", json!({})), deburr_context(None, false)),
        (
            "both edges, an inner tool, a machine",
            deburr_request(&holes, "both", json!({"inner_tool": 8, "machine": "mill"})),
            deburr_context(Some(2.0), true),
        ),
        ("exact method", deburr_request(&holes[..3], "inner", json!({"method": "exact"})), deburr_context(None, false)),
    ];
    for (label, request, context) in cases {
        for part_seconds in [1e-9, 1e-3] {
            assert_split_is_whole::<DeburrCapability>(label, &request, &context, part_seconds);
        }
        assert!(DeburrCapability::split(&request, &context, &Sizing { part_seconds: 1e6, max_parts: 1000 }).is_none());
    }
    // A pattern's copies split too; one hole does not.
    let mut pattern = deburr_request(
        &[],
        "outer",
        json!({"hole": {"shape": "slot", "radius": 3, "centre_distance": 6}, "pattern": {"around_deg": [0, 120, 240], "pitch": 30, "count": 2}}),
    );
    pattern.holes = None;
    assert_split_is_whole::<DeburrCapability>("pattern", &pattern, &deburr_context(None, false), 1e-9);
    let mut one = pattern.clone();
    one.pattern = None;
    assert!(
        DeburrCapability::split(&one, &deburr_context(None, false), &Sizing { part_seconds: 1e-9, max_parts: 9 })
            .is_none()
    );
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, ..ProptestConfig::default() })]

    /// Any number of layers cut anywhere into parts merges into the whole contour.
    #[test]
    fn contour_parts_cut_anywhere_are_the_whole(
        layers in 1usize..14,
        cuts in proptest::collection::vec(0usize..100, 0..6),
        tilted in any::<bool>(),
        machine in any::<bool>(),
    ) {
        let extra = if tilted { json!({"tilt_deg": 2}) } else if machine { json!({"machine": "mill"}) } else { json!({}) };
        let request = contour_request(layers, extra);
        let context = contour_context(machine && !tilted);
        let parts = cut(layers, &cuts);
        let (json, program) = whole_of::<ContourCapability>(&request, &context);
        let (split_json, split_program) = parts_of::<ContourCapability>(&request, &context, &parts);
        prop_assert!(split_json == json, "{} parts of {layers} layers", parts.len());
        prop_assert!(split_program == program);
    }

    /// Any list of holes cut anywhere into parts merges into the whole deburring, visiting
    /// order, turns and tool change included.
    #[test]
    fn deburr_parts_cut_anywhere_are_the_whole(
        holes in proptest::collection::vec((3.0f64..6.0, prop_oneof![Just(0.0), Just(90.0), Just(180.0), -60.0f64..60.0], 0.0f64..200.0), 1..7),
        cuts in proptest::collection::vec(0usize..100, 0..6),
        both in any::<bool>(),
    ) {
        let (edge, extra, inner) = if both { ("both", json!({"inner_tool": 8}), Some(2.0)) } else { ("outer", json!({}), None) };
        // Holes far enough apart along the tube not to meet.
        let holes: Vec<(f64, f64, f64)> =
            holes.iter().enumerate().map(|(i, &(r, a, along))| (r, a, (along / 20.0).floor() * 20.0 + 200.0 * i as f64)).collect();
        let request = deburr_request(&holes, edge, extra);
        let context = deburr_context(inner, false);
        let loops = holes.len() * if both { 2 } else { 1 };
        let parts = cut(loops, &cuts);
        let (json, program) = whole_of::<DeburrCapability>(&request, &context);
        let (split_json, split_program) = parts_of::<DeburrCapability>(&request, &context, &parts);
        prop_assert!(split_json == json, "{} parts of {loops} loops", parts.len());
        prop_assert!(split_program == program);
    }
}
