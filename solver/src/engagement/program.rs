//! The G-code program of one evaluated path (engagement.md §3.2 adoption, §11 items 3 and 12):
//! the path at the cutting depth with the feed plan's F words (or the nominal feed), rapids
//! lifted to the clearance plane, arcs as chords.

use super::answer::{EngagementAnswer, PathEngagement};
use super::segments::Route;
use crate::error::SolverError;
use crate::gcode::{self, Post, Program, Reference};
use crate::geometry::Vec3;
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
/// `E_INPUT` at `candidate` for an index out of range, and at `axial_depth` when the request
/// gave no axial depth (the cutting Z is `stock_top_z − axial_depth`).
pub fn program(answer: &EngagementAnswer, candidate: usize, post: &Post) -> Result<String, SolverError> {
    let candidates = answer.candidates();
    let result = candidates.get(candidate).ok_or_else(|| {
        SolverError::input("candidate", format!("candidate {candidate} does not exist ({} path(s))", candidates.len()))
    })?;
    let data = &result.post;
    let depth = data.axial_depth.ok_or_else(|| {
        SolverError::input(
            "axial_depth",
            "the G-code program needs axial_depth: it cuts at Z = stock_top_z − axial_depth",
        )
    })?;
    let lift = match post.reference {
        Reference::Tip => 0.0,
        Reference::Centre => data.centre_height,
    };
    let cut_z = data.stock_top_z - depth + lift;
    let safe_z = data.stock_top_z + data.clearance + lift;
    let route = &data.route.0;
    let chords: f64 = route.pieces.iter().map(|p| p.shape.chord_count(CHORD_TOLERANCE)).sum();
    if chords > super::MAX_CHORDS {
        return Err(SolverError::new(
            "E_TOO_LARGE",
            format!(
                "the program would need {chords:.2e} moves for the arcs at {CHORD_TOLERANCE} mm; the limit is {:.0e}",
                super::MAX_CHORDS
            ),
        )
        .at("path"));
    }
    let mut path = Toolpath::default();
    let Some(first) = route.pieces.first() else {
        return Err(SolverError::new("E_PATH", "the path is empty").at("path"));
    };
    let start = first.shape.start_point();
    path.rapid(Vec3::new(start.x, start.y, safe_z));
    let mut raised = true;
    let mut at = start;
    for run in runs(result) {
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
                let points = piece.shape.portion(from, to).flatten(CHORD_TOLERANCE);
                for p in points.into_iter().skip(1) {
                    path.linear(Vec3::new(p.x, p.y, cut_z), feed);
                    at = p;
                }
            }
        }
    }
    let mut comments = data.description.clone();
    comments.push(format!("cut Z {:.4}, clearance Z {:.4}, control point {}", cut_z, safe_z, post.reference.as_str()));
    if let Some(plan) = &result.feed_plan {
        comments.push(format!(
            "feeds hold {} mm chip thickness ({} basis) for {} flutes, max feed {}",
            plan.target_thickness,
            match plan.basis {
                super::request::FeedBasis::Tooth => "tooth",
                super::request::FeedBasis::Sum => "sum",
            },
            plan.flute_count,
            plan.max_feed
        ));
    }
    Ok(gcode::write(&Program {
        dialect: post.dialect,
        number: 1000,
        title: "kerf engagement",
        comments,
        tool: post.tool.clone(),
        spindle_rpm: data.spindle_rpm,
        spindle_direction: data.spindle_direction,
        safe_z,
        blend_tolerance: CHORD_TOLERANCE * 5.0,
        path: &path,
    }))
}
