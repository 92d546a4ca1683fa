//! Reading G-code programs into typed moves with their source line numbers and modal state, and
//! rewriting a program with new coordinates while keeping everything else byte for byte
//! (docs/spec/predict.md §8 corrected G-code; docs/spec/engagement.md §11 G-code import).
//!
//! The reader understands the RS274/Fanuc subset that CAM posts emit for 3-axis milling: `G0`
//! `G1` `G2` `G3` (arcs by `I J K` or `R`, helical arcs, LinuxCNC's `P` turns), `G17` `G18` `G19`,
//! `G20` `G21`, `G90` `G91`, `G90.1` `G91.1`, `G94` `G95`, `F`, `S`, `T`, `M3` `M4` `M5` `M6`,
//! `N` numbers, comments `( )` and `;`, `%` delimiter lines, and block delete `/`. Non-geometric
//! codes (work offsets, length offsets, path-control and look-ahead modes, coolant, dwell) are
//! accepted and ignored. Codes that would change the geometry in ways this reader cannot follow
//! (cutter compensation, canned cycles, coordinate shifts and rotations, scaling, polar and
//! inverse-time modes, sub-programs, macros, rotary axes) are refused with `E_GCODE_UNSUPPORTED`
//! and the line number, rather than silently misread.
//!
//! Conventions, chosen to match LinuxCNC (`rs274`):
//! * a number without a decimal point is in whole units (`X10` is 10 mm, not 10 µm);
//! * inch programs (`G20`) are converted: every length in a [`ReadMove`] is in mm and every feed
//!   in mm/min, whatever units the line was written in; the rewrite writes back in the line's units;
//! * `G28`/`G30`/`G53` moves and tool changes leave the position unknown until the program sets
//!   each axis again (moves from an unknown position have `from` = `None` on that axis);
//! * reading stops at `M2`/`M30` (later lines are kept for the rewrite but not interpreted);
//! * an arc whose end is not on its circle (radius at the end differs from the radius at the start
//!   by more than 0.002 mm and 0.1 %) is refused with `E_ARC_NOT_CLOSED`.
//!
//! Every error is a [`SolverError`] tied to the field the caller names (e.g. `path.program`), with
//! `line N:` at the start of its message.

mod arcs;
mod lexer;
mod modal;
mod rewrite;

pub use rewrite::{MoveEdit, rewrite, rewrite_cancellable};

use crate::control::Control;
use crate::error::ErrorCode;
use crate::error::SolverError;
use arcs::{ArcGeometry, arc_kind};
use lexer::{syntax, tokenize};
use modal::{Block, parse_block};

/// Millimetres per inch.
pub const MM_PER_INCH: f64 = 25.4;

/// Largest program accepted by default, in lines.
pub const DEFAULT_MAX_LINES: usize = 2_000_000;

/// Absolute part of the arc-closure tolerance, mm.
const ARC_CLOSURE_MM: f64 = 0.002;
/// Relative part of the arc-closure tolerance.
const ARC_CLOSURE_RELATIVE: f64 = 0.001;
/// Most full turns an arc may ask for with `P`.
const MAX_ARC_TURNS: u32 = 1000;
/// Most chords one arc may be split into.
const MAX_ARC_CHORDS: usize = 100_000;

/// Length units of a block.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Units {
    /// `G21`.
    Mm,
    /// `G20`.
    Inch,
}

impl Units {
    /// Millimetres per program unit.
    pub fn scale(self) -> f64 {
        match self {
            Self::Mm => 1.0,
            Self::Inch => MM_PER_INCH,
        }
    }
}

/// Arc plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plane {
    /// `G17`: arcs in XY, helix along Z, offsets `I J`.
    Xy,
    /// `G18`: arcs in ZX, helix along Y, offsets `K I`.
    Zx,
    /// `G19`: arcs in YZ, helix along X, offsets `J K`.
    Yz,
}

impl Plane {
    /// The two in-plane axes (0 = X, 1 = Y, 2 = Z) in the order that makes `G3` counter-clockwise
    /// (first × second = normal), and the normal axis.
    pub fn axes(self) -> (usize, usize, usize) {
        match self {
            Self::Xy => (0, 1, 2),
            Self::Zx => (2, 0, 1),
            Self::Yz => (1, 2, 0),
        }
    }
}

/// Absolute or incremental coordinates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Distance {
    /// `G90`.
    Absolute,
    /// `G91`.
    Incremental,
}

