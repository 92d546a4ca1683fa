//! Reading a candidate path into a route of lines and arcs (docs/spec/engagement.md §2.3): a
//! point list, `start` + `segments`, or G-code text through the shared reader.

use super::super::P2;
use super::super::request::{Direction, PathInput, PathSegments, SegmentInput};
use super::super::segments::{Route, Shape};
use super::{point, too_large};
use crate::engagement::MAX_SEGMENTS;
use crate::error::{ErrorCode, SolverError, Warning};
use crate::gcode::reader::{MoveKind, Plane, ReadOptions, read as read_program};

/// A path's pieces, zero-length ones dropped with a warning (docs/spec/engagement.md §2.3).
pub(crate) fn read_path(input: &PathInput, field: &str, warnings: &mut Vec<Warning>) -> Result<Route, SolverError> {
    read_path_levels(input, field, warnings, &mut Vec::new())
}

/// [`read_path`], adding to `levels` the Z (mm) and line of both ends of every XY feed move of
/// a G-code path whose Z is known.
pub(super) fn read_path_levels(
    input: &PathInput,
    field: &str,
    warnings: &mut Vec<Warning>,
    levels: &mut Vec<(f64, usize)>,
) -> Result<Route, SolverError> {
    let mut shapes: Vec<(Shape, bool, usize)> = Vec::new();
    let mut dropped = Vec::new();
    match input {
        PathInput::Points(points) => {
            if points.len() > MAX_SEGMENTS + 1 {
                return Err(too_large(field, "path points", points.len(), MAX_SEGMENTS + 1));
            }
            let mut previous: Option<P2> = None;
            for (index, p) in points.iter().enumerate() {
                let here = point(&format!("{field}[{index}]"), *p)?;
                if let Some(from) = previous {
                    let shape = Shape::Line { from, to: here };
                    if shape.length() <= 1e-9 {
                        dropped.push(format!("{field}[{index}]"));
                    } else {
                        shapes.push((shape, false, index - 1));
                    }
                }
                previous = Some(here);
            }
        }
        PathInput::Segments(PathSegments { gcode: Some(text), start, segments }) => {
            if start.is_some() || segments.is_some() {
                return Err(SolverError::new(
                    ErrorCode::Path,
                    "give the path as gcode or as start and segments, not both",
                )
                .at(format!("{field}.gcode")));
            }
            read_gcode_path(text, &format!("{field}.gcode"), &mut shapes, &mut dropped, levels)?;
        }
        PathInput::Segments(program) => {
            let start = program.start.ok_or_else(|| {
                SolverError::new(ErrorCode::Path, "the path needs a start point [x, y]").at(format!("{field}.start"))
            })?;
            let segments = program.segments.as_ref().ok_or_else(|| {
                SolverError::new(ErrorCode::Path, "the path needs segments").at(format!("{field}.segments"))
            })?;
            if segments.len() > MAX_SEGMENTS {
                return Err(too_large(&format!("{field}.segments"), "path segments", segments.len(), MAX_SEGMENTS));
            }
            let mut from = point(&format!("{field}.start"), start)?;
            for (index, segment) in segments.iter().enumerate() {
                let here = format!("{field}.segments[{index}]");
                match segment {
                    SegmentInput::Line { to, rapid } => {
                        let to = point(&format!("{here}.to"), *to)?;
                        let shape = Shape::Line { from, to };
                        if shape.length() <= 1e-9 {
                            dropped.push(here);
                        } else {
                            shapes.push((shape, *rapid, index));
                        }
                        from = to;
                    }
                    SegmentInput::Arc { to, center, dir } => {
                        let to = point(&format!("{here}.to"), *to)?;
                        let centre = point(&format!("{here}.center"), *center)?;
                        shapes.push((
                            arc_shape(from, to, centre, *dir == Direction::Cw, 0, &format!("{here}.center"))?,
                            false,
                            index,
                        ));
                        from = to;
                    }
                }
            }
        }
    }
    if shapes.is_empty() {
        return Err(SolverError::new(
            ErrorCode::Path,
            "the path is empty: it needs at least one move of non-zero length",
        )
        .at(field));
    }
    if let Some(first) = dropped.first() {
        warnings.push(Warning::new(
            "W_SEGMENT_ZERO",
            format!("{} zero-length segment(s) dropped (first: {first})", dropped.len()),
        ));
    }
    Ok(Route::new(shapes))
}

