//! Segmentation with C_ep (docs/spec/segment.md §2.9): greedy maximal chords (first crossing), the
//! per-window procedure of embodiments 1, 2 and 6 (Fig. 7/8, S101–S108) with carry-over and the
//! progress rule, and the single-value run of embodiments 3–5 and of fixed-tolerance baselines.
//! Paths are split at corners (E11): every corner is a command point and starts fresh windows.

use crate::error::ErrorCode;
use std::cell::Cell;

use super::shape::{Shape, circumradius};
use super::{reference, search};
use crate::capability::{AnswerBudget, Control};
use crate::error::SolverError;
use crate::geometry::Vec3;
use crate::machine::rule::{BlockRule, ChordStatus, Infeasible, chord_length};

/// Slack on the chord error when testing a chord (docs/spec/segment.md §2.9: eps = 1e-12 mm).
pub(crate) const EPS: f64 = 1e-12;
/// Width (mm of arc length) to which the crossing is bracketed.
pub(crate) const CROSSING_WIDTH: f64 = 1e-12;
/// A chord shorter than this (mm) means the search made no progress (E14).
const MIN_PROGRESS: f64 = 1e-9;
/// Largest ratio of a window's 3-point radius to the smallest radius inside the window that is
/// used as it is; beyond it the radius is held at this multiple of the smallest (E10). A chord
/// cut with it is at least 1/√SPREAD_CAP of the target chord long.
pub(crate) const SPREAD_CAP: f64 = 1.1;
/// Slack on window ends (docs/spec/segment.md §2.9: s1 + 1e-12).
const WINDOW_SLACK: f64 = 1e-12;
/// Most blocks a cut reserves room for before it starts (beyond it the vectors grow as needed).
const MOST_RESERVED: usize = 1 << 20;

/// How the chord ends are found (docs/spec/segment.md §2.9a).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum Numerics {
    /// A handful of deviations per block (`search`).
    #[default]
    Fast,
    /// The reference numerics of §2.9 (`reference`), the test oracle.
    Reference,
}

/// A command point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Vertex {
    /// Curve parameter.
    pub u: f64,
    /// Arc length from the curve start, mm.
    pub s: f64,
    /// P(u).
    pub point: Vec3,
}

/// How a window's chord error was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Status {
    Surface,
    Straight,
    ClampedToMin,
    LimitedByTolerance,
}

/// One window of constant chord error.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WindowRecord {
    pub s_start: f64,
    pub s_end: f64,
    /// Radius the chord error came from (infinite when straight).
    pub radius: f64,
    /// C_ep before the accuracy bound.
    pub rule_chord_error: f64,
    /// Chord error used for the chords.
    pub chord_error: f64,
    pub status: Status,
    /// The radius estimate exceeds the smallest radius inside the window by this factor (E10).
    pub spread: f64,
    pub blocks: usize,
}

/// The result of a cut: command points, windows, and which blocks end a span (a corner or the
/// path end).
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Cut {
    pub vertices: Vec<Vertex>,
    /// Each block's deviation where the search measured it (`None`: compute it).
    pub deviations: Vec<Option<f64>>,
    pub windows: Vec<WindowRecord>,
    /// Block indices (block i runs from vertex i to i + 1) that end at a corner or the path end.
    pub span_ends: Vec<usize>,
}

/// How the window radius is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Estimate {
    /// Circumradius of P(s0), P(sm), P(s1) (docs/spec/segment.md §2.8, the patent).
    ThreePoint,
    /// Smallest radius over the window and the reach of its first chord.
    Minimum,
}

/// Where a failure happened: E3 with its arc length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct InfeasibleAt {
    pub s: f64,
    pub infeasible: Infeasible,
}

/// Why a cut stopped.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum CutError {
    Infeasible(InfeasibleAt),
    Solver(SolverError),
}

impl From<SolverError> for CutError {
    fn from(error: SolverError) -> Self {
        Self::Solver(error)
    }
}