/// Spindle state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Spindle {
    /// `M5` (or never started).
    Off,
    /// `M3`: clockwise seen from above (from the spindle toward the tip).
    Clockwise,
    /// `M4`: counter-clockwise.
    CounterClockwise,
}

/// The modal state a move runs under.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Modal {
    /// Arc plane.
    pub plane: Plane,
    /// Units the line was written in (lengths in [`ReadMove`] are always mm).
    pub units: Units,
    /// Absolute or incremental axis words.
    pub distance: Distance,
    /// Arc centre words absolute (`G90.1`) instead of relative to the start (`G91.1`, default).
    pub absolute_arc_centre: bool,
    /// Feed in mm/min (`G95` feeds converted with the spindle speed), if programmed.
    pub feed: Option<f64>,
    /// Spindle speed in rpm, if programmed.
    pub spindle_rpm: Option<f64>,
    /// Spindle direction.
    pub spindle: Spindle,
    /// Tool number of the last `T` word, if any.
    pub tool: Option<u32>,
}

impl Default for Modal {
    fn default() -> Self {
        Self {
            plane: Plane::Xy,
            units: Units::Mm,
            distance: Distance::Absolute,
            absolute_arc_centre: false,
            feed: None,
            spindle_rpm: None,
            spindle: Spindle::Off,
            tool: None,
        }
    }
}

/// What kind of motion a move is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MoveKind {
    /// `G0`.
    Rapid,
    /// `G1`.
    Linear,
    /// `G2` (clockwise) or `G3`, seen from the positive end of the plane normal.
    Arc {
        /// Centre, mm, absolute; its normal-axis coordinate is that of the start.
        centre: [f64; 3],
        /// `G2`.
        clockwise: bool,
        /// Full turns beyond the first partial one (LinuxCNC `P` minus 1).
        extra_turns: u32,
    },
}

/// A point whose axes may still be unknown (before the program sets them).
pub type Position = [Option<f64>; 3];

/// Where a coordinate word sits in its source line (byte offsets of the number).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct WordSpan {
    start: usize,
    end: usize,
    decimals: usize,
}

/// The source-text anchors of one move, for the rewrite.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct MoveWords {
    axes: [Option<WordSpan>; 3],
    offsets: [Option<WordSpan>; 3],
    radius: Option<WordSpan>,
    /// Byte offset after the last word of the block (before any trailing comment): where
    /// missing coordinate words are inserted.
    insert_at: usize,
}

/// One motion block.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadMove {
    /// Source line, 1-based.
    pub line: usize,
    /// `N` number of the block, if any.
    pub block_number: Option<u64>,
    /// Rapid, linear or arc.
    pub kind: MoveKind,
    /// Start point, mm (axes still unknown are `None`).
    pub from: Position,
    /// End point, mm.
    pub to: Position,
    /// Modal state of the block.
    pub modal: Modal,
    pub(crate) words: MoveWords,
}

impl ReadMove {
    /// Start point when every axis is known.
    pub fn from_xyz(&self) -> Option<[f64; 3]> {
        known(&self.from)
    }

    /// End point when every axis is known.
    pub fn to_xyz(&self) -> Option<[f64; 3]> {
        known(&self.to)
    }

    /// The move as a polyline from its start: arcs are split into chords whose sagitta is at most
    /// `chord_tolerance` (mm); the last point is exactly `to`. Lines and rapids give `[to]`.
    /// `None` when the start or the end has an unknown axis.
    pub fn points(&self, chord_tolerance: f64) -> Option<Vec<[f64; 3]>> {
        let from = self.from_xyz()?;
        let to = self.to_xyz()?;
        let MoveKind::Arc { centre, clockwise, extra_turns } = self.kind else {
            return Some(vec![to]);
        };
        let (a, b, normal) = self.modal.plane.axes();
        let arc = ArcGeometry::new(from, to, centre, clockwise, extra_turns, (a, b));
        let tolerance = chord_tolerance.max(1e-9);
        let max_step =
            if arc.radius > tolerance { 2.0 * (1.0 - tolerance / arc.radius).acos() } else { std::f64::consts::PI };
        let chords = ((arc.sweep.abs() / max_step).ceil() as usize).clamp(1, MAX_ARC_CHORDS);
        let mut points = Vec::with_capacity(chords);
        for index in 1..chords {
            let fraction = index as f64 / chords as f64;
            let angle = arc.start_angle + arc.sweep * fraction;
            let mut point = [0.0; 3];
            point[a] = centre[a] + arc.radius * angle.cos();
            point[b] = centre[b] + arc.radius * angle.sin();
            point[normal] = from[normal] + (to[normal] - from[normal]) * fraction;
            points.push(point);
        }
        points.push(to);
        Some(points)
    }
}

