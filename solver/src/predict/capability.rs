//! Error prediction as a capability (the seam of engineering.md): `POST /api/v1/predict`, job
//! operation `predict`. The STL file of a `mesh` stock comes as the run's upload.

use std::sync::atomic::AtomicUsize;

use serde::{Deserialize, Serialize};

use super::answer::PassStatus;
use super::pipeline::{self, Context, Outcome};
use super::request::Method;
use super::{PathInput, Predict, PredictRequest, ProgramOptions, correct};
use crate::capability::{
    Capability, Control, Endpoint, OutputOptions, Part, PartSink, PartSource, Refs, Resolved, Run, Sizing, Split,
};
use crate::error::{ErrorCode, SolverError};
use crate::gcode::{Reference, ToolCall};
use crate::geometry::Vec3;
use crate::machine::MachineProfile;
use crate::stock::Stock;
use crate::tool::Tool;
use crate::verify::Verification;
use crate::verify::own::{self, GivenStock, OwnModel};

/// The predict capability.
#[derive(Debug, Clone, Copy)]
pub struct PredictCapability;

/// How long the prediction took (only with `?timings=true`, and in job results: equal requests
/// otherwise give byte-identical answers). Also sent as the `Server-Timing` header.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Timings {
    /// Wall time of the prediction and correction, ms (a job split into parts on several
    /// workers: the parts' times added up, and the finish step's).
    pub solve_ms: f64,
    /// Passes predicted (those in `pass_range`, every round).
    pub passes: usize,
    /// Passes predicted per second of wall time.
    pub passes_per_s: f64,
}

/// The prediction answer: the tool used and the solver's result.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PredictAnswer {
    /// The tool, as resolved from the table or given inline.
    pub tool: Tool,
    /// Per-pass predictions, summary and warnings.
    #[serde(flatten)]
    pub result: Predict,
    /// Timings, when asked for (`?timings=true`) and in job results.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub timings: Option<Timings>,
    /// The corrected program (the one the answer writes) cut on the given stock
    /// (docs/spec/verify.md §9.2): rapids through material, neck, shank and holder contact and
    /// the air share; no part is given, so no gouge or material left. Absent when the request
    /// turns verification off.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verification: Option<Verification>,
}

