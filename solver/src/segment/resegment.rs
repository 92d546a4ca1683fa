//! Re-segmenting a CAM program (docs/spec/resegment.md): the runs of feed moves of a G-code
//! program cut again by the machine's block-time rule in mode `guarantee`, every other line kept
//! byte for byte.
//!
//! A *run* is a stretch of feed moves on consecutive lines that the rewrite may replace: every
//! line holds nothing but the motion (`G0`–`G3`, `N`, `X Y Z`, `I J K R`, `F`; no comment, no
//! other code, no block delete), under `G90`, with one feed, plane, units and tool, from a known
//! position. Straight moves make a polyline run (two moves at least), cut through the segment
//! capability's polyline rule; a `G17` arc of at most a full turn without a helix is a run of its
//! own, cut as an arc. Everything else (rapids, tool changes, spindle, coolant, comments, helical
//! arcs, moves of incremental mode, lines with more than the motion on them) stays as it was,
//! in order, and ends the run before it. A run the rule cannot cut (a feed too high for its
//! smallest radius, a run without length) stays as it was, with a warning.
//!
//! The re-cut blocks are written as kerf's posts write G01 blocks: `G01 X Y Z` with every axis, 4
//! decimals in the run's units, the run's first `F` word (as written) on its first block. A
//! program asked for in another post than its own is re-posted line by line
//! ([`crate::gcode::repost`]).

use crate::validate::Measure;
use serde::{Deserialize, Serialize};

use super::{Curve, Direction, SegmentRequest, SegmentSolution};
use crate::capability::{Capability, Control, Endpoint, OutputOptions, Refs, Resolved, Run};
use crate::error::{ErrorCode, SolverError, Warning};
use crate::gcode::Dialect;
use crate::gcode::reader::{self, Distance, MoveKind, Plane, ReadMove, ReadOptions, Units};
use crate::gcode::repost::Reposter;
use crate::machine::MachineProfile;
use crate::machine::rule::MS_PER_MIN;

/// Most moves of one polyline run: a longer stretch is cut as several runs, so one cut's tables
/// stay within memory that a request may take.
pub const MAX_RUN_MOVES: usize = 100_000;

/// Chord tolerance for the arc lengths of the figures, mm.
const ARC_LENGTH_TOLERANCE: f64 = 1e-4;

/// The chord error of a run is at least this many units of the last decimal its coordinates
/// are written with: the points carry that rounding (up to 0.71 unit off the curve, 1.4 between
/// two of them), which a smaller chord error would take for curvature and cut into short blocks.
pub const ROUNDING_FLOOR_UNITS: f64 = 4.0;

/// Factor on the margin of the block-time rule for the runs: with the rounding floor it keeps
/// every block at least feed × block time long though the rounding eats up to 1.4 units of the
/// chord error (a chord of error C − 1.4u is at least √0.65 of a chord of error C ≥ 4u, and
/// 1.3 × √0.65 > 1).
pub const ROUNDING_MARGIN: f64 = 1.3;

/// Most warnings of one code listed; the others are counted in the last one.
const WARNINGS_PER_CODE: usize = 5;

/// A block counts as short when below feed × block time by more than this fraction (as
/// `machine::stats`).
const SHORT_SLACK: f64 = 1e-9;

/// `POST /api/v1/resegment`: cut the feed moves of a G-code program again by the block-time rule
/// (mode `guarantee`), keeping every other line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct ResegmentRequest {
    /// The G-code program (RS274/Fanuc for 3-axis milling, as the G-code reader takes it).
    pub program: String,
    /// A registered machine whose values are the defaults of this request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// T_b: block processing time of the control, ms (default: the machine's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_time_ms: Option<f64>,
    /// k_f: margin factor on the feed, ≥ 1 (default: the machine's, else 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// C_emin: lower bound of the chord error, mm (default: the machine's, else 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_chord_error: Option<f64>,
    /// C_tol: accuracy bound, mm: the new blocks never deviate more from the program's path
    /// (where the rule wants more, they are shorter than feed × block time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Smallest direction change between two straight moves that makes a corner, degrees
    /// (default 20): corners stay command points.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corner_angle_deg: Option<f64>,
    /// The post the program was written for (default `fanuc`; the reader takes the RS274
    /// family: `fanuc`, `haas`, `linuxcnc`, `grbl`). A program asked for in another post (the
    /// machine's, or `?dialect=`) is re-posted line by line; in this one its lines stay as sent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub program_dialect: Option<Dialect>,
    /// `mm` or `inch`: the units of `min_chord_error`, `tolerance` and the answer's lengths
    /// (default: the named machine's `units`, else `mm`); the program keeps its own G20/G21.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
}

/// Block figures of a program's feed moves (`G1`, `G2`, `G3`; rapids are not counted).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ProgramFigures {
    /// Feed blocks.
    pub blocks: usize,
    /// Feed blocks shorter than their feed × block time that do not end a span: each starves
    /// the control.
    pub short_blocks: usize,
    /// Short feed blocks that end a span (before a rapid, a tool change, a change of feed or
    /// plane, the program end, a corner), where the control slows down anyway.
    pub short_end_blocks: usize,
    /// Block-limited time of the feed blocks, Σ max(L/F, T_b), s (docs/spec/segment.md §6.3).
    pub estimated_time_s: f64,
}

impl ProgramFigures {
    fn add(&mut self, other: &Self) {
        self.blocks += other.blocks;
        self.short_blocks += other.short_blocks;
        self.short_end_blocks += other.short_end_blocks;
        self.estimated_time_s += other.estimated_time_s;
    }

    fn remove(&mut self, other: &Self) {
        self.blocks -= other.blocks;
        self.short_blocks -= other.short_blocks;
        self.short_end_blocks -= other.short_end_blocks;
        self.estimated_time_s -= other.estimated_time_s;
    }

