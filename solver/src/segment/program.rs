//! The G-code program of a segment answer (docs/spec/segment.md §6.1): G01 blocks through the command points
//! with the F word, written by the house post; with `arcs = g2g3` a circle or arc is written as
//! G02/G03 blocks of at most half a turn ending at the last command point.
//!
//! The path: rapid to the clearance plane above the first point, feed down to it, the G01
//! blocks, and (by the post) back up to the clearance plane. A segment program has no tool of its
//! own: the caller says how the program selects one. Coordinates are those of the curve (the
//! programmed point), 2-D curves at z = 0.

use super::answer::{CommandPoint, SegmentSolution};
use crate::capability::Control;
use crate::error::ErrorCode;
use crate::error::SolverError;
use crate::gcode::{self, Arcs, Post, Program, SpindleDirection};
use crate::geometry::Vec3;
use crate::machine::MachineProfile;
use crate::machine::cycle::{CycleTime, Step, cycle_time as cycle_time_of};
use crate::path::Toolpath;

/// The cycle time of the chord program on `machine` (None without its `max_accel`): from the
/// clearance plane above the first point, the plunge (air) at the plunge feed, every block
/// (cutting), the retract; one tool change when `tool_change`.
pub(crate) fn cycle_time(
    answer: &SegmentSolution,
    machine: &MachineProfile,
    plunge_feed: Option<f64>,
    tool_change: bool,
) -> Option<CycleTime> {
    let dynamics = machine.dynamics()?;
    let points: Vec<Vec3> = answer.points.iter().map(CommandPoint::to_vec3).collect();
    let first = *points.first()?;
    let above = Vec3::new(first.x, first.y, answer.safe_z);
    let mut steps = vec![Step::Feed { to: first, feed: gcode::plunge_feed(answer.feed, plunge_feed), air: true }];
    steps.extend(points[1..].iter().map(|&to| Step::Feed { to, feed: answer.feed, air: false }));
    let last = points[points.len() - 1];
    steps.push(Step::Rapid(Vec3::new(last.x, last.y, answer.safe_z)));
    Some(cycle_time_of(above, &steps, &dynamics, usize::from(tool_change)))
}

/// The complete program for a segment answer. `post.reference` does not apply: the curve is
/// the programmed point.
///
/// # Errors
/// `E_NO_PROGRAM` when the answer has no block (it always has one when `solve` succeeded).
pub fn program(answer: &SegmentSolution, post: &Post) -> Result<String, SolverError> {
    program_controlled(answer, post, Control::default())
}

/// [`program`] that stops with `E_CANCELLED` once `control`'s cancel flag is set.
///
/// # Errors
/// As [`program`]; `E_CANCELLED` when cancelled.
pub fn program_controlled(answer: &SegmentSolution, post: &Post, control: Control<'_>) -> Result<String, SolverError> {
    let points: Vec<Vec3> = answer.points.iter().map(CommandPoint::to_vec3).collect();
    let Some(first) = points.first() else {
        return Err(SolverError::new(ErrorCode::NoProgram, "the answer has no points"));
    };
    if points.len() < 2 {
        return Err(SolverError::new(ErrorCode::NoProgram, "the answer has no block"));
    }
    let mut path = Toolpath::default();
    path.rapid(Vec3::new(first.x, first.y, answer.safe_z));
    path.linear(*first, answer.feed);
    match (&answer.circle, post.arcs) {
        (Some(arc), Arcs::G2g3) => {
            let end = points[points.len() - 1];
            path.arc_sweep(*first, end, arc.centre, arc.sense * arc.sweep, answer.feed);
        }
        _ => {
            for (index, point) in points[1..].iter().enumerate() {
                if index % gcode::MOVES_PER_CHECK == 0 {
                    control.check()?;
                }
                path.linear(*point, answer.feed);
            }
        }
    }
    control.check()?;
    let program = Program {
        dialect: post.dialect,
        number: 1001,
        title: "kerf segment",
        comments: answer.description.clone(),
        tool: post.tool.clone(),
        spindle_rpm: answer.spindle_rpm,
        spindle_direction: SpindleDirection::Cw,
        safe_z: answer.safe_z,
        blend_tolerance: answer.chord_error.max(1e-4),
        plunges: Some(gcode::Plunges { feed: post.plunge_feed }),
        path: &path,
        units: post.units,
    };
    program.check_written(&[], "spindle_rpm", "feed")?;
    gcode::write_cancellable(&program, &[], control)
}