impl Capability for PredictCapability {
    const NAME: &'static str = "predict";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Predicts the machining error of a ball-end-mill finishing path and corrects the path.",
        description: "Returns one record per pass (error along the surface normal, contact angle, generation \
            point, normal, flags, corrected end point), a summary with the worst passes and warnings \
            (JSON), or with `Accept: text/x-gcode` / `?format=gcode` the corrected program. The body \
            is JSON, or a form with the JSON in part `request` and the STL stock in part `stock`. \
            Long paths exceed the synchronous time limit (422 `E_TIMEOUT`): submit them as a job \
            (`operation = \"predict\"`).",
        not_found: "Unknown tool number",
        refused: "Impossible or over a limit: tool kind, no shape-error table, G-code errors with the \
            line, open mesh, resolution over the memory limit; `E_TIMEOUT` over the synchronous time \
            limit: submit a job; `E_TOO_LARGE_ANSWER` when the answer would not fit the answer budget",
    };
    type Request = PredictRequest;
    type Answer = PredictAnswer;
    type Tool = Tool;

    fn refs(request: &PredictRequest) -> Refs<'_> {
        Refs { tool: Some(&request.tool), machine: None, material: None }
    }

    fn check_output(request: &PredictRequest, output: &OutputOptions) -> Result<(), SolverError> {
        check_reference(request, output.reference)
    }

    /// A `mesh` stock needs the uploaded STL file, and an upload needs a `mesh` stock.
    fn solve(request: &PredictRequest, context: Resolved<Tool>, run: &Run<'_>) -> Result<PredictAnswer, SolverError> {
        check_upload(request, run)?;
        let model = own_model(request, &context.tool, run.upload)?;
        let result = super::solve_run(request, &context.tool, run)?;
        verified(request, model, PredictAnswer { tool: context.tool, result, timings: None, verification: None }, run)
    }

    /// Pass ranges of about `sizing.part_seconds` each (see `cost`). Not split: a refused
    /// request, a mesh stock (a job cannot carry one), `iterations` ≥ 2, whose second round
    /// predicts the path corrected by the first round's errors of every pass, so no part could
    /// start it before all of the first round is done, and `merge_similar_passes`, whose runs of
    /// similar passes would be cut at the part boundaries (the merged answer would differ from
    /// one process's).
    fn split(request: &PredictRequest, context: &Resolved<Tool>, sizing: &Sizing) -> Option<Split> {
        if matches!(request.stock, Stock::Mesh { .. }) {
            return None;
        }
        let job = request.validate(&context.tool, None, Control::default()).ok()?;
        if job.iterations != 1 || job.merge_tolerance.is_some() {
            return None;
        }
        let cost = cost(&job);
        Split::even(job.pass_range.clone(), cost.pass_seconds, cost.setup_seconds, cost.finish_seconds, sizing)
    }

    /// Predicts the passes of `part` (the whole path still sweeps the stock, as with
    /// `pass_range`) and hands on their raw outcomes, in full precision.
    fn solve_part(
        request: &PredictRequest,
        context: Resolved<Tool>,
        part: &Part,
        run: &Run<'_>,
        sink: &mut impl PartSink,
    ) -> Result<(), SolverError> {
        check_upload(request, run)?;
        let mut ranged = request.clone();
        ranged.pass_range = Some([part.units.start, part.units.end]);
        let job = ranged.validate(&context.tool, run.upload, run.control)?;
        let mut outcomes = pipeline::run_round(
            &Context::new(&job),
            &job.path,
            &run.control,
            &AtomicUsize::new(0),
            job.pass_range.len().max(1),
            &|outcome| match run.budget {
                None => Ok(()),
                Some(budget) => budget.charge(super::answer::pass_bytes(outcome, run.purpose, true), 1, 1),
            },
        )?;
        let passes = outcomes.drain(job.pass_range.clone()).collect();
        sink.put(&PartPasses { from: job.pass_range.start, passes })
    }

    /// Merges the parts' passes and finishes as [`super::solve_with`] finishes its one round:
    /// the node corrections from every pass's error, clamped, the per-pass records and summary,
    /// the warnings.
    fn finish(
        request: &PredictRequest,
        context: Resolved<Tool>,
        parts: &mut impl PartSource,
        run: &Run<'_>,
    ) -> Result<PredictAnswer, SolverError> {
        check_upload(request, run)?;
        let model = own_model(request, &context.tool, run.upload)?;
        let job = request.validate(&context.tool, run.upload, run.control)?;
        let count = job.path.passes.len();
        let mut outcomes: Vec<Option<Outcome>> = vec![None; count];
        let mut read = 0;
        while let Some(part) = parts.next_part::<PartPasses>() {
            let part = part?;
            for (offset, pass) in part.passes.into_iter().enumerate() {
                let index = part.from + offset;
                match outcomes.get_mut(index) {
                    Some(slot @ None) if job.pass_range.contains(&index) => *slot = Some(pass),
                    _ => return Err(mismatch(format!("pass {index} is outside the request or in two parts"))),
                }
            }
            read += 1;
            run.control.report(read, parts.count());
            run.control.check()?;
        }
        let outcomes = outcomes
            .into_iter()
            .enumerate()
            .map(|(index, outcome)| match outcome {
                Some(outcome) => Ok(outcome),
                None if !job.pass_range.contains(&index) => Ok(Outcome::empty(PassStatus::NotPredicted)),
                None => Err(mismatch(format!("no part predicted pass {index}"))),
            })
            .collect::<Result<Vec<Outcome>, SolverError>>()?;
        // solve_with's round 0, the only one of a split request.
        let node_count = job.path.nodes.len();
        let (step, _, ambiguous) = super::node_corrections(&job.path, &outcomes, f64::INFINITY);
        let mut total = vec![Vec3::zeros(); node_count];
        let mut clamped = vec![false; node_count];
        for node in 0..node_count {
            total[node] += step[node];
            clamped[node] = correct::clamp(&mut total[node], job.max_correction);
        }
        run.control.check()?;
        let mut result = super::assemble(&job, &[outcomes], &total, &clamped, &ambiguous);
        result.warnings.extend(super::rapid_collisions(&job, &run.control)?);
        verified(request, model, PredictAnswer { tool: context.tool, result, timings: None, verification: None }, run)
    }

    fn set_cut_resolution(request: &mut PredictRequest, resolution: f64) {
        request.verification.get_or_insert_with(Default::default).resolution = Some(resolution);
    }

    /// The given stock less what the corrected program (with its verification's header comments)
    /// cut, up to `upto_line`, coloured by what it cut (there is no part).
    fn cut_stock(
        request: &PredictRequest,
        context: Resolved<Tool>,
        upto_line: Option<usize>,
        units: crate::units::Units,
        run: &Run<'_>,
    ) -> Result<Option<Vec<u8>>, SolverError> {
        check_upload(request, run)?;
        let model = own_model(request, &context.tool, run.upload)?;
        let answer = Self::solve(request, context, run)?;
        let Some((model, grid)) = model else {
            return Ok(None);
        };
        let ask = own::StockAsk { upto_line, units };
        own::partless_cut_stock::<PredictCapability>(&model, grid, request, &answer, &answer.tool, ask, run)
    }

    /// A G-code path is the input program with only the coordinates of moved end points changed
    /// (same lines, comments and modal words; the dialect does not apply); a `points` path becomes
    /// a complete program written for `output.reference` (the request's when not given).
    fn program(
        request: &PredictRequest,
        answer: &PredictAnswer,
        output: &OutputOptions,
        control: Control<'_>,
    ) -> Result<String, SolverError> {
        check_reference(request, output.reference)?;
        let options = ProgramOptions {
            dialect: output.dialect_for(None),
            tool: ToolCall::for_tool(&answer.tool),
            units: output.units.unwrap_or_default(),
        };
        let header = answer.verification.as_ref().map(own::comments).unwrap_or_default();
        match (&request.path, output.reference) {
            (PathInput::Points { points }, Some(asked)) if asked != request.reference => {
                // Tip = centre − R·z: move the points to the other programmed point.
                let shift = if asked == Reference::Centre { answer.tool.radius } else { -answer.tool.radius };
                let mut converted = request.clone();
                converted.reference = asked;
                converted.path =
                    PathInput::Points { points: points.iter().map(|p| [p[0], p[1], p[2] + shift]).collect() };
                super::corrected_program_headed(&converted, &answer.result, &options, &header, control)
            }
            _ => super::corrected_program_headed(request, &answer.result, &options, &header, control),
        }
    }

    fn units(request: &PredictRequest) -> Option<crate::units::Units> {
        request.units
    }

    fn scale_request(request: &mut PredictRequest, scaling: crate::units::Scaling) -> Result<(), SolverError> {
        crate::units::Scale::scale(request, scaling);
        Ok(())
    }

    fn scale_answer(answer: &mut PredictAnswer, scaling: crate::units::Scaling) {
        crate::units::Scale::scale(answer, scaling);
    }

    fn machine(_answer: &PredictAnswer) -> Option<&MachineProfile> {
        None
    }

    fn record_time(answer: &mut PredictAnswer, seconds: f64) {
        let rounds = answer.result.summary.rounds.len().max(1);
        let passes =
            answer.result.passes.iter().filter(|p| p.status != super::PassStatus::NotPredicted).count() * rounds;
        answer.timings = Some(Timings {
            solve_ms: (seconds * 1e4).round() / 10.0,
            passes,
            passes_per_s: if seconds > 0.0 { (passes as f64 / seconds).round() } else { 0.0 },
        });
    }
}