    /// Counts one block of `length` mm at `feed` mm/min.
    fn block(&mut self, length: f64, feed: f64, block_time_ms: f64, span_end: bool) {
        self.blocks += 1;
        let short = length < feed * block_time_ms / MS_PER_MIN * (1.0 - SHORT_SLACK);
        if short && span_end {
            self.short_end_blocks += 1;
        } else if short {
            self.short_blocks += 1;
        }
        self.estimated_time_s += (length / feed * 60.0).max(block_time_ms / 1000.0);
    }
}

/// The re-segmented program's figures.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ResegmentAnswer {
    /// The machine the request named, as registered.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine: Option<MachineProfile>,
    /// T_b used, ms.
    pub block_time_ms: f64,
    /// Lines of the program.
    pub lines: usize,
    /// Runs cut again.
    pub runs: usize,
    /// Feed moves in those runs.
    pub run_moves: usize,
    /// The feed blocks of the program as sent.
    pub before: ProgramFigures,
    /// The feed blocks of the program returned.
    pub after: ProgramFigures,
    /// Largest distance of the program's path from the new blocks, mm.
    pub max_deviation: f64,
    /// Largest chord error the rule chose, mm.
    pub chord_error: f64,
    /// Runs left as they were and why, feeds capped by the machine, and the like.
    pub warnings: Vec<Warning>,
    /// The new blocks of each run, for the program.
    #[serde(skip)]
    pub cuts: Vec<RunCut>,
}

/// One run cut again: the source lines it replaces and the points of its new blocks.
#[derive(Debug, Clone, PartialEq)]
pub struct RunCut {
    /// First source line replaced, 1-based.
    pub first_line: usize,
    /// Last source line replaced.
    pub last_line: usize,
    /// Units the points are written in.
    pub units: Units,
    /// The end points of the new blocks, mm (the run's start is where the tool already is).
    pub points: Vec<[f64; 3]>,
}

/// The re-segment capability.
#[derive(Debug, Clone, Copy)]
pub struct ResegmentCapability;

impl Capability for ResegmentCapability {
    const NAME: &'static str = "resegment";
    const ENDPOINT: Endpoint = Endpoint {
        summary: "Cuts the feed moves of a G-code program again by the block-time rule.",
        description: "Reads a program, cuts each run of feed moves (dense G01 points as a polyline, G02/G03 \
            as arcs) in mode `guarantee` for the machine's block time, and returns the block figures before \
            and after and the largest deviation (JSON), or with `Accept: text/x-gcode` / `?format=gcode` the \
            program with every other line (rapids, tool changes, spindle, coolant, comments) byte for byte as \
            sent, or re-posted line by line in the post of `?dialect=` or the machine when it is not the \
            program's own (`program_dialect`; a code without a counterpart there is refused naming its line). \
            The program keeps its programmed point: `reference` and `arcs` do not apply.",
        not_found: "Unknown machine",
        refused: "Impossible request: `E_INPUT` (no block time, bad factors), `E_GCODE_SYNTAX`, \
            `E_GCODE_UNSUPPORTED`, `E_ARC_NOT_CLOSED`, `E_ARC_RADIUS`, `E_TOO_MANY_LINES` (each naming \
            `program` and the line); `E_TIMEOUT` over the synchronous time limit: submit a job",
    };
    type Request = ResegmentRequest;
    type Answer = ResegmentAnswer;
    type Tool = Option<crate::tool::Tool>;

    fn refs(request: &ResegmentRequest) -> Refs<'_> {
        Refs { tool: None, machine: request.machine.as_deref(), material: None }
    }

    fn solve(
        request: &ResegmentRequest,
        context: Resolved<Option<crate::tool::Tool>>,
        run: &Run<'_>,
    ) -> Result<ResegmentAnswer, SolverError> {
        resegment(request, context.machine, run.control)
    }

    fn program(
        request: &ResegmentRequest,
        answer: &ResegmentAnswer,
        output: &OutputOptions,
        control: Control<'_>,
    ) -> Result<String, SolverError> {
        match output.dialect {
            Some(target) => write_posted(&request.program, &answer.cuts, program_dialect(request)?, target, control),
            None => write(&request.program, &answer.cuts, control),
        }
    }

    fn units(request: &ResegmentRequest) -> Option<crate::units::Units> {
        request.units
    }

    /// The chord-error bounds; the program is read in its own G20/G21.
    fn scale_request(request: &mut ResegmentRequest, scaling: crate::units::Scaling) -> Result<(), SolverError> {
        use crate::units::Scale;
        let ResegmentRequest {
            program: _,
            machine: _,
            block_time_ms: _,
            margin: _,
            min_chord_error,
            tolerance,
            corner_angle_deg: _,
            program_dialect: _,
            units: _,
        } = request;
        min_chord_error.scale(scaling);
        tolerance.scale(scaling);
        Ok(())
    }

    /// The echoed machine, the deviation and the chord error (the figures are counts and times;
    /// the new blocks, kept for the program, stay in mm).
    fn scale_answer(answer: &mut ResegmentAnswer, scaling: crate::units::Scaling) {
        use crate::units::Scale;
        let ResegmentAnswer {
            machine,
            block_time_ms: _,
            lines: _,
            runs: _,
            run_moves: _,
            before: _,
            after: _,
            max_deviation,
            chord_error,
            warnings,
            cuts: _,
        } = answer;
        machine.scale(scaling);
        warnings.scale(scaling);
        max_deviation.scale(scaling);
        chord_error.scale(scaling);
    }

    fn machine(answer: &ResegmentAnswer) -> Option<&MachineProfile> {
        answer.machine.as_ref()
    }
}

