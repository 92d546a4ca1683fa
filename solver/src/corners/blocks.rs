//! Block figures of a contour with the block-time rule (issue 3, chord.md §4 and §6): how many
//! feed blocks, the shortest, how many are shorter than feed × block time, and a cycle time that
//! accounts for the block limit; and the warnings that explain the short blocks.

use serde::Serialize;

use super::answer::ContourLayer;
use super::element::{Chording, Element, rule_steps_bound};
use super::pass::PassPlan;
use crate::chord::{BlockRule, BlockStats, block_stats};
use crate::error::{SolverError, Warning};
use crate::geometry::Vec3;

/// The blocks of a contour's feed moves on a control with a block processing time.
///
/// A *span* is a run of feed moves between two rapids; its last block ends where the control
/// stops anyway (a retract follows), so a short one there is counted apart.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ContourBlocks {
    /// Block processing time T_b of the control, ms.
    pub block_time_ms: f64,
    /// feed × T_b / 60000 at the cutting feed: the shortest block the control digests at full
    /// feed, mm.
    pub block_length: f64,
    /// Feed blocks (G01) in all layers.
    pub blocks: usize,
    /// Shortest feed block that does not end a span, mm (the shortest of all when every block
    /// ends one).
    pub min_block_length: f64,
    /// Feed blocks shorter than their feed × T_b that do not end a span: the control slows down
    /// there. Arcs never add any unless reported in the warnings; short contour edges, leads and
    /// loop legs can.
    pub short_blocks: usize,
    /// Short blocks at the end of a span (before a retract): harmless.
    pub short_end_blocks: usize,
    /// Σ max(L / F, T_b) over the feed blocks at their feeds, s: the feed time with the block
    /// limit (no acceleration modelled). Compare `estimated_time_s` of the summary.
    pub estimated_time_s: f64,
    /// Finest chord tolerance the rule gave an arc of the first layer, mm (absent without arcs).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub finest_arc_tolerance: Option<f64>,
}

/// Adds the figures of one run of blocks at one feed.
#[derive(Default)]
struct Tally {
    blocks: usize,
    inner_min: f64,
    end_min: f64,
    short: usize,
    short_end: usize,
    time_s: f64,
}

impl Tally {
    fn add(&mut self, stats: &BlockStats, ends_span: bool) {
        self.blocks += stats.blocks;
        if stats.blocks > 1 {
            self.inner_min = self.inner_min.min(stats.min_block_length);
        }
        // `block_stats` counts the run's last block as an end; a run that ends at a feed change
        // goes on, so its last block is an inner one.
        if ends_span {
            self.end_min = self.end_min.min(stats.last_block_length);
            self.short_end += stats.short_end_blocks;
        } else {
            self.inner_min = self.inner_min.min(stats.last_block_length);
            self.short += stats.short_end_blocks;
        }
        self.short += stats.short_blocks;
        self.time_s += stats.estimated_time_s;
    }
}

/// The block figures of `layers` (moves in machining order) for `block_time_ms`.
///
/// # Errors
/// `E_INPUT` when a feed or the block time is not positive (validated before).
pub(crate) fn figures(
    layers: &[ContourLayer],
    block_time_ms: f64,
    feed: f64,
    finest_arc_tolerance: Option<f64>,
) -> Result<ContourBlocks, SolverError> {
    let mut tally = Tally { inner_min: f64::INFINITY, end_min: f64::INFINITY, ..Tally::default() };
    let mut from: Option<Vec3> = None;
    let mut run: Vec<Vec3> = Vec::new();
    let mut run_feed: Option<f64> = None;
    let mut flush = |run: &mut Vec<Vec3>, feed: Option<f64>, ends_span: bool| -> Result<(), SolverError> {
        if let (Some(feed), true) = (feed, run.len() > 1) {
            tally.add(&block_stats(run, feed, block_time_ms)?, ends_span);
        }
        let last = run.last().copied();
        run.clear();
        if !ends_span && let Some(last) = last {
            run.push(last);
        }
        Ok(())
    };
    for step in layers.iter().flat_map(|layer| &layer.moves) {
        let to = Vec3::from(step.to);
        match step.feed {
            None => flush(&mut run, run_feed, true)?,
            Some(step_feed) => {
                if run_feed != Some(step_feed) && run.len() > 1 {
                    flush(&mut run, run_feed, false)?;
                }
                if run.is_empty() {
                    run.push(from.unwrap_or(to));
                }
                run.push(to);
                run_feed = Some(step_feed);
            }
        }
        from = Some(to);
    }
    flush(&mut run, run_feed, true)?;
    let min_block_length = if tally.inner_min.is_finite() {
        tally.inner_min
    } else if tally.end_min.is_finite() {
        tally.end_min
    } else {
        0.0
    };
    Ok(ContourBlocks {
        block_time_ms,
        block_length: feed * block_time_ms / crate::chord::rule::MS_PER_MIN,
        blocks: tally.blocks,
        min_block_length,
        short_blocks: tally.short,
        short_end_blocks: tally.short_end,
        estimated_time_s: tally.time_s,
        finest_arc_tolerance,
    })
}

