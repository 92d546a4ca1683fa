//! Warnings and program header of a segment answer (docs/spec/segment.md §4: E1, E4, E5, E8–E10, E12, E13;
//! §6.1 comment block).

use super::cut::{self, Cut, Status};
use super::job::{Job, Plan};
use super::request::SegmentRequest;
use super::shape;
use crate::error::Warning;
use crate::machine::stats::BlockStats;
use crate::validate::Measure;

/// A polyline is its own true curve: where its points are not much closer than the chords, its
/// corners (not the curve they sample) decide the chord lengths.
pub(super) fn sparse_polyline(job: &Job) -> Option<Warning> {
    let shape::Shape::Polyline(line) = &job.shape else {
        return None;
    };
    // Edges next to a bend that is not a corner (corners split the path and are kept).
    let corner = |station: f64| {
        let index = job.spans.partition_point(|&(start, _)| start < station);
        job.spans.get(index).is_some_and(|&(start, _)| start == station)
    };
    // In squares, and only where an edge could be the longest yet (a dense polyline of 100 000
    // points spent a tenth of its solve here).
    let mut longest_squared = 0.0_f64;
    for (k, three) in line.vertices.windows(3).enumerate() {
        let (before, after) = (three[1] - three[0], three[2] - three[1]);
        let (before_squared, after_squared) = (before.norm_squared(), after.norm_squared());
        let longer = before_squared.max(after_squared);
        if longer <= longest_squared {
            continue;
        }
        let bends = before.cross(&after).norm_squared() > 1e-24 * before_squared * after_squared;
        if bends && !corner(line.stations[k + 1]) {
            longest_squared = longer;
        }
    }
    let longest = longest_squared.sqrt();
    let target = job.rule.target_chord();
    (longest > 0.25 * target).then(|| {
        Warning::new(
            "W_SPARSE_POLYLINE",
            format!(
                "the polyline's points are up to {longest:.4} mm apart, more than a quarter of the {target:.4} mm \
                 chord the rule aims at: its own corners limit the chords, so blocks may come out shorter; send \
                 denser points or the curve itself (arc, ellipse, bspline)"
            ),
        )
    })
}

/// Warnings about the windows: clamps, straights, the accuracy bound, unreliable radius
/// estimates, resolution (E1, E4, E5, E10, E13).
pub(super) fn window_warnings(job: &Job, cut: &Cut) -> Vec<Warning> {
    let rule = &job.rule;
    let mut warnings = Vec::new();
    let count = |status: Status| cut.windows.iter().filter(|w| w.status == status).count();
    let total = cut.windows.len();
    let clamped = count(Status::ClampedToMin);
    if clamped > 0 {
        warnings.push(Warning::new(
            "I_CLAMPED_TO_CEMIN",
            format!(
                "{clamped} of {total} windows use min_chord_error {} mm: the rule asked for less (E5)",
                rule.min_chord_error
            ),
        ));
    }
    let straight = count(Status::Straight);
    if straight > 0 {
        warnings.push(Warning::new(
            "I_STRAIGHT",
            format!("{straight} of {total} windows are straight: their chords run to the end of the straight (E1)"),
        ));
    }
    if let Some(tolerance) = job.tolerance {
        let limited: Vec<_> = cut.windows.iter().filter(|w| w.status == Status::LimitedByTolerance).collect();
        if !limited.is_empty() {
            let largest = limited.iter().map(|w| w.rule_chord_error).fold(0.0, f64::max);
            let feed =
                limited.iter().map(|w| rule.feed_for_tolerance(w.radius, tolerance)).fold(f64::INFINITY, f64::min);
            let advice = if rule.min_chord_error > tolerance {
                format!("min_chord_error {} mm is above the tolerance; lower it", rule.min_chord_error)
            } else {
                format!("at feed {:.0} mm/min the rule meets the tolerance with blocks of one block time", feed.floor())
            };
            warnings.push(Warning::new(
                "W_CHORD_ERROR_EXCEEDS_TOLERANCE",
                format!(
                    "in {} of {total} windows the rule's chord error (up to {largest:.6} mm) exceeds the tolerance \
                     {tolerance} mm: they are cut with the tolerance, so their blocks are shorter than feed × block \
                     time; {advice} (E4)",
                    limited.len()
                ),
            ));
        }
    }
    if let Plan::Window { estimate: cut::Estimate::ThreePoint, .. } = job.plan {
        let unreliable: Vec<_> = cut.windows.iter().filter(|w| w.spread > cut::SPREAD_CAP).collect();
        if let Some(worst) = unreliable.iter().max_by(|a, b| a.spread.total_cmp(&b.spread)) {
            warnings.push(Warning::new(
                "W_CURVATURE_ESTIMATE_UNRELIABLE",
                format!(
                    "in {} of {total} windows the curvature grows inside the window (worst at s = {:.3} mm: the \
                     3-point radius is {} the smallest radius there); their radius was held at most {} times \
                     the smallest. Use a shorter window or radius_estimate \"minimum\" (E10)",
                    unreliable.len(),
                    worst.s_start,
                    if worst.spread.is_finite() {
                        format!("{:.2} times", worst.spread)
                    } else {
                        "infinite, not".to_owned()
                    },
                    cut::SPREAD_CAP
                ),
            ));
        }
    }
    let finest = cut.windows.iter().map(|w| w.chord_error).filter(|&c| c > 0.0).fold(f64::INFINITY, f64::min);
    // A chord error below 5 of the program's least increments is resolution-limited (E13).
    if finest < 5.0 * job.least_increment {
        warnings.push(Warning::new(
            "W_RESOLUTION_LIMITED",
            format!(
                "chord error {} is below 5 increments of the G-code's {}: rounding the points adds up to \
                 about half an increment of error (E13)",
                Measure::Length.quote(finest),
                Measure::Length.quote(job.least_increment)
            ),
        ));
    }
    warnings
}