/// Re-segments `request.program` on `machine` (the one the request names, if any).
///
/// # Errors
/// `E_INPUT` naming the field (`program` empty, no `block_time_ms`, bad factors); the reader's
/// errors naming `program` and the line; `E_CANCELLED`.
pub fn resegment(
    request: &ResegmentRequest,
    machine: Option<MachineProfile>,
    control: Control<'_>,
) -> Result<ResegmentAnswer, SolverError> {
    if request.program.trim().is_empty() {
        return Err(SolverError::input("program", "the program is empty"));
    }
    program_dialect(request)?;
    let block_time_ms = match request.block_time_ms.or(machine.as_ref().map(|m| m.block_time_ms)) {
        Some(value) => crate::validate::positive("block_time_ms", value, Measure::Number)?,
        None => {
            return Err(SolverError::input("block_time_ms", "give block_time_ms or a machine that has one"));
        }
    };
    if let Some(angle) = request.corner_angle_deg {
        crate::validate::finite("corner_angle_deg", angle)?;
    }
    let machine_ref = machine.as_ref();
    let margin = match request.margin.or(machine_ref.and_then(|m| m.margin)) {
        Some(value) if value.is_finite() && value >= 1.0 => value,
        Some(value) => return Err(SolverError::input("margin", format!("margin {value} must be at least 1"))),
        None => 1.0,
    };
    let min_chord_error = match request.min_chord_error.or(machine_ref.and_then(|m| m.min_chord_error)) {
        Some(value) => crate::validate::non_negative("min_chord_error", value, Measure::Length)?,
        None => 0.0,
    };
    if let Some(tolerance) = request.tolerance {
        crate::validate::positive("tolerance", tolerance, Measure::Length)?;
    }
    let program = reader::read_cancellable(&request.program, "program", &ReadOptions::default(), control)?;
    let lines: Vec<&str> = request.program.split('\n').collect();
    let moves = &program.moves;
    let shapes: Vec<LineShape> = moves.iter().map(|m| line_shape(lines[m.line - 1])).collect();

    let mut before = ProgramFigures::default();
    let mut move_figures = Vec::with_capacity(moves.len());
    for (index, read) in moves.iter().enumerate() {
        let mut figures = ProgramFigures::default();
        if let (Some(feed), Some(length)) = (read.modal.feed.filter(|f| *f > 0.0), feed_length(read)) {
            figures.block(length, feed, block_time_ms, span_end(moves, index));
        }
        before.add(&figures);
        move_figures.push(figures);
    }

    let mut answer = ResegmentAnswer {
        machine,
        block_time_ms,
        lines: program.line_count,
        runs: 0,
        run_moves: 0,
        before,
        after: before,
        max_deviation: 0.0,
        chord_error: 0.0,
        warnings: Vec::new(),
        cuts: Vec::new(),
    };
    let runs = find_runs(moves, &shapes);
    let mut warnings: Vec<Warning> = Vec::new();
    for (done, range) in runs.iter().enumerate() {
        control.check()?;
        control.report(done, runs.len());
        let run = &moves[range.clone()];
        let Some((curve, feed, first)) = run_curve(run, request.corner_angle_deg) else {
            continue;
        };
        let decimals = shapes[range.clone()].iter().map(|s| s.decimals).max().unwrap_or(0);
        let rounding = ROUNDING_FLOOR_UNITS * 10f64.powi(-(decimals as i32)) * run[0].modal.units.scale();
        let mut segment = SegmentRequest::guarantee(curve, feed, block_time_ms);
        segment.margin = Some(margin * ROUNDING_MARGIN);
        segment.min_chord_error = Some(min_chord_error.max(rounding));
        segment.tolerance = request.tolerance;
        let solution = match super::solve_controlled(&segment, answer.machine.as_ref(), control) {
            Ok(solution) => solution,
            Err(error) if error.code() == ErrorCode::Cancelled => return Err(error),
            Err(error) if error.code() == ErrorCode::Input => {
                // A field of the request, not of the run: the whole request is wrong.
                if matches!(error.field(), Some("margin" | "min_chord_error" | "tolerance" | "block_time_ms")) {
                    return Err(error);
                }
                warnings.push(kept_warning(run, &error));
                continue;
            }
            Err(error) => {
                warnings.push(kept_warning(run, &error));
                continue;
            }
        };
        warnings.extend(solution.warnings.iter().filter(|w| w.code == "W_FEED_ABOVE_MACHINE_MAX").cloned());
        let last_read = range.end - 1;
        let cut = new_blocks(&solution, run, first);
        let mut old = ProgramFigures::default();
        for figures in &move_figures[range.clone()] {
            old.add(figures);
        }
        let new = new_figures(&solution, &cut.points, first, feed, block_time_ms, span_end(moves, last_read));
        answer.after.remove(&old);
        answer.after.add(&new);
        answer.max_deviation = answer.max_deviation.max(solution.max_deviation);
        answer.chord_error = answer.chord_error.max(solution.chord_error);
        answer.runs += 1;
        answer.run_moves += run.len();
        answer.cuts.push(cut);
    }
    answer.warnings = condense(warnings);
    Ok(answer)
}

/// The post the request's program was written for: one of the RS274 family the reader takes.
fn program_dialect(request: &ResegmentRequest) -> Result<Dialect, SolverError> {
    match request.program_dialect.unwrap_or_default() {
        dialect @ (Dialect::Fanuc | Dialect::Haas | Dialect::Linuxcnc | Dialect::Grbl) => Ok(dialect),
        other => Err(SolverError::input(
            "program_dialect",
            format!(
                "the G-code reader takes RS274/Fanuc programs (fanuc, haas, linuxcnc, grbl), not {}",
                other.as_str()
            ),
        )),
    }
}

/// What a move's source line holds besides its motion.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LineShape {
    /// Nothing but the motion: the rewrite may replace the line.
    pure: bool,
    /// It states its motion code (`G0`–`G3`).
    motion_word: bool,
    /// Most decimals of its axis words.
    decimals: usize,
    /// Where its `F` word is (letter to end of number), if it has one.
    feed: Option<(usize, usize)>,
}

