//! Lead-in, lead-out and the G-code program of a deburr job (docs/spec/deburr.md §6.3, §7): a
//! program complete and safe to run as it is.
//!
//! Outer edge: rapid above the lead point A0 = C0 − δ·u0 (δ back along the bisector, in air), feed
//! down to A0 and on to C0, run the loop, back to A0 and up. Inner edge: rapid above the hole
//! axis, feed down the axis to the ball-centre level, out to C0, run the loop, and back the same
//! way.

use super::answer::{Deburr, LeadMotion, LeadMove};
use super::frame::Frame;
use super::job::Job;
use super::request::Edge;
use crate::capability::Control;
use crate::error::ErrorCode;
use crate::error::SolverError;
use crate::gcode::{self, Post, Program, Reference, SpindleDirection, ToolCall};
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

/// A lead move to ball centre `centre`, with its tip.
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
        // A job is validated per ridge: `both` never reaches here (it is the outer one if it did).
        Edge::Outer | Edge::Both => {
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
    program_for_holes(&[deburr], post, Control::default())
}

/// One program for several holes deburred with one tool: [`program_for_loops`] with
/// one tool, the tube never turned.
///
/// # Errors
/// As [`program_for_loops`].
pub fn program_for_holes(holes: &[&Deburr], post: &Post, control: Control<'_>) -> Result<String, SolverError> {
    let legs: Vec<Leg<'_>> = holes.iter().map(|deburr| Leg { deburr, tool: 0, turned: false }).collect();
    program_for_loops(&legs, std::slice::from_ref(&post.tool), post, control)
}

/// One loop of a several-loop program.
#[derive(Debug, Clone, Copy)]
pub struct Leg<'a> {
    /// The solved loop.
    pub deburr: &'a Deburr,
    /// Which of the program's tools cuts it.
    pub tool: usize,
    /// Whether the tube is turned half a turn about its axis for it.
    pub turned: bool,
}

/// The moves of a program visiting several loops, in machine coordinates of the programmed point.
#[derive(Debug, Clone)]
pub(crate) struct Visit {
    /// Every loop's approach, loop and way out in order, and the travel between loops: up to the
    /// clearance plane, across, and on to the next approach.
    pub path: Toolpath,
    /// Per move of `path`: whether it runs out of the material (leads, travel), for the cycle
    /// time.
    pub air: Vec<bool>,
    /// Where the tool or the tube's turn changes between loops: the index of the first move
    /// after, and the leg after it.
    pub stops: Vec<(usize, usize)>,
    /// Z of the programmed point on the clearance plane: the highest of the loops'.
    pub safe_z: f64,
}

/// Offset from the ball centre to the programmed point of a loop.
fn offset(deburr: &Deburr, reference: Reference) -> Vec3 {
    match reference {
        Reference::Tip => -deburr.ball_radius * Vec3::z(),
        Reference::Centre => Vec3::zeros(),
    }
}

/// Where the programmed point starts a loop's approach and ends its way out.
fn ends(deburr: &Deburr, reference: Reference) -> (Vec3, Vec3) {
    let offset = offset(deburr, reference);
    let first = deburr.points.first().map_or_else(Vec3::zeros, |p| vec3(p.centre));
    let start = deburr.lead_in.first().map_or(first, |step| vec3(step.centre));
    let end = deburr.lead_out.last().map_or(first, |step| vec3(step.centre));
    (start + offset, end + offset)
}

/// Z of the programmed point on the clearance plane of `loops`: the highest of theirs (each
/// loop's ball centre plane, less its radius at the tip).
///
/// # Errors
/// `E_NO_CLEARANCE_PLANE` when a loop's plane is unknown.
pub(crate) fn safe_z(loops: &[&Deburr], reference: Reference) -> Result<f64, SolverError> {
    let mut safe = f64::NEG_INFINITY;
    for deburr in loops {
        let z = deburr.summary.safe_centre_z.ok_or_else(|| {
            SolverError::new(ErrorCode::NoClearancePlane, "the clearance plane is unknown; give safe_z").at("safe_z")
        })?;
        safe = safe.max(z + offset(deburr, reference).z);
    }
    Ok(safe)
}

/// The length of the travel from the end of loop `from` to the start of loop `to` along the moves
/// the program makes: up to the clearance plane `safe_z`, across, and down to the approach.
pub(crate) fn travel(from: &Deburr, to: &Deburr, safe_z: f64, reference: Reference) -> f64 {
    let (_, end) = ends(from, reference);
    let (start, _) = ends(to, reference);
    (safe_z - end.z).max(0.0) + (start.x - end.x).hypot(start.y - end.y) + (safe_z - start.z).max(0.0)
}