/// A `mesh` stock needs the uploaded STL file, and an upload needs a `mesh` stock.
fn check_upload(request: &PredictRequest, run: &Run<'_>) -> Result<(), SolverError> {
    match (&request.stock, run.upload) {
        (Stock::Mesh { .. }, None) => Err(SolverError::input(
            "stock",
            "a mesh stock needs its STL file: send multipart/form-data with the JSON in part `request` and the STL \
             file in part `stock`",
        )),
        (stock, Some(_)) if !matches!(stock, Stock::Mesh { .. }) => {
            Err(SolverError::input("stock.kind", "an STL file was uploaded but stock.kind is not \"mesh\""))
        }
        _ => Ok(()),
    }
}

/// The prediction's own model and its grid (docs/spec/verify.md §9.2), built before any work so a
/// resolution over the memory limit is refused up front: the given stock, raised by the ball's
/// radius for a path of ball centres, with no part (the design surface is not an input).
/// `None`: verification turned off, or a stock the solve refuses (which names its field).
fn own_model(
    request: &PredictRequest,
    tool: &Tool,
    upload: Option<&[u8]>,
) -> Result<Option<(GivenStock, own::Grid)>, SolverError> {
    let options = request.verification.unwrap_or_default();
    if !options.enabled || !tool.radius.is_finite() || tool.radius <= 0.0 {
        return Ok(None);
    }
    let mesh = if matches!(request.stock, Stock::Mesh { .. }) { upload } else { None };
    let Ok(stock) = request.stock.model(mesh) else {
        return Ok(None);
    };
    let lift = if request.reference == Reference::Centre { tool.radius } else { 0.0 };
    let description = format!(
        "stock: the given {} from 1 mm under the program's lowest tip up{}; part: none (the design surface is not \
         an input), so only rapids through material, neck, shank and holder contact and the air share are checked",
        match request.stock {
            Stock::Box { .. } => "box",
            Stock::Plane { .. } => "plane",
            Stock::Cylinder { .. } => "cylinder",
            Stock::Grid { .. } => "height grid",
            Stock::Mesh { .. } => "mesh",
        },
        if lift > 0.0 { format!(", raised {lift} mm as the program gives ball centres") } else { String::new() }
    );
    let model = GivenStock { stock, lift, description };
    let grid = own::grid(model.footprint(), tool, &options)?;
    Ok(Some((model, grid)))
}

