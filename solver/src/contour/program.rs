//! The G-code program of a solved contour (docs/spec/api.md G-code conventions): every layer's moves in
//! order, rapids as G00, cuts, loops and links as G01 at their feeds (loops at `loop_feed` where
//! they clear the stock). With `arcs = g2g3` the chords of each arc (loops, round joins) become
//! G02/G03 blocks from the arc's exact start to its exact end.

use super::answer::{ContourSolution, MoveKind};
use crate::capability::Control;
use crate::error::ErrorCode;
use crate::error::SolverError;

use crate::gcode::{self, Arcs, Post, Program, Reference, SpindleDirection};
use crate::geometry::Vec3;
use crate::path::Toolpath;

/// The complete program for a solved contour job.
///
/// # Errors
/// `E_TILT_NEEDS_5_AXIS` (at `tilt_deg`) when the walls are tilted: the moves then carry a tool
/// axis that a 3-axis program cannot express.
pub fn program(answer: &ContourSolution, post: &Post) -> Result<String, SolverError> {
    program_controlled(answer, post, Control::default())
}

/// [`program`] that stops with `E_CANCELLED` once `control`'s cancel flag is set (checked per
/// layer and every [`gcode::MOVES_PER_CHECK`] moves written).
///
/// # Errors
/// As [`program`]; `E_CANCELLED` when cancelled.
pub fn program_controlled(answer: &ContourSolution, post: &Post, control: Control<'_>) -> Result<String, SolverError> {
    if answer.tilted {
        return Err(SolverError::new(
            ErrorCode::TiltNeeds5Axis,
            "tilted walls need a 5-axis program with tool orientation; only the JSON answer carries the axes",
        )
        .at("tilt_deg"));
    }
    let lift = match post.reference {
        Reference::Tip => 0.0,
        Reference::Centre => answer.centre_height,
    };
    let offset = Vec3::new(0.0, 0.0, lift);
    // Sized once: a large contour's path would otherwise be copied as it doubles.
    let mut path = Toolpath { moves: Vec::with_capacity(answer.layers.iter().map(|layer| layer.moves.len()).sum()) };
    for layer in &answer.layers {
        control.check()?;
        let mut spans = layer.arcs.iter().filter(|_| post.arcs == Arcs::G2g3).peekable();
        let mut index = 0;
        while let Some(step) = layer.moves.get(index) {
            if index % gcode::MOVES_PER_CHECK == 0 {
                control.check()?;
            }
            if let Some(span) = spans.next_if(|span| span.first == index)
                && let Some(feed) = step.feed
            {
                let height = layer.z + lift;
                let start = Vec3::new(span.start[0], span.start[1], height);
                // The move before was lengthened to the first chord vertex under the block-time
                // rule: it ends at the arc's start again, on the same line.
                if let Some(previous) = path.moves.last_mut() {
                    previous.to = start;
                }
                let end = Vec3::new(span.end[0], span.end[1], height);
                path.arc_sweep(start, end, Vec3::new(span.centre[0], span.centre[1], height), span.sweep, feed);
                index = span.last + 1;
                continue;
            }
            let to = Vec3::from(step.to) + offset;
            match (step.kind, step.feed) {
                (MoveKind::Rapid, _) | (_, None) => path.rapid(to),
                (_, Some(feed)) => path.linear(to, feed),
            }
            index += 1;
        }
    }
    let mut comments = answer.description.clone();
    comments.push(format!("control point: {} of the {} tool", post.reference.as_str(), answer.tool_kind.as_str()));
    let program = Program {
        dialect: post.dialect,
        number: 1000,
        title: "kerf contour",
        comments,
        tool: post.tool.clone(),
        spindle_rpm: answer.summary.spindle_rpm,
        spindle_direction: SpindleDirection::Cw,
        safe_z: answer.summary.safe_z + lift,
        blend_tolerance: answer.summary.tolerance,
        plunges: Some(gcode::Plunges { feed: post.plunge_feed }),
        path: &path,
        units: post.units,
    };
    program.check_written(&[], "spindle_rpm", "feed")?;
    gcode::write_cancellable(&program, &[], control)
}