fn known(p: &Position) -> Option<[f64; 3]> {
    Some([p[0]?, p[1]?, p[2]?])
}

/// Reader settings.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadOptions {
    /// Skip blocks starting with `/` (the control's block-delete switch on). Default: off, the
    /// blocks run.
    pub block_delete: bool,
    /// Refuse programs with more lines (`E_TOO_MANY_LINES`).
    pub max_lines: usize,
    /// Position before the first line, mm; axes left `None` are unknown until programmed.
    pub start: Position,
}

impl Default for ReadOptions {
    fn default() -> Self {
        Self { block_delete: false, max_lines: DEFAULT_MAX_LINES, start: [None; 3] }
    }
}

/// A program as read.
#[derive(Debug, Clone, PartialEq)]
pub struct ReadProgram {
    /// Every motion block in program order.
    pub moves: Vec<ReadMove>,
    /// Number of source lines.
    pub line_count: usize,
    /// Modal state after the last interpreted line.
    pub modal: Modal,
}

/// Reads a program. `field` names the request field the text came from, for errors.
///
/// # Errors
/// `E_GCODE_SYNTAX` (unparsable text), `E_GCODE_UNSUPPORTED`, `E_ARC_NOT_CLOSED`,
/// `E_ARC_RADIUS` (an `R` arc whose radius is shorter than half its chord),
/// `E_GCODE_POSITION` (an arc from a position the program never set) and `E_TOO_MANY_LINES`,
/// each with the line number in the message.
pub fn read(text: &str, field: &str, options: &ReadOptions) -> Result<ReadProgram, SolverError> {
    read_cancellable(text, field, options, Control::default())
}

/// [`read`] that stops with `E_CANCELLED` once `control`'s cancel flag is set (checked every
/// [`crate::gcode::MOVES_PER_CHECK`] lines: a program of millions of lines takes seconds).
///
/// # Errors
/// As [`read`]; `E_CANCELLED` when cancelled.
pub fn read_cancellable(
    text: &str,
    field: &str,
    options: &ReadOptions,
    control: Control<'_>,
) -> Result<ReadProgram, SolverError> {
    let mut reader = Reader {
        modal: Modal::default(),
        motion: None,
        feed_per_rev: false,
        feed_word: None,
        position: options.start,
        moves: Vec::new(),
    };
    let mut words = Vec::new();
    let mut line_count = 0;
    let mut ended = false;
    for (index, raw) in text.split('\n').enumerate() {
        let line_number = index + 1;
        line_count = line_number;
        if index % crate::gcode::MOVES_PER_CHECK == 0 {
            control.check()?;
        }
        if line_number > options.max_lines {
            return Err(SolverError::new(
                ErrorCode::TooManyLines,
                format!("the program has more than {} lines, the limit", options.max_lines),
            )
            .at(field));
        }
        if ended {
            continue;
        }
        let Some((code, offset)) = block_code(raw, options.block_delete) else {
            continue;
        };
        words.clear();
        let code_end = tokenize(code, line_number, field, &mut words)? + offset;
        for word in &mut words {
            word.span.start += offset;
            word.span.end += offset;
        }
        if words.is_empty() {
            continue;
        }
        let block = parse_block(&words, line_number, field)?;
        reader.set_modes(&block);
        reader.execute(&block, line_number, code_end, field)?;
        if block.end {
            ended = true;
        }
    }
    Ok(ReadProgram { moves: reader.moves, line_count, modal: reader.modal })
}

/// The part of a source line the control executes and its byte offset in the line: `None` for
/// `%` lines and, with block delete on, for blocks starting with `/`.
fn block_code(raw: &str, block_delete: bool) -> Option<(&str, usize)> {
    let line = raw.strip_suffix('\r').unwrap_or(raw);
    let trimmed = line.trim_start();
    if trimmed.starts_with('%') {
        return None;
    }
    let mut code = line;
    let mut offset = 0;
    if let Some(rest) = trimmed.strip_prefix('/') {
        if block_delete {
            return None;
        }
        offset = line.len() - rest.len();
        code = rest;
    }
    Some((code, offset))
}

/// The control's state as the program runs: modal state, motion mode, feed words and where the
/// tool is, and the moves so far.
struct Reader {
    modal: Modal,
    motion: Option<u32>,
    feed_per_rev: bool,
    /// The last `F` word, in mm (per minute, or per revolution under `G95`).
    feed_word: Option<f64>,
    position: Position,
    moves: Vec<ReadMove>,
}

