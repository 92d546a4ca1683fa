//! Block statistics of any polyline at a feed and block time (docs/spec/segment.md §6.2–§6.3, E8, E9): the
//! figures a CAM engineer checks before sending a program to a control with a block processing
//! time: how many blocks, the shortest, how many starve the control, and a cycle time that
//! accounts for the block limit; and the same over a whole path of feed moves and rapids.

use serde::{Deserialize, Serialize};

use super::rule::{BlockRule, MS_PER_MIN};
use crate::error::{SolverError, Warning};
use crate::geometry::Vec3;
use crate::validate::{Measure, positive};

/// A block counts as short when it is below `F·T_b/60000` by more than this fraction (rounding
/// of a chord that sits exactly on the surface must not count).
const SHORT_SLACK: f64 = 1e-9;

/// Block figures of a polyline run at one feed on a control with a block processing time.
///
/// A *span end* is a block that ends where the control stops or nearly stops anyway: the end of
/// the path, or a corner the path was split at (docs/spec/segment.md E8, E11). Greedy chords leave a shorter
/// remainder there; it is counted apart from the other blocks.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct BlockStats {
    /// Number of blocks (linear moves).
    pub blocks: usize,
    /// F·T_b/60000: the distance covered in one block time at the feed, mm. A shorter block
    /// starves the control.
    pub block_length: f64,
    /// Shortest block that does not end a span (the one that must be at least `block_length`),
    /// mm; the shortest of all blocks when every block ends a span.
    pub min_block_length: f64,
    /// Longest block, mm.
    pub max_block_length: f64,
    /// Length of the final block (the remainder at the path end), mm.
    pub last_block_length: f64,
    /// Blocks shorter than `block_length` that do not end a span: must be 0 (E9).
    pub short_blocks: usize,
    /// Blocks shorter than `block_length` that end a span: the final remainder and remainders at
    /// corners, harmless where the control stops (E8), not on a loop that continues.
    pub short_end_blocks: usize,
    /// Shortest non-end block over `block_length` (below 1 when blocks starve the control).
    pub min_block_ratio: f64,
    /// Length of the polyline, mm.
    pub path_length: f64,
    /// Block-limited time Σ max(Lᵢ/F, T_b), s (docs/spec/segment.md §6.3). Does not model acceleration or
    /// deceleration at vertices, so it flatters coarse polygons.
    pub estimated_time_s: f64,
    /// Path length over feed, s: the time if blocks were free.
    pub path_time_s: f64,
    /// Largest direction change between consecutive blocks, degrees.
    pub max_vertex_angle_deg: f64,
    /// Mean direction change between consecutive blocks, degrees.
    pub mean_vertex_angle_deg: f64,
}

/// The block figures of `points` (in order, mm) run at `feed` (mm/min) on a control with
/// `block_time_ms`; the last block is the only span end. Zero-length moves count as blocks.
///
/// ```
/// use kerf_solver::machine::block_stats;
/// use kerf_solver::geometry::Vec3;
/// let points = [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.5, 0.0, 0.0)];
/// let stats = block_stats(&points, 10_000.0, 4.0).unwrap();
/// assert_eq!((stats.blocks, stats.short_blocks, stats.short_end_blocks), (2, 0, 1));
/// assert!((stats.estimated_time_s - (0.006 + 0.004)).abs() < 1e-12);
/// ```
///
/// # Errors
/// `E_INPUT` when `feed` or `block_time_ms` is not a positive finite number.
pub fn block_stats(points: &[Vec3], feed: f64, block_time_ms: f64) -> Result<BlockStats, SolverError> {
    let feed = positive("feed", feed, Measure::Feed)?;
    let block_time_ms = positive("block_time_ms", block_time_ms, Measure::Number)?;
    let last = points.len().saturating_sub(2);
    Ok(stats_with_ends(points, feed, block_time_ms, &[last]))
}

/// [`block_stats`] with the span ends given as block indices (block i joins points i and i + 1).
///
/// One pass over the blocks, without a list of their lengths or of the angles between them (a
/// segment answer of a long curve has about 100 000 blocks).
pub(crate) fn stats_with_ends(points: &[Vec3], feed: f64, block_time_ms: f64, span_ends: &[usize]) -> BlockStats {
    stats_along(points, |point| point, feed, block_time_ms, span_ends)
}