/// The segmentation of one curve under a block limit.
pub(crate) struct Cutter<'a> {
    pub shape: &'a Shape,
    /// How chord ends are searched.
    pub numerics: Numerics,
    /// Parameter step of the last chord: the fast search's first trial for the next.
    pub last_step: Cell<f64>,
    /// The deviation of the chord `greedy_end` returned last, where the search measured it.
    pub last_deviation: Cell<Option<f64>>,
    /// Parameter ranges between corners, in order.
    pub spans: &'a [(f64, f64)],
    /// Most blocks before `E_TOO_MANY_BLOCKS`.
    pub max_blocks: usize,
    /// Field blamed when the limit is hit.
    pub limit_field: &'a str,
    /// Checked once per block: a cancelled request stops here.
    pub control: Control<'a>,
    /// The answer budget the command points are charged to, a block of points at a time; `None`:
    /// not counted.
    pub charge: Option<PointCharge<'a>>,
}

/// How a cutter's command points are charged to an answer budget.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PointCharge<'a> {
    /// The budget.
    pub budget: &'a AnswerBudget,
    /// Most bytes one command point takes, in memory and as the answer is delivered.
    pub point_bytes: u64,
}

/// Command points charged to the budget at once: a unit of work small against any budget (a few
/// hundred kB), large enough that charging costs nothing beside the search.
pub(crate) const CHARGED_POINTS: usize = 4096;

impl<'a> Cutter<'a> {
    /// A cutter for `spans` of `shape`, failing past `max_blocks` blocks with `limit_field`.
    pub(crate) fn new(
        shape: &'a Shape,
        spans: &'a [(f64, f64)],
        max_blocks: usize,
        limit_field: &'a str,
        numerics: Numerics,
        control: Control<'a>,
    ) -> Self {
        Self {
            shape,
            numerics,
            last_step: Cell::new(0.0),
            last_deviation: Cell::new(None),
            spans,
            max_blocks,
            limit_field,
            control,
            charge: None,
        }
    }

    /// Refuses at once a curve that certainly needs more than twice the block limit (else
    /// found out only after the whole limit's worth of chords otherwise). On a curve whose radius
    /// of curvature stays at most R_max no chord with a sagitta of at most `largest_chord_error`
    /// is longer than the circle's, 2·√(2·R_max·e), so length ÷ that chord is a lower bound of the
    /// block count. The factor 2 keeps estimates (window radii) from refusing a feasible curve.
    /// Polylines and NURBS, which may be straight, are not bounded.
    ///
    /// # Errors
    /// `E_TOO_MANY_BLOCKS` at the limit's field.
    pub(crate) fn refuse_certain_overflow(&self, largest_chord_error: f64) -> Result<(), SolverError> {
        let Some(least_blocks) = self.least_blocks(largest_chord_error) else {
            return Ok(());
        };
        if least_blocks > 2.0 * self.max_blocks as f64 {
            return Err(SolverError::new(
                ErrorCode::TooManyBlocks,
                format!(
                    "the segmentation needs at least {least_blocks:.3e} blocks (the limit is {}); raise the chord \
                     error (feed, margin, min_chord_error or tolerance) or shorten the curve",
                    self.max_blocks
                ),
            )
            .at(self.limit_field));
        }
        Ok(())
    }

    /// The lower bound of the block count of [`Cutter::refuse_certain_overflow`]; `None` for
    /// polylines and NURBS, and for a chord error of 0 (no chord fits at all: the search says so,
    /// E14, where it fails).
    fn least_blocks(&self, largest_chord_error: f64) -> Option<f64> {
        let (_, max_radius) = self.shape.radius_bounds()?;
        if largest_chord_error <= 0.0 {
            return None;
        }
        let longest_chord = 2.0 * (2.0 * max_radius * largest_chord_error).sqrt();
        Some(self.shape.length() / longest_chord)
    }

    /// The largest chord error the rule can give on this curve (at its smallest radius of
    /// curvature), within `tolerance`; `None` when unknown or infeasible there.
    pub(crate) fn largest_rule_chord_error(&self, rule: &BlockRule, tolerance: Option<f64>) -> Option<f64> {
        let (min_radius, _) = self.shape.radius_bounds()?;
        let (chord_error, _) = rule.chord_error(min_radius).ok()?;
        Some(tolerance.map_or(chord_error, |limit| chord_error.min(limit)))
    }

    /// dev of the chord between two parameters as the answer reports it: the reference's
    /// (exact for arcs, ellipse chords, polylines and chords inside a cubic B-spline span; 32
    /// samples refined for other NURBS).
    pub(crate) fn deviation(&self, ua: f64, ub: f64) -> f64 {
        match (self.numerics, self.shape) {
            (Numerics::Fast, Shape::Arc(_) | Shape::Ellipse(_) | Shape::Polyline(_)) => {
                self.shape.fast_deviation(ua, ub, f64::INFINITY).0
            }
            (Numerics::Fast, Shape::Spline(_)) => {
                self.shape.checked_deviation(ua, ub).unwrap_or_else(|| self.shape.deviation(ua, ub))
            }
            _ => self.shape.deviation(ua, ub),
        }
    }

