//! Machining-error prediction and path correction for ball-end-mill finishing (spec:
//! docs/spec/predict.md; patent 002, JP2010-237843 A).
//!
//! For every pass of a finishing path this module finds where on the ball the surviving surface
//! is generated (the generation point C, contact angle θ_c, azimuth φ_c and the rotation angle ψ_c
//! of the generating flute), evaluates the error there from the tool's shape-error table δ(θ)
//! and its deflection under the cutting force at that instant, and moves the path nodes against
//! the predicted errors. A pass is one feed line or one chord of an arc; the path is taken in
//! program order, the ball centre is the programmed point plus R·ẑ for tip-referenced paths.
//!
//! * [`request`]: the request and its validation, reading G-code into ball-centre passes;
//! * `stock`, `stl`: box, half-space, cylinder, height grid or closed STL stock (§1.2);
//! * `passes`, `scene`, `capsule`: swept volumes T1/T2 split at s₀ ± n_g·f_t and their closed
//!   forms (§3.5, §6.3);
//! * `sampling`: the resolution-free surface sampling (§6.6), the default method;
//! * `render`: the depth buffer from below with the rotated and zoomed views (§3.5, §3.10);
//! * `force`: engagement and the mechanistic force model (§3.7);
//! * [`dynamics`]: deflection over one revolution from static, modal or measured compliance
//!   (§3.8);
//! * [`shape`]: the shape-error table (§3.13);
//! * [`correct`]: the node correction rule (§3.14);
//! * `exclusion`: the low-angle pass exclusion of claim 8 (§3.4), with `exclusion_deg` (and e_S
//!   for the excluded passes with `exclusion_shape_error`);
//! * `merge`: merging near-identical consecutive passes (§3.2), with `merge_similar_passes`;
//! * `pipeline`: the per-pass flow of §3.1 over all passes in parallel.
//!
//! Choices where the spec is open (documented for users):
//! * the default method is `sampling`: at every contact angle it is at least as accurate as the
//!   depth buffer (area-weighted, no projection loss at the rim) and needs no view correction;
//!   `depth_buffer` follows the patent, with the view correction of §3.10;
//! * the prediction position is the middle of the pass when the ball cuts there, else the nearest
//!   cutting station at steps of max(f_t, L/16) (the T0-front centroid of §3.3 for a pass cut over
//!   its whole length is its middle);
//! * the engagement for the force is the exact point test (case D's reference) on the N_θ × N_t
//!   edge grid, for both methods;
//! * swept volumes include rapid moves (the tool occupies that space); moves from an unknown
//!   position (after a tool change or a home return) sweep nothing;
//! * inch programs are converted to mm and the corrected program is written back in inches;
//! * arcs are corrected at their chord points and refitted (the centre on the corrected ends'
//!   bisector, least squares), so the corrected program keeps G2/G3 with new I/J/K or R;
//! * the gouge check against the design surface of §3.14 is not done (the design surface is not
//!   an input); the clamp limits every node move.

pub mod answer;
mod capability;
mod capsule;
pub mod correct;
pub mod dynamics;
mod exclusion;
mod force;
mod job;
mod merge;
mod passes;
mod pipeline;
mod render;
pub mod request;
mod sampling;
mod scene;
pub mod shape;
mod units;

use std::sync::atomic::AtomicUsize;

pub use crate::capability::Control;
pub use answer::{
    MergeSummary, PassFlag, PassHistory, PassStatus, Predict, PredictSummary, PredictedPass, RoundSummary, WorstPass,
};
pub use capability::{PredictAnswer, PredictCapability, Timings};
pub use force::CuttingCoefficients;
pub use request::{CorrectionOptions, Method, PathInput, PredictRequest, PrescribedDeflection, SpindleDirection};

use answer::Corrections;
use correct::PassError;
use job::Job;
use passes::PathModel;
use pipeline::{Context, Outcome};

use crate::error::{SolverError, Warning};
use crate::gcode::reader::{self, MoveEdit, MoveKind, ReadOptions};
use crate::gcode::{self, Dialect, Program, ToolCall};
use crate::geometry::{Vec3, array3, vec3};
use crate::path::Toolpath;
use crate::tool::Tool;

/// How many worst passes the summary lists.
const WORST: usize = 20;
/// Clearance above the highest point for programs written from points, mm.
const CLEARANCE: f64 = 5.0;