/// Scans a motion line: which words it has (the reader has already checked them).
fn line_shape(raw: &str) -> LineShape {
    let line = raw.strip_suffix('\r').unwrap_or(raw);
    let bytes = line.as_bytes();
    let mut shape = LineShape { pure: true, motion_word: false, decimals: 0, feed: None };
    let mut index = 0;
    while index < bytes.len() {
        let c = bytes[index].to_ascii_uppercase();
        if c == b' ' || c == b'\t' {
            index += 1;
            continue;
        }
        if !c.is_ascii_alphabetic() {
            // A comment, block delete, `%`: the line stays as it is.
            shape.pure = false;
            return shape;
        }
        let start = index;
        index += 1;
        while index < bytes.len() && matches!(bytes[index], b' ' | b'\t') {
            index += 1;
        }
        let number = index;
        while index < bytes.len() && matches!(bytes[index], b'0'..=b'9' | b'.' | b'+' | b'-') {
            index += 1;
        }
        let text = &line[number..index];
        match c {
            b'G' => match text.parse::<f64>() {
                Ok(code) if [0.0, 1.0, 2.0, 3.0].contains(&code) => shape.motion_word = true,
                _ => shape.pure = false,
            },
            b'F' => shape.feed = Some((start, index)),
            b'X' | b'Y' | b'Z' => {
                let decimals = text.find('.').map_or(0, |point| text.len() - point - 1);
                shape.decimals = shape.decimals.max(decimals);
            }
            b'N' | b'I' | b'J' | b'K' | b'R' => {}
            _ => shape.pure = false,
        }
    }
    shape
}

/// Length of a feed move, mm; `None` for rapids and moves from an unknown position.
fn feed_length(read: &ReadMove) -> Option<f64> {
    if read.kind == MoveKind::Rapid {
        return None;
    }
    let mut at = read.from_xyz()?;
    let mut length = 0.0;
    for point in read.points(ARC_LENGTH_TOLERANCE)? {
        length += distance(at, point);
        at = point;
    }
    Some(length)
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2) + (b[2] - a[2]).powi(2)).sqrt()
}

/// Whether feed move `index` ends a span: the next move is a rapid, comes after a tool change
/// (from an unknown position), changes feed or plane, or there is none.
fn span_end(moves: &[ReadMove], index: usize) -> bool {
    let Some(next) = moves.get(index + 1) else {
        return true;
    };
    let this = &moves[index];
    next.kind == MoveKind::Rapid
        || next.from_xyz().is_none()
        || next.modal.feed != this.modal.feed
        || next.modal.plane != this.modal.plane
        || next.modal.tool != this.modal.tool
}

/// The kind of run a move may be part of.
#[derive(Debug, Clone, Copy, PartialEq)]
enum RunKind {
    Lines,
    Arc,
}

/// Which run a move may join, if any.
fn run_kind(read: &ReadMove, shape: &LineShape) -> Option<RunKind> {
    let feed_ok = read.modal.feed.is_some_and(|f| f.is_finite() && f > 0.0);
    if !shape.pure || !feed_ok || read.modal.distance != Distance::Absolute {
        return None;
    }
    let (from, to) = (read.from_xyz()?, read.to_xyz()?);
    match read.kind {
        MoveKind::Rapid => None,
        MoveKind::Linear => Some(RunKind::Lines),
        MoveKind::Arc { extra_turns, .. } => {
            let flat = (from[2] - to[2]).abs() <= 1e-9;
            (read.modal.plane == Plane::Xy && extra_turns == 0 && flat).then_some(RunKind::Arc)
        }
    }
}

/// The runs of `moves` (index ranges) that may be cut again.
fn find_runs(moves: &[ReadMove], shapes: &[LineShape]) -> Vec<std::ops::Range<usize>> {
    let mut runs = Vec::new();
    let mut index = 0;
    while index < moves.len() {
        let Some(kind) = run_kind(&moves[index], &shapes[index]) else {
            index += 1;
            continue;
        };
        let start = index;
        index += 1;
        if kind == RunKind::Lines {
            let first = &moves[start];
            while index < moves.len()
                && index - start < MAX_RUN_MOVES
                && moves[index].line == moves[index - 1].line + 1
                && run_kind(&moves[index], &shapes[index]) == Some(RunKind::Lines)
                && moves[index].modal.feed == first.modal.feed
                && moves[index].modal.units == first.modal.units
                && moves[index].modal.tool == first.modal.tool
                && moves[index].modal.plane == first.modal.plane
                // A later F word (even of the same feed) keeps its line: the run's first F word is the only one written.
                && shapes[index].feed.is_none()
            {
                index += 1;
            }
        }
        let mut end = index;
        // The move after the run may rely on the modal motion code the run leaves: an arc run
        // becomes straight blocks, so a following move without its own motion word keeps the arc.
        let next_needs_mode = moves.get(end).is_some_and(|_| !shapes[end].motion_word);
        if kind == RunKind::Arc && next_needs_mode {
            end -= 1;
        }
        let worth = match kind {
            RunKind::Lines => end - start >= 2,
            RunKind::Arc => end > start,
        };
        if worth {
            runs.push(start..end);
        }
    }
    runs
}

