//! Reading G-code programs into typed moves with their source line numbers and modal state, and
//! rewriting a program with new coordinates while keeping everything else byte for byte.
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

use std::fmt::Write as _;

use crate::error::SolverError;

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

/// Start angle, signed sweep and radius of an arc in its plane.
#[derive(Debug, Clone, Copy)]
struct ArcGeometry {
    radius: f64,
    start_angle: f64,
    sweep: f64,
}

impl ArcGeometry {
    fn new(
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

/// One word of a block: letter, value and where its number sits in the line.
#[derive(Debug, Clone, Copy)]
struct Word {
    letter: u8,
    value: f64,
    span: WordSpan,
}

/// Splits a line into `words` and returns the byte offset after the last word.
fn tokenize(line: &str, line_number: usize, field: &str, words: &mut Vec<Word>) -> Result<usize, SolverError> {
    let bytes = line.as_bytes();
    let mut index = 0;
    let mut code_end = 0;
    let fail = |message: String| syntax(field, line_number, message);
    while index < bytes.len() {
        let c = bytes[index];
        match c {
            b' ' | b'\t' => index += 1,
            b'(' => match line[index..].find(')') {
                Some(close) => index += close + 1,
                None => return Err(fail("comment opened with ( is not closed".to_owned())),
            },
            b';' => break,
            b'#' | b'[' | b'<' => {
                return Err(unsupported(
                    field,
                    line_number,
                    "parameters, expressions and named o-codes are not supported",
                ));
            }
            c if c.is_ascii_alphabetic() => {
                let letter = c.to_ascii_uppercase();
                index += 1;
                while index < bytes.len() && (bytes[index] == b' ' || bytes[index] == b'\t') {
                    index += 1;
                }
                let start = index;
                if index < bytes.len() && (bytes[index] == b'+' || bytes[index] == b'-') {
                    index += 1;
                }
                let mut digits = 0;
                let mut decimals = 0;
                let mut point = false;
                while index < bytes.len() {
                    match bytes[index] {
                        b'0'..=b'9' => {
                            digits += 1;
                            if point {
                                decimals += 1;
                            }
                        }
                        b'.' if !point => point = true,
                        _ => break,
                    }
                    index += 1;
                }
                if digits == 0 {
                    return Err(fail(format!("{} must be followed by a number", letter as char)));
                }
                let text = &line[start..index];
                let value: f64 = text.parse().map_err(|_| fail(format!("{}{text} is not a number", letter as char)))?;
                if !value.is_finite() {
                    return Err(fail(format!("{}{text} is out of range", letter as char)));
                }
                words.push(Word { letter, value, span: WordSpan { start, end: index, decimals } });
                code_end = index;
            }
            _ => {
                let shown: String = line[index..].chars().next().into_iter().collect();
                return Err(fail(format!("unexpected character '{shown}'")));
            }
        }
    }
    Ok(code_end)
}

fn syntax(field: &str, line: usize, message: impl std::fmt::Display) -> SolverError {
    SolverError::new("E_GCODE_SYNTAX", format!("line {line}: {message}")).at(field)
}

fn unsupported(field: &str, line: usize, message: impl std::fmt::Display) -> SolverError {
    SolverError::new("E_GCODE_UNSUPPORTED", format!("line {line}: {message}")).at(field)
}

/// A `G` code as tenths (`G90.1` is 901, `G1` is 10), so codes compare exactly.
fn g_tenths(value: f64) -> Option<u32> {
    let tenths = (value * 10.0).round();
    ((tenths - value * 10.0).abs() < 1e-6 && (0.0..100_000.0).contains(&tenths)).then_some(tenths as u32)
}

/// Modal groups of the `G` codes this reader knows, to refuse two codes of one group in a block.
fn g_group(code: u32) -> Option<u8> {
    match code {
        0 | 10 | 20 | 30 | 800 => Some(1),
        170 | 180 | 190 => Some(2),
        900 | 910 => Some(3),
        901 | 911 => Some(4),
        940 | 950 => Some(5),
        200 | 210 => Some(6),
        _ => None,
    }
}

/// Everything one block asks for, before it is executed.
#[derive(Debug, Default)]
struct Block {
    block_number: Option<u64>,
    motion: Option<u32>,
    plane: Option<Plane>,
    units: Option<Units>,
    distance: Option<Distance>,
    arc_centre_absolute: Option<bool>,
    feed_per_rev: Option<bool>,
    /// `G4`, `G10`, `G28`, `G30`, `G53`: axis words are not a move of the modal motion.
    non_modal: Option<u32>,
    axes: [Option<Word>; 3],
    offsets: [Option<Word>; 3],
    radius: Option<Word>,
    turns: Option<Word>,
    feed: Option<f64>,
    spindle_rpm: Option<f64>,
    tool: Option<u32>,
    spindle: Option<Spindle>,
    tool_change: bool,
    end: bool,
}

/// Reads a program. `field` names the request field the text came from, for errors.
///
/// # Errors
/// `E_GCODE_SYNTAX` (unparsable text), `E_GCODE_UNSUPPORTED`, `E_ARC_NOT_CLOSED`,
/// `E_ARC_RADIUS` (an `R` arc whose radius is shorter than half its chord),
/// `E_GCODE_POSITION` (an arc from a position the program never set) and `E_TOO_MANY_LINES`,
/// each with the line number in the message.
pub fn read(text: &str, field: &str, options: &ReadOptions) -> Result<ReadProgram, SolverError> {
    let mut modal = Modal::default();
    let mut motion: Option<u32> = None;
    let mut feed_per_rev = false;
    let mut feed_word: Option<f64> = None;
    let mut position: Position = options.start;
    let mut moves = Vec::new();
    let mut words = Vec::new();
    let mut line_count = 0;
    let mut ended = false;
    for (index, raw) in text.split('\n').enumerate() {
        let line_number = index + 1;
        line_count = line_number;
        if line_number > options.max_lines {
            return Err(SolverError::new(
                "E_TOO_MANY_LINES",
                format!("the program has more than {} lines, the limit", options.max_lines),
            )
            .at(field));
        }
        if ended {
            continue;
        }
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let trimmed = line.trim_start();
        if trimmed.starts_with('%') {
            continue;
        }
        let mut code = line;
        let mut offset = 0;
        if let Some(rest) = trimmed.strip_prefix('/') {
            if options.block_delete {
                continue;
            }
            offset = line.len() - rest.len();
            code = rest;
        }
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
        // Modal changes take effect before the block's motion (RS274 order of execution).
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
            feed_per_rev = per_rev;
        }
        if let Some(rpm) = block.spindle_rpm {
            modal.spindle_rpm = Some(rpm);
        }
        if let Some(feed) = block.feed {
            feed_word = Some(feed * modal.units.scale());
        }
        modal.feed = if feed_per_rev {
            match (feed_word, modal.spindle_rpm) {
                (Some(per_rev), Some(rpm)) => Some(per_rev * rpm),
                _ => None,
            }
        } else {
            feed_word
        };
        if let Some(tool) = block.tool {
            modal.tool = Some(tool);
        }
        if let Some(spindle) = block.spindle {
            modal.spindle = spindle;
        }
        if block.tool_change {
            position = [None; 3];
        }
        if let Some(code) = block.motion {
            motion = Some(code);
        }
        let has_axes = block.axes.iter().any(Option::is_some);
        let scale = modal.units.scale();
        let target = |position: &Position| -> Position {
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
        };
        match block.non_modal {
            Some(40 | 100) => {}
            Some(280 | 300) => {
                // Through the intermediate point (if any) to the reference point: unknown here.
                position = [None; 3];
            }
            Some(530) => {
                // Machine coordinates: the end is unknown in work coordinates.
                for (axis, word) in position.iter_mut().zip(&block.axes) {
                    if word.is_some() {
                        *axis = None;
                    }
                }
            }
            Some(_) | None if has_axes || matches!(block.motion, Some(20 | 30)) => {
                let Some(code) = motion else {
                    return Err(syntax(field, line_number, "axis words without a motion mode (G0, G1, G2 or G3)"));
                };
                if code == 800 {
                    return Err(syntax(field, line_number, "axis words while the motion mode is cancelled (G80)"));
                }
                let to = target(&position);
                let kind = match code {
                    0 => MoveKind::Rapid,
                    10 => MoveKind::Linear,
                    _ => arc_kind(&block, &modal, &position, &to, code == 20, line_number, field)?,
                };
                // Missing axis words go right after the block's last axis word.
                let insert_at = block.axes.iter().flatten().map(|w| w.span.end).max().unwrap_or(code_end);
                let words = MoveWords {
                    axes: block.axes.map(|w| w.map(|w| w.span)),
                    offsets: block.offsets.map(|w| w.map(|w| w.span)),
                    radius: block.radius.map(|w| w.span),
                    insert_at,
                };
                moves.push(ReadMove {
                    line: line_number,
                    block_number: block.block_number,
                    kind,
                    from: position,
                    to,
                    modal,
                    words,
                });
                position = to;
            }
            Some(_) | None => {}
        }
        if block.end {
            ended = true;
        }
    }
    Ok(ReadProgram { moves, line_count, modal })
}

fn parse_block(words: &[Word], line: usize, field: &str) -> Result<Block, SolverError> {
    let mut block = Block::default();
    let mut groups: Vec<u8> = Vec::new();
    let mut seen: [bool; 26] = [false; 26];
    for word in words {
        let letter = word.letter;
        let slot = usize::from(letter - b'A');
        let repeatable = matches!(letter, b'G' | b'M');
        if !repeatable {
            if seen[slot] {
                return Err(syntax(field, line, format!("{} appears twice in one block", letter as char)));
            }
            seen[slot] = true;
        }
        let value = word.value;
        match letter {
            b'G' => {
                let Some(code) = g_tenths(value) else {
                    return Err(syntax(field, line, format!("G{value} is not a G code")));
                };
                if let Some(group) = g_group(code) {
                    if groups.contains(&group) {
                        return Err(syntax(field, line, "two G codes of the same modal group in one block"));
                    }
                    groups.push(group);
                }
                apply_g(&mut block, code, line, field)?;
            }
            b'M' => {
                let Some(code) = g_tenths(value) else {
                    return Err(syntax(field, line, format!("M{value} is not an M code")));
                };
                match code {
                    30 => block.spindle = Some(Spindle::Clockwise),
                    40 => block.spindle = Some(Spindle::CounterClockwise),
                    50 => block.spindle = Some(Spindle::Off),
                    60 => block.tool_change = true,
                    20 | 300 => block.end = true,
                    970 | 980 | 990 => {
                        return Err(unsupported(field, line, "sub-program calls are not supported"));
                    }
                    // Stops, coolant and machine-specific M codes do not move the tool.
                    _ => {}
                }
            }
            b'X' | b'Y' | b'Z' => block.axes[usize::from(letter - b'X')] = Some(*word),
            b'I' | b'J' | b'K' => block.offsets[usize::from(letter - b'I')] = Some(*word),
            b'R' => block.radius = Some(*word),
            b'P' => block.turns = Some(*word),
            b'F' => {
                if value <= 0.0 {
                    return Err(syntax(field, line, format!("feed F{value} must be positive")));
                }
                block.feed = Some(value);
            }
            b'S' => {
                if value < 0.0 {
                    return Err(syntax(field, line, format!("spindle speed S{value} is negative")));
                }
                block.spindle_rpm = Some(value);
            }
            b'T' => {
                if value < 0.0 || value.fract() != 0.0 || value > f64::from(u32::MAX) {
                    return Err(syntax(field, line, format!("T{value} is not a tool number")));
                }
                block.tool = Some(value as u32);
            }
            b'N' => {
                if value < 0.0 || value.fract() != 0.0 || value > 1e15 {
                    return Err(syntax(field, line, format!("N{value} is not a block number")));
                }
                block.block_number = Some(value as u64);
            }
            b'O' => {}
            b'A' | b'B' | b'C' | b'U' | b'V' | b'W' => {
                return Err(unsupported(
                    field,
                    line,
                    format!("axis {} is not supported: only X, Y and Z", letter as char),
                ));
            }
            // H, D, Q, L, E: offsets and cycle data of codes that need no geometry here.
            _ => {}
        }
    }
    let non_modal_words = matches!(block.non_modal, Some(40 | 100));
    if non_modal_words {
        // G4 X is a dwell time, G10 words are table data: not axis moves.
        block.axes = [None; 3];
    }
    Ok(block)
}

fn apply_g(block: &mut Block, code: u32, line: usize, field: &str) -> Result<(), SolverError> {
    match code {
        0 | 10 | 20 | 30 | 800 => block.motion = Some(code),
        170 => block.plane = Some(Plane::Xy),
        180 => block.plane = Some(Plane::Zx),
        190 => block.plane = Some(Plane::Yz),
        200 => block.units = Some(Units::Inch),
        210 => block.units = Some(Units::Mm),
        900 => block.distance = Some(Distance::Absolute),
        910 => block.distance = Some(Distance::Incremental),
        901 => block.arc_centre_absolute = Some(true),
        911 => block.arc_centre_absolute = Some(false),
        940 => block.feed_per_rev = Some(false),
        950 => block.feed_per_rev = Some(true),
        40 | 100 | 280 | 300 | 530 => {
            if block.non_modal.is_some() {
                return Err(syntax(field, line, "two non-modal G codes in one block"));
            }
            block.non_modal = Some(code);
        }
        // Non-geometric: smoothing and look-ahead (G5, G5.1, G8), exact stop (G9), cutter
        // compensation off (G40), length offsets (G43, G43.4, G44, G49), work offsets (G54–G59,
        // G54.1), path control (G61, G61.1, G64), cancels (G15, G50, G69, G80), feed mode (G94),
        // cycle return levels (G98, G99), Haas smoothing (G187).
        50
        | 51
        | 80
        | 90
        | 150
        | 400
        | 430
        | 434
        | 440
        | 490
        | 500
        | 540..=590
        | 610
        | 611
        | 640
        | 690
        | 980
        | 990
        | 1870 => {}
        410 | 420 | 411 | 421 => {
            return Err(unsupported(
                field,
                line,
                "cutter radius compensation (G41/G42) is not supported: post the program with compensation in the CAM system",
            ));
        }
        730 | 740 | 760 | 810..=890 => {
            return Err(unsupported(field, line, "canned cycles are not supported"));
        }
        _ => {
            return Err(unsupported(field, line, format!("G{} is not supported", format_code(code))));
        }
    }
    Ok(())
}

fn format_code(tenths: u32) -> String {
    if tenths.is_multiple_of(10) { format!("{}", tenths / 10) } else { format!("{}.{}", tenths / 10, tenths % 10) }
}

/// Centre and turns of a `G2`/`G3` block, checked for closure.
fn arc_kind(
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
            "E_GCODE_POSITION",
            format!("line {line}: arc from a position the program has not set yet"),
        )
        .at(field));
    };
    let scale = modal.units.scale();
    let extra_turns = match block.turns {
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
    };
    let offset_letters = ['I', 'J', 'K'];
    let (centre_a, centre_b) = if let Some(radius_word) = block.radius {
        if block.offsets.iter().any(Option::is_some) {
            return Err(syntax(field, line, "an arc takes either R or I/J/K, not both"));
        }
        let radius = radius_word.value * scale;
        let (dx, dy) = (end_a - start_a, end_b - start_b);
        let chord = dx.hypot(dy);
        if chord < 1e-9 {
            return Err(syntax(field, line, "a full circle cannot be given with R: use I/J/K"));
        }
        let half = chord / 2.0;
        if radius.abs() < half - ARC_CLOSURE_MM.max(ARC_CLOSURE_RELATIVE * half) {
            return Err(SolverError::new(
                "E_ARC_RADIUS",
                format!(
                    "line {line}: arc radius R{} is shorter than half the chord ({:.4} mm)",
                    radius_word.value,
                    half / scale
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
        (mid_a - side * rise * dy / chord, mid_b + side * rise * dx / chord)
    } else {
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
        if modal.absolute_arc_centre {
            (oa.unwrap_or(start_a), ob.unwrap_or(start_b))
        } else {
            (start_a + oa.unwrap_or(0.0), start_b + ob.unwrap_or(0.0))
        }
    };
    let start_radius = (start_a - centre_a).hypot(start_b - centre_b);
    let end_radius = (end_a - centre_a).hypot(end_b - centre_b);
    if start_radius < 1e-9 {
        return Err(syntax(field, line, "arc centre coincides with its start"));
    }
    let tolerance = ARC_CLOSURE_MM.max(ARC_CLOSURE_RELATIVE * start_radius);
    if (end_radius - start_radius).abs() > tolerance {
        return Err(SolverError::new(
            "E_ARC_NOT_CLOSED",
            format!(
                "line {line}: the arc does not close: radius {:.4} mm at the start but {:.4} mm at the end (tolerance {:.4} mm)",
                start_radius, end_radius, tolerance
            ),
        )
        .at(field));
    }
    let mut centre = [0.0; 3];
    centre[a] = centre_a;
    centre[b] = centre_b;
    centre[normal] = from[normal].unwrap_or(0.0);
    Ok(MoveKind::Arc { centre, clockwise, extra_turns })
}

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
/// inserted after the block's last word. Incremental (`G91`) blocks get new increments so every
/// later end point stays where it was. `program` must be the result of [`read`] on `text`.
///
/// # Errors
/// `E_INPUT` for an edit that names no move, or a non-finite coordinate.
pub fn rewrite(text: &str, program: &ReadProgram, edits: &[MoveEdit], field: &str) -> Result<String, SolverError> {
    let count = program.moves.len();
    let mut new_to: Vec<Position> = program.moves.iter().map(|m| m.to).collect();
    let mut centres: Vec<Option<[f64; 3]>> = vec![None; count];
    for edit in edits {
        if edit.index >= count {
            return Err(SolverError::input(field, format!("edit names move {} of {count}", edit.index)));
        }
        if edit.to.iter().chain(edit.centre.iter().flatten()).any(|v| !v.is_finite()) {
            return Err(SolverError::input(field, "an edited coordinate is not finite"));
        }
        new_to[edit.index] = edit.to.map(Some);
        centres[edit.index] = edit.centre;
    }
    // Where each move of the rewritten program really ends (written values are rounded), so
    // incremental words and modal axes follow the control, not the exact edits.
    let mut actual: Vec<Position> = Vec::with_capacity(count);
    let mut replacements: Vec<LineEdit> = Vec::new();
    for (index, read_move) in program.moves.iter().enumerate() {
        let continuous = index > 0 && program.moves[index - 1].to == read_move.from;
        let start = if continuous { actual[index - 1] } else { read_move.from };
        if start == read_move.from && new_to[index] == read_move.to && centres[index].is_none() {
            actual.push(read_move.to);
            continue;
        }
        let scale = read_move.modal.units.scale();
        let mut end_actual = read_move.to;
        let mut changes: Vec<(WordSpan, String)> = Vec::new();
        let mut inserts: Vec<String> = Vec::new();
        let letters = ['X', 'Y', 'Z'];
        for axis in 0..3 {
            let (Some(end), Some(old_end)) = (new_to[index][axis], read_move.to[axis]) else {
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
            && let (Some(from), Some(to)) = (known(&start), known(&end_actual))
        {
            arc_words(read_move, from, to, centres[index].unwrap_or(centre), clockwise, &mut changes, &mut inserts);
        }
        actual.push(end_actual);
        if !changes.is_empty() || !inserts.is_empty() {
            replacements.push(LineEdit {
                line: read_move.line,
                changes,
                inserts,
                insert_at: read_move.words.insert_at,
            });
        }
    }
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
    Ok(out)
}

/// The text changes of one rewritten line.
struct LineEdit {
    line: usize,
    changes: Vec<(WordSpan, String)>,
    inserts: Vec<String>,
    insert_at: usize,
}

/// New centre words for an arc whose ends moved: the centre is put on the new chord's
/// perpendicular bisector, nearest to `wanted`, so the arc closes exactly.
fn arc_words(
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
fn number(value: f64, decimals: usize) -> String {
    let text = format!("{value:.decimals$}");
    if text.starts_with('-') && text[1..].bytes().all(|b| b == b'0' || b == b'.') { text[1..].to_owned() } else { text }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_ok(text: &str) -> ReadProgram {
        read(text, "program", &ReadOptions::default()).unwrap()
    }

    fn read_err(text: &str) -> SolverError {
        read(text, "program", &ReadOptions::default()).unwrap_err()
    }

    #[test]
    fn reads_moves_with_lines_and_modal_state() {
        let program = read_ok(
            "%\nO1000 (TEST)\nN10 G21 G17 G90 G94\nN20 T3 M06\nN30 S6000 M03\n\
             N40 G00 X0 Y0 Z10 ; rapid\nN50 G01 Z-1 F300\nN60 X10\n/N70 Y5\nN80 G91 X1 Y1\nM30\n%\n",
        );
        let moves = &program.moves;
        assert_eq!(moves.len(), 5);
        assert_eq!(moves[0].line, 6);
        assert_eq!(moves[0].kind, MoveKind::Rapid);
        assert_eq!(moves[0].from, [None; 3]);
        assert_eq!(moves[0].to_xyz(), Some([0.0, 0.0, 10.0]));
        assert_eq!(moves[1].block_number, Some(50));
        assert_eq!(moves[1].modal.feed, Some(300.0));
        assert_eq!(moves[1].modal.spindle, Spindle::Clockwise);
        assert_eq!(moves[1].modal.spindle_rpm, Some(6000.0));
        assert_eq!(moves[1].modal.tool, Some(3));
        assert_eq!(moves[2].to_xyz(), Some([10.0, 0.0, -1.0]));
        assert_eq!(moves[3].line, 9);
        assert_eq!(moves[3].to_xyz(), Some([10.0, 5.0, -1.0]));
        assert_eq!(moves[4].to_xyz(), Some([11.0, 6.0, -1.0]));
        assert_eq!(moves[4].modal.distance, Distance::Incremental);
        let skipped = read(
            "G0 X0 Y0 Z0\n/G1 X5 F100\nG1 Y5 F100\n",
            "program",
            &ReadOptions { block_delete: true, ..ReadOptions::default() },
        )
        .unwrap();
        assert_eq!(skipped.moves.len(), 2);
        assert_eq!(skipped.moves[1].to_xyz(), Some([0.0, 5.0, 0.0]));
    }

    #[test]
    fn inch_programs_are_converted_to_mm() {
        let program = read_ok("G20 G90\nG0 X1 Y2 Z0.5\nG1 X2 F10\nG2 X3 Y3 I0 J1\n");
        assert_eq!(program.moves[0].to_xyz(), Some([25.4, 50.8, 12.7]));
        assert_eq!(program.moves[1].modal.feed, Some(254.0));
        assert_eq!(program.moves[1].modal.units, Units::Inch);
        let MoveKind::Arc { centre, .. } = program.moves[2].kind else {
            panic!("not an arc");
        };
        assert!((centre[0] - 50.8).abs() < 1e-12 && (centre[1] - 76.2).abs() < 1e-12);
    }

    #[test]
    fn arcs_by_centre_and_radius_agree_and_linearise_within_tolerance() {
        let by_centre = read_ok("G0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F100\n");
        let by_radius = read_ok("G0 X10 Y0 Z0\nG3 X0 Y10 R10 F100\n");
        let (MoveKind::Arc { centre: c1, .. }, MoveKind::Arc { centre: c2, .. }) =
            (by_centre.moves[1].kind, by_radius.moves[1].kind)
        else {
            panic!("not arcs");
        };
        assert!((0..3).all(|axis| (c1[axis] - c2[axis]).abs() < 1e-12));
        let points = by_centre.moves[1].points(0.001).unwrap();
        let mut previous = [10.0, 0.0, 0.0];
        for point in &points {
            assert!(((point[0]).hypot(point[1]) - 10.0).abs() < 1e-9);
            let mid = [(previous[0] + point[0]) / 2.0, (previous[1] + point[1]) / 2.0];
            assert!(10.0 - mid[0].hypot(mid[1]) <= 0.001 + 1e-12);
            previous = *point;
        }
        assert_eq!(*points.last().unwrap(), [0.0, 10.0, 0.0]);
        // Long arc with negative R, clockwise.
        let long = read_ok("G0 X10 Y0 Z0\nG2 X0 Y10 R-10 F100\n");
        let MoveKind::Arc { centre, .. } = long.moves[1].kind else {
            panic!("not an arc");
        };
        assert!(centre[0].abs() < 1e-9 && centre[1].abs() < 1e-9);
        let short_cw = read_ok("G0 X10 Y0 Z0\nG2 X0 Y10 R10 F100\n");
        let MoveKind::Arc { centre, .. } = short_cw.moves[1].kind else {
            panic!("not an arc");
        };
        assert!((centre[0] - 10.0).abs() < 1e-9 && (centre[1] - 10.0).abs() < 1e-9);
        // Full circle and a helix in the ZX plane.
        let full = read_ok("G0 X10 Y0 Z0\nG2 X10 Y0 I-10 J0 F100\n");
        assert!(full.moves[1].points(0.01).unwrap().len() > 50);
        let helix = read_ok("G18 G0 X10 Y0 Z0\nG3 X0 Y4 Z10 I-10 K0 F100\n");
        let points = helix.moves[1].points(0.01).unwrap();
        assert!((points[points.len() / 2][1] - 2.0).abs() < 0.2);
    }

    #[test]
    fn bad_programs_are_refused_with_the_line_number() {
        let cases = [
            ("G0 X0 Y0 Z0\nG1 X1 Y1 Q\n", "E_GCODE_SYNTAX", "line 2"),
            ("G0 X0 Y0 Z0\nG1 X1 (open\n", "E_GCODE_SYNTAX", "line 2"),
            ("G0 X0 Y0 Z0\nG1 X1 X2 F1\n", "E_GCODE_SYNTAX", "line 2"),
            ("G0 X0 Y0 Z0\n\nG41 D1 G1 X5 F100\n", "E_GCODE_UNSUPPORTED", "line 3"),
            ("G81 X0 Y0 Z-1 R1 F100\n", "E_GCODE_UNSUPPORTED", "line 1"),
            ("G0 X0 Y0 Z0\nG1 A10 F100\n", "E_GCODE_UNSUPPORTED", "line 2"),
            ("#1=5\n", "E_GCODE_UNSUPPORTED", "line 1"),
            ("G0 X10 Y0 Z0\nG2 X0 Y10 I-10 J1 F100\n", "E_ARC_NOT_CLOSED", "line 2"),
            ("G0 X10 Y0 Z0\nG2 X-10 Y0 R5 F100\n", "E_ARC_RADIUS", "line 2"),
            ("G2 X0 Y10 I-10 J0 F100\n", "E_GCODE_POSITION", "line 1"),
            ("X10\n", "E_GCODE_SYNTAX", "line 1"),
            ("G0 G1 X1\n", "E_GCODE_SYNTAX", "line 1"),
            ("G1 X1 F-5\n", "E_GCODE_SYNTAX", "line 1"),
            ("G0 X1 &\n", "E_GCODE_SYNTAX", "line 1"),
            ("M98 P100\n", "E_GCODE_UNSUPPORTED", "line 1"),
        ];
        for (text, code, line) in cases {
            let error = read_err(text);
            assert_eq!(error.code(), code, "{text}: {}", error.message());
            assert!(error.message().starts_with(line), "{text}: {}", error.message());
            assert_eq!(error.field(), Some("program"));
        }
        let limited = read("G0 X0\nG0 X1\nG0 X2\n", "program", &ReadOptions { max_lines: 2, ..ReadOptions::default() })
            .unwrap_err();
        assert_eq!(limited.code(), "E_TOO_MANY_LINES");
    }

    #[test]
    fn non_geometric_words_and_home_returns_do_not_move_the_tool() {
        let program =
            read_ok("G0 G54 G43 H1 X0 Y0 Z5\nG4 X2.5\nG10 L2 P1 X5\nG1 Z0 F100\nG91 G28 Z0\nG90 G0 X1\nG0 Y1 Z1\n");
        assert_eq!(program.moves.len(), 4);
        assert_eq!(program.moves[1].to_xyz(), Some([0.0, 0.0, 0.0]));
        assert_eq!(program.moves[2].from, [None; 3]);
        assert_eq!(program.moves[2].to, [Some(1.0), None, None]);
        assert_eq!(program.moves[3].from, [Some(1.0), None, None]);
        assert_eq!(program.moves[3].to_xyz(), Some([1.0, 1.0, 1.0]));
        let stopped = read_ok("G0 X0 Y0 Z0\nM30\nG0 X5\n");
        assert_eq!(stopped.moves.len(), 1);
        assert_eq!(stopped.line_count, 4);
    }

    #[test]
    fn rewrite_changes_only_coordinates() {
        let text = "%\nN10 G90 G0 X0 Y0 Z5 (START)\nN20 G1 Z0.000 F300\nN30 X10. ; cut\nN40 Y5\nN50 G0 Z5\n%\n";
        let program = read_ok(text);
        let edits = [
            MoveEdit { index: 2, to: [10.0, 0.01, -0.002], centre: None },
            MoveEdit { index: 3, to: [10.0, 5.0, -0.001], centre: None },
        ];
        let out = rewrite(text, &program, &edits, "program").unwrap();
        assert_eq!(
            out,
            "%\nN10 G90 G0 X0 Y0 Z5 (START)\nN20 G1 Z0.000 F300\nN30 X10. Y0.0100 Z-0.0020 ; cut\nN40 Y5 Z-0.0010\nN50 G0 Z5\n%\n"
        );
        assert_eq!(out.lines().count(), text.lines().count());
        let reread = read_ok(&out);
        assert_eq!(reread.moves[2].to_xyz(), Some([10.0, 0.01, -0.002]));
        assert_eq!(reread.moves[4].to_xyz(), Some([10.0, 5.0, 5.0]));
    }

    #[test]
    fn incremental_rewrite_keeps_later_end_points() {
        let text = "G90 G0 X0 Y0 Z0\nG91 G1 X10 F100\nX10\nX10\n";
        let program = read_ok(text);
        let edits = [MoveEdit { index: 2, to: [20.5, 0.0, 0.0], centre: None }];
        let out = rewrite(text, &program, &edits, "program").unwrap();
        assert_eq!(out, "G90 G0 X0 Y0 Z0\nG91 G1 X10 F100\nX10.5000\nX9.5000\n");
    }

    #[test]
    fn rewritten_arcs_close_and_keep_their_format() {
        let text = "G0 X10 Y0 Z0\nG3 X0 Y10 I-10 J0 F100\nG3 X-10 Y0 R10\n";
        let program = read_ok(text);
        let edits = [
            MoveEdit { index: 1, to: [0.0, 10.01, 0.0], centre: None },
            MoveEdit { index: 2, to: [-10.01, 0.0, 0.0], centre: Some([0.0, 0.0, 0.0]) },
        ];
        let out = rewrite(text, &program, &edits, "program").unwrap();
        let reread = read_ok(&out);
        assert_eq!(reread.moves[1].to_xyz(), Some([0.0, 10.01, 0.0]));
        assert_eq!(reread.moves[2].to_xyz(), Some([-10.01, 0.0, 0.0]));
        assert!(out.lines().nth(2).unwrap().contains('R'));
        let inch = "G20 G0 X1 Y0 Z0\nG1 X2 F10\n";
        let program = read_ok(inch);
        let out =
            rewrite(inch, &program, &[MoveEdit { index: 1, to: [50.8 + 0.254, 0.0, 0.0], centre: None }], "program")
                .unwrap();
        assert_eq!(out, "G20 G0 X1 Y0 Z0\nG1 X2.0100 F10\n");
    }
}