/// Predicts the errors of a path and corrects it.
///
/// `mesh` carries the STL file (ASCII or binary bytes) of a `{"kind": "mesh"}` stock; it is
/// ignored for the other stocks.
///
/// # Errors
/// `E_INPUT` naming the field for bad numbers, `E_TOOL_KIND`, `E_NO_SHAPE_ERROR`,
/// `E_RESOLUTION_LIMIT`, `E_GRID_TOO_LARGE`, the mesh errors (`E_MESH_FORMAT`,
/// `E_MESH_NOT_CLOSED`, `E_MESH_EMPTY`, `E_MESH_TOO_LARGE`), the G-code errors (`E_GCODE_SYNTAX`,
/// `E_GCODE_UNSUPPORTED`, `E_GCODE_POSITION`, `E_ARC_NOT_CLOSED`, `E_ARC_RADIUS`,
/// `E_TOO_MANY_LINES`, with the line number), `E_NO_FEED`, `E_NO_SPINDLE`, `E_NO_PASSES`,
/// `E_TOO_MANY_PASSES`, `E_TOO_MANY_SPINDLE_SPEEDS`.
pub fn solve(request: &PredictRequest, tool: &Tool, mesh: Option<&[u8]>) -> Result<Predict, SolverError> {
    solve_with(request, tool, mesh, &Control::default())
}

/// [`solve`] with progress reports and cancellation (for jobs). Same answer as [`solve`].
///
/// # Errors
/// As [`solve`], and `E_CANCELLED` when `control.cancel` was set.
pub fn solve_with(
    request: &PredictRequest,
    tool: &Tool,
    mesh: Option<&[u8]>,
    control: &Control<'_>,
) -> Result<Predict, SolverError> {
    solve_charged(request, tool, mesh, control, None)
}

/// As [`solve_with`] under `run`: its control and upload, and its answer budget charged for every
/// pass as it is predicted (in memory, and at most as delivered for `run.purpose`), so a path
/// whose answer would not fit is refused a pass past the budget instead of after every pass.
///
/// # Errors
/// As [`solve_with`]; `E_TOO_LARGE_ANSWER` over the budget.
pub fn solve_run(
    request: &PredictRequest,
    tool: &Tool,
    run: &crate::capability::Run<'_>,
) -> Result<Predict, SolverError> {
    solve_charged(request, tool, run.upload, &run.control, run.budget.map(|budget| (budget, run.purpose)))
}

fn solve_charged(
    request: &PredictRequest,
    tool: &Tool,
    mesh: Option<&[u8]>,
    control: &Control<'_>,
    budget: Option<(&crate::capability::AnswerBudget, crate::capability::Purpose)>,
) -> Result<Predict, SolverError> {
    let job = request.validate(tool, mesh, *control)?;
    let context = Context::new(&job);
    let node_count = job.path.nodes.len();
    let total_work = (job.pass_range.len() * job.iterations as usize).max(1);
    let done = AtomicUsize::new(0);
    let mut rounds: Vec<Vec<Outcome>> = Vec::new();
    let mut total = vec![Vec3::zeros(); node_count];
    let mut clamped = vec![false; node_count];
    let mut ambiguous = vec![false; node_count];
    let mut current: Option<PathModel> = None;
    for round in 0..job.iterations {
        let path = current.as_ref().unwrap_or(&job.path);
        // Every round's outcomes are held to the end; the last round's are the answer's passes.
        let delivered = round + 1 == job.iterations;
        let charge = |outcome: &pipeline::Outcome| match budget {
            None => Ok(()),
            Some((budget, purpose)) => {
                let bytes = answer::pass_bytes(outcome, purpose, delivered);
                budget.charge(bytes, done.load(std::sync::atomic::Ordering::Relaxed), total_work)
            }
        };
        let outcomes = pipeline::run_round(&context, path, control, &done, total_work, &charge)?;
        let (step, _, round_ambiguous) = node_corrections(path, &outcomes, f64::INFINITY);
        for node in 0..node_count {
            total[node] += step[node];
            clamped[node] = correct::clamp(&mut total[node], job.max_correction);
            if round == 0 {
                ambiguous[node] = round_ambiguous[node];
            }
        }
        rounds.push(outcomes);
        if round + 1 < job.iterations {
            let moved: Vec<Vec3> = job.path.nodes.iter().zip(&total).map(|(n, c)| n + c).collect();
            current = Some(job.path.with_nodes(moved, job.radius));
        }
    }
    control.check()?;
    let mut answer = assemble(&job, &rounds, &total, &clamped, &ambiguous);
    answer.warnings.extend(rapid_collisions(&job, control)?);
    Ok(answer)
}