    pub(crate) fn vertex(&self, u: f64) -> Vertex {
        Vertex { u, s: self.shape.s_at(u), point: self.shape.point(u) }
    }

    /// The end of the longest chord from `start` whose deviation stays within `chord_error`
    /// (docs/spec/segment.md §2.9 `greedy_end`), up to `limit`; `step_guess` is the circle chord of the
    /// window's radius (mm). By the fast search, or by the reference numerics for the oracle.
    pub(crate) fn greedy_end(
        &self,
        start: &Vertex,
        chord_error: f64,
        limit: &Vertex,
        step_guess: f64,
    ) -> Result<Vertex, SolverError> {
        let (end, deviation) = match self.numerics {
            Numerics::Fast => search::chord_end(self.shape, start, chord_error, limit, step_guess, &self.last_step)?,
            Numerics::Reference => (reference::greedy_end(self.shape, start, chord_error, limit, step_guess)?, None),
        };
        if end >= limit.u {
            self.last_deviation.set(deviation);
            return Ok(*limit);
        }
        let end = self.vertex(end);
        // A remainder below a nanometre is not a block: the chord takes it.
        let taken = limit.s - end.s < MIN_PROGRESS;
        self.last_deviation.set(if taken { None } else { deviation });
        Ok(if taken { *limit } else { end })
    }

    /// Whether the chord from `from` to the window's end `u1` fits, measured exactly (fast
    /// numerics only): then the greedy chord ends at or past the window's end, so the window
    /// carries over without searching it (a fifth of all searches on the chord bench were such
    /// chords, searched and dropped). Where the deviation grows with the chord, as it does on a
    /// piece that bends one way, this is the same test as searching and comparing the end.
    fn reaches(&self, from: &Vertex, u1: f64, chord_error: f64) -> bool {
        if self.numerics != Numerics::Fast || u1 <= from.u {
            return false;
        }
        let (deviation, exact) = self.shape.fast_deviation(from.u, u1, chord_error + EPS);
        exact && deviation <= chord_error + EPS
    }

    /// Appends a command point; `span_end` is the parameter where its span ends.
    pub(crate) fn push(&self, cut: &mut Cut, vertex: Vertex, span_end: f64) -> Result<(), SolverError> {
        self.control.check()?;
        if cut.vertices.len() > self.max_blocks {
            return Err(SolverError::new(
                ErrorCode::TooManyBlocks,
                format!(
                    "the segmentation needs more than {} blocks; raise the chord error (feed, margin, \
                     min_chord_error or tolerance) or shorten the curve",
                    self.max_blocks
                ),
            )
            .at(self.limit_field));
        }
        if let Some(last) = cut.vertices.last()
            && vertex.s - last.s < MIN_PROGRESS
            && vertex.u != span_end
        {
            return Err(SolverError::new(
                ErrorCode::NumericFailure,
                format!(
                    "no chord longer than {MIN_PROGRESS} mm fits at s = {:.6} mm: the chord error is too small for \
                     the curve here (E14)",
                    last.s
                ),
            )
            .at("curve"));
        }
        if cut.vertices.len().is_multiple_of(256) {
            self.control.report_fraction(vertex.s / self.shape.length());
        }
        if let Some(charge) = self.charge
            && cut.vertices.len().is_multiple_of(CHARGED_POINTS)
        {
            // Charged ahead for the block of points this one starts; the estimate scales what was
            // charged by the share of the curve's length cut so far.
            const PARTS: usize = 1_000_000;
            let done = ((vertex.s / self.shape.length()) * PARTS as f64).ceil();
            let done = if done.is_finite() { (done as usize).clamp(1, PARTS) } else { PARTS };
            charge.budget.charge(CHARGED_POINTS as u64 * charge.point_bytes, done, PARTS)?;
        }
        cut.vertices.push(vertex);
        cut.deviations.push(self.last_deviation.take());
        Ok(())
    }

