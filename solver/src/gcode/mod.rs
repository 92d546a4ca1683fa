//! G-code posts: turns a [`Toolpath`] into a complete program for a Fanuc-style control or
//! LinuxCNC (docs/spec/api.md, G-code conventions; docs/guide/gcode.md).
//!
//! Both dialects print every coordinate with 4 decimals in mm (never `-0.0000`), absolute mode,
//! feed per minute, and start with a safety line, the tool change with its length offset and the
//! spindle, and end with spindle stop and `M30`. They differ where the controls differ: the Fanuc
//! post wraps the program in `%` with an `O` number; the LinuxCNC post adds `G64 P` (path blending
//! held within the path tolerance). Both are accepted by LinuxCNC's `rs274` interpreter.

pub mod job;
pub mod reader;

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::control::Control;
use crate::error::SolverError;
use crate::geometry::Vec3;
use crate::path::{Motion, Toolpath};

/// The control the program is written for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Dialect {
    /// Fanuc-style controls (also Haas, Okuma in G-code mode, ...): `%`, `O` number.
    #[default]
    Fanuc,
    /// LinuxCNC (rs274ngc): adds `G64 P` blending tolerance.
    Linuxcnc,
}

/// How circular moves are written: as the control's own circular interpolation or as
/// straight chords.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Arcs {
    /// G01 chords within the capability's tolerance (and the block-time rule with a block time):
    /// what every control runs.
    #[default]
    Chords,
    /// G02/G03 in the XY plane (G17) with the centre as I/J relative to the start (both
    /// dialects: incremental I/J is Fanuc's and LinuxCNC's default); the end point is the chord
    /// version's last point. Curves that are not circular (ellipses, NURBS, polylines) stay chords.
    G2g3,
}

impl Arcs {
    /// The name used in comments and JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Chords => "chords",
            Self::G2g3 => "g2g3",
        }
    }
}

/// Which point of the tool the program coordinates describe.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Reference {
    /// The tool tip (lowest point along the tool axis); the length offset is measured to the tip.
    #[default]
    Tip,
    /// The ball centre (or the centre of the end's rounding); the length offset is measured to it.
    Centre,
}

impl Reference {
    /// The name used in comments and JSON.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Tip => "tip",
            Self::Centre => "centre",
        }
    }
}

/// How the program selects its tool.
#[derive(Debug, Clone, PartialEq)]
pub enum ToolCall {
    /// A tool from the machine's table: `T n M06` and length offset `H n`.
    Table(u32),
    /// A tool given inline, unknown to the control: the program stops (`M00`) and asks the
    /// operator to load it and activate its length offset.
    Manual(String),
}

impl ToolCall {
    /// The call for `tool`: from the table when it has a number, otherwise a manual change.
    pub fn for_tool(tool: &crate::tool::Tool) -> Self {
        match tool.number {
            Some(number) => Self::Table(number),
            None => Self::Manual(format!("{} R{}", tool.kind.as_str(), mm(tool.radius))),
        }
    }
}

/// How a caller wants a capability's program written: every `program(answer, &Post)` takes one.
#[derive(Debug, Clone, PartialEq)]
pub struct Post {
    /// Control dialect.
    pub dialect: Dialect,
    /// Programmed point: tip or centre.
    pub reference: Reference,
    /// Tool selection.
    pub tool: ToolCall,
    /// Circular moves as G02/G03 or as chords.
    pub arcs: Arcs,
    /// Feed of plunges, mm/min (the tool's, else the machine's); `None`: a fraction
    /// [`DEFAULT_PLUNGE_FRACTION`] of the cutting feed.
    pub plunge_feed: Option<f64>,
}

/// A plunge runs at this fraction of the cutting feed when neither tool nor machine gives a
/// `plunge_feed` (never a plunge at the cutting feed).
pub const DEFAULT_PLUNGE_FRACTION: f64 = 0.5;

/// The feed of a plunge after cutting at `feed`: `plunge_feed` when slower, else
/// [`DEFAULT_PLUNGE_FRACTION`] of `feed`.
pub fn plunge_feed(feed: f64, plunge_feed: Option<f64>) -> f64 {
    plunge_feed.map_or(feed * DEFAULT_PLUNGE_FRACTION, |plunge| plunge.min(feed))
}

impl Post {
    /// A post writing arcs as chords (the default of every option but the tool).
    pub fn new(dialect: Dialect, reference: Reference, tool: ToolCall) -> Self {
        Self { dialect, reference, tool, arcs: Arcs::Chords, plunge_feed: None }
    }
}