/// Rapid moves whose ball enters stock that earlier motion has not removed (§5 E17): the ball's
/// lowest point and four points at 60° from it are tested along each rapid, every R/2.
fn rapid_collisions(job: &Job, control: &Control<'_>) -> Result<Option<Warning>, SolverError> {
    let path = &job.path;
    let radius = job.radius;
    let mut scratch = scene::Scratch::default();
    let mut pieces = Vec::new();
    let mut lines: Vec<usize> = Vec::new();
    let (sin, cos) = 60f64.to_radians().sin_cos();
    for (index, segment) in path.segments.iter().enumerate() {
        let Some(line) = segment.rapid_line else {
            continue;
        };
        control.check()?;
        if lines.last() == Some(&line) {
            continue;
        }
        let (a, b) = path.ends(index);
        let steps = ((segment.length / (0.5 * radius)).ceil() as usize).max(1);
        scene::gather(
            path,
            &scene::Query {
                centre: 0.5 * (a + b),
                sigma: segment.sigma,
                gap: 0.0,
                radius,
                reach: 0.5 * segment.length + 2.0 * radius,
                any_view: true,
                order: scene::PieceOrder::Height,
                stock_top: f64::INFINITY,
            },
            &mut scratch,
            &mut pieces,
        );
        pieces.retain(|p| p.side == scene::Side::Before);
        let earlier = scene::Scene::new(&pieces, Vec3::zeros(), nalgebra::Matrix3::identity(), radius);
        let all: Vec<u32> = (0..earlier.before.len() as u32).collect();
        let hits = (0..=steps).any(|k| {
            let centre = a + (k as f64 / steps as f64) * (b - a);
            [(0.0, 0.0)]
                .into_iter()
                .chain([0.0, 90.0, 180.0, 270.0].map(|phi: f64| {
                    let (s, c) = phi.to_radians().sin_cos();
                    (c, s)
                }))
                .any(|(c, s)| {
                    let offset = if c == 0.0 && s == 0.0 {
                        -radius * Vec3::z()
                    } else {
                        radius * Vec3::new(sin * c, sin * s, -cos)
                    };
                    let q = centre + offset;
                    let mut hint = 0;
                    job.stock.contains(&q, earlier.eps)
                        && earlier.cover(&q, scene::Side::Before, &all, &mut hint) == scene::Cover::Open
                })
        });
        if hits {
            lines.push(line);
        }
    }
    if lines.is_empty() {
        return Ok(None);
    }
    let shown: Vec<String> = lines.iter().take(10).map(ToString::to_string).collect();
    Ok(Some(Warning::new(
        "W_RAPID_COLLISION",
        format!(
            "{} rapid move(s) run through uncut stock, at line(s) {}{}",
            lines.len(),
            shown.join(", "),
            if lines.len() > 10 { ", …" } else { "" }
        ),
    )))
}

/// Node corrections of one round (unclamped when `limit` is infinite).
fn node_corrections(path: &PathModel, outcomes: &[Outcome], limit: f64) -> (Vec<Vec3>, Vec<bool>, Vec<bool>) {
    let count = path.nodes.len();
    let mut previous: Vec<Option<PassError>> = vec![None; count];
    let mut next: Vec<Option<PassError>> = vec![None; count];
    for segment in &path.segments {
        let error = segment.pass.and_then(|p| {
            let o = &outcomes[p];
            match (o.status, o.error, o.normal) {
                // Excluded passes with e_S (`exclusion_shape_error`) are corrected for it too.
                (PassStatus::Ok | PassStatus::SkippedSmallAngle, Some(error), Some(n)) => {
                    Some(PassError { error, normal: array3(&n) })
                }
                _ => None,
            }
        });
        previous[segment.end_node] = error;
        next[segment.start_node] = error;
    }
    let mut offsets = Vec::with_capacity(count);
    let mut clamped = Vec::with_capacity(count);
    let mut ambiguous = Vec::with_capacity(count);
    for node in 0..count {
        let (c, unclear) = correct::node_correction(previous[node], next[node]);
        let mut c = vec3(c);
        clamped.push(correct::clamp(&mut c, limit));
        offsets.push(c);
        ambiguous.push(unclear);
    }
    (offsets, clamped, ambiguous)
}