/// The moves of the program visiting `legs` in order. Where a loop's clearance plane is unknown
/// (it has no program) the travel goes over the highest end of the loops' leads instead.
pub(crate) fn visit(legs: &[Leg<'_>], reference: Reference) -> Visit {
    let all: Vec<&Deburr> = legs.iter().map(|leg| leg.deburr).collect();
    let safe_z = safe_z(&all, reference).unwrap_or_else(|_| {
        all.iter()
            .flat_map(|deburr| {
                let (start, end) = ends(deburr, reference);
                [start.z, end.z]
            })
            .fold(f64::NEG_INFINITY, f64::max)
    });
    let mut path = Toolpath::default();
    let mut air = Vec::new();
    let mut stops = Vec::new();
    for (index, leg) in legs.iter().enumerate() {
        let deburr = leg.deburr;
        let offset = offset(deburr, reference);
        let feed = deburr.summary.feed;
        if index > 0
            && let Some(last) = path.moves.last().map(|m| m.to)
        {
            // Up to the clearance plane, (the stop,) across, and on to this loop's approach.
            let (next, _) = ends(deburr, reference);
            let up = Vec3::new(last.x, last.y, safe_z);
            let across = Vec3::new(next.x, next.y, safe_z);
            if up != last {
                path.rapid(up);
                air.push(true);
            }
            let before = legs[index - 1];
            if leg.tool != before.tool || leg.turned != before.turned {
                stops.push((path.moves.len(), index));
            }
            if across != up && across != next {
                path.rapid(across);
                air.push(true);
            }
        }
        let mut add = |motion: LeadMotion, centre: [f64; 3], in_air: bool| {
            match motion {
                LeadMotion::Rapid => path.rapid(vec3(centre) + offset),
                LeadMotion::Feed => path.linear(vec3(centre) + offset, feed),
            }
            air.push(in_air);
        };
        for step in &deburr.lead_in {
            add(step.motion, step.centre, true);
        }
        for point in deburr.points.iter().skip(1) {
            add(LeadMotion::Feed, point.centre, false);
        }
        for step in &deburr.lead_out {
            add(step.motion, step.centre, true);
        }
    }
    Visit { path, air, stops, safe_z }
}

/// One program for several loops: holes, and with `edge: both` each hole's outer and
/// inner ridge: each loop's approach, loop and way out in the order given, the tool lifted to
/// the highest clearance plane of them between loops and moved across there. `tools[leg.tool]`
/// cuts a leg; where the tool changes the program changes it (`T M06`, `G43 H`, spindle), and
/// where the tube's turn changes it stops (`M00`) for the operator to turn the tube half a turn
/// about its axis. The header is the first loop's with the number of loops and tools.
///
/// # Errors
/// The first loop's reason when one has no program (`program_blocker`); `E_NO_PROGRAM` without
/// loops; `E_CANCELLED` once `control`'s cancel flag is set.
pub fn program_for_loops(
    legs: &[Leg<'_>],
    tools: &[ToolCall],
    post: &Post,
    control: Control<'_>,
) -> Result<String, SolverError> {
    let Some(first) = legs.first() else {
        return Err(SolverError::new(ErrorCode::NoProgram, "no hole to deburr"));
    };
    let deburr = first.deburr;
    if let Some(blocker) = legs.iter().find_map(|leg| leg.deburr.program_blocker.as_ref()) {
        return Err(blocker.clone());
    }
    let all: Vec<&Deburr> = legs.iter().map(|leg| leg.deburr).collect();
    safe_z(&all, post.reference)?;
    let visit = visit(legs, post.reference);
    let tool_of = |index: usize| tools.get(index).or(tools.last()).cloned().unwrap_or_else(|| post.tool.clone());
    let mut comments = deburr.description.clone();
    if legs.len() > 1 {
        let inner = legs.iter().filter(|leg| leg.deburr.edge == super::request::Edge::Inner).count();
        let edges = if inner > 0 && inner < legs.len() {
            format!(" ({} outer, {inner} inner)", legs.len() - inner)
        } else {
            String::new()
        };
        comments.push(format!("{} loops in one program{edges}: the first is described above", legs.len()));
    }
    let mut used: Vec<usize> = Vec::new();
    for leg in legs {
        if used.last() != Some(&leg.tool) {
            used.push(leg.tool);
        }
    }
    if used.len() > 1 {
        let names: Vec<String> = used
            .iter()
            .map(|&index| match tool_of(index) {
                ToolCall::Table(number) | ToolCall::Named { number, .. } => format!("T{number}"),
                ToolCall::Manual(description) => description,
            })
            .collect();
        comments.push(format!("tools in order: {}", names.join(", ")));
    }
    let turns = visit.stops.iter().filter(|(_, leg)| legs[*leg].turned != legs[leg - 1].turned).count();
    if turns > 0 || first.turned {
        comments.push(format!(
            "holes pointing down are deburred with the tube turned 180 deg about its axis: {} M00 stops to turn it",
            turns + usize::from(first.turned)
        ));
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
    let turn_notice = |turned: bool| {
        if turned {
            "turn the tube 180 deg about its axis: the holes pointing down now point up, then cycle start"
        } else {
            "turn the tube back 180 deg about its axis, then cycle start"
        }
        .to_owned()
    };
    let stops: Vec<gcode::ProgramStop> = visit
        .stops
        .iter()
        .map(|&(before, index)| {
            let (leg, previous) = (legs[index], legs[index - 1]);
            gcode::ProgramStop {
                before,
                notice: (leg.turned != previous.turned).then(|| turn_notice(leg.turned)),
                tool: (leg.tool != previous.tool).then(|| tool_of(leg.tool)),
                spindle_rpm: leg.deburr.summary.spindle_rpm,
            }
        })
        .collect();
    if first.turned {
        comments.push(turn_notice(true));
    }
    control.check()?;
    let program = Program {
        dialect: post.dialect,
        number: 1000,
        title: "kerf deburr",
        comments,
        tool: tool_of(first.tool),
        spindle_rpm: deburr.summary.spindle_rpm,
        spindle_direction: SpindleDirection::Cw,
        safe_z: visit.safe_z,
        blend_tolerance: deburr.summary.tolerance,
        // Every move down runs in air: to the lead point beside the edge, or down the hole.
        plunges: None,
        path: &visit.path,
        units: post.units,
    };
    program.check_written(&stops, "spindle_rpm", "feed")?;
    gcode::write_cancellable(&program, &stops, control)
}