    /// The cut's first command point, with room for the blocks expected when they are about
    /// `typical_chord` mm long (growing a vector of 100 000 command points by doubling cost 2 %
    /// of the chord bench's B-spline in copies).
    pub(crate) fn start(&self, typical_chord: f64) -> Option<Cut> {
        let &(first, _) = self.spans.first()?;
        let mut cut = Cut::default();
        let room = self.expected_blocks(typical_chord);
        cut.vertices.reserve(room + 1);
        cut.deviations.reserve(room);
        cut.vertices.push(self.vertex(first));
        Some(cut)
    }

    /// The block count of the whole curve cut into chords `typical_chord` mm long, within the
    /// block limit and [`MOST_RESERVED`] (a failing request must not claim memory up front); 0
    /// when unknown.
    pub(crate) fn expected_blocks(&self, typical_chord: f64) -> usize {
        let blocks = (self.shape.length() / typical_chord).ceil();
        if blocks.is_finite() && blocks > 0.0 { (blocks as usize).min(self.max_blocks).min(MOST_RESERVED) } else { 0 }
    }

    /// Embodiments 3–5 and fixed tolerances: one chord error for the whole curve. `radius` is
    /// the radius it came from (for the step guess; infinite when unknown or straight).
    pub(crate) fn constant(&self, chord_error: f64, radius: f64) -> Result<Cut, SolverError> {
        self.refuse_certain_overflow(chord_error)?;
        let Some(mut cut) = self.start(step_guess(radius, chord_error, f64::INFINITY)) else {
            return Ok(Cut::default());
        };
        for &(u_start, u_end) in self.spans {
            let mut from = self.vertex(u_start);
            let limit = self.vertex(u_end);
            let guess = step_guess(radius, chord_error, limit.s - from.s);
            while from.s < limit.s && from.u != limit.u {
                let next = self.greedy_end(&from, chord_error, &limit, guess)?;
                self.push(&mut cut, next, limit.u)?;
                from = next;
            }
            cut.span_ends.push(cut.vertices.len().saturating_sub(2));
        }
        Ok(cut)
    }

    /// Radius estimates of windows of length `window` laid end to end along every span
    /// (embodiment 3, Eq. 10: the chord error is the largest over these), with the arc length
    /// where each window starts.
    pub(crate) fn tiled_radii(
        &self,
        window: f64,
        estimate: Estimate,
        scale: f64,
    ) -> Result<Vec<(f64, f64)>, SolverError> {
        let mut out = Vec::new();
        for &(u_start, u_end) in self.spans {
            let (s_start, s_end) = (self.shape.s_at(u_start), self.shape.s_at(u_end));
            let count = ((s_end - s_start) / window).ceil().max(1.0);
            if out.len() as f64 + count > self.max_blocks as f64 {
                return Err(SolverError::new(
                    ErrorCode::TooManyBlocks,
                    format!(
                        "windows of {window} mm cut this curve into more than {} pieces; lengthen the window",
                        self.max_blocks
                    ),
                )
                .at("window"));
            }
            let count = count as usize;
            for k in 0..count {
                let s0 = s_start + window * k as f64;
                let s1 = (s0 + window).min(s_end);
                let (u0, u1) = (self.shape.u_at(s0), self.shape.u_at(s1));
                let three_point = circumradius(
                    &self.shape.point(u0),
                    &self.shape.point(self.shape.u_at(0.5 * (s0 + s1))),
                    &self.shape.point(u1),
                );
                let smallest = self.shape.min_radius(u0, u1, scale).0;
                let radius = match estimate {
                    Estimate::ThreePoint if three_point.is_finite() => three_point.min(SPREAD_CAP * smallest),
                    _ => smallest,
                };
                out.push((s0, radius));
            }
        }
        Ok(out)
    }

