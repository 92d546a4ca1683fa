//! Arcs of the G-code reader (docs/spec/predict.md §8, engagement.md §11: `G2`/`G3` import): start
//! angle, sweep and radius in the plane, and the centre and turns of a `G2`/`G3` block checked for
//! closure.

use super::lexer::syntax;
use super::modal::Block;
use super::{ARC_CLOSURE_MM, ARC_CLOSURE_RELATIVE, MAX_ARC_TURNS, Modal, MoveKind, Position};
use crate::error::ErrorCode;
use crate::error::SolverError;

/// Start angle, signed sweep and radius of an arc in its plane.
#[derive(Debug, Clone, Copy)]
pub(super) struct ArcGeometry {
    pub(super) radius: f64,
    pub(super) start_angle: f64,
    pub(super) sweep: f64,
}

impl ArcGeometry {
    pub(super) fn new(
        from: [f64; 3],
        to: [f64; 3],
        centre: [f64; 3],
        clockwise: bool,
        extra_turns: u32,
        (a, b): (usize, usize),
    ) -> Self {
        let (sa, sb) = (from[a] - centre[a], from[b] - centre[b]);
        let (ea, eb) = (to[a] - centre[a], to[b] - centre[b]);
        let start_angle = sb.atan2(sa);
        let end_angle = eb.atan2(ea);
        let tau = std::f64::consts::TAU;
        let mut sweep = if clockwise {
            -(start_angle - end_angle).rem_euclid(tau)
        } else {
            (end_angle - start_angle).rem_euclid(tau)
        };
        // Coincident start and end is a full circle, never a zero-length arc.
        if sweep.abs() < 1e-12 {
            sweep = if clockwise { -tau } else { tau };
        }
        sweep += f64::from(extra_turns) * if clockwise { -tau } else { tau };
        Self { radius: sa.hypot(sb), start_angle, sweep }
    }
}

/// Centre and turns of a `G2`/`G3` block, checked for closure.
pub(super) fn arc_kind(
    block: &Block,
    modal: &Modal,
    from: &Position,
    to: &Position,
    clockwise: bool,
    line: usize,
    field: &str,
) -> Result<MoveKind, SolverError> {
    let (a, b, normal) = modal.plane.axes();
    let (Some(start_a), Some(start_b), Some(end_a), Some(end_b)) = (from[a], from[b], to[a], to[b]) else {
        return Err(SolverError::new(
            ErrorCode::GcodePosition,
            format!("line {line}: arc from a position the program has not set yet"),
        )
        .at(field));
    };
    let extra_turns = arc_turns(block, line, field)?;
    let (start, end) = ([start_a, start_b], [end_a, end_b]);
    let (centre_a, centre_b) = if let Some(radius_word) = block.radius {
        if block.offsets.iter().any(Option::is_some) {
            return Err(syntax(field, line, "an arc takes either R or I/J/K, not both"));
        }
        radius_centre(radius_word.value, modal.units.scale(), start, end, clockwise, line, field)?
    } else {
        offset_centre(block, modal, start, line, field)?
    };
    check_closure([centre_a, centre_b], start, end, line, field)?;
    let mut centre = [0.0; 3];
    centre[a] = centre_a;
    centre[b] = centre_b;
    centre[normal] = from[normal].unwrap_or(0.0);
    Ok(MoveKind::Arc { centre, clockwise, extra_turns })
}

/// Full turns beyond the first partial one: LinuxCNC's `P` word minus 1 (0 without it).
fn arc_turns(block: &Block, line: usize, field: &str) -> Result<u32, SolverError> {
    Ok(match block.turns {
        None => 0,
        Some(word) => {
            let turns = word.value;
            if turns < 1.0 || turns.fract() != 0.0 || turns > f64::from(MAX_ARC_TURNS) {
                return Err(syntax(
                    field,
                    line,
                    format!("arc turns P{turns} must be a whole number from 1 to {MAX_ARC_TURNS}"),
                ));
            }
            turns as u32 - 1
        }
    })
}