/// `answer` with the program it writes cut on the given stock: its `verification`, and the
/// warnings and program header comments of what that found.
fn verified(
    request: &PredictRequest,
    model: Option<(GivenStock, own::Grid)>,
    mut answer: PredictAnswer,
    run: &Run<'_>,
) -> Result<PredictAnswer, SolverError> {
    let Some((model, grid)) = model else {
        return Ok(answer);
    };
    let program = own::program::<PredictCapability>(request, &answer, run)?;
    let mut verification = own::verify(&model, grid, &program, &answer.tool, own::Limits::WITHOUT_PART, run)?;
    // The header lines are written from the verification by `program`.
    own::report(&mut verification, &mut answer.result.warnings, &mut Vec::new());
    answer.verification = Some(verification);
    Ok(answer)
}

fn mismatch(detail: String) -> SolverError {
    SolverError::new(ErrorCode::Internal, format!("the parts do not belong to this prediction: {detail}"))
}

/// What a prediction costs, in core-seconds of the reference machine (docs/guide/performance.md, "Split cost models": measured by `tests/load/cost_model.rs`, section `predict`, one thread, CPU time).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Cost {
    /// Per predicted pass.
    pass_seconds: f64,
    /// What every part repeats: reading the request (the G-code, the stock, the path model).
    setup_seconds: f64,
    /// The finish step: merging the parts, correcting, writing the answer and the program, and
    /// compressing them for the store.
    finish_seconds: f64,
}

/// A pass's core-seconds by method: `[fixed, per neighbouring pass, at N = 256]`. A pass costs a
/// constant (its stations, the force model), a share for every pass within 2R of it (the swept
/// volumes gathered and tested around it) and a share growing with the samples or pixels, N².
/// Measured on the raster of `tests/predict_support` (Ø10 ball, one thread, CPU time; passes per
/// mm² d at picks of 1, 0.5 and 0.3 mm: 1.0, 4.0 and 11.2): sampling at N = 256 took 0.50, 0.81 and
/// 1.53 ms per pass, and 0.86 and 0.97 ms at N = 128 and 512 (d = 4.0).
const SAMPLING_PASS_SECONDS: [f64; 3] = [0.36e-3, 0.33e-6, 0.035e-3];
/// The depth buffer: 1.98 and 3.43 ms at N = 256 (d = 4.0, 11.2), 1.03 ms at N = 128 (d = 4.0).
const DEPTH_BUFFER_PASS_SECONDS: [f64; 3] = [0.0, 0.64e-6, 1.26e-3];
/// Reading the request, per pass of the path: 0.16 s for the 103 041 passes of the raster, 0.46 s
/// for 286 225.
const SETUP_PASS_SECONDS: f64 = 1.6e-6;
/// The finish step, per pass of the path: 7 µs merging and writing (0.71 s for 103 041
/// passes), and compressing the answer's 730 bytes per pass for the store.
const FINISH_PASS_SECONDS: f64 = 30e-6;