/// The target curve of a run, its feed and its start point.
fn run_curve(run: &[ReadMove], corner_angle_deg: Option<f64>) -> Option<(Curve, f64, [f64; 3])> {
    let first = run.first()?;
    let feed = first.modal.feed?;
    let start = first.from_xyz()?;
    match first.kind {
        MoveKind::Arc { centre, clockwise, .. } => {
            let to = first.to_xyz()?;
            let radius = ((start[0] - centre[0]).powi(2) + (start[1] - centre[1]).powi(2)).sqrt();
            let start_deg = (start[1] - centre[1]).atan2(start[0] - centre[0]).to_degrees();
            let mut end_deg = (to[1] - centre[1]).atan2(to[0] - centre[0]).to_degrees();
            // Same start and end: a full turn (the reader's reading of such an arc).
            if (end_deg - start_deg).abs() < 1e-9 {
                end_deg = start_deg + 360.0;
            }
            let direction = if clockwise { Direction::Cw } else { Direction::Ccw };
            let curve =
                Curve::Arc { centre: vec![centre[0], centre[1], start[2]], radius, start_deg, end_deg, direction };
            Some((curve, feed, start))
        }
        _ => {
            let mut points = Vec::with_capacity(run.len() + 1);
            points.push(start.to_vec());
            points.extend(run.iter().filter_map(|m| m.to_xyz()).map(|p| p.to_vec()));
            Some((Curve::Polyline { points, corner_angle_deg }, feed, start))
        }
    }
}

/// The new blocks of a run: the solution's command points after the first, the last replaced
/// by the run's exact end (an arc's end may sit up to the reader's closure tolerance off its
/// circle).
fn new_blocks(solution: &SegmentSolution, run: &[ReadMove], start: [f64; 3]) -> RunCut {
    let first = &run[0];
    let last = &run[run.len() - 1];
    let mut points: Vec<[f64; 3]> = solution
        .points
        .iter()
        .skip(1)
        .map(|p| {
            let v = p.to_vec3();
            [v.x, v.y, if p.dimension() == 3 { v.z } else { start[2] }]
        })
        .collect();
    if let (Some(end), Some(point)) = (last.to_xyz(), points.last_mut()) {
        *point = end;
    }
    RunCut { first_line: first.line, last_line: last.line, units: first.modal.units, points }
}

/// The figures of a run's new blocks.
fn new_figures(
    solution: &SegmentSolution,
    points: &[[f64; 3]],
    start: [f64; 3],
    feed: f64,
    block_time_ms: f64,
    ends_span: bool,
) -> ProgramFigures {
    let stats = &solution.stats;
    let mut figures = ProgramFigures::default();
    let mut at = start;
    for (index, &point) in points.iter().enumerate() {
        let last = index + 1 == points.len();
        figures.block(distance(at, point), feed, block_time_ms, last && ends_span);
        at = point;
    }
    // Corner remainders are span ends in the cut's figures: the control slows down there.
    let corner_ends = stats.short_end_blocks.saturating_sub(usize::from(stats.last_block_length < stats.block_length));
    let moved = corner_ends.min(figures.short_blocks);
    figures.short_blocks -= moved;
    figures.short_end_blocks += moved;
    figures
}

fn kept_warning(run: &[ReadMove], error: &SolverError) -> Warning {
    Warning::new(
        "W_RUN_KEPT",
        format!(
            "lines {}–{} are kept as they were: {}",
            run[0].line,
            run[run.len() - 1].line,
            error.to_string().trim_end_matches('.')
        ),
    )
}

