//! Lead-in, lead-out and the G-code program of a deburr job (issue: "complete and safe to run";
//! deburr.md §6.3, §7).
//!
//! Outer edge: rapid above the lead point A0 = C0 − δ·u0 (δ back along the bisector, in air), feed
//! down to A0 and on to C0, run the loop, back to A0 and up. Inner edge: rapid above the hole
//! axis, feed down the axis to the ball-centre level, out to C0, run the loop, and back the same
//! way.

use super::answer::{Deburr, LeadMotion, LeadMove};
use super::frame::Frame;
use super::job::Job;
use super::request::Edge;
use crate::error::ErrorCode;
use crate::error::SolverError;
use crate::gcode::{self, Post, Program, Reference, SpindleDirection};
use crate::geometry::{Vec3, array3, vec3};
use crate::path::Toolpath;

/// Z of the ball centre on the clearance plane, or why it is unknown.
pub(crate) fn safe_centre_z(job: &Job, frame: &Frame) -> Result<f64, SolverError> {
    if let Some(tip_z) = job.safe_z {
        return Ok(tip_z + job.tool.radius);
    }
    match job.top_distance {
        // A tube's axis is horizontal, so its highest point is R_T above the axis.
        Some(top) if job.tube_radii.is_some() => Ok(frame.origin.z + top + job.clearance + job.tool.radius),
        // A block face is only known to be the top when the hole is vertical.
        Some(face) if frame.vector(&Vec3::z()).z >= 1.0 - 1e-12 => {
            Ok(frame.origin.z + face + job.clearance + job.tool.radius)
        }
        _ => Err(SolverError::new(
            ErrorCode::NoClearancePlane,
            "the clearance plane is unknown for this bore_block: give workpiece.face_distance (vertical holes) or safe_z",
        )
        .at("safe_z")),
    }
}

fn lead(motion: LeadMotion, centre: Vec3, ball_radius: f64) -> LeadMove {
    LeadMove { motion, centre: array3(&centre), tip: array3(&(centre - ball_radius * Vec3::z())) }
}

/// The approach to the first centre and the way out from it, in machine coordinates.
pub(crate) fn leads(
    job: &Job,
    first_centre: Vec3,
    first_bisector: Vec3,
    safe_z: f64,
) -> (Vec<LeadMove>, Vec<LeadMove>) {
    let ball = job.tool.radius;
    let above = |p: Vec3| Vec3::new(p.x, p.y, safe_z);
    match job.edge {
        Edge::Outer => {
            let lead_point = first_centre - job.lead_distance * first_bisector;
            (
                vec![
                    lead(LeadMotion::Rapid, above(lead_point), ball),
                    lead(LeadMotion::Feed, lead_point, ball),
                    lead(LeadMotion::Feed, first_centre, ball),
                ],
                vec![lead(LeadMotion::Feed, lead_point, ball), lead(LeadMotion::Rapid, above(lead_point), ball)],
            )
        }
        Edge::Inner => {
            let local_first = job.frame.rotation.transpose() * (first_centre - job.frame.origin);
            let axis_x = job.profile.centre_x;
            let entry_height = job.top_distance.unwrap_or(job.cylinder_radius) + job.clearance + ball;
            let over_hole = job.frame.point(&Vec3::new(axis_x, 0.0, entry_height));
            let on_axis = job.frame.point(&Vec3::new(axis_x, 0.0, local_first.z));
            let mut lead_in = vec![lead(LeadMotion::Rapid, above(over_hole), ball)];
            let mut lead_out = vec![
                lead(LeadMotion::Feed, on_axis, ball),
                lead(LeadMotion::Feed, over_hole, ball),
                lead(LeadMotion::Rapid, above(over_hole), ball),
            ];
            if over_hole.z < safe_z {
                lead_in.push(lead(LeadMotion::Rapid, over_hole, ball));
            } else {
                lead_out.pop();
            }
            lead_in.push(lead(LeadMotion::Feed, on_axis, ball));
            lead_in.push(lead(LeadMotion::Feed, first_centre, ball));
            (lead_in, lead_out)
        }
    }
}

/// The complete program for a solved deburr job.
pub fn program(deburr: &Deburr, post: &Post) -> Result<String, SolverError> {
    program_for_holes(&[deburr], post)
}

/// One program for several holes deburred with one tool (issue 15): each hole's approach, loop
/// and way out in order, the tool lifted to the highest clearance plane of them between holes
/// and moved across there. The header is the first hole's with the number of holes.
///
/// # Errors
/// The first hole's reason when one has no program (`program_blocker`); `E_NO_PROGRAM` without
/// holes.
pub fn program_for_holes(holes: &[&Deburr], post: &Post) -> Result<String, SolverError> {
    let Some(deburr) = holes.first() else {
        return Err(SolverError::new(ErrorCode::NoProgram, "no hole to deburr"));
    };
    if let Some(blocker) = holes.iter().find_map(|hole| hole.program_blocker.as_ref()) {
        return Err(blocker.clone());
    }
    let offset = match post.reference {
        Reference::Tip => -deburr.ball_radius * Vec3::z(),
        Reference::Centre => Vec3::zeros(),
    };
    let mut safe_centre_z = f64::NEG_INFINITY;
    for hole in holes {
        let z = hole.summary.safe_centre_z.ok_or_else(|| {
            SolverError::new(ErrorCode::NoClearancePlane, "the clearance plane is unknown; give safe_z").at("safe_z")
        })?;
        safe_centre_z = safe_centre_z.max(z);
    }
    let mut path = Toolpath::default();
    for (index, hole) in holes.iter().enumerate() {
        let feed = hole.summary.feed;
        if index > 0
            && let (Some(last), Some(next)) = (path.moves.last().map(|m| m.to), hole.lead_in.first())
        {
            // Up to the highest clearance plane, across, and on to this hole's own approach.
            let next = vec3(next.centre) + offset;
            let up = Vec3::new(last.x, last.y, safe_centre_z + offset.z);
            let across = Vec3::new(next.x, next.y, up.z);
            if up != last {
                path.rapid(up);
            }
            if across != up && across != next {
                path.rapid(across);
            }
        }
        let mut add = |motion: LeadMotion, centre: [f64; 3]| match motion {
            LeadMotion::Rapid => path.rapid(vec3(centre) + offset),
            LeadMotion::Feed => path.linear(vec3(centre) + offset, feed),
        };
        for step in &hole.lead_in {
            add(step.motion, step.centre);
        }
        for point in hole.points.iter().skip(1) {
            add(LeadMotion::Feed, point.centre);
        }
        for step in &hole.lead_out {
            add(step.motion, step.centre);
        }
    }
    let mut comments = deburr.description.clone();
    if holes.len() > 1 {
        comments.push(format!("{} holes in one program: the first is described above", holes.len()));
    }
    comments.push(format!(
        "control point: {}{}",
        post.reference.as_str(),
        if post.reference == Reference::Tip {
            " (length offset to the ball tip)"
        } else {
            " (length offset to the ball centre)"
        }
    ));
    Ok(gcode::write(&Program {
        dialect: post.dialect,
        number: 1000,
        title: "kerf deburr",
        comments,
        tool: post.tool.clone(),
        spindle_rpm: deburr.summary.spindle_rpm,
        spindle_direction: SpindleDirection::Cw,
        safe_z: safe_centre_z + offset.z,
        blend_tolerance: deburr.summary.tolerance,
        // Every move down runs in air: to the lead point beside the edge, or down the hole.
        plunges: None,
        path: &path,
    }))
}