/// Everything the post needs besides the path.
#[derive(Debug, Clone)]
pub struct Program<'a> {
    /// Dialect to write.
    pub dialect: Dialect,
    /// Program number for the Fanuc `O` word (1–9999).
    pub number: u32,
    /// Short title, e.g. `KERF DEBURR`.
    pub title: &'a str,
    /// Header comment lines naming the job parameters.
    pub comments: Vec<String>,
    /// The tool.
    pub tool: ToolCall,
    /// Spindle speed, rpm.
    pub spindle_rpm: f64,
    /// Spindle rotation (M03 or M04).
    pub spindle_direction: SpindleDirection,
    /// Z of the clearance plane the program starts and ends at.
    pub safe_z: f64,
    /// Path blending tolerance for LinuxCNC's `G64 P`, mm.
    pub blend_tolerance: f64,
    /// Plunges (straight feed moves straight down: X and Y unchanged, Z lower) run at
    /// [`plunge_feed`] of their feed with this value; `None`: at their own feed (the capability
    /// made sure they run in air).
    pub plunges: Option<Plunges>,
    /// The moves; the first should start from the clearance plane.
    pub path: &'a Toolpath,
}

/// How a program slows its plunges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plunges {
    /// The tool's or machine's plunge feed, mm/min.
    pub feed: Option<f64>,
}

/// Spindle rotation seen from the spindle, looking down the tool at the workpiece.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum SpindleDirection {
    /// M03, clockwise: a right-hand cutter cuts.
    #[default]
    Cw,
    /// M04, counter-clockwise.
    Ccw,
}

impl SpindleDirection {
    /// The M code that starts the spindle this way.
    pub fn m_code(self) -> &'static str {
        match self {
            Self::Cw => "M03",
            Self::Ccw => "M04",
        }
    }
}

/// A coordinate or value in mm with 4 decimals, never printed as `-0.0000`.
pub fn mm(value: f64) -> String {
    let text = format!("{value:.4}");
    if text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.') { text[1..].to_owned() } else { text }
}

/// A comment safe for both dialects: upper case, no parentheses or control characters.
pub fn comment(text: &str) -> String {
    let cleaned: String = text
        .chars()
        .map(|c| if c == '(' || c == ')' || c.is_control() || !c.is_ascii() { ' ' } else { c.to_ascii_uppercase() })
        .collect();
    format!("({})", cleaned.trim())
}

/// A stop in the middle of a program (a deburr of both edges whose inside needs another
/// tool, or of holes on both sides of a tube): before move `before` of the path the spindle
/// stops and the tool goes up to the clearance plane; the program stops for the operator with a
/// notice (`M00`) if there is one, changes the tool with its length offset if there is one, and
/// starts the spindle again.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgramStop {
    /// The index of the move the stop comes before.
    pub before: usize,
    /// What the operator does at an `M00` (turn the part), if anything.
    pub notice: Option<String>,
    /// The new tool, if it changes.
    pub tool: Option<ToolCall>,
    /// The spindle speed after it, rpm (the direction stays the program's).
    pub spindle_rpm: f64,
}

