//! The writer as it was before programs were written into one buffer from scaled integers: a
//! `String` per number through `format!("{:.4}")`. Under test, every Fanuc and LinuxCNC program
//! the solver's unit tests write is written by it too and must be the same text byte for byte
//! ([`check`]); [`every_capability_writes_as_before`] writes each capability's example program
//! both ways.

use std::cell::Cell;
use std::fmt::Write as _;

use super::{Dialect, MOVES_PER_CHECK, Program, ProgramStop, ToolCall, plunge_feed};
use crate::geometry::Vec3;
use crate::path::Motion;

thread_local! {
    /// Programs this thread compared with the old writer.
    pub(crate) static COMPARED: Cell<usize> = const { Cell::new(0) };
}

/// Panics unless `written` is what the old writer writes for `program` (Fanuc and LinuxCNC in mm,
/// the posts and units it had).
pub(super) fn check(program: &Program<'_>, stops: &[ProgramStop], written: &str) {
    if !matches!(program.dialect, Dialect::Fanuc | Dialect::Linuxcnc) || program.units != crate::units::Units::Mm {
        return;
    }
    let Ok(old) = old_write_checking(program, stops, || Ok::<(), std::convert::Infallible>(()));
    if old != written {
        let line = old.lines().zip(written.lines()).position(|(a, b)| a != b).unwrap_or(0);
        panic!(
            "the writer differs from the old one at line {}: old {:?}, new {:?}",
            line + 1,
            old.lines().nth(line),
            written.lines().nth(line)
        );
    }
    COMPARED.with(|count| count.set(count.get() + 1));
}

/// A coordinate or value in mm with 4 decimals, never printed as `-0.0000`.
fn mm(value: f64) -> String {
    let text = format!("{value:.4}");
    if text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.') { text[1..].to_owned() } else { text }
}

/// A comment safe for both dialects: upper case, no parentheses or control characters.
fn comment(text: &str) -> String {
    let cleaned: String = text
        .chars()
        .map(|c| if c == '(' || c == ')' || c.is_control() || !c.is_ascii() { ' ' } else { c.to_ascii_uppercase() })
        .collect();
    format!("({})", cleaned.trim())
}

/// Writes the tool call of `tool` with its length offset at `safe_z`.
fn old_tool_call(out: &mut String, tool: &ToolCall, safe_z: f64) {
    match tool {
        ToolCall::Table(number) | ToolCall::Named { number, .. } => {
            let _ = writeln!(out, "T{number} M06");
            let _ = writeln!(out, "G00 G43 H{number} Z{}", mm(safe_z));
        }
        ToolCall::Manual(description) => {
            let _ = writeln!(out, "{}", comment(&format!("TOOL NOT IN THE TOOL TABLE: {description}")));
            let _ = writeln!(out, "{}", comment("LOAD IT, ACTIVATE ITS LENGTH OFFSET, THEN CYCLE START"));
            out.push_str("M00\n");
            let _ = writeln!(out, "G00 Z{}", mm(safe_z));
        }
    }
}

fn old_write_checking<E>(
    program: &Program<'_>,
    stops: &[ProgramStop],
    mut check: impl FnMut() -> Result<(), E>,
) -> Result<String, E> {
    let mut out = String::with_capacity(64 + program.path.moves.len() * 40);
    let fanuc = program.dialect == Dialect::Fanuc;
    if fanuc {
        out.push_str("%\n");
        let _ = writeln!(out, "O{:04} {}", program.number, comment(program.title));
    } else {
        let _ = writeln!(out, "{}", comment(program.title));
    }
    for line in &program.comments {
        let _ = writeln!(out, "{}", comment(line));
    }
    out.push_str("G21 G17 G90 G40 G49 G80 G94\n");
    if !fanuc {
        // As the writer: never `G64 P0.0000`, which LinuxCNC reads as no tolerance at all.
        let _ = writeln!(out, "G64 P{}", mm(program.blend_tolerance.max(1e-4)));
    }
    old_tool_call(&mut out, &program.tool, program.safe_z);
    let _ = writeln!(out, "S{} {}", program.spindle_rpm.round(), program.spindle_direction.m_code());
    let mut current_feed: Option<f64> = None;
    let mut position: Option<Vec3> = None;
    let mut stops = stops.iter().peekable();
    for (index, step) in program.path.moves.iter().enumerate() {
        if index % MOVES_PER_CHECK == 0 {
            check()?;
        }
        while let Some(stop) = stops.next_if(|stop| stop.before <= index) {
            out.push_str("M05\n");
            let _ = writeln!(out, "G00 Z{}", mm(program.safe_z));
            if let Some(notice) = &stop.notice {
                let _ = writeln!(out, "{}", comment(notice));
                out.push_str("M00\n");
            }
            if let Some(tool) = &stop.tool {
                old_tool_call(&mut out, tool, program.safe_z);
            }
            let _ = writeln!(out, "S{} {}", stop.spindle_rpm.round(), program.spindle_direction.m_code());
            if let Some(at) = &mut position {
                at.z = program.safe_z;
            }
            // The first feed move after the change states its feed again.
            current_feed = None;
        }
        let (x, y, z) = (mm(step.to.x), mm(step.to.y), mm(step.to.z));
        let feed = match step.motion {
            Motion::Rapid => {
                let _ = writeln!(out, "G00 X{x} Y{y} Z{z}");
                position = Some(step.to);
                continue;
            }
            // An arc needs its start; a path never starts with one (the post writes a straight
            // move there rather than a wrong centre). An arc whose printed end is its printed
            // start would be a full circle on one control and nothing on another: written as the
            // straight move it is meant to be (producers split full circles).
            Motion::Arc { feed, centre, clockwise }
                if position.is_some_and(|start| mm(start.x) != x || mm(start.y) != y) =>
            {
                let start = position.unwrap_or_default();
                let word = if clockwise { "G02" } else { "G03" };
                let (i, j) = (mm(centre.x - start.x), mm(centre.y - start.y));
                let _ = write!(out, "{word} X{x} Y{y} Z{z} I{i} J{j}");
                feed
            }
            Motion::Linear { feed } | Motion::Arc { feed, .. } => {
                let _ = write!(out, "G01 X{x} Y{y} Z{z}");
                match (program.plunges, position) {
                    (Some(plunges), Some(from)) if old_is_plunge(from, step.to) => plunge_feed(feed, plunges.feed),
                    _ => feed,
                }
            }
        };
        if current_feed == Some(feed) {
            out.push('\n');
        } else {
            let _ = writeln!(out, " F{}", feed_word(feed));
            current_feed = Some(feed);
        }
        position = Some(step.to);
    }
    out.push_str("M05\n");
    let _ = writeln!(out, "G00 Z{}", mm(program.safe_z));
    out.push_str("M30\n");
    if fanuc {
        out.push_str("%\n");
    }
    Ok(out)
}

/// Whether the straight move from `from` to `to` goes straight down the tool axis.
fn old_is_plunge(from: Vec3, to: Vec3) -> bool {
    to.z < from.z - 1e-9 && (to.x - from.x).abs() <= 1e-9 && (to.y - from.y).abs() <= 1e-9
}

/// Feed word value: whole mm/min where exact, else one decimal.
fn feed_word(feed: f64) -> String {
    if feed.fract() == 0.0 { format!("{feed:.0}") } else { format!("{feed:.1}") }
}