/// The cost model of a prediction. The passes around one are estimated from the passes per mm²
/// of the path's extent in XY (a raster's density; the force model's share, under 2 % at
/// N_t = 360, N_θ = 90, is in the constant).
fn cost(job: &super::job::Job) -> Cost {
    let pixels = (f64::from(job.resolution) / 256.0).powi(2);
    let [fixed, per_neighbour, per_pixels] = match job.method {
        Method::Sampling => SAMPLING_PASS_SECONDS,
        Method::DepthBuffer => DEPTH_BUFFER_PASS_SECONDS,
    };
    let passes = job.path.passes.len() as f64;
    let reach = std::f64::consts::PI * (2.0 * job.radius).powi(2);
    let (lo, hi) = job.path.nodes.iter().fold(([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]), |(lo, hi), node| {
        ([lo[0].min(node.x), lo[1].min(node.y)], [hi[0].max(node.x), hi[1].max(node.y)])
    });
    let area = ((hi[0] - lo[0]) * (hi[1] - lo[1])).max(reach);
    let neighbours = (passes * reach / area).min(passes);
    Cost {
        pass_seconds: fixed + per_neighbour * neighbours + per_pixels * pixels,
        setup_seconds: SETUP_PASS_SECONDS * passes,
        finish_seconds: FINISH_PASS_SECONDS * passes,
    }
}

/// A part's output: the raw outcome of passes `from`, `from + 1`, ….
#[derive(Debug, Serialize, Deserialize)]
struct PartPasses {
    from: usize,
    passes: Vec<Outcome>,
}