fn assemble(job: &Job, rounds: &[Vec<Outcome>], total: &[Vec3], clamped: &[bool], ambiguous: &[bool]) -> Predict {
    let path = &job.path;
    let first = &rounds[0];
    let residual = rounds.get(1);
    let mut passes = Vec::with_capacity(first.len());
    for (index, outcome) in first.iter().enumerate() {
        let pass = path.passes[index];
        let end_node = path.segments[pass.segment].end_node;
        let mut flags = outcome.flags.clone();
        if clamped[end_node] {
            flags.push(PassFlag::CorrectionClamped);
        }
        if ambiguous[end_node] {
            flags.push(PassFlag::CorrectionAmbiguous);
        }
        let correction = total[end_node];
        passes.push(PredictedPass {
            index,
            line: pass.source.line,
            block_number: pass.source.block_number,
            status: outcome.status,
            flags,
            position: outcome.position,
            centre: outcome.centre.as_ref().map(array3),
            error: outcome.error,
            error_deflection: outcome.error_deflection,
            error_shape: outcome.error_shape,
            contact_angle_deg: outcome.contact_angle.map(f64::to_degrees),
            azimuth_deg: outcome.azimuth.map(degrees_0_360),
            rotation_angle_deg: outcome.rotation_angle.map(degrees_0_360),
            generation_point: outcome.point.as_ref().map(array3),
            normal: outcome.normal.as_ref().map(array3),
            deflection: outcome.deflection,
            cut_count: outcome.cut_count,
            finished_count: outcome.finished_count,
            view: outcome.view.as_ref().map(array3),
            residual_error: residual.and_then(|r| r[index].error),
            correction: array3(&correction),
            corrected: array3(&(path.nodes[end_node] + correction + job.reference_offset)),
            history: outcome.history.clone(),
            merged_with: outcome.merged_with,
            merge_bound: outcome.merge_bound,
        });
    }
    let errors: Vec<(usize, f64)> = passes.iter().filter_map(|p| p.error.map(|e| (p.index, e))).collect();
    let count_status = |status: PassStatus| passes.iter().filter(|p| p.status == status).count();
    let mut worst = errors.clone();
    worst.sort_by(|a, b| b.1.abs().total_cmp(&a.1.abs()).then(a.0.cmp(&b.0)));
    worst.truncate(WORST);
    let round_summary = |outcomes: &Vec<Outcome>| {
        let values: Vec<f64> = outcomes.iter().filter_map(|o| o.error).collect();
        RoundSummary {
            predicted: values.len(),
            max_abs_error: values.iter().map(|e| e.abs()).reduce(f64::max),
            rms_error: rms(&values),
        }
    };
    let values: Vec<f64> = errors.iter().map(|(_, e)| *e).collect();
    let summary = PredictSummary {
        passes: passes.len(),
        predicted: count_status(PassStatus::Ok),
        no_cut: count_status(PassStatus::NoCut),
        no_surface: count_status(PassStatus::NoSurface),
        outside_stock: count_status(PassStatus::OutsideStock),
        skipped_small_angle: job.exclusion.map(|_| count_status(PassStatus::SkippedSmallAngle)),
        min_error: values.iter().copied().reduce(f64::min),
        max_error: values.iter().copied().reduce(f64::max),
        mean_error: (!values.is_empty()).then(|| values.iter().sum::<f64>() / values.len() as f64),
        rms_error: rms(&values),
        worst: worst.iter().map(|&(index, error)| WorstPass { index, line: passes[index].line, error }).collect(),
        max_correction: total.iter().map(Vec3::norm).fold(0.0, f64::max),
        clamped: clamped.iter().filter(|c| **c).count(),
        rounds: rounds.iter().map(round_summary).collect(),
        method: job.method,
        resolution: job.resolution,
        pixel_size: 2.0 * job.radius / f64::from(job.resolution),
        samples_per_revolution: job.steps,
        edge_elements: job.edge_elements,
        merge: job.merge_tolerance.map(|tolerance| {
            let merged: Vec<f64> = first.iter().filter_map(|o| o.merge_bound).collect();
            MergeSummary {
                tolerance,
                simulated: first.iter().filter(|o| o.status != PassStatus::NotPredicted).count() - merged.len(),
                merged: merged.len(),
                max_bound: merged.iter().copied().fold(0.0, f64::max),
            }
        }),
    };
    Predict {
        passes,
        summary,
        warnings: warnings(job),
        corrections: Corrections {
            nodes: path.nodes.clone(),
            offsets: total.to_vec(),
            sources: job.node_sources.clone(),
            reference_offset: job.reference_offset,
        },
    }
}