/// What the rule did to the arcs of the first layer's passes: the finest chord tolerance, and
/// the warnings for arcs too tight for one block at their feed (chord.md E3) and for arcs whose
/// block-length chord error the `tolerance` overrides (E4).
pub(crate) fn arc_report(passes: &[PassPlan], chording: &Chording) -> (Option<f64>, Vec<Warning>) {
    let mut finest: Option<f64> = None;
    // (count, smallest radius, largest feasible feed) for E3; (count, largest feed) for E4.
    let mut infeasible = (0usize, f64::INFINITY, f64::INFINITY);
    let mut overridden = (0usize, f64::INFINITY);
    for element in passes.iter().flat_map(|p| &p.elements) {
        let Element::Arc { radius, sweep, kind, .. } = element else { continue };
        let Some(rule) = chording.rule(*kind) else { continue };
        let tolerance = chording.arc_tolerance(*radius, *kind);
        finest = Some(finest.map_or(tolerance, |f: f64| f.min(tolerance)));
        if let Err(error) = rule.chord_error(*radius) {
            infeasible.0 += 1;
            infeasible.1 = infeasible.1.min(*radius);
            infeasible.2 = infeasible.2.min(error.feed_limit);
        } else if rule_steps_bound(*radius, *sweep, tolerance, chording.tolerance).1 {
            // The tolerance needs more (so shorter) chords than a block allows: at or above the
            // rule's chord error, or just below it where whole chords do not fit the sweep.
            overridden.0 += 1;
            overridden.1 = overridden.1.min(rule.feed_for_tolerance(*radius, chording.tolerance));
        }
    }
    let mut warnings = Vec::new();
    if infeasible.0 > 0 {
        warnings.push(Warning::new(
            "W_INFEASIBLE_FEED_FOR_RADIUS",
            format!(
                "{} arcs per layer (smallest radius {:.4} mm) cannot hold one block at their feed: they are chorded at \
                 the tolerance and their blocks are short; {:.0} mm/min is the largest feed for them",
                infeasible.0, infeasible.1, infeasible.2
            ),
        ));
    }
    if overridden.0 > 0 {
        warnings.push(Warning::new(
            "W_CHORD_ERROR_EXCEEDS_TOLERANCE",
            format!(
                "{} arcs per layer need a chord error above the tolerance {} mm for blocks of one block time: the \
                 tolerance wins and their blocks are short; below about {:.0} mm/min they fit within it",
                overridden.0, chording.tolerance, overridden.1
            ),
        ));
    }
    (finest, warnings)
}

/// `W_BLOCK_TIME_VIOLATION` (chord.md E9) when inner blocks are short.
pub(crate) fn short_block_warning(blocks: &ContourBlocks, rule: &BlockRule) -> Option<Warning> {
    (blocks.short_blocks > 0).then(|| {
        Warning::new(
            "W_BLOCK_TIME_VIOLATION",
            format!(
                "{} feed blocks are shorter than feed × block time (the shortest {:.4} mm, {:.4} mm needed at {} mm/min): \
                 short contour edges, leads and loop legs the rule cannot lengthen; the control slows down there",
                blocks.short_blocks,
                blocks.min_block_length,
                rule.block_length(),
                rule.feed
            ),
        )
    })
}