/// A G-code path is written back with its own programmed point: another one is refused.
fn check_reference(request: &PredictRequest, reference: Option<Reference>) -> Result<(), SolverError> {
    match (&request.path, reference) {
        (PathInput::Gcode { .. }, Some(asked)) if asked != request.reference => Err(SolverError::input(
            "reference",
            format!(
                "a G-code path is written back with its own programmed point (the request's reference, {}); \
                 leave ?reference out or ask for {}",
                request.reference.as_str(),
                request.reference.as_str()
            ),
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod budget_tests {
    use super::*;
    use crate::capability::{AnswerBudget, Purpose};
    use crate::tool::ToolRef;

    /// A raster of `lines` lines of `points` points over a 40 mm box, ball R3 with a modal
    /// stiffness.
    fn raster(lines: usize, points: usize) -> (PredictRequest, Resolved<Tool>) {
        let mut program = String::from("G21 G90 G17\nS8000 M03\nG0 X-4 Y-3 Z10\nG1 Z0 F1600\n");
        for line in 0..lines {
            let y = -3.0 + 0.5 * line as f64;
            for k in 0..points {
                let i = if line % 2 == 0 { k } else { points - 1 - k };
                let x = -4.0 + 8.0 * i as f64 / (points - 1) as f64;
                program.push_str(&format!("X{x:.4} Y{y:.4}\n"));
            }
        }
        let modal = serde_json::json!([{"stiffness": 3000, "frequency_hz": 1800, "damping_ratio": 0.04}]);
        let request: PredictRequest = serde_json::from_value(serde_json::json!({
            "tool": {"kind": "ball", "radius": 3, "flutes": 2, "stiffness": {"kind": "modal", "x": modal, "y": modal},
                     "shape_error": [{"angle_deg": 0, "error": 0.004}, {"angle_deg": 90, "error": 0.009}]},
            "stock": {"kind": "box", "min": [-20, -20, -10], "max": [20, 20, 0.25]},
            "path": {"kind": "gcode", "program": program},
            "cutting": {"ktc": 2000, "krc": 800, "kac": 300},
            "resolution": 32
        }))
        .unwrap();
        let ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        let context = Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() };
        (request, context)
    }

    #[test]
    fn passes_over_the_budget_are_refused_a_pass_past_it() {
        let (request, context) = raster(40, 81);
        let budget = AnswerBudget::new(256 * 1024);
        let run = Run { budget: Some(&budget), ..Run::default() };
        let error = PredictCapability::solve(&request, context, &run).unwrap_err();
        assert_eq!(error.code(), ErrorCode::TooLargeAnswer, "{error}");
        // Each worker thread may finish the pass it is on.
        let passes = rayon::current_num_threads() as u64 + 1;
        assert!(budget.used() <= budget.limit() + passes * 8 * 1024, "{} charged", budget.used());
    }

    #[test]
    fn the_charges_cover_what_is_built() {
        let (request, context) = raster(6, 9);
        let answer = PredictCapability::solve(&request, context.clone(), &Run::default()).unwrap();
        let records: u64 =
            answer.result.passes.len() as u64 * std::mem::size_of::<super::super::PredictedPass>() as u64;
        let json = serde_json::to_vec(&answer.result.passes).unwrap().len() as u64;
        let budget = AnswerBudget::new(u64::MAX);
        let run = Run { budget: Some(&budget), purpose: Purpose::Json, ..Run::default() };
        PredictCapability::solve(&request, context, &run).unwrap();
        assert!(records + json <= budget.used(), "{} built, {} charged", records + json, budget.used());
    }
}

#[cfg(test)]
mod verification_tests {
    use super::*;
    use crate::tool::ToolRef;
    use crate::verify::{FindingKind, VerificationOptions};

    /// Two finishing lines over a 40 mm box at Z0, 0.25 mm under its top, with a ball R3.
    const CLEAN: &str = "G21 G90 G17\nS8000 M03\nG0 X-4 Y-3 Z10\nG1 Z0 F1600\nX4\nY-2.5\nX-4\nG0 Z10\nM05\nM30\n";
    /// The same with a rapid at the cutting height across uncut stock, at line 8.
    const RAPID_THROUGH: &str =
        "G21 G90 G17\nS8000 M03\nG0 X-4 Y-3 Z10\nG1 Z0 F1600\nX4\nY-2.5\nX-4\nG0 Y6\nG1 X4\nG0 Z10\nM05\nM30\n";

    fn request(path: serde_json::Value, reference: &str) -> (PredictRequest, Resolved<Tool>) {
        let modal = serde_json::json!([{"stiffness": 3000, "frequency_hz": 1800, "damping_ratio": 0.04}]);
        let request: PredictRequest = serde_json::from_value(serde_json::json!({
            "tool": {"kind": "ball", "radius": 3, "flutes": 2, "stiffness": {"kind": "modal", "x": modal, "y": modal},
                     "shape_error": [{"angle_deg": 0, "error": 0.004}, {"angle_deg": 90, "error": 0.009}]},
            "stock": {"kind": "box", "min": [-20, -20, -10], "max": [20, 20, 0.25]},
            "path": path, "reference": reference, "feed": 1600, "spindle_rpm": 8000,
            "cutting": {"ktc": 2000, "krc": 800, "kac": 300},
            "resolution": 32
        }))
        .unwrap();
        let ToolRef::Inline(tool) = &request.tool else { unreachable!("an inline tool") };
        let context = Resolved { tool: tool.clone(), machine: None, material: None, other_tools: Vec::new() };
        (request, context)
    }

    fn gcode(program: &str) -> (PredictRequest, Resolved<Tool>) {
        request(serde_json::json!({"kind": "gcode", "program": program}), "tip")
    }

    fn fanuc(request: &PredictRequest, answer: &PredictAnswer) -> String {
        let output = OutputOptions { dialect: Some(crate::gcode::Dialect::Fanuc), ..OutputOptions::default() };
        crate::capability::program::<PredictCapability>(request, answer, &output, Control::default()).unwrap()
    }

    #[test]
    fn finishing_lines_cut_clean_on_the_given_stock() {
        let (request, context) = gcode(CLEAN);
        let answer = PredictCapability::solve(&request, context, &Run::default()).unwrap();
        let verification = answer.verification.as_ref().expect("verified");
        assert!(verification.ok, "{verification:#?}");
        assert!(verification.removed_volume_mm3 > 0.0);
        assert_eq!(verification.part_volume_mm3, 0.0);
        assert!(answer.result.warnings.iter().all(|warning| !warning.code.starts_with("W_VERIFY")));
        assert!(!fanuc(&request, &answer).contains("WARNING"));
    }

    /// Points of ball centres: the stock is raised by the radius, so the same lines remove the
    /// same material as the tip-referenced program.
    #[test]
    fn a_path_of_ball_centres_cuts_where_the_tip_runs() {
        let points =
            serde_json::json!({"kind": "points", "points": [[-4, -3, 3], [4, -3, 3], [4, -2.5, 3], [-4, -2.5, 3]]});
        let (request, context) = request(points, "centre");
        let answer = PredictCapability::solve(&request, context, &Run::default()).unwrap();
        let centres = answer.verification.expect("verified");
        let (request, context) = gcode(CLEAN);
        let tips = PredictCapability::solve(&request, context, &Run::default()).unwrap().verification.unwrap();
        assert!(centres.ok, "{centres:#?}");
        let (a, b) = (centres.removed_volume_mm3, tips.removed_volume_mm3);
        // The tip program's plunge from Z10 at X-4 Y-3 is the points program's first move too.
        assert!((a / b - 1.0).abs() < 0.02, "{a} against {b}");
    }

    #[test]
    fn verification_can_be_turned_off_and_a_grid_too_fine_is_refused_up_front() {
        let (mut request, context) = gcode(CLEAN);
        request.verification = Some(VerificationOptions { enabled: false, resolution: None });
        let answer = PredictCapability::solve(&request, context.clone(), &Run::default()).unwrap();
        assert!(answer.verification.is_none());
        assert!(!serde_json::to_string(&answer).unwrap().contains("verification"));
        request.verification = Some(VerificationOptions { enabled: true, resolution: Some(0.001) });
        let error = PredictCapability::solve(&request, context, &Run::default()).unwrap_err();
        assert_eq!((error.code(), error.field()), (ErrorCode::GridMemory, Some("verification.resolution")));
    }

    /// A rapid at the cutting height across stock no pass has cut: found at its line of the
    /// corrected program, warned, and in the header after the program's first line.
    #[test]
    fn a_rapid_through_the_stock_is_found_at_its_line() {
        let (request, context) = gcode(RAPID_THROUGH);
        let answer = PredictCapability::solve(&request, context, &Run::default()).unwrap();
        let verification = answer.verification.as_ref().unwrap();
        assert!(!verification.ok);
        let rapids: Vec<_> =
            verification.findings.iter().filter(|finding| finding.kind == FindingKind::RapidThroughMaterial).collect();
        assert_eq!(rapids.len(), 1, "{:#?}", verification.findings);
        assert!(answer.result.warnings.iter().any(|warning| warning.code == "W_VERIFY_RAPID_THROUGH_MATERIAL"));
        let program = fanuc(&request, &answer);
        let lines: Vec<&str> = program.lines().collect();
        let line = rapids[0].line.unwrap();
        assert_eq!(lines[line - 1], "G0 Y6", "{program}");
        assert_eq!(line, 8 + 2, "{program}");
        assert!(lines[0].starts_with("(WARNING VERIFICATION FOUND 1 PROBLEMS"), "{program}");
        assert!(lines[1].starts_with(&format!("(WARNING RAPID THROUGH MATERIAL AT LINE {line}: ")), "{program}");
        // The rest is the corrected program as before.
        assert_eq!(lines[2..].join("\n"), {
            let mut unverified = answer.clone();
            unverified.verification = None;
            fanuc(&request, &unverified).trim_end().to_owned()
        });
    }
}
