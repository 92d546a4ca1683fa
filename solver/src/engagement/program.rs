//! The G-code program of one evaluated path (docs/spec/engagement.md §3.2 adoption, §11 items 3 and 12):
//! the path at the cutting depth with the feed plan's F words (or the nominal feed), rapids
//! lifted to the clearance plane, arcs as chords (with a block time, by the block-time rule of
//! docs/spec/segment.md) or as G02/G03 (`arcs = g2g3`); and the block figures of the chord program
//! for the answer.

use super::answer::{EngagementSolution, PathEngagement};
use super::segments::{Route, Shape};
use crate::capability::Control;
use crate::error::ErrorCode;
use crate::error::{SolverError, Warning};
use crate::gcode::Arcs;
use crate::gcode::{self, Post, Program, Reference};
use crate::geometry::Vec3;
use crate::machine::{BlockRule, PathBlocks, path_blocks, short_block_warning};
use crate::path::Toolpath;

/// Largest distance of an arc from its chords in the program, mm.
pub const CHORD_TOLERANCE: f64 = 0.001;

/// A stretch of one piece at one feed (`None`: rapid).
struct Run {
    piece: usize,
    from_s: f64,
    to_s: f64,
    feed: Option<f64>,
}

fn piece_at(route: &Route, s: f64) -> usize {
    let index = route.pieces.partition_point(|p| p.end_s() < s);
    index.min(route.pieces.len().saturating_sub(1))
}

fn runs(result: &PathEngagement) -> Vec<Run> {
    let route = &result.post.route.0;
    match &result.feed_plan {
        Some(plan) => plan
            .blocks
            .iter()
            .map(|block| Run {
                piece: piece_at(route, 0.5 * (block.from_s + block.to_s)),
                from_s: block.from_s,
                to_s: block.to_s,
                feed: block.feed,
            })
            .collect(),
        None => route
            .pieces
            .iter()
            .enumerate()
            .map(|(index, piece)| Run {
                piece: index,
                from_s: piece.start_s,
                to_s: piece.end_s(),
                feed: (!piece.rapid).then_some(result.post.nominal_feed),
            })
            .collect(),
    }
}

/// The complete program for candidate `candidate` (0 for a single-path answer).
///
/// # Errors
/// `E_INPUT` at `candidate` for an index out of range, at `axial_depth` when the request
/// gave no axial depth (the cutting Z is `stock_top_z − axial_depth`), and at `spindle_rpm` or
/// the feed's field when the program cannot run as asked (above the machine's
/// `max_spindle_rpm`, or a value written as `S0` or `F0`).
pub fn program(answer: &EngagementSolution, candidate: usize, post: &Post) -> Result<String, SolverError> {
    let candidates = answer.candidates();
    let result = candidates.get(candidate).ok_or_else(|| {
        SolverError::input("candidate", format!("candidate {candidate} does not exist ({} path(s))", candidates.len()))
    })?;
    let data = &result.post;
    crate::machine::spindle_within(data.max_spindle_rpm, "spindle_rpm", data.spindle_rpm)?;
    let lift = match post.reference {
        Reference::Tip => 0.0,
        Reference::Centre => data.centre_height,
    };
    let Cut { path, cut_z, safe_z, .. } = cut(result, lift, post.arcs, Control::default())?;
    let mut comments = data.description.clone();
    comments.push(format!(
        "cut Z {:.4} mm, clearance Z {:.4} mm, control point {}",
        cut_z,
        safe_z,
        post.reference.as_str()
    ));
    if let Some(plan) = &result.feed_plan {
        comments.push(format!(
            "feeds hold {} mm chip thickness ({} basis) for {} flutes, max feed {} mm/min",
            plan.target_thickness,
            match plan.basis {
                super::request::FeedBasis::Tooth => "tooth",
                super::request::FeedBasis::Sum => "sum",
            },
            plan.flute_count,
            plan.max_feed
        ));
    }
    if let Some(rule) = &data.rule {
        comments.push(format!("arcs chorded for a {} ms block time", rule.block_time_ms));
    }
    let program = Program {
        dialect: post.dialect,
        number: 1000,
        title: "kerf engagement",
        comments,
        tool: post.tool.clone(),
        spindle_rpm: data.spindle_rpm,
        spindle_direction: data.spindle_direction,
        safe_z,
        blend_tolerance: CHORD_TOLERANCE * 5.0,
        plunges: Some(gcode::Plunges { feed: post.plunge_feed }),
        path: &path,
        units: post.units,
    };
    program.check_written(&[], "spindle_rpm", data.feed_field)?;
    Ok(gcode::write(&program))
}

