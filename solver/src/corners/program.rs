//! The G-code program of a solved contour (api.md G-code conventions): every layer's moves in
//! order, rapids as G00, cuts, loops and links as G01 at their feeds (loops at `loop_feed` where
//! they clear the stock).

use super::answer::{ContourAnswer, MoveKind};
use crate::error::ErrorCode;
use crate::error::SolverError;

use crate::gcode::{self, Post, Program, Reference, SpindleDirection};
use crate::geometry::Vec3;
use crate::path::Toolpath;

/// The complete program for a solved contour job.
///
/// # Errors
/// `E_TILT_NEEDS_5_AXIS` (at `tilt_deg`) when the walls are tilted: the moves then carry a tool
/// axis that a 3-axis program cannot express.
pub fn program(answer: &ContourAnswer, post: &Post) -> Result<String, SolverError> {
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
    let mut path = Toolpath::default();
    for layer in &answer.layers {
        for step in &layer.moves {
            let to = Vec3::from(step.to) + offset;
            match (step.kind, step.feed) {
                (MoveKind::Rapid, _) | (_, None) => path.rapid(to),
                (_, Some(feed)) => path.linear(to, feed),
            }
        }
    }
    let mut comments = answer.description.clone();
    comments.push(format!("control point: {} of the {} tool", post.reference.as_str(), answer.tool_kind.as_str()));
    Ok(gcode::write(&Program {
        dialect: post.dialect,
        number: 1000,
        title: "kerf contour",
        comments,
        tool: post.tool.clone(),
        spindle_rpm: answer.summary.spindle_rpm,
        spindle_direction: SpindleDirection::Cw,
        safe_z: answer.summary.safe_z + lift,
        blend_tolerance: answer.summary.tolerance,
        path: &path,
    }))
}
