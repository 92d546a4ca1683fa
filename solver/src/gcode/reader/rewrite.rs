//! Rewriting a program with new end points (and arc centres) while keeping everything else byte for
//! byte (docs/spec/predict.md §8 corrected G-code: same format, line numbers, comments and modal
//! state; only coordinates change).

use std::fmt::Write as _;

use super::{Distance, MoveKind, Position, ReadMove, ReadProgram, WordSpan, known};
use crate::control::Control;
use crate::error::SolverError;

/// New geometry for one move of a [`ReadProgram`], in mm, absolute.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveEdit {
    /// Index of the move in [`ReadProgram::moves`].
    pub index: usize,
    /// New end point.
    pub to: [f64; 3],
    /// For arcs: the wanted centre (its in-plane part is used). The centre written is the point
    /// of the new chord's perpendicular bisector nearest to it, so the arc always closes. `None`
    /// keeps the original centre as nearly as the new end points allow.
    pub centre: Option<[f64; 3]>,
}

/// Writes `text` again with the moves' end points (and arc centres) replaced by `edits`.
///
/// Everything else stays byte for byte: line count, block numbers, comments, modal words and the
/// coordinates of unchanged moves. A changed coordinate is written in the line's units with at
/// least 4 decimals (more if the line had more); a changed axis the line did not program is
/// inserted after the block's last word. Incremental (`G91`) feed blocks get new increments so
/// every later end point stays where it was. Rapids without an edit are never rewritten, so the
/// program's air moves stay as its post wrote them: after a moved cut they start, and in the axes
/// they do not program end, where that cut ended; the next feed move is written to its own end
/// point from there. `program` must be the
/// result of [`super::read`] on `text`.
///
/// # Errors
/// `E_INPUT` for an edit that names no move, or a non-finite coordinate.
pub fn rewrite(text: &str, program: &ReadProgram, edits: &[MoveEdit], field: &str) -> Result<String, SolverError> {
    rewrite_cancellable(text, program, edits, field, Control::default())
}

/// [`rewrite`] that stops with `E_CANCELLED` once `control`'s cancel flag is set (checked every
/// [`crate::gcode::MOVES_PER_CHECK`] moves).
///
/// # Errors
/// As [`rewrite`]; `E_CANCELLED` when cancelled.
pub fn rewrite_cancellable(
    text: &str,
    program: &ReadProgram,
    edits: &[MoveEdit],
    field: &str,
    control: Control<'_>,
) -> Result<String, SolverError> {
    let count = program.moves.len();
    let targets = Targets::of(program, edits, field)?;
    // Where each move of the rewritten program really ends (written values are rounded), so
    // incremental words and modal axes follow the control, not the exact edits.
    let mut actual: Vec<Position> = Vec::with_capacity(count);
    let mut replacements: Vec<LineEdit> = Vec::new();
    for (index, read_move) in program.moves.iter().enumerate() {
        if index % crate::gcode::MOVES_PER_CHECK == 0 {
            control.check()?;
        }
        let continuous = index > 0 && program.moves[index - 1].to == read_move.from;
        let start = if continuous { actual[index - 1] } else { read_move.from };
        if start == read_move.from && targets.to[index] == read_move.to && targets.centres[index].is_none() {
            actual.push(read_move.to);
            continue;
        }
        // A rapid nobody edited stays as written, byte for byte: after a moved cut
        // it starts elsewhere, so the axes it does not program (absolute) or all of them
        // (incremental) end shifted with its start; the next cutting move is rewritten to its
        // own end point from there.
        if read_move.kind == MoveKind::Rapid && !targets.edited[index] {
            actual.push(shifted_rapid(read_move, &start));
            continue;
        }
        let (end_actual, edit) = rewrite_move(read_move, &start, &targets.to[index], targets.centres[index]);
        actual.push(end_actual);
        replacements.extend(edit);
    }
    Ok(apply(text, &replacements))
}

/// Per move of the program: its wanted end, wanted arc centre and whether an edit names it.
struct Targets {
    to: Vec<Position>,
    centres: Vec<Option<[f64; 3]>>,
    edited: Vec<bool>,
}