/// An angle in degrees in [0, 360) (a tiny negative angle would otherwise print as 360).
fn degrees_0_360(radians: f64) -> f64 {
    let degrees = radians.to_degrees().rem_euclid(360.0);
    if degrees >= 360.0 { 0.0 } else { degrees }
}

fn rms(values: &[f64]) -> Option<f64> {
    (!values.is_empty()).then(|| (values.iter().map(|e| e * e).sum::<f64>() / values.len() as f64).sqrt())
}

fn warnings(job: &Job) -> Vec<Warning> {
    let mut warnings = Vec::new();
    if job.deflection.is_none() {
        let missing = match (job.stiffness.is_some(), job.cutting.is_some()) {
            (true, true) => None,
            (false, true) => Some("the tool has no stiffness"),
            (true, false) => Some("the request has no cutting coefficients"),
            (false, false) => Some("the tool has no stiffness and the request no cutting coefficients"),
        };
        if let Some(missing) = missing {
            warnings.push(Warning::new("W_NO_DEFLECTION", format!("{missing}: errors are the shape error alone")));
        }
    }
    warnings
}

/// How to write a corrected program for a path given as points (G-code paths keep their own
/// format).
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramOptions {
    /// Control dialect.
    pub dialect: Dialect,
    /// Tool selection.
    pub tool: ToolCall,
    /// The program's units (G20 or G21).
    pub units: crate::units::Units,
}

/// The corrected program for `answer` (computed from `request`).
///
/// A G-code path is written back with the same lines, block numbers, comments and modal words;
/// only the coordinates of moved end points change (arcs get new centre words so they close). A
/// path of points becomes a complete program through the corrected points (`options`).
///
/// # Errors
/// `E_INPUT` when `answer` does not belong to `request`; the reader's errors if the program no
/// longer reads.
pub fn corrected_program(
    request: &PredictRequest,
    answer: &Predict,
    options: &ProgramOptions,
) -> Result<String, SolverError> {
    corrected_program_controlled(request, answer, options, Control::default())
}

/// [`corrected_program`] that stops with `E_CANCELLED` once `control`'s cancel flag is set
/// (checked while reading, correcting and writing the program).
///
/// # Errors
/// As [`corrected_program`]; `E_CANCELLED` when cancelled.
pub fn corrected_program_controlled(
    request: &PredictRequest,
    answer: &Predict,
    options: &ProgramOptions,
    control: Control<'_>,
) -> Result<String, SolverError> {
    corrected_program_headed(request, answer, options, &[], control)
}