/// Warnings about the blocks: short remainders and block-time violations (E8, E9, E12).
pub(super) fn block_warnings(job: &Job, cut: &Cut, stats: &BlockStats) -> Vec<Warning> {
    let mut warnings = Vec::new();
    if stats.blocks == 1 && stats.short_end_blocks == 1 {
        warnings.push(Warning::new(
            "W_BLOCK_TIME_VIOLATION",
            format!(
                "the whole curve ({:.4} mm) is shorter than one block time at the feed ({:.4} mm): one block (E12)",
                stats.path_length, stats.block_length
            ),
        ));
        return warnings;
    }
    if stats.last_block_length < stats.block_length * (1.0 - 1e-9) {
        let closed = match (cut.vertices.first(), cut.vertices.last()) {
            (Some(first), Some(last)) => (first.point - last.point).norm() <= 1e-9,
            _ => false,
        };
        let corners = stats.short_end_blocks.saturating_sub(1);
        warnings.push(Warning::new(
            "W_SHORT_LAST_BLOCK",
            format!(
                "the last block is {:.4} mm, shorter than one block time at the feed ({:.4} mm){}{} (E8)",
                stats.last_block_length,
                stats.block_length,
                if closed {
                    ": the curve is closed, so on a loop that continues the control starves here"
                } else {
                    ": harmless where the control stops at the path end"
                },
                if corners > 0 { format!("; {corners} more short remainders end at corners") } else { String::new() }
            ),
        ));
    }
    if stats.short_blocks > 0 {
        warnings.push(Warning::new(
            "W_BLOCK_TIME_VIOLATION",
            format!(
                "{} blocks are shorter than one block time at the feed ({:.4} mm), the shortest {:.6} mm ({:.3} % of \
                 it): the control will slow down there{} (E9)",
                stats.short_blocks,
                stats.block_length,
                stats.min_block_length,
                100.0 * stats.min_block_ratio,
                if job.tolerance.is_some() {
                    "; the tolerance or a curvature change inside windows may cause it"
                } else if matches!(job.shape, shape::Shape::Polyline(_)) {
                    "; a polyline's own edges shorten the chords a little: raise margin (1.02 is plenty for dense \
                     points), use radius_estimate \"minimum\" or mode \"guarantee\""
                } else {
                    "; raise margin, use radius_estimate \"minimum\" or mode \"guarantee\""
                }
            ),
        ));
    }
    warnings
}

/// Header comments for the program (docs/spec/segment.md §6.1).
pub(super) fn describe(
    job: &Job,
    request: &SegmentRequest,
    chord_error: f64,
    min_chord_error: f64,
    stats: &BlockStats,
) -> Vec<String> {
    let rule = &job.rule;
    let mode = match job.plan {
        Plan::Window { length, estimate } => format!(
            "mode window {length:.3} mm {}",
            match estimate {
                cut::Estimate::ThreePoint => "three point",
                cut::Estimate::Minimum => "minimum radius",
            }
        ),
        Plan::Max { length, .. } => format!("mode curve max over {length:.3} mm windows"),
        Plan::Extremes { .. } => "mode curve extremes".to_owned(),
        Plan::NormalAccel { .. } => "mode curve normal accel".to_owned(),
        Plan::Guarantee => "mode guarantee (each chord from its smallest radius)".to_owned(),
    };
    let mut lines = vec![
        format!(
            "block time {} ms feed {} margin {} min chord error {}",
            rule.block_time_ms,
            Measure::Feed.quote(rule.feed),
            rule.margin,
            Measure::Length.quote(rule.min_chord_error)
        ),
        mode,
        format!("chord error {min_chord_error:.6} mm to {chord_error:.6} mm"),
        format!(
            "blocks {} shortest {:.4} mm short {} est time {:.3} s",
            stats.blocks, stats.min_block_length, stats.short_blocks, stats.estimated_time_s
        ),
    ];
    if let Some(name) = &request.machine {
        lines.insert(0, format!("machine {name}"));
    }
    lines
}
