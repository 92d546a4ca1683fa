//! Mode `guarantee` (docs/spec/segment.md §2.9a, revision 2): no short blocks. Each chord's C_e comes from
//! the smallest radius of curvature along that chord, so every block but a span's final
//! remainder is at least k_f·F·T_b/60000 long; the remainder is merged into its neighbour, or
//! the last two chords are split evenly, when that keeps the chords within their errors and
//! both long enough.
//!
//! Why it holds: a curve whose curvature stays below 1/r between two points a chord L apart
//! lies within the lens of the two radius-r arcs through them, so its deviation is at most the
//! sagitta of L on radius r. The search ends the chord where the deviation reaches
//! C_e(r_min), the sagitta of the target chord on r_min; hence L is at least the target chord.
//! The smallest radius is taken over a stretch that contains the whole chord (widened and
//! searched again when the chord runs past it).

use super::cut::{Cut, CutError, Cutter, EPS, InfeasibleAt, Status, Vertex, WindowRecord, classify};
use crate::error::ErrorCode;
use crate::machine::rule::{BlockRule, chord_length};

/// First stretch checked for the smallest radius, in previous chords (or target chords).
const REACH: f64 = 1.25;
/// Most widenings of the stretch for one chord.
const WIDENINGS: usize = 16;
/// Slack on "long enough" when rebalancing the remainder (the rule's chords sit exactly on it).
const LENGTH_SLACK: f64 = 1e-9;

/// One chord of a guarantee cut before it is pushed.
struct Chord {
    end: Vertex,
    radius: f64,
    rule_chord_error: f64,
    chord_error: f64,
    status: Status,
}

impl Cutter<'_> {
    /// Mode `guarantee`: every chord's error from the smallest radius along it, with the
    /// accuracy bound `tolerance` (which may shorten chords: the user asked for it).
    pub(crate) fn guarantee(&self, rule: &BlockRule, tolerance: Option<f64>) -> Result<Cut, CutError> {
        if let Some(largest) = self.largest_rule_chord_error(rule, tolerance) {
            self.refuse_certain_overflow(largest)?;
        }
        let target = rule.target_chord();
        let Some(mut cut) = self.start(target) else {
            return Ok(Cut::default());
        };
        cut.windows.reserve(self.expected_blocks(target));
        for &(u_start, u_end) in self.spans {
            let limit = self.vertex(u_end);
            let mut from = self.vertex(u_start);
            let first_block = cut.vertices.len() - 1;
            let speed = self.shape.speed(from.u);
            let mut reach = if speed > 0.0 { REACH * target / speed } else { u_end - u_start };
            while from.s < limit.s && from.u != limit.u {
                let chord = self.guaranteed_chord(rule, tolerance, &from, &limit, reach)?;
                self.push(&mut cut, chord.end, limit.u)?;
                cut.windows.push(WindowRecord {
                    s_start: from.s,
                    s_end: chord.end.s,
                    radius: chord.radius,
                    rule_chord_error: chord.rule_chord_error,
                    chord_error: chord.chord_error,
                    status: chord.status,
                    spread: 1.0,
                    blocks: 1,
                });
                reach = REACH * (chord.end.u - from.u);
                from = chord.end;
            }
            self.rebalance_remainder(rule, tolerance, &mut cut, first_block)?;
            cut.span_ends.push(cut.vertices.len().saturating_sub(2));
        }
        Ok(cut)
    }

    /// The chord from `from` cut with C_e of the smallest radius on a stretch that holds it;
    /// `reach` is the first stretch's parameter length.
    fn guaranteed_chord(
        &self,
        rule: &BlockRule,
        tolerance: Option<f64>,
        from: &Vertex,
        limit: &Vertex,
        reach: f64,
    ) -> Result<Chord, CutError> {
        let scale = rule.target_chord();
        let mut stretch_end = (from.u + reach).min(limit.u);
        for _ in 0..WIDENINGS {
            let (radius, at) = self.shape.min_radius(from.u, stretch_end, scale);
            let (rule_chord_error, surface) = rule
                .chord_error(radius)
                .map_err(|infeasible| CutError::Infeasible(InfeasibleAt { s: self.shape.s_at(at), infeasible }))?;
            let (chord_error, status) = classify(rule_chord_error, surface, radius, tolerance);
            let guess = if radius.is_finite() { chord_length(radius, chord_error) } else { limit.s - from.s };
            let end = self.greedy_end(from, chord_error, limit, guess)?;
            if end.u <= stretch_end || stretch_end >= limit.u {
                return Ok(Chord { end, radius, rule_chord_error, chord_error, status });
            }
            // The chord ran past the stretch whose curvature it was cut for: widen and redo.
            stretch_end = (end.u + 0.25 * (end.u - from.u)).min(limit.u);
        }
        Err(CutError::Solver(
            crate::error::SolverError::new(
                ErrorCode::NumericFailure,
                format!("the guaranteed chord did not settle at s = {:.6} mm (E14)", from.s),
            )
            .at("curve"),
        ))
    }

    /// docs/spec/segment.md §2.9a: a span's final remainder shorter than the target chord is merged into
    /// the chord before it when the merged chord stays within the error of the smallest radius
    /// of both, or the two are split evenly (by arc length) when both halves stay within it and
    /// are at least the target chord long. `first_block` is the span's first block.
    fn rebalance_remainder(
        &self,
        rule: &BlockRule,
        tolerance: Option<f64>,
        cut: &mut Cut,
        first_block: usize,
    ) -> Result<(), CutError> {
        let target = rule.target_chord() * (1.0 - LENGTH_SLACK);
        let n = cut.vertices.len();
        if n < first_block + 3 {
            return Ok(());
        }
        let (before, middle, last) = (cut.vertices[n - 3], cut.vertices[n - 2], cut.vertices[n - 1]);
        if (last.point - middle.point).norm() >= target {
            return Ok(());
        }
        let windows = cut.windows.len();
        let (previous, remainder) = (cut.windows[windows - 2], cut.windows[windows - 1]);
        let radius = previous.radius.min(remainder.radius);
        let (rule_chord_error, surface) = rule
            .chord_error(radius)
            .map_err(|infeasible| CutError::Infeasible(InfeasibleAt { s: before.s, infeasible }))?;
        let (chord_error, status) = classify(rule_chord_error, surface, radius, tolerance);
        let merged = WindowRecord {
            s_start: before.s,
            s_end: last.s,
            radius,
            rule_chord_error,
            chord_error,
            status,
            spread: 1.0,
            blocks: 1,
        };
        let merged_deviation = self.deviation(before.u, last.u);
        if merged_deviation <= chord_error + EPS {
            cut.vertices.remove(n - 2);
            cut.deviations.truncate(n - 3);
            cut.deviations.push(Some(merged_deviation));
            cut.windows.truncate(windows - 2);
            cut.windows.push(merged);
            return Ok(());
        }
        let half = self.vertex(self.shape.u_at(0.5 * (before.s + last.s)));
        let fits = |a: &Vertex, b: &Vertex| {
            (b.point - a.point).norm() >= target && self.deviation(a.u, b.u) <= chord_error + EPS
        };
        if fits(&before, &half) && fits(&half, &last) {
            cut.vertices[n - 2] = half;
            cut.deviations.truncate(n - 3);
            cut.deviations.extend([None, None]);
            cut.windows.truncate(windows - 2);
            cut.windows.push(WindowRecord { s_end: half.s, ..merged });
            cut.windows.push(WindowRecord { s_start: half.s, ..merged });
        }
        Ok(())
    }
}