impl Reader {
    /// The block's modal changes, which take effect before its motion (RS274 order of
    /// execution).
    fn set_modes(&mut self, block: &Block) {
        let modal = &mut self.modal;
        if let Some(units) = block.units {
            modal.units = units;
        }
        if let Some(plane) = block.plane {
            modal.plane = plane;
        }
        if let Some(distance) = block.distance {
            modal.distance = distance;
        }
        if let Some(absolute) = block.arc_centre_absolute {
            modal.absolute_arc_centre = absolute;
        }
        if let Some(per_rev) = block.feed_per_rev {
            self.feed_per_rev = per_rev;
        }
        if let Some(rpm) = block.spindle_rpm {
            modal.spindle_rpm = Some(rpm);
        }
        if let Some(feed) = block.feed {
            self.feed_word = Some(feed * modal.units.scale());
        }
        modal.feed = if self.feed_per_rev {
            match (self.feed_word, modal.spindle_rpm) {
                (Some(per_rev), Some(rpm)) => Some(per_rev * rpm),
                _ => None,
            }
        } else {
            self.feed_word
        };
        if let Some(tool) = block.tool {
            modal.tool = Some(tool);
        }
        if let Some(spindle) = block.spindle {
            modal.spindle = spindle;
        }
        if block.tool_change {
            self.position = [None; 3];
        }
        if let Some(code) = block.motion {
            self.motion = Some(code);
        }
    }

    /// The block's motion: a move in the current motion mode, or a home return or machine-
    /// coordinate move that leaves axes unknown.
    fn execute(&mut self, block: &Block, line_number: usize, code_end: usize, field: &str) -> Result<(), SolverError> {
        let has_axes = block.axes.iter().any(Option::is_some);
        match block.non_modal {
            Some(40 | 100) => {}
            Some(280 | 300) => {
                // Through the intermediate point (if any) to the reference point: unknown here.
                self.position = [None; 3];
            }
            Some(530) => {
                // Machine coordinates: the end is unknown in work coordinates.
                for (axis, word) in self.position.iter_mut().zip(&block.axes) {
                    if word.is_some() {
                        *axis = None;
                    }
                }
            }
            Some(_) | None if has_axes || matches!(block.motion, Some(20 | 30)) => {
                self.motion_move(block, line_number, code_end, field)?;
            }
            Some(_) | None => {}
        }
        Ok(())
    }

    /// A move in the current motion mode to the block's axis words.
    fn motion_move(
        &mut self,
        block: &Block,
        line_number: usize,
        code_end: usize,
        field: &str,
    ) -> Result<(), SolverError> {
        let modal = self.modal;
        let position = self.position;
        let Some(code) = self.motion else {
            return Err(syntax(field, line_number, "axis words without a motion mode (G0, G1, G2 or G3)"));
        };
        if code == 800 {
            return Err(syntax(field, line_number, "axis words while the motion mode is cancelled (G80)"));
        }
        let to = target(block, &modal, &position);
        let kind = match code {
            0 => MoveKind::Rapid,
            10 => MoveKind::Linear,
            _ => arc_kind(block, &modal, &position, &to, code == 20, line_number, field)?,
        };
        // Missing axis words go right after the block's last axis word.
        let insert_at = block.axes.iter().flatten().map(|w| w.span.end).max().unwrap_or(code_end);
        let words = MoveWords {
            axes: block.axes.map(|w| w.map(|w| w.span)),
            offsets: block.offsets.map(|w| w.map(|w| w.span)),
            radius: block.radius.map(|w| w.span),
            insert_at,
        };
        self.moves.push(ReadMove {
            line: line_number,
            block_number: block.block_number,
            kind,
            from: position,
            to,
            modal,
            words,
        });
        self.position = to;
        Ok(())
    }
}

/// Where the block's axis words take the tool from `position`, in mm: absolute words set their
/// axis, incremental ones add to it (an unknown axis stays unknown).
fn target(block: &Block, modal: &Modal, position: &Position) -> Position {
    let scale = modal.units.scale();
    let mut to = *position;
    for axis in 0..3 {
        if let Some(word) = block.axes[axis] {
            let value = word.value * scale;
            to[axis] = match modal.distance {
                Distance::Absolute => Some(value),
                Distance::Incremental => position[axis].map(|p| p + value),
            };
        }
    }
    to
}

#[cfg(test)]
mod tests;