    /// Embodiments 1, 2 and 6: the per-window procedure (docs/spec/segment.md §2.9, normative version).
    /// `chord_error_of(radius)` is the rule (with the accuracy bound applied by the caller's
    /// `tolerance`); `window` is Δs.
    pub(crate) fn windows(
        &self,
        rule: &BlockRule,
        tolerance: Option<f64>,
        window: f64,
        estimate: Estimate,
    ) -> Result<Cut, CutError> {
        if let Some(largest) = self.largest_rule_chord_error(rule, tolerance) {
            self.refuse_certain_overflow(largest)?;
        }
        let scale = rule.target_chord();
        let Some(mut cut) = self.start(scale) else {
            return Ok(Cut::default());
        };
        cut.windows.reserve(self.expected_blocks(window));
        for &(u_start, u_end) in self.spans {
            let span_end = self.vertex(u_end);
            let (s_end, mut s0) = (span_end.s, self.shape.s_at(u_start));
            let mut from = self.vertex(u_start);
            let mut s1 = s0 + window;
            let mut last_window = false;
            if s1 >= s_end {
                (s1, last_window) = (s_end, true);
            }
            loop {
                let u0 = from.u;
                let u1 = if last_window { u_end } else { self.shape.u_at(s1) };
                let three_point = {
                    let middle = self.shape.point(self.shape.u_at(0.5 * (s0 + s1)));
                    circumradius(&from.point, &middle, &self.shape.point(u1))
                };
                let (smallest, _) = self.shape.min_radius(u0, u1, scale);
                let spread = if three_point.is_finite() {
                    three_point / smallest
                } else if smallest.is_finite() {
                    f64::INFINITY
                } else {
                    1.0
                };
                let radius = match estimate {
                    // The 3-point circle of a window whose curvature grows inside it (towards a
                    // flat point, an inflection, three collinear points on an S) can be orders of
                    // magnitude too large, so C_ep tiny and the chords far shorter than a block:
                    // the estimate is held within SPREAD_CAP of the smallest radius there (E10).
                    Estimate::ThreePoint if three_point.is_infinite() => smallest,
                    Estimate::ThreePoint => three_point.min(SPREAD_CAP * smallest),
                    Estimate::Minimum => self.reach_radius(rule, smallest, s0, s1, u0, s_end)?,
                };
                let (rule_chord_error, surface) = rule
                    .chord_error(radius)
                    .map_err(|infeasible| CutError::Infeasible(InfeasibleAt { s: s0, infeasible }))?;
                let (chord_error, status) = classify(rule_chord_error, surface, radius, tolerance);
                let guess = step_guess(radius, chord_error, window);
                let mut blocks = 0;
                let limit = span_end;
                while from.s < s_end && from.u != u_end {
                    if blocks > 0 && !last_window && from.s + guess > s1 && self.reaches(&from, u1, chord_error) {
                        break; // carry over, without searching the chord that would be dropped
                    }
                    let next = self.greedy_end(&from, chord_error, &limit, guess)?;
                    let beyond = next.s > s1 + WINDOW_SLACK && !last_window;
                    if beyond && blocks > 0 {
                        break; // carry over: the next window starts at the last command point
                    }
                    self.push(&mut cut, next, limit.u)?;
                    from = next;
                    blocks += 1;
                    if beyond {
                        break; // progress rule
                    }
                }
                cut.windows.push(WindowRecord {
                    s_start: s0,
                    s_end: s1,
                    radius,
                    rule_chord_error,
                    chord_error,
                    status,
                    spread,
                    blocks,
                });
                if last_window || from.s >= s_end || from.u == u_end {
                    break;
                }
                s0 = from.s;
                s1 = s0 + window;
                if s1 >= s_end {
                    (s1, last_window) = (s_end, true);
                }
            }
            cut.span_ends.push(cut.vertices.len().saturating_sub(2));
        }
        Ok(cut)
    }

    /// The smallest radius over the window and over the reach of a chord cut with it, so that
    /// the first chord (which may run past the window, progress rule) also sees every bend.
    fn reach_radius(
        &self,
        rule: &BlockRule,
        window_radius: f64,
        s0: f64,
        s1: f64,
        u0: f64,
        s_end: f64,
    ) -> Result<f64, CutError> {
        let mut radius = window_radius;
        for _ in 0..8 {
            let (chord_error, _) = rule
                .chord_error(radius)
                .map_err(|infeasible| CutError::Infeasible(InfeasibleAt { s: s0, infeasible }))?;
            let reach = (s0 + 1.05 * chord_length(radius, chord_error)).min(s_end);
            if reach <= s1 {
                break;
            }
            let (wider, _) = self.shape.min_radius(u0, self.shape.u_at(reach), rule.target_chord());
            if wider >= radius {
                break;
            }
            radius = wider;
        }
        Ok(radius)
    }
}

/// The chord error a window cuts with and why.
pub(crate) fn classify(
    rule_chord_error: f64,
    surface: ChordStatus,
    radius: f64,
    tolerance: Option<f64>,
) -> (f64, Status) {
    if let Some(limit) = tolerance
        && rule_chord_error > limit
    {
        return (limit, Status::LimitedByTolerance);
    }
    let status = match surface {
        ChordStatus::ClampedToMin => Status::ClampedToMin,
        ChordStatus::Surface if radius == f64::INFINITY => Status::Straight,
        ChordStatus::Surface => Status::Surface,
    };
    (rule_chord_error, status)
}