/// [`corrected_program_controlled`] with `header` comment lines before every move, one line each:
/// a G-code path gets them after its leading `%` and `O` number lines, as `( )` comments; a
/// program written from points among its header comments.
pub(crate) fn corrected_program_headed(
    request: &PredictRequest,
    answer: &Predict,
    options: &ProgramOptions,
    header: &[String],
    control: Control<'_>,
) -> Result<String, SolverError> {
    let corrections = &answer.corrections;
    let mismatch = || SolverError::input("path", "this answer was not computed from this request");
    match &request.path {
        PathInput::Gcode { program: text } => {
            let read_options =
                ReadOptions { block_delete: request.block_delete.unwrap_or(false), ..ReadOptions::default() };
            let program = reader::read_cancellable(text, "path.program", &read_options, control)?;
            let corrected =
                |node: usize| corrections.nodes[node] + corrections.offsets[node] + corrections.reference_offset;
            let mut edits = Vec::new();
            let mut node = 0;
            while node < corrections.sources.len() {
                if node % gcode::MOVES_PER_CHECK == 0 {
                    control.check()?;
                }
                let source = corrections.sources[node];
                if source.chords == 0 || source.chord != 0 {
                    node += 1;
                    continue;
                }
                // Nodes node .. node + chords − 1 are the chord ends of one move.
                let last = node + source.chords - 1;
                let Some(read_move) = program.moves.get(source.item) else {
                    return Err(mismatch());
                };
                if last >= corrections.sources.len() || corrections.sources[last].item != source.item {
                    return Err(mismatch());
                }
                let moved = (node..=last).any(|n| corrections.offsets[n] != Vec3::zeros())
                    || (node > 0 && corrections.offsets[node - 1] != Vec3::zeros());
                // Rapids are never rewritten: only cutting moves change.
                if moved
                    && read_move.kind != MoveKind::Rapid
                    && let Some(to) = read_move.to_xyz()
                {
                    let new_to = vec3(to) + corrections.offsets[last];
                    let centre = match read_move.kind {
                        MoveKind::Arc { centre, .. } if node > 0 => {
                            let (a, b, _) = read_move.modal.plane.axes();
                            let interior: Vec<Vec3> = (node..last).map(corrected).collect();
                            let fitted =
                                correct::refit_centre(&corrected(node - 1), &new_to, &interior, &vec3(centre), (a, b));
                            Some(array3(&fitted))
                        }
                        _ => None,
                    };
                    edits.push(MoveEdit { index: source.item, to: array3(&new_to), centre });
                }
                node = last + 1;
            }
            let rewritten = reader::rewrite_cancellable(text, &program, &edits, "path.program", control)?;
            Ok(with_header(rewritten, header))
        }
        PathInput::Points { points } => {
            if points.len() != corrections.nodes.len() {
                return Err(mismatch());
            }
            let corrected: Vec<Vec3> = points.iter().zip(&corrections.offsets).map(|(p, c)| vec3(*p) + c).collect();
            let feed = request.feed.ok_or_else(|| SolverError::input("feed", "feed is needed"))?;
            let spindle_rpm =
                request.spindle_rpm.ok_or_else(|| SolverError::input("spindle_rpm", "spindle_rpm is needed"))?;
            // The rapids are those of the uncorrected path (a correction changes only
            // the cutting moves): the clearance plane over the programmed points, above the
            // programmed first and last point.
            let safe_z = points.iter().map(|p| p[2]).fold(f64::NEG_INFINITY, f64::max) + CLEARANCE;
            let mut path = Toolpath::default();
            let (first, last) = (vec3(points[0]), vec3(points[points.len() - 1]));
            path.rapid(Vec3::new(first.x, first.y, safe_z));
            for p in &corrected {
                path.linear(*p, feed);
            }
            path.rapid(Vec3::new(last.x, last.y, safe_z));
            let program = Program {
                dialect: options.dialect,
                number: 1000,
                title: "kerf corrected path",
                comments: vec![
                    format!("control point: {}", request.reference.as_str()),
                    format!(
                        "max correction {:.4} mm, predicted max error {:.4} mm",
                        answer.summary.max_correction,
                        answer.summary.rounds[0].max_abs_error.unwrap_or(0.0)
                    ),
                ]
                .into_iter()
                .chain(header.iter().cloned())
                .collect(),
                tool: options.tool.clone(),
                spindle_rpm,
                spindle_direction: request.spindle_direction.unwrap_or_default(),
                safe_z,
                blend_tolerance: 0.001,
                // The points are the caller's path, written as given.
                plunges: None,
                path: &path,
                units: options.units,
            };
            program.check_written(&[], "spindle_rpm", "feed")?;
            gcode::write_cancellable(&program, &[], control)
        }
    }
}

/// `text` with a `( )` comment line per `header` line after its leading `%` and `O` number
/// lines (which a control expects first).
fn with_header(text: String, header: &[String]) -> String {
    if header.is_empty() {
        return text;
    }
    let mut at = 0;
    for line in text.split_inclusive('\n') {
        let word = line.trim_start();
        let leading = word.starts_with('%')
            || word.strip_prefix(['O', 'o']).is_some_and(|rest| rest.starts_with(|c: char| c.is_ascii_digit()));
        if !leading || !line.ends_with('\n') {
            break;
        }
        at += line.len();
    }
    let mut headed = String::with_capacity(text.len() + header.iter().map(|line| line.len() + 3).sum::<usize>());
    headed.push_str(&text[..at]);
    for line in header {
        headed.push_str(&gcode::comment(line));
        headed.push('\n');
    }
    headed.push_str(&text[at..]);
    headed
}