/// The cycle time of candidate `candidate`'s chord program on a machine with `dynamics`
/// (docs/spec/engagement.md §11 item 7): one tool change, plunges in the air at the plunge feed,
/// the final retract, so the time is the program's as the control runs it. `None` when the
/// answer has no program (no `axial_depth`, no such candidate).
pub(crate) fn cycle_time(
    answer: &EngagementSolution,
    candidate: usize,
    dynamics: &crate::machine::cycle::Dynamics,
    plunge_feed: Option<f64>,
) -> Option<crate::machine::cycle::CycleTime> {
    let candidates = answer.candidates();
    let result = candidates.get(candidate)?;
    let Cut { mut path, safe_z, .. } = cut(result, 0.0, Arcs::Chords, Control::default()).ok()?;
    // The post's retract to the clearance plane after the spindle stops.
    let last = path.moves.last()?.to;
    path.rapid(Vec3::new(last.x, last.y, safe_z));
    crate::machine::cycle::path_cycle_time(&path, dynamics, plunge_feed, 1)
}

/// The moves of a program and what the block-time rule did to its arcs.
struct Cut {
    path: Toolpath,
    cut_z: f64,
    safe_z: f64,
    /// Finest chord tolerance of an arc, mm (None without arcs).
    finest_arc_tolerance: Option<f64>,
    /// Arcs too tight for one block at their feed: count, smallest radius, largest feasible feed.
    infeasible: (usize, f64, f64),
    /// Arcs whose [`CHORD_TOLERANCE`] needs chords shorter than a block (docs/spec/segment.md E4).
    overridden_arcs: usize,
}

/// The tool path of `result` with the control point `lift` above the tip: the cut at
/// `stock_top_z − axial_depth`, rapids at the clearance plane, arcs as chords within
/// [`CHORD_TOLERANCE`], or with a block time at the block-time rule's chord error for the arc's
/// radius and feed (chords of one block), never coarser than that; with [`Arcs::G2g3`] each arc
/// portion is one circular move to the chords' last point.
fn cut(result: &PathEngagement, lift: f64, arcs: Arcs, control: Control<'_>) -> Result<Cut, SolverError> {
    let data = &result.post;
    let depth = data.axial_depth.ok_or_else(|| {
        SolverError::input(
            "axial_depth",
            "the G-code program needs axial_depth (it cuts at Z = stock_top_z − axial_depth) or the path's Z (cut_z)",
        )
    })?;
    // At the path's own Z when a_p came from it (also above the top, where a_p is 0).
    let cut_z = data.cut_z.unwrap_or(data.stock_top_z - depth) + lift;
    let safe_z = data.stock_top_z + data.clearance + lift;
    let route = &data.route.0;
    let mut path = Toolpath::default();
    let Some(first) = route.pieces.first() else {
        return Err(SolverError::new(ErrorCode::Path, "the path is empty").at("path"));
    };
    let start = first.shape.start_point();
    path.rapid(Vec3::new(start.x, start.y, safe_z));
    let mut raised = true;
    let mut at = start;
    let mut finest_arc_tolerance: Option<f64> = None;
    let mut infeasible = (0, f64::INFINITY, f64::INFINITY);
    let mut overridden_arcs = 0;
    let mut chords = 0.0;
    for run in runs(result) {
        control.check()?;
        let Some(piece) = route.pieces.get(run.piece) else {
            continue;
        };
        let (from, to) = (run.from_s - piece.start_s, run.to_s - piece.start_s);
        match run.feed {
            None => {
                if !raised {
                    path.rapid(Vec3::new(at.x, at.y, safe_z));
                    raised = true;
                }
                at = piece.shape.point(to);
                path.rapid(Vec3::new(at.x, at.y, safe_z));
            }
            Some(feed) => {
                if raised {
                    // Down into the cut no faster than the nominal feed.
                    path.linear(Vec3::new(at.x, at.y, cut_z), feed.min(data.nominal_feed));
                    raised = false;
                }
                let portion = piece.shape.portion(from, to);
                if let (Arcs::G2g3, Shape::Arc { centre, sweep, .. }) = (arcs, portion) {
                    // The chords' last point, computed as they compute it.
                    if let Some(end) = portion.flatten_into(1).last().copied() {
                        let start = portion.point(0.0);
                        let (start, end3) = (Vec3::new(start.x, start.y, cut_z), Vec3::new(end.x, end.y, cut_z));
                        path.arc_sweep(start, end3, Vec3::new(centre.x, centre.y, cut_z), sweep, feed);
                        at = end;
                    }
                    continue;
                }
                let count = match (portion, &data.rule) {
                    (Shape::Arc { radius, .. }, Some(rule)) => {
                        let rule = BlockRule { feed, ..*rule };
                        match portion.rule_chords(&rule, CHORD_TOLERANCE) {
                            Ok((count, overridden)) => {
                                let tolerance =
                                    rule.tolerance_for(radius, Some(CHORD_TOLERANCE)).unwrap_or(CHORD_TOLERANCE);
                                finest_arc_tolerance =
                                    Some(finest_arc_tolerance.map_or(tolerance, |f: f64| f.min(tolerance)));
                                overridden_arcs += usize::from(overridden);
                                count
                            }
                            Err(error) => {
                                infeasible.0 += 1;
                                infeasible.1 = infeasible.1.min(radius);
                                infeasible.2 = infeasible.2.min(error.feed_limit);
                                finest_arc_tolerance =
                                    Some(finest_arc_tolerance.map_or(CHORD_TOLERANCE, |f: f64| f.min(CHORD_TOLERANCE)));
                                portion.chord_count(CHORD_TOLERANCE) as usize
                            }
                        }
                    }
                    _ => portion.chord_count(CHORD_TOLERANCE) as usize,
                };
                chords += count as f64;
                if chords > super::MAX_CHORDS {
                    return Err(SolverError::new(
                        ErrorCode::TooLarge,
                        format!(
                            "the program would need more than {:.0e} moves for its arcs; the limit is {:.0e}",
                            super::MAX_CHORDS,
                            super::MAX_CHORDS
                        ),
                    )
                    .at("path"));
                }
                for p in portion.flatten_into(count).into_iter().skip(1) {
                    path.linear(Vec3::new(p.x, p.y, cut_z), feed);
                    at = p;
                }
            }
        }
    }
    Ok(Cut { path, cut_z, safe_z, finest_arc_tolerance, infeasible, overridden_arcs })
}