/// At most [`WARNINGS_PER_CODE`] warnings of each code, the last of them counting the others.
fn condense(warnings: Vec<Warning>) -> Vec<Warning> {
    let mut kept: Vec<Warning> = Vec::new();
    let mut dropped: Vec<(&'static str, usize)> = Vec::new();
    for warning in warnings {
        if kept.iter().any(|w| w.code == warning.code && w.message == warning.message) {
            continue;
        }
        if kept.iter().filter(|w| w.code == warning.code).count() < WARNINGS_PER_CODE {
            kept.push(warning);
        } else if let Some(entry) = dropped.iter_mut().find(|(code, _)| *code == warning.code) {
            entry.1 += 1;
        } else {
            dropped.push((warning.code, 1));
        }
    }
    for (code, count) in dropped {
        kept.push(Warning::new(code, format!("and {count} more like the above")));
    }
    kept
}

/// The program with each run's lines replaced by its new blocks; every other line as sent.
///
/// # Errors
/// `E_CANCELLED` once `control`'s cancel flag is set.
pub fn write(source: &str, cuts: &[RunCut], control: Control<'_>) -> Result<String, SolverError> {
    let new_lines: usize = cuts.iter().map(|c| c.points.len()).sum();
    let mut out = String::with_capacity(source.len() + new_lines * 40);
    let mut cuts = cuts.iter().peekable();
    let mut skip_until = 0;
    for (index, line) in source.split_inclusive('\n').enumerate() {
        let number = index + 1;
        if index % crate::gcode::MOVES_PER_CHECK == 0 {
            control.check()?;
        }
        if number <= skip_until {
            continue;
        }
        match cuts.next_if(|cut| cut.first_line == number) {
            Some(cut) => {
                let ending = if line.ends_with("\r\n") { "\r\n" } else { "\n" };
                // The run's feed is its first line's F word (the later lines have none).
                write_blocks(&mut out, cut, feed_word_of(line).as_deref(), ending);
                if !line.ends_with('\n') {
                    // The source's last line had no line end: neither has the last block.
                    out.truncate(out.len() - ending.len());
                }
                skip_until = cut.last_line;
            }
            None => out.push_str(line),
        }
    }
    Ok(out)
}

/// The program for the post `target`: each run's lines replaced by its new blocks in the post's
/// words, every other line re-posted in order ([`Reposter`]), or kept as sent when `target` is
/// the program's own post (`source_dialect`).
///
/// # Errors
/// `E_GCODE_UNSUPPORTED` naming the line whose code has no counterpart in `target`;
/// `E_CANCELLED`.
pub fn write_posted(
    source: &str,
    cuts: &[RunCut],
    source_dialect: Dialect,
    target: Dialect,
    control: Control<'_>,
) -> Result<String, SolverError> {
    if target == source_dialect {
        return write(source, cuts, control);
    }
    let mut out = Reposter::new(target, source, "program");
    let program = reader::read_cancellable(source, "program", &ReadOptions::default(), control)?;
    let mut moves = program.moves.iter().peekable();
    let mut cuts = cuts.iter().peekable();
    let mut skip_until = 0;
    let last = source.split('\n').count();
    for (index, line) in source.split('\n').enumerate() {
        let number = index + 1;
        if index % crate::gcode::MOVES_PER_CHECK == 0 {
            control.check()?;
        }
        while moves.next_if(|m| m.line < number).is_some() {}
        if number <= skip_until {
            continue;
        }
        if line.is_empty() && number == last {
            // The text after the last line end.
            break;
        }
        match cuts.next_if(|cut| cut.first_line == number) {
            Some(cut) => {
                out.feed_blocks(number, &cut.points, cut.units, feed_word_of(line).as_deref())?;
                skip_until = cut.last_line;
            }
            None => out.line(number, line, moves.peek().copied().filter(|m| m.line == number))?,
        }
    }
    out.finish(source)
}

/// The `F` word of a line as written, if it has one.
fn feed_word_of(line: &str) -> Option<String> {
    let shape = line_shape(line.strip_suffix('\n').unwrap_or(line));
    shape.feed.map(|(start, end)| line[start..end].replace([' ', '\t'], ""))
}

fn write_blocks(out: &mut String, cut: &RunCut, feed_word: Option<&str>, ending: &str) {
    use std::fmt::Write as _;
    let scale = cut.units.scale();
    for (index, point) in cut.points.iter().enumerate() {
        let [x, y, z] = point.map(|v| crate::gcode::mm(v / scale));
        let _ = write!(out, "G01 X{x} Y{y} Z{z}");
        if index == 0
            && let Some(word) = feed_word
        {
            out.push(' ');
            out.push_str(word);
        }
        out.push_str(ending);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn request(program: String) -> ResegmentRequest {
        ResegmentRequest {
            program,
            machine: None,
            block_time_ms: Some(4.0),
            margin: None,
            min_chord_error: None,
            tolerance: None,
            corner_angle_deg: None,
            program_dialect: None,
            units: None,
        }
    }

    /// A 0.01 mm-step circle of radius 100 at 6000 mm/min between a rapid and a retract.
    fn dense_circle() -> String {
        let mut text =
            String::from("%\nO1000 (DENSE)\nG21 G17 G90\nT1 M06\nS6000 M03\nM08\nG00 X100. Y0. Z5.\nG01 Z-1. F300\n");
        let steps = (std::f64::consts::TAU * 100.0 / 0.01).round() as usize;
        for k in 1..=steps {
            let angle = std::f64::consts::TAU * k as f64 / steps as f64;
            let f = if k == 1 { " F6000" } else { "" };
            text.push_str(&format!("G01 X{:.4} Y{:.4}{f}\n", 100.0 * angle.cos(), 100.0 * angle.sin()));
        }
        text.push_str("G00 Z5.\nM09\nM05\nM30\n%\n");
        text
    }

    #[test]
    fn a_dense_circle_loses_its_short_blocks_and_keeps_every_other_line() {
        let source = dense_circle();
        let answer = resegment(&request(source.clone()), None, Control::default()).unwrap();
        assert!(answer.before.short_blocks > 60_000, "{:?}", answer.before);
        assert_eq!(answer.after.short_blocks, 0, "{:?}", answer.after);
        assert!(answer.after.blocks < answer.before.blocks / 40, "{:?}", answer.after);
        assert!(answer.after.estimated_time_s < answer.before.estimated_time_s / 10.0);
        let text = write(&source, &answer.cuts, Control::default()).unwrap();
        let kept = |program: &str| -> Vec<String> {
            program.lines().filter(|l| !l.starts_with("G01 X")).map(str::to_owned).collect()
        };
        assert_eq!(kept(&text), kept(&source));
        assert!(text.contains("G01 Z-1. F300\nG01 X"));
        assert!(text.ends_with("Y0.0000 Z-1.0000\nG00 Z5.\nM09\nM05\nM30\n%\n"), "{}", &text[text.len() - 200..]);
    }

    #[test]
    fn a_cancelled_run_stops_reading_cutting_and_writing() {
        let source = dense_circle();
        let cancel = std::sync::atomic::AtomicBool::new(true);
        let control = Control { progress: None, cancel: Some(&cancel) };
        let error = resegment(&request(source.clone()), None, control).unwrap_err();
        assert_eq!(error.code(), ErrorCode::Cancelled);
        let answer = resegment(&request(source.clone()), None, Control::default()).unwrap();
        assert_eq!(write(&source, &answer.cuts, control).unwrap_err().code(), ErrorCode::Cancelled);
    }

    #[test]
    fn lines_with_more_than_motion_stay() {
        let shape = line_shape("G01 X1 Y2 F300");
        assert!(shape.pure && shape.motion_word && shape.feed == Some((10, 14)));
        assert!(!line_shape("G01 X1 Y2 (edge)").pure);
        assert!(!line_shape("G01 X1 Y2 M08").pure);
        assert!(!line_shape("G90 G01 X1").pure);
        assert!(!line_shape("/G01 X1").pure);
        assert!(!line_shape("X1 Y2").motion_word);
    }

    #[test]
    fn an_arc_whose_next_move_keeps_its_mode_stays() {
        let source = "G21 G17 G90\nG00 X10 Y0 Z0\nG03 X-10 Y0 I-10 J0 F60000\nX10 Y0 I10 J0\nM30\n";
        let answer = resegment(&request(source.to_owned()), None, Control::default()).unwrap();
        assert_eq!(answer.cuts.len(), 1);
        assert_eq!((answer.cuts[0].first_line, answer.cuts[0].last_line), (4, 4));
        let text = write(source, &answer.cuts, Control::default()).unwrap();
        assert!(text.contains("\nG03 X-10 Y0 I-10 J0 F60000\nG01 X"), "{text}");
        assert!(text.ends_with("G01 X10.0000 Y0.0000 Z0.0000\nM30\n"), "{text}");
        assert!(answer.max_deviation <= answer.chord_error + 1e-9 && answer.chord_error > 0.0);
    }

    #[test]
    fn inch_runs_are_written_in_inch() {
        let mut source = String::from("G20 G17 G90\nG00 X0 Y0 Z0\n");
        for k in 1..=400 {
            let f = if k == 1 { " F100" } else { "" };
            source.push_str(&format!("G01 X{:.4} Y0{f}\n", f64::from(k) * 0.0005));
        }
        source.push_str("M30\n");
        let answer = resegment(&request(source.clone()), None, Control::default()).unwrap();
        let text = write(&source, &answer.cuts, Control::default()).unwrap();
        assert!(text.contains("G01 X0.2000 Y0.0000 Z0.0000 F100\nM30"), "{text}");
    }

    #[test]
    fn a_fanuc_program_is_reposted_for_sinumerik_in_its_words_and_order() {
        let source = dense_circle();
        let answer = resegment(&request(source.clone()), None, Control::default()).unwrap();
        let text = write_posted(&source, &answer.cuts, Dialect::Fanuc, Dialect::Sinumerik, Control::default()).unwrap();
        assert!(
            text.starts_with("; DENSE\nG71 G17 G90\nT1 D1\nM6\nS6000 M3\nM8\nG0 X100. Y0. Z5.\nG1 Z-1. F300\nG1 X"),
            "{}",
            &text[..200]
        );
        assert!(text.ends_with(" Z-1.0000\nG0 Z5.\nM9\nM5\nM30\n"), "{}", &text[text.len() - 200..]);
        assert!(!text.contains('(') && !text.contains('%') && !text.contains("G01"));
        assert_eq!(text.lines().filter(|l| l.starts_with("G1 X")).count(), answer.after.blocks - 1);
    }

    #[test]
    fn a_fanuc_program_is_reposted_as_klartext_blocks_in_order() {
        let source = dense_circle();
        let answer = resegment(&request(source.clone()), None, Control::default()).unwrap();
        let text =
            write_posted(&source, &answer.cuts, Dialect::Fanuc, Dialect::Heidenhain, Control::default()).unwrap();
        // The speed by a tool call without a tool; spindle and coolant on the next move, which
        // the program gives before any Z.
        assert!(
            text.starts_with(
                "0 BEGIN PGM KERF1000 MM\n1 ; DENSE\n2 TOOL CALL 1 Z\n3 TOOL CALL Z S6000\n\
                 4 L X+100.0000 Y+0.0000 Z+5.0000 R0 FMAX M3 M8\n5 L Z-1.0000 R0 F300\n6 L X+99.9986 Y+0.5182 Z-1.0000 R0 F6000\n"
            ),
            "{}",
            &text[..400]
        );
        let blocks: Vec<&str> = text.lines().map(|l| l.split_once(' ').unwrap().1).collect();
        assert!(text.lines().enumerate().all(|(k, l)| l.starts_with(&format!("{k} "))), "block numbers");
        let tail = &blocks[blocks.len() - 6..];
        assert_eq!(
            tail,
            [
                "L X+100.0000 Y+0.0000 Z-1.0000 R0",
                "L Z+5.0000 R0 FMAX",
                "L Z+5.0000 R0 FMAX M9",
                "L Z+5.0000 R0 FMAX M5",
                "L Z+5.0000 R0 FMAX M30",
                "END PGM KERF1000 MM"
            ]
        );
        assert_eq!(
            blocks.iter().filter(|b| b.starts_with("L X") && !b.contains("FMAX")).count(),
            answer.after.blocks - 1
        );
    }

    #[test]
    fn klartext_says_inch_feeds_arcs_and_helices_and_refuses_what_it_cannot() {
        let source = "%\nO0042 (ARCS)\nG20 G17 G90 G54\nT3 M06\nS5000 M03\nG00 X1. Y0. Z0.2\nG01 Z-0.1 F10.\n\
                      G03 X-1. Y0. I-1. J0. F20. (HALF)\nG02 X1. Y0. Z-0.2 R1.\nG00 Z0.2\nM00\nM05\nM30\n%\n";
        let answer = resegment(&request(source.to_owned()), None, Control::default()).unwrap();
        let text = write_posted(source, &answer.cuts, Dialect::Fanuc, Dialect::Heidenhain, Control::default()).unwrap();
        let blocks: Vec<&str> = text.lines().map(|l| l.split_once(' ').unwrap().1).collect();
        // F in 0.1 inch/min; the M3 before any position on the first move.
        assert_eq!(
            blocks[..9],
            [
                "BEGIN PGM KERF42 INCH",
                "; ARCS",
                "TOOL CALL 3 Z",
                "TOOL CALL Z S5000",
                "L X+1.0000 Y+0.0000 Z+0.2000 R0 FMAX M3",
                "L Z-0.1000 R0 F100",
                "CC X+0.0000 Y+0.0000",
                "C X-1.0000 Y+0.0000 DR+ F200",
                "; HALF",
            ],
            "{text}"
        );
        // The helical half turn as straight blocks, ending at its end.
        let helix: Vec<&&str> = blocks[9..].iter().take_while(|b| b.starts_with("L X")).collect();
        assert!(helix.len() > 20, "{text}");
        assert_eq!(*helix[helix.len() - 1], "L X+1.0000 Y+0.0000 Z-0.2000 R0");
        assert!(
            blocks.ends_with(&[
                "L Z+0.2000 R0 FMAX",
                "STOP",
                "L Z+0.2000 R0 FMAX M5",
                "L Z+0.2000 R0 FMAX M30",
                "END PGM KERF42 INCH"
            ]),
            "{text}"
        );
        for (program, line, what) in [
            ("G21 G90\nG00 X0 Y0 Z1\nG55\n", 3, "G55"),
            ("G21 G90\nG00 X0 Y0 Z1\nG20\n", 3, "G20"),
            ("G21 G90\nG00 X0 Y0 Z1\nM06\n", 3, "M6 without a tool"),
            ("G21 G90 G18\nG00 X0 Y0 Z1\nG02 X2 Z1 I1 K0 F100\n", 3, "outside the XY plane"),
            ("G21 G90\nG95\n", 2, "G95"),
            ("G21 G90\nM08\nT1 M06\n", 2, "M8 before any Z"),
        ] {
            let answer = resegment(&request(program.to_owned()), None, Control::default()).unwrap();
            let error = write_posted(program, &answer.cuts, Dialect::Fanuc, Dialect::Heidenhain, Control::default())
                .unwrap_err();
            assert_eq!((error.code(), error.field()), (ErrorCode::GcodeUnsupported, Some("program")), "{program}");
            let message = error.to_string();
            assert!(message.contains(&format!("line {line}: ")) && message.contains(what), "{message}");
        }
    }

    #[test]
    fn a_haas_machine_with_smoothing_gets_g187_after_the_heading_and_no_other_does() {
        let source = dense_circle();
        let program = |machine: &str, dialect: Option<Dialect>| {
            let machine: MachineProfile = serde_json::from_str(machine).unwrap();
            let request = request(source.clone());
            let answer = resegment(&request, Some(machine), Control::default()).unwrap();
            let output = OutputOptions { dialect, ..OutputOptions::default() };
            crate::capability::program::<ResegmentCapability>(&request, &answer, &output, Control::default()).unwrap()
        };
        let smooth = r#"{"block_time_ms": 4, "max_feed": 10000, "dialect": "haas", "haas_smoothing": 2}"#;
        // The program's own post (fanuc) asked for on the Haas: its heading, then G187.
        let kept = program(smooth, Some(Dialect::Fanuc));
        assert!(!kept.contains("G187"), "a Fanuc program has no G187");
        let haas = program(smooth, None);
        assert!(haas.starts_with("%\nO01000 (DENSE)\nG187 P2\nG21 G17 G90\n"), "{}", &haas[..100]);
        assert_eq!(haas.matches("G187").count(), 1);
        let plain = program(r#"{"block_time_ms": 4, "max_feed": 10000, "dialect": "haas"}"#, None);
        assert!(!plain.contains("G187"), "{}", &plain[..100]);
        assert_eq!(haas.replacen("G187 P2\n", "", 1), plain);
        // A Haas source kept as sent (its own post) gets it too.
        let mut own = request(source.clone());
        own.program_dialect = Some(Dialect::Haas);
        let machine: MachineProfile = serde_json::from_str(smooth).unwrap();
        let answer = resegment(&own, Some(machine), Control::default()).unwrap();
        let text = crate::capability::program::<ResegmentCapability>(
            &own,
            &answer,
            &OutputOptions::default(),
            Control::default(),
        )
        .unwrap();
        assert!(text.starts_with("%\nO1000 (DENSE)\nG187 P2\nG21 G17 G90\n"), "{}", &text[..100]);
    }

    #[test]
    fn heidenhain_iso_numbers_the_blocks_and_writes_arc_centres_absolute() {
        let source = "%\nO0042 (ARC)\nG21 G17 G90\nT3 M06\nG00 G43 H3 Z5.\nG00 X10 Y0\nG01 Z-1 F100\nG03 X-10 Y0 I-10 J0 F600 (HALF)\nM30\n%\n";
        let answer = resegment(&request(source.to_owned()), None, Control::default()).unwrap();
        assert!(answer.cuts.is_empty(), "a line with a comment stays");
        let text =
            write_posted(source, &answer.cuts, Dialect::Fanuc, Dialect::HeidenhainIso, Control::default()).unwrap();
        assert_eq!(
            text,
            "%KERF42 G71 *\nN10 ; ARC *\nN20 G71 G17 G90 *\nN30 T3 G17 *\nN40 G00 Z+5. *\nN50 G00 X+10 Y+0 *\n\
             N60 G01 Z-1 F100 *\nN70 I+0.0000 J+0.0000 *\nN80 G03 X-10 Y+0 F600 *\nN90 ; HALF *\nN100 M30 *\nN99999999 %KERF42 G71 *\n"
        );
    }

    #[test]
    fn a_line_without_a_counterpart_is_refused_naming_it_unless_the_post_is_the_programs() {
        let source = "G21 G17 G90\nG00 X0 Y0 Z1\nG04 P500\nM30\n";
        let answer = resegment(&request(source.to_owned()), None, Control::default()).unwrap();
        for target in [Dialect::Sinumerik, Dialect::Linuxcnc, Dialect::Grbl, Dialect::Heidenhain] {
            let error = write_posted(source, &answer.cuts, Dialect::Fanuc, target, Control::default()).unwrap_err();
            assert_eq!(error.code(), ErrorCode::GcodeUnsupported);
            assert!(error.to_string().contains("line 3: G04"), "{error}");
        }
        let same = write_posted(source, &answer.cuts, Dialect::Fanuc, Dialect::Fanuc, Control::default()).unwrap();
        assert_eq!(same, source);
        let mut sinumerik = request(source.to_owned());
        sinumerik.program_dialect = Some(Dialect::Sinumerik);
        let error = resegment(&sinumerik, None, Control::default()).unwrap_err();
        assert_eq!(error.field(), Some("program_dialect"));
    }
}