impl Targets {
    /// The edits laid over the program's own end points.
    ///
    /// # Errors
    /// `E_INPUT` for an edit that names no move, or a non-finite coordinate.
    fn of(program: &ReadProgram, edits: &[MoveEdit], field: &str) -> Result<Self, SolverError> {
        let count = program.moves.len();
        let mut new_to: Vec<Position> = program.moves.iter().map(|m| m.to).collect();
        let mut centres: Vec<Option<[f64; 3]>> = vec![None; count];
        let mut edited = vec![false; count];
        for edit in edits {
            if edit.index >= count {
                return Err(SolverError::input(field, format!("edit names move {} of {count}", edit.index)));
            }
            if edit.to.iter().chain(edit.centre.iter().flatten()).any(|v| !v.is_finite()) {
                return Err(SolverError::input(field, "an edited coordinate is not finite"));
            }
            new_to[edit.index] = edit.to.map(Some);
            centres[edit.index] = edit.centre;
            edited[edit.index] = true;
        }
        Ok(Self { to: new_to, centres, edited })
    }
}

/// Where an unedited rapid ends when it starts at `start`: the axes it programs absolutely stay,
/// the others move with its start.
fn shifted_rapid(read_move: &ReadMove, start: &Position) -> Position {
    std::array::from_fn(|axis| match read_move.modal.distance {
        Distance::Absolute if read_move.words.axes[axis].is_some() => read_move.to[axis],
        _ => match (start[axis], read_move.from[axis], read_move.to[axis]) {
            (Some(now), Some(before), Some(end)) => Some(now + (end - before)),
            (_, _, end) => end,
        },
    })
}

/// The words of one move from `start` to `new_to` (and for arcs its centre words): where the
/// move really ends as written, and the line's changes if any.
fn rewrite_move(
    read_move: &ReadMove,
    start: &Position,
    new_to: &Position,
    wanted_centre: Option<[f64; 3]>,
) -> (Position, Option<LineEdit>) {
    let scale = read_move.modal.units.scale();
    let mut end_actual = read_move.to;
    let mut changes: Vec<(WordSpan, String)> = Vec::new();
    let mut inserts: Vec<String> = Vec::new();
    let letters = ['X', 'Y', 'Z'];
    for axis in 0..3 {
        let (Some(end), Some(old_end)) = (new_to[axis], read_move.to[axis]) else {
            continue;
        };
        let span = read_move.words.axes[axis];
        let decimals = span.map_or(4, |s| s.decimals.max(4));
        // The value to write, what the line means now (kept), and where the axis lands if
        // written.
        let (value, kept_value, base) = match read_move.modal.distance {
            Distance::Absolute => match (span, start[axis]) {
                // A word the line does not have leaves the axis where the move starts.
                (None, Some(from)) => (end / scale, from / scale, 0.0),
                (None, None) => continue,
                (Some(_), _) => (end / scale, old_end / scale, 0.0),
            },
            Distance::Incremental => {
                let (Some(from), Some(old_from)) = (start[axis], read_move.from[axis]) else {
                    continue;
                };
                ((end - from) / scale, (old_end - old_from) / scale, from)
            }
        };
        let written = number(value, decimals);
        if written == number(kept_value, decimals) {
            end_actual[axis] = Some(base + kept_value * scale);
            continue;
        }
        end_actual[axis] = Some(base + written.parse::<f64>().unwrap_or(value) * scale);
        match span {
            Some(span) => changes.push((span, written)),
            None => inserts.push(format!("{}{written}", letters[axis])),
        }
    }
    if let MoveKind::Arc { centre, clockwise, .. } = read_move.kind
        && let (Some(from), Some(to)) = (known(start), known(&end_actual))
    {
        arc_words(read_move, from, to, wanted_centre.unwrap_or(centre), clockwise, &mut changes, &mut inserts);
    }
    let edit = (!changes.is_empty() || !inserts.is_empty()).then_some(LineEdit {
        line: read_move.line,
        changes,
        inserts,
        insert_at: read_move.words.insert_at,
    });
    (end_actual, edit)
}