/// Writes the tool call of `tool` with its length offset at `safe_z`.
fn write_tool_call(out: &mut String, tool: &ToolCall, safe_z: f64) {
    match tool {
        ToolCall::Table(number) => {
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

/// Writes the whole program.
pub fn write(program: &Program<'_>) -> String {
    write_changing(program, &[])
}

/// Writes the whole program with stops in it (`stops` in the order of their moves); each is
/// `M05`, `G00 Z` to the clearance plane, the notice as a comment with `M00`, the tool call as at
/// the start, and the spindle line. Without stops, [`fn@write`].
pub fn write_changing(program: &Program<'_>, stops: &[ProgramStop]) -> String {
    let Ok(text) = write_checking(program, stops, || Ok::<(), std::convert::Infallible>(()));
    text
}

/// [`write_changing`] that stops with `E_CANCELLED` once `control`'s cancel flag is set (checked
/// every [`MOVES_PER_CHECK`] moves), so a program of millions of moves that no one waits for any
/// more does not keep its solver slot.
///
/// # Errors
/// `E_CANCELLED` when cancelled.
pub fn write_cancellable(
    program: &Program<'_>,
    stops: &[ProgramStop],
    control: Control<'_>,
) -> Result<String, SolverError> {
    write_checking(program, stops, || control.check())
}

/// Moves written between two cancel checks (about a millisecond of writing).
pub const MOVES_PER_CHECK: usize = 1024;

fn write_checking<E>(
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
        let _ = writeln!(out, "G64 P{}", mm(program.blend_tolerance));
    }
    write_tool_call(&mut out, &program.tool, program.safe_z);
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
                write_tool_call(&mut out, tool, program.safe_z);
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
                    (Some(plunges), Some(from)) if is_plunge(from, step.to) => plunge_feed(feed, plunges.feed),
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
fn is_plunge(from: Vec3, to: Vec3) -> bool {
    to.z < from.z - 1e-9 && (to.x - from.x).abs() <= 1e-9 && (to.y - from.y).abs() <= 1e-9
}

/// Feed word value: whole mm/min where exact, else one decimal.
fn feed_word(feed: f64) -> String {
    if feed.fract() == 0.0 { format!("{feed:.0}") } else { format!("{feed:.1}") }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mm_never_prints_negative_zero() {
        assert_eq!(mm(-0.00001), "0.0000");
        assert_eq!(mm(-0.0), "0.0000");
        assert_eq!(mm(-1.23456), "-1.2346");
        assert_eq!(mm(12.0), "12.0000");
    }

    #[test]
    fn comments_cannot_break_out() {
        assert_eq!(comment("a (b) c"), "(A  B  C)");
        assert_eq!(comment("ø3\nx"), "(3 X)");
    }

    #[test]
    fn program_has_prologue_moves_and_epilogue() {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(1.0, 2.0, 50.0));
        path.linear(Vec3::new(1.0, 2.0, 3.0), 300.0);
        path.linear(Vec3::new(2.0, 2.0, 3.0), 300.0);
        path.rapid(Vec3::new(2.0, 2.0, 50.0));
        let program = Program {
            dialect: Dialect::Fanuc,
            number: 1000,
            title: "kerf test",
            comments: vec!["tool t7".to_owned()],
            tool: ToolCall::Table(7),
            spindle_rpm: 6000.0,
            spindle_direction: SpindleDirection::Cw,
            safe_z: 50.0,
            blend_tolerance: 0.01,
            plunges: None,
            path: &path,
        };
        let fanuc = write(&program);
        assert!(fanuc.starts_with("%\nO1000 (KERF TEST)\n(TOOL T7)\nG21"));
        assert!(fanuc.contains("T7 M06\nG00 G43 H7 Z50.0000\nS6000 M03\n"));
        assert!(fanuc.contains("G01 X1.0000 Y2.0000 Z3.0000 F300\nG01 X2.0000 Y2.0000 Z3.0000\n"));
        assert!(fanuc.ends_with("M05\nG00 Z50.0000\nM30\n%\n"));
        let linuxcnc = write(&Program { dialect: Dialect::Linuxcnc, ..program });
        assert!(linuxcnc.starts_with("(KERF TEST)\n"));
        assert!(linuxcnc.contains("G64 P0.0100\n"));
        assert!(!linuxcnc.contains('%'));
    }

    #[test]
    fn arcs_are_written_with_i_j_from_their_start() {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(10.0, 0.0, 5.0));
        path.linear(Vec3::new(10.0, 0.0, -1.0), 100.0);
        // A full turn counter-clockwise: two half turns, the last ending exactly at the end.
        let centre = Vec3::new(0.0, 0.0, -1.0);
        path.arc_sweep(Vec3::new(10.0, 0.0, -1.0), Vec3::new(10.0, 0.0, -1.0), centre, std::f64::consts::TAU, 400.0);
        // A degenerate arc (end = start) is a straight move, never a full circle.
        path.arc(Vec3::new(10.0, 0.0, -1.0), centre, true, 400.0);
        let program = Program {
            dialect: Dialect::Linuxcnc,
            number: 1000,
            title: "arcs",
            comments: Vec::new(),
            tool: ToolCall::Table(1),
            spindle_rpm: 1000.0,
            spindle_direction: SpindleDirection::Cw,
            safe_z: 5.0,
            blend_tolerance: 0.01,
            plunges: None,
            path: &path,
        };
        let text = write(&program);
        assert!(
            text.contains(
                "G01 X10.0000 Y0.0000 Z-1.0000 F100\n\
                 G03 X-10.0000 Y0.0000 Z-1.0000 I-10.0000 J0.0000 F400\n\
                 G03 X10.0000 Y0.0000 Z-1.0000 I10.0000 J0.0000\n\
                 G01 X10.0000 Y0.0000 Z-1.0000\n"
            ),
            "{text}"
        );
    }
}