/// [`stats_with_ends`] of the positions `position` reads from `points` (a segmentation's command
/// points, without copying their positions out first).
pub(crate) fn stats_along<P>(
    points: &[P],
    position: impl Fn(&P) -> &Vec3,
    feed: f64,
    block_time_ms: f64,
    span_ends: &[usize],
) -> BlockStats {
    let block_length = feed * block_time_ms / MS_PER_MIN;
    let short_below = block_length * (1.0 - SHORT_SLACK);
    let (mut inner_min, mut all_min, mut max) = (f64::INFINITY, f64::INFINITY, 0.0_f64);
    let (mut short_blocks, mut short_end_blocks) = (0, 0);
    let mut estimated_time_s = 0.0;
    // The sums start at -0.0 as `Iterator::sum` of f64 does (they were such sums): the same bits
    // even with no blocks, whose path length is -0.0.
    let mut path_length = -0.0;
    let (mut max_angle, mut angle_sum, mut angles) = (0.0_f64, -0.0, 0_usize);
    let mut last_length = 0.0;
    // The previous block's vector and length: the direction change is taken where it ends.
    let mut previous: Option<(Vec3, f64)> = None;
    for (index, pair) in points.windows(2).enumerate() {
        let step = position(&pair[1]) - position(&pair[0]);
        let length = step.norm();
        let span_end = span_ends.binary_search(&index).is_ok();
        all_min = all_min.min(length);
        max = max.max(length);
        if span_end {
            short_end_blocks += usize::from(length < short_below);
        } else {
            inner_min = inner_min.min(length);
            short_blocks += usize::from(length < short_below);
        }
        estimated_time_s += (length / feed * 60.0).max(block_time_ms / 1000.0);
        path_length += length;
        if let Some((before, before_length)) = previous {
            let norms = before_length * length;
            if norms > 0.0 {
                let angle = (before.dot(&step) / norms).clamp(-1.0, 1.0).acos().to_degrees();
                max_angle = max_angle.max(angle);
                angle_sum += angle;
                angles += 1;
            }
        }
        previous = Some((step, length));
        last_length = length;
    }
    let min_block_length = if inner_min.is_finite() {
        inner_min
    } else if all_min.is_finite() {
        all_min
    } else {
        0.0
    };
    BlockStats {
        blocks: points.len().saturating_sub(1),
        block_length,
        min_block_length,
        max_block_length: max,
        last_block_length: last_length,
        short_blocks,
        short_end_blocks,
        min_block_ratio: min_block_length / block_length,
        path_length,
        estimated_time_s,
        path_time_s: path_length / feed * 60.0,
        max_vertex_angle_deg: max_angle,
        mean_vertex_angle_deg: if angles == 0 { 0.0 } else { angle_sum / angles as f64 },
    }
}

/// The blocks of a path's feed moves (a contour's layers, an engagement program) on a control
/// with a block processing time.
///
/// A *span* is a run of feed moves between two rapids; its last block ends where the control
/// stops anyway (a retract follows), so a short one there is counted apart.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PathBlocks {
    /// Block processing time T_b of the control, ms.
    pub block_time_ms: f64,
    /// feed × T_b / 60000 at the cutting feed: the shortest block the control digests at full
    /// feed, mm.
    pub block_length: f64,
    /// Feed blocks (G01).
    pub blocks: usize,
    /// Shortest feed block that does not end a span, mm (the shortest of all when every block
    /// ends one).
    pub min_block_length: f64,
    /// Feed blocks shorter than their feed × T_b that do not end a span: the control slows down
    /// there. Arcs never add any unless reported in the warnings; short straight moves can.
    pub short_blocks: usize,
    /// Short blocks at the end of a span (before a retract): harmless.
    pub short_end_blocks: usize,
    /// Σ max(L / F, T_b) over the feed blocks at their feeds, s: the feed time with the block
    /// limit (no acceleration modelled). Compare `estimated_time_s` of the summary.
    pub estimated_time_s: f64,
    /// Finest chord tolerance the rule gave an arc, mm (absent without arcs; a contour's: of its
    /// first layer).
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

/// The block figures of `moves` (end point and feed, `None` for a rapid, in machining order)
/// for `block_time_ms`; `feed` is the cutting feed `block_length` is given for.
///
/// # Errors
/// `E_INPUT` when a feed or the block time is not positive (validated before).
pub fn path_blocks(
    moves: impl IntoIterator<Item = (Vec3, Option<f64>)>,
    block_time_ms: f64,
    feed: f64,
    finest_arc_tolerance: Option<f64>,
) -> Result<PathBlocks, SolverError> {
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
    for (to, step_feed) in moves {
        match step_feed {
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
    Ok(PathBlocks {
        block_time_ms,
        block_length: feed * block_time_ms / MS_PER_MIN,
        blocks: tally.blocks,
        min_block_length,
        short_blocks: tally.short,
        short_end_blocks: tally.short_end,
        estimated_time_s: tally.time_s,
        finest_arc_tolerance,
    })
}

/// `W_BLOCK_TIME_VIOLATION` (docs/spec/segment.md E9) when inner blocks of `blocks` are short.
pub fn short_block_warning(blocks: &PathBlocks, rule: &BlockRule) -> Option<Warning> {
    (blocks.short_blocks > 0).then(|| {
        Warning::new(
            "W_BLOCK_TIME_VIOLATION",
            format!(
                "{} feed blocks are shorter than feed × block time (the shortest {:.4} mm, {:.4} mm needed at {} mm/min): \
                 short straight moves (edges, leads, loop legs) the rule cannot lengthen; the control slows down there",
                blocks.short_blocks,
                blocks.min_block_length,
                rule.block_length(),
                rule.feed
            ),
        )
    })
}