/// The arc from `from` to `to` about `centre` (a full turn when they coincide), plus
/// `extra_turns`; refused when the centre is not equidistant from both ends.
fn arc_shape(
    from: P2,
    to: P2,
    centre: P2,
    clockwise: bool,
    extra_turns: u32,
    field: &str,
) -> Result<Shape, SolverError> {
    let (r0, r1) = ((from - centre).norm(), (to - centre).norm());
    if r0 <= 1e-9 {
        return Err(SolverError::new(ErrorCode::Path, "the arc centre coincides with its start point").at(field));
    }
    if (r0 - r1).abs() > 1e-6 * r0.max(r1) {
        return Err(SolverError::new(
            ErrorCode::Path,
            format!("the arc centre is {r0:.6} mm from the start point but {r1:.6} mm from the end point"),
        )
        .at(field));
    }
    let start_angle = (from.y - centre.y).atan2(from.x - centre.x);
    let end_angle = (to.y - centre.y).atan2(to.x - centre.x);
    let turn = std::f64::consts::TAU;
    let full = (to - from).norm() <= 1e-9 * r0.max(1.0);
    let sweep = match (clockwise, full) {
        (_, true) => turn,
        (false, false) => (end_angle - start_angle).rem_euclid(turn),
        (true, false) => (start_angle - end_angle).rem_euclid(turn),
    } + turn * f64::from(extra_turns);
    let sweep = if clockwise { -sweep } else { sweep };
    Ok(Shape::Arc { centre, radius: r0, start: start_angle, sweep })
}

/// The XY moves of a G-code program (read by the shared reader) as path pieces, each numbered by
/// its program line (the samples' `segment`). Moves before the first fully known XY position are
/// skipped (the tool's position is unknown there); pure Z moves have no length in the plane and
/// are dropped like other zero-length segments.
fn read_gcode_path(
    text: &str,
    field: &str,
    shapes: &mut Vec<(Shape, bool, usize)>,
    dropped: &mut Vec<String>,
    levels: &mut Vec<(f64, usize)>,
) -> Result<(), SolverError> {
    let program = read_program(text, field, &ReadOptions { max_lines: MAX_SEGMENTS, ..ReadOptions::default() })?;
    for step in &program.moves {
        let (Some(fx), Some(fy), Some(tx), Some(ty)) = (step.from[0], step.from[1], step.to[0], step.to[1]) else {
            continue;
        };
        let (from, to) = (P2::new(fx, fy), P2::new(tx, ty));
        let here = format!("{field} (line {})", step.line);
        let (shape, rapid) = match step.kind {
            MoveKind::Rapid => (Shape::Line { from, to }, true),
            MoveKind::Linear => (Shape::Line { from, to }, false),
            MoveKind::Arc { centre, clockwise, extra_turns } => {
                if step.modal.plane != Plane::Xy {
                    return Err(SolverError::new(
                        ErrorCode::Path,
                        format!("line {}: arcs must be in the XY plane (G17) for an engagement path", step.line),
                    )
                    .at(field));
                }
                (arc_shape(from, to, P2::new(centre[0], centre[1]), clockwise, extra_turns, field)?, false)
            }
        };
        if shape.length() <= 1e-9 {
            dropped.push(here);
        } else {
            if !rapid {
                levels.extend([step.from[2], step.to[2]].into_iter().flatten().map(|z| (z, step.line)));
            }
            shapes.push((shape, rapid, step.line));
        }
    }
    Ok(())
}