/// With a block time and an axial depth: the block figures of the program's feed moves and the
/// warnings that explain short ones (arcs too tight for one block at their feed, docs/spec/segment.md E3;
/// short straight moves, E9).
///
/// # Errors
/// As the program: `E_TOO_LARGE` for a program over the move limit; `E_CANCELLED` once
/// `control`'s cancel flag is set.
pub(crate) fn blocks(
    result: &PathEngagement,
    control: Control<'_>,
) -> Result<Option<(PathBlocks, Vec<Warning>)>, SolverError> {
    let (Some(rule), Some(_)) = (&result.post.rule, result.post.axial_depth) else {
        return Ok(None);
    };
    let cut = cut(result, 0.0, Arcs::Chords, control)?;
    let moves = cut.path.moves.iter().map(|step| (step.to, step.motion.feed()));
    let figures = path_blocks(moves, rule.block_time_ms, rule.feed, cut.finest_arc_tolerance)?;
    let mut warnings = Vec::new();
    let (count, radius, feed_limit) = cut.infeasible;
    if count > 0 {
        warnings.push(Warning::new(
            "W_INFEASIBLE_FEED_FOR_RADIUS",
            format!(
                "{count} arcs (smallest radius {radius:.4} mm) cannot hold one block at their feed: they are chorded at \
                 {CHORD_TOLERANCE} mm and their blocks are short; {feed_limit:.0} mm/min is the largest feed for them"
            ),
        ));
    }
    if cut.overridden_arcs > 0 {
        warnings.push(Warning::new(
            "W_CHORD_ERROR_EXCEEDS_TOLERANCE",
            format!(
                "{} arcs need a chord error above {CHORD_TOLERANCE} mm for blocks of one block time: the tolerance \
                 wins and their blocks are short",
                cut.overridden_arcs
            ),
        ));
    }
    warnings.extend(short_block_warning(&figures, rule));
    Ok(Some((figures, warnings)))
}