/// `text` with the line edits (in line order) applied; other lines byte for byte.
fn apply(text: &str, replacements: &[LineEdit]) -> String {
    let mut out = String::with_capacity(text.len() + replacements.len() * 8);
    let mut pending = replacements.iter().peekable();
    for (index, raw) in text.split('\n').enumerate() {
        if index > 0 {
            out.push('\n');
        }
        let line_number = index + 1;
        let mut line_changes: Vec<(usize, usize, String)> = Vec::new();
        while let Some(edit) = pending.peek() {
            if edit.line != line_number {
                break;
            }
            for (span, written) in &edit.changes {
                line_changes.push((span.start, span.end, written.clone()));
            }
            if !edit.inserts.is_empty() {
                let at = edit.insert_at;
                let mut inserted = String::new();
                for word in &edit.inserts {
                    let _ = write!(inserted, " {word}");
                }
                line_changes.push((at, at, inserted));
            }
            pending.next();
        }
        if line_changes.is_empty() {
            out.push_str(raw);
            continue;
        }
        line_changes.sort_by_key(|(start, _, _)| *start);
        let mut cursor = 0;
        for (start, end, written) in line_changes {
            if start < cursor || end > raw.len() {
                continue;
            }
            out.push_str(&raw[cursor..start]);
            out.push_str(&written);
            cursor = end;
        }
        out.push_str(&raw[cursor..]);
    }
    out
}

/// The text changes of one rewritten line.
pub(super) struct LineEdit {
    line: usize,
    changes: Vec<(WordSpan, String)>,
    inserts: Vec<String>,
    insert_at: usize,
}

/// New centre words for an arc whose ends moved: the centre is put on the new chord's
/// perpendicular bisector, nearest to `wanted`, so the arc closes exactly.
pub(super) fn arc_words(
    read_move: &ReadMove,
    from: [f64; 3],
    to: [f64; 3],
    wanted: [f64; 3],
    clockwise: bool,
    changes: &mut Vec<(WordSpan, String)>,
    inserts: &mut Vec<String>,
) {
    let (a, b, _) = read_move.modal.plane.axes();
    let (mid_a, mid_b) = ((from[a] + to[a]) / 2.0, (from[b] + to[b]) / 2.0);
    let (chord_a, chord_b) = (to[a] - from[a], to[b] - from[b]);
    let chord = chord_a.hypot(chord_b);
    let (centre_a, centre_b) = if chord < 1e-12 {
        (wanted[a], wanted[b])
    } else {
        // Bisector direction: the chord turned by +90°.
        let (dir_a, dir_b) = (-chord_b / chord, chord_a / chord);
        let along = (wanted[a] - mid_a) * dir_a + (wanted[b] - mid_b) * dir_b;
        (mid_a + along * dir_a, mid_b + along * dir_b)
    };
    let scale = read_move.modal.units.scale();
    let words = &read_move.words;
    let (MoveKind::Arc { centre: old_centre, .. }, Some(old_from)) = (read_move.kind, read_move.from_xyz()) else {
        return;
    };
    if let Some(span) = words.radius {
        let radius = (from[a] - centre_a).hypot(from[b] - centre_b);
        // Keep the long/short choice of the original R sign.
        let cross = chord_a * (centre_b - from[b]) - chord_b * (centre_a - from[a]);
        let left = cross > 0.0;
        let signed = if left != clockwise { radius } else { -radius };
        let decimals = span.decimals.max(4);
        let old_radius = (old_from[a] - old_centre[a]).hypot(old_from[b] - old_centre[b]);
        let written = number(signed / scale, decimals);
        if written.trim_start_matches('-') != number(old_radius / scale, decimals) {
            changes.push((span, written));
        }
        return;
    }
    let letters = ['I', 'J', 'K'];
    for (axis, centre) in [(a, centre_a), (b, centre_b)] {
        let value = if read_move.modal.absolute_arc_centre { centre } else { centre - from[axis] } / scale;
        let span = words.offsets[axis];
        let decimals = span.map_or(4, |s| s.decimals.max(4));
        let written = number(value, decimals);
        let old_value =
            if read_move.modal.absolute_arc_centre { old_centre[axis] } else { old_centre[axis] - old_from[axis] }
                / scale;
        if written == number(old_value, decimals) {
            continue;
        }
        match span {
            Some(span) => changes.push((span, written)),
            None => inserts.push(format!("{}{written}", letters[axis])),
        }
    }
}

/// A value with `decimals` decimals, never `-0.000…`.
pub(super) fn number(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    if text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.') { text[1..].to_owned() } else { text }
}