/// The in-plane centre of an `R` arc from `start` to `end` (mm): `r_word` in the line's units
/// (`scale` mm each), negative for the long arc.
fn radius_centre(
    r_word: f64,
    scale: f64,
    start: [f64; 2],
    end: [f64; 2],
    clockwise: bool,
    line: usize,
    field: &str,
) -> Result<(f64, f64), SolverError> {
    let ([start_a, start_b], [end_a, end_b]) = (start, end);
    let radius = r_word * scale;
    let (dx, dy) = (end_a - start_a, end_b - start_b);
    let chord = dx.hypot(dy);
    if chord < 1e-9 {
        return Err(syntax(field, line, "a full circle cannot be given with R: use I/J/K"));
    }
    let half = chord / 2.0;
    if radius.abs() < half - ARC_CLOSURE_MM.max(ARC_CLOSURE_RELATIVE * half) {
        return Err(SolverError::new(
            ErrorCode::ArcRadius,
            format!(
                "line {line}: arc radius R{r_word} ({:.4} mm) is shorter than half the chord ({half:.4} mm)",
                radius.abs()
            ),
        )
        .at(field));
    }
    let rise = (radius * radius - half * half).max(0.0).sqrt();
    // The centre lies left of the chord for a short counter-clockwise arc or a long
    // clockwise one (negative R asks for the long arc).
    let left = (radius >= 0.0) != clockwise;
    let side = if left { 1.0 } else { -1.0 };
    let (mid_a, mid_b) = ((start_a + end_a) / 2.0, (start_b + end_b) / 2.0);
    Ok((mid_a - side * rise * dy / chord, mid_b + side * rise * dx / chord))
}

/// The in-plane centre of an `I J K` arc starting at `start` (mm): offsets from the start, or
/// absolute under `G90.1`; a missing word leaves that coordinate at the start's.
fn offset_centre(
    block: &Block,
    modal: &Modal,
    start: [f64; 2],
    line: usize,
    field: &str,
) -> Result<(f64, f64), SolverError> {
    let (a, b, normal) = modal.plane.axes();
    let [start_a, start_b] = start;
    let scale = modal.units.scale();
    let offset_letters = ['I', 'J', 'K'];
    let offset = |axis: usize| block.offsets[axis].map(|w| w.value * scale);
    let (oa, ob) = (offset(a), offset(b));
    if block.offsets[normal].is_some() {
        return Err(syntax(
            field,
            line,
            format!("{} is not an arc-centre word in the selected plane", offset_letters[normal]),
        ));
    }
    if oa.is_none() && ob.is_none() {
        return Err(syntax(field, line, "an arc needs R or centre words I/J/K"));
    }
    Ok(if modal.absolute_arc_centre {
        (oa.unwrap_or(start_a), ob.unwrap_or(start_b))
    } else {
        (start_a + oa.unwrap_or(0.0), start_b + ob.unwrap_or(0.0))
    })
}

/// Refuses an arc whose centre is its start, or whose end is off its circle by more than the
/// closure tolerance.
fn check_closure(
    centre: [f64; 2],
    start: [f64; 2],
    end: [f64; 2],
    line: usize,
    field: &str,
) -> Result<(), SolverError> {
    let ([centre_a, centre_b], [start_a, start_b], [end_a, end_b]) = (centre, start, end);
    let start_radius = (start_a - centre_a).hypot(start_b - centre_b);
    let end_radius = (end_a - centre_a).hypot(end_b - centre_b);
    if start_radius < 1e-9 {
        return Err(syntax(field, line, "arc centre coincides with its start"));
    }
    let tolerance = ARC_CLOSURE_MM.max(ARC_CLOSURE_RELATIVE * start_radius);
    if (end_radius - start_radius).abs() > tolerance {
        return Err(SolverError::new(
            ErrorCode::ArcNotClosed,
            format!(
                "line {line}: the arc does not close: radius {:.4} mm at the start but {:.4} mm at the end (tolerance {:.4} mm)",
                start_radius, end_radius, tolerance
            ),
        )
        .at(field));
    }
    Ok(())
}