/// The step guess of docs/spec/segment.md §2.9: the circle chord `2√(2rC − C²)`, or `fallback` (Δs, or the
/// span) when the radius is infinite or the chord error zero.
fn step_guess(radius: f64, chord_error: f64, fallback: f64) -> f64 {
    if radius.is_finite() && chord_error > 0.0 { chord_length(radius, chord_error) } else { fallback }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::segment::shape::Arc;

    fn circle(radius: f64) -> Shape {
        Shape::Arc(Arc { centre: Vec3::zeros(), radius, start: 0.0, sense: 1.0, sweep: std::f64::consts::TAU })
    }

    #[test]
    fn the_block_limit_names_its_field() {
        let shape = circle(50.0);
        let spans = [shape.domain()];
        let cutter = Cutter::new(&shape, &spans, 10, "compare_tolerance", Numerics::Fast, Control::default());
        let error = cutter.constant(0.001, 50.0).unwrap_err();
        assert_eq!(error.code(), ErrorCode::TooManyBlocks);
        assert_eq!(error.field(), Some("compare_tolerance"));
    }

    #[test]
    fn the_least_block_count_never_exceeds_the_cut() {
        // Ellipses from round to 20:1, partial and full sweeps, chord errors over four decades.
        for (a, b) in [(10.0, 10.0), (50.0, 20.0), (100.0, 5.0), (3.0, 60.0)] {
            for end_deg in [37.0, 180.0, 360.0] {
                let request: crate::segment::SegmentRequest = serde_json::from_value(serde_json::json!({
                    "curve": {"kind": "ellipse", "centre": [0, 0], "semi_axes": [a, b], "start_deg": 0, "end_deg": end_deg},
                    "feed": 1000, "block_time_ms": 4
                }))
                .unwrap();
                let job = request.validate(None).unwrap();
                let cutter =
                    Cutter::new(&job.shape, &job.spans, 1_000_000, "tolerance", Numerics::Fast, Control::default());
                for chord_error in [1e-4, 1e-3, 1e-2, 1e-1] {
                    let blocks = cutter.constant(chord_error, f64::INFINITY).unwrap().vertices.len() - 1;
                    let least = cutter.least_blocks(chord_error).unwrap();
                    assert!(least <= blocks as f64, "{a}x{b} to {end_deg}°, e {chord_error}: {least} > {blocks}");
                }
            }
        }
    }

    #[test]
    fn a_search_without_progress_fails_instead_of_looping() {
        // Chord error 0 on a 0.1 µm circle: the longest fitting chord is below 1 nm (E14).
        let shape = circle(1e-7);
        let spans = [shape.domain()];
        let cutter = Cutter::new(&shape, &spans, 1000, "tolerance", Numerics::Fast, Control::default());
        let error = cutter.constant(0.0, f64::INFINITY).unwrap_err();
        assert_eq!(error.code(), ErrorCode::NumericFailure);
    }

    #[test]
    fn greedy_chords_on_a_circle_have_the_sagitta_length() {
        let shape = circle(50.0);
        let spans = [shape.domain()];
        let cutter = Cutter::new(&shape, &spans, 1000, "tolerance", Numerics::Fast, Control::default());
        let cut = cutter.constant(0.01, 50.0).unwrap();
        assert_eq!(cut.vertices.len(), 159);
        let chord = (cut.vertices[1].point - cut.vertices[0].point).norm();
        assert!((chord - chord_length(50.0, 0.01)).abs() < 1e-9);
        assert_eq!(cut.span_ends, vec![157]);
    }

    /// A deterministic stream of numbers in [0, 1) (the same curves every run).
    struct Stream(u64);

    impl Stream {
        fn next(&mut self) -> f64 {
            self.0 = self.0.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1_u64 << 53) as f64
        }

        fn between(&mut self, lo: f64, hi: f64) -> f64 {
            lo + (hi - lo) * self.next()
        }
    }

    /// Cuts `curve` at the fixed chord error `chord_error` by the fast search and checks every
    /// chord against the reference deviation of docs/spec/segment.md §2.9 (32 samples refined by
    /// Brent's method on the curve's own points, none of the fast search's closed forms): none
    /// above the chord error (+1e-12 mm and the rounding of the distances), none but a span's
    /// last more than 3e-8 below it (the chord is the greedy one, not a shorter one that also
    /// fits), each reported deviation within the chord error, and the reference greedy's block count.
    fn check_fixed_chord_error(curve: serde_json::Value, chord_error: f64) {
        let request: crate::segment::SegmentRequest = serde_json::from_value(serde_json::json!({
            "curve": curve, "feed": 1000, "block_time_ms": 1, "mode": "curve",
            "min_chord_error": chord_error, "tolerance": chord_error
        }))
        .unwrap();
        let job = request.validate(None).unwrap();
        let cut_by = |numerics| {
            Cutter::new(&job.shape, &job.spans, MAX_BLOCKS_CHECKED, "tolerance", numerics, Control::default())
                .constant(chord_error, f64::INFINITY)
                .unwrap()
        };
        let (fast, reference) = (cut_by(Numerics::Fast), cut_by(Numerics::Reference));
        let size = fast.vertices.iter().map(|v| v.point.amax()).fold(0.0, f64::max);
        let rounding = 16.0 * f64::EPSILON * size;
        for (block, pair) in fast.vertices.windows(2).enumerate() {
            let measured = job.shape.deviation(pair[0].u, pair[1].u);
            assert!(measured <= chord_error + EPS + rounding, "{curve}: block {block} deviates {measured}");
            if let Some(reported) = fast.deviations[block] {
                assert!(reported <= chord_error + EPS, "{curve}: block {block} reports {reported}");
            }
            if !fast.span_ends.contains(&block) {
                assert!(measured >= chord_error * (1.0 - 3e-8), "{curve}: block {block} is short: {measured}");
            }
        }
        // Both greedy to their brackets: the reference's is 1e-12 mm, its chords a hair longer
        // or shorter, so a count of hundreds may differ by one (as on the old search too).
        let (blocks, oracle) = (fast.vertices.len() - 1, reference.vertices.len() - 1);
        assert!(blocks.abs_diff(oracle) <= 1, "{curve}: {blocks} blocks, the reference greedy {oracle}");
    }

    const MAX_BLOCKS_CHECKED: usize = 100_000;

    #[test]
    fn random_ellipses_keep_every_chord_within_the_chord_error_and_greedy() {
        let mut stream = Stream(1);
        for _ in 0..24 {
            let a = stream.between(5.0, 300.0);
            let b = a * stream.between(0.1, 1.0);
            let start_deg = stream.between(-360.0, 360.0);
            let sweep_deg = stream.between(10.0, 360.0);
            let clockwise = stream.next() < 0.5;
            let curve = serde_json::json!({
                "kind": "ellipse", "centre": [stream.between(-100.0, 100.0), stream.between(-100.0, 100.0)],
                "semi_axes": [a, b], "start_deg": start_deg,
                "end_deg": if clockwise { start_deg - sweep_deg } else { start_deg + sweep_deg },
                "rotation_deg": stream.between(-180.0, 180.0), "direction": if clockwise { "cw" } else { "ccw" }
            });
            // Some 200 to 2 000 chords a turn.
            check_fixed_chord_error(curve, a * 10_f64.powf(stream.between(-6.0, -4.0)));
        }
    }

    #[test]
    fn random_cubic_bsplines_keep_every_chord_within_the_chord_error_and_greedy() {
        let mut stream = Stream(2);
        for case in 0..24 {
            let count = 6 + (stream.next() * 20.0) as usize;
            let flat = case % 2 == 0;
            // A wandering control polygon, steps of 5 to 20 mm turning by up to 80°.
            let (mut point, mut heading) = ([0.0_f64; 3], 0.0_f64);
            let control: Vec<[f64; 3]> = (0..count)
                .map(|_| {
                    heading += stream.between(-1.4, 1.4);
                    let step = stream.between(5.0, 20.0);
                    point = [
                        point[0] + step * heading.cos(),
                        point[1] + step * heading.sin(),
                        if flat { 0.0 } else { stream.between(-3.0, 3.0) },
                    ];
                    point
                })
                .collect();
            let curve = serde_json::json!({"kind": "bspline", "degree": 3, "control_points": control});
            check_fixed_chord_error(curve, 10_f64.powf(stream.between(-4.0, -2.0)));
        }
    }
}
