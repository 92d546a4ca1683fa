//! Heidenhain TNC conversational programs (Klartext): numbered blocks from `0 BEGIN PGM … MM` to
//! `END PGM … MM`, `TOOL CALL n Z S…` (the tool's length applies with the call), straight moves
//! `L X… Y… Z… R0 F…` (`FMAX` for rapids), arcs as the centre `CC X… Y…` followed by
//! `C X… Y… DR±`, and `;` comments. A helical arc (its Z changing) becomes straight moves within
//! the program's path tolerance. Its structure differs from the word-for-word posts of the post
//! table, so it is written here, and so is the re-posting of an RS274/Fanuc program as Klartext
//! ([`Reposter`]).

use std::fmt::Write as _;

use super::repost::{Item, has_word, program_number, read_items, refusal, source_units, words_in};
use super::table::CommentStyle;
use super::{
    Buffer, Dialect, MOVES_PER_CHECK, Program, ProgramStop, SpindleDirection, ToolCall, helix_points, number,
    push_comment, same_printed,
};
use crate::error::SolverError;
use crate::gcode::reader::{MoveKind, Plane, Position, ReadMove, Units};
use crate::geometry::Vec3;
use crate::path::Motion;

/// Decimals of lengths, mm.
const DECIMALS: usize = 4;

/// A Klartext program being written.
struct Klartext {
    text: Buffer,
    line: u32,
    /// What an F word's number counts per unit of feed: 1 in an `MM` program (mm/min), 10 in an
    /// `INCH` program, whose F is in 0.1 inch/min ([`FEED_PER_INCH_MIN`]).
    feed_scale: f64,
}

/// F units per inch/min in an `INCH` program: Heidenhain's conversational F is mm/min in `MM`
/// programs and 1/10 inch/min in `INCH` programs (F100 = 10 in/min), as the CAM posts for the
/// TNC write it (docs/spec/resegment.md §4 names the sources).
pub(super) const FEED_PER_INCH_MIN: f64 = 10.0;

/// The `MM`/`INCH` word of `BEGIN PGM` and `END PGM`, and the F scale of those units.
fn units_words(units: crate::units::Units) -> (&'static str, f64) {
    match units {
        crate::units::Units::Mm => ("MM", 1.0),
        crate::units::Units::Inch => ("INCH", FEED_PER_INCH_MIN),
    }
}

impl Klartext {
    /// Starts a block with its number.
    fn begin(&mut self) {
        number::push_whole(&mut self.text.0, f64::from(self.line));
        // Block 0 is `0`, which `push_whole` writes as Display does.
        self.text.push(' ');
        self.line += 1;
    }

    fn block(&mut self, words: &str) {
        self.begin();
        self.text.push_str(words);
        self.text.push('\n');
    }

    fn comment(&mut self, text: &str) {
        self.begin();
        push_comment(&mut self.text, CommentStyle::Semicolon, text, None);
        self.text.push('\n');
    }

    /// ` X+…` with the sign always written.
    fn word(&mut self, letter: char, value: f64) {
        self.text.push(' ');
        self.text.push(letter);
        number::push_fixed(&mut self.text.0, value, DECIMALS, true);
    }

    /// `L Z… R0 FMAX` with an M function.
    fn up(&mut self, z: f64, m: &str) {
        self.begin();
        self.text.push('L');
        self.word('Z', z);
        let _ = writeln!(self.text, " R0 FMAX {m}");
    }

    /// The tool call (`TOOL CALL n Z S…`; a tool not in the table stops for the operator, and
    /// the call without a number keeps the loaded tool and sets the speed).
    fn tool_call(&mut self, tool: Option<&ToolCall>, rpm: f64) {
        let number = match tool {
            Some(ToolCall::Table(number) | ToolCall::Named { number, .. }) => Some(*number),
            Some(ToolCall::Manual(description)) => {
                self.comment(&format!("TOOL NOT IN THE TOOL TABLE: {description}"));
                self.comment("LOAD IT, ACTIVATE ITS LENGTH OFFSET, THEN CYCLE START");
                self.block("STOP");
                None
            }
            None => None,
        };
        self.begin();
        self.text.push_str("TOOL CALL");
        if let Some(number) = number {
            let _ = write!(self.text, " {number}");
        }
        self.text.push_str(" Z S");
        number::push_whole(&mut self.text.0, rpm.round());
        self.text.push('\n');
    }

    /// ` F…` when the feed changes.
    fn feed(&mut self, feed: f64, current: &mut Option<f64>) {
        if *current != Some(feed) {
            self.text.push_str(" F");
            number::push_feed(&mut self.text.0, feed * self.feed_scale);
            *current = Some(feed);
        }
    }

    /// `L X… Y… Z… R0` and the feed.
    fn line_to(&mut self, to: Vec3, feed: f64, current: &mut Option<f64>) {
        self.begin();
        self.text.push('L');
        self.word('X', to.x);
        self.word('Y', to.y);
        self.word('Z', to.z);
        self.text.push_str(" R0");
        self.feed(feed, current);
        self.text.push('\n');
    }
}

/// The M function starting the spindle `direction`.
fn spindle_on(direction: SpindleDirection) -> &'static str {
    match direction {
        SpindleDirection::Cw => "M3",
        SpindleDirection::Ccw => "M4",
    }
}

/// Writes the program (as [`super::write_cancellable`]).
pub(super) fn write<E>(
    program: &Program<'_>,
    stops: &[ProgramStop],
    mut check: impl FnMut() -> Result<(), E>,
) -> Result<String, E> {
    let (units, feed_scale) = units_words(program.units);
    let mut out = Klartext { text: Buffer::with_capacity(256 + program.path.moves.len() * 48), line: 0, feed_scale };
    let name = format!("KERF{}", program.number);
    out.block(&format!("BEGIN PGM {name} {units}"));
    out.comment(program.title);
    for line in &program.comments {
        out.comment(line);
    }
    out.tool_call(Some(&program.tool), program.spindle_rpm);
    out.up(program.safe_z, spindle_on(program.spindle_direction));
    let mut current_feed: Option<f64> = None;
    let mut position: Option<Vec3> = None;
    let mut stops = stops.iter().peekable();
    for (index, step) in program.path.moves.iter().enumerate() {
        if index % MOVES_PER_CHECK == 0 {
            check()?;
        }
        while let Some(stop) = stops.next_if(|stop| stop.before <= index) {
            out.up(program.safe_z, "M5");
            if let Some(notice) = &stop.notice {
                out.comment(notice);
                out.block("STOP");
            }
            out.tool_call(stop.tool.as_ref(), stop.spindle_rpm);
            out.up(program.safe_z, spindle_on(program.spindle_direction));
            if let Some(at) = &mut position {
                at.z = program.safe_z;
            }
            current_feed = None;
        }
        match step.motion {
            Motion::Rapid => {
                out.begin();
                out.text.push('L');
                out.word('X', step.to.x);
                out.word('Y', step.to.y);
                out.word('Z', step.to.z);
                out.text.push_str(" R0 FMAX\n");
            }
            // As the word posts: an arc needs its start, and one printed as ending where it
            // starts is the straight move it is meant to be.
            Motion::Arc { feed, centre, clockwise }
                if position.is_some_and(|start| !same_printed(start, step.to, DECIMALS)) =>
            {
                let start = position.unwrap_or_default();
                if number::prints_equal(start.z, step.to.z, DECIMALS) {
                    out.begin();
                    out.text.push_str("CC");
                    out.word('X', centre.x);
                    out.word('Y', centre.y);
                    out.text.push('\n');
                    out.begin();
                    out.text.push('C');
                    out.word('X', step.to.x);
                    out.word('Y', step.to.y);
                    out.text.push_str(if clockwise { " DR-" } else { " DR+" });
                    out.feed(feed, &mut current_feed);
                    out.text.push('\n');
                } else {
                    for point in helix_points(start, step.to, centre, clockwise, program.blend_tolerance) {
                        out.line_to(point, feed, &mut current_feed);
                    }
                }
            }
            Motion::Linear { feed } | Motion::Arc { feed, .. } => {
                let feed = program.plunge_feed_of(position, step.to, feed).unwrap_or(feed);
                out.line_to(step.to, feed, &mut current_feed);
            }
        }
        position = Some(step.to);
    }
    out.up(program.safe_z, "M5");
    out.up(program.safe_z, "M30");
    out.block(&format!("END PGM {name} {units}"));
    Ok(out.text.into_string())
}

/// Chord tolerance of a helical arc re-posted as straight blocks, mm.
const HELIX_TOLERANCE_MM: f64 = 0.001;

/// A program read as RS274/Fanuc re-posted as Klartext, line by line and in order
/// (docs/spec/resegment.md §4): moves from what the reader made of them (absolute positions,
/// arc centres as `CC`), the tool change as `TOOL CALL`, the spindle speed as a `TOOL CALL`
/// without a tool, spindle, coolant and program end as M functions on a positioning block,
/// `M0` as `STOP`, comments as `;` blocks; a code without a counterpart refuses the line.
pub struct Reposter {
    out: Klartext,
    /// `KERF` and the heading's program number.
    name: String,
    /// The program's units (its first `G20`/`G21`): one for the whole program.
    units: Units,
    field: &'static str,
    /// Where the tool is, mm (axes the program has not set yet: `None`).
    position: Position,
    /// The program's feed, its units per minute, as its last `F` word says.
    feed: Option<f64>,
    /// The feed the last F word written gives.
    written_feed: Option<f64>,
    /// The spindle speed, rpm, as its last `S` word says.
    spindle_rpm: Option<f64>,
    /// The tool the program last named (`T`), for an `M6` on a line of its own.
    tool: Option<u32>,
    /// M functions waiting for a positioning block (the program has set no Z yet), with the line
    /// that asked for the first.
    pending: Option<(usize, Vec<&'static str>)>,
}

impl Reposter {
    /// A re-poster of `source`, whose errors name `field`: `BEGIN PGM` in the program's units.
    pub(super) fn new(source: &str, field: &'static str) -> Self {
        let units = source_units(source);
        let program_units = match units {
            Units::Mm => crate::units::Units::Mm,
            Units::Inch => crate::units::Units::Inch,
        };
        let (words, feed_scale) = units_words(program_units);
        let mut out = Klartext { text: Buffer::with_capacity(source.len() + source.len() / 2), line: 0, feed_scale };
        let name = format!("KERF{}", program_number(source));
        out.block(&format!("BEGIN PGM {name} {words}"));
        Self {
            out,
            name,
            units,
            field,
            position: [None; 3],
            feed: None,
            written_feed: None,
            spindle_rpm: None,
            tool: None,
            pending: None,
        }
    }

    /// The program written: `END PGM` after the last block.
    ///
    /// # Errors
    /// `E_GCODE_UNSUPPORTED` naming the line of an M function the program gave no position to
    /// carry it.
    pub(super) fn finish(mut self) -> Result<String, SolverError> {
        self.flush_pending()?;
        let units = if self.units == Units::Inch { "INCH" } else { "MM" };
        self.out.block(&format!("END PGM {} {units}", self.name));
        Ok(self.out.text.into_string())
    }

    fn refuse(&self, number: usize, what: &str) -> SolverError {
        refusal(Dialect::Heidenhain, self.field, number, what)
    }

    /// ` X+…` of a length in mm, in the program's units.
    fn length(&mut self, letter: char, mm: f64) {
        self.out.word(letter, mm / self.units.scale());
    }

    /// ` F…` when the feed differs from the last one written.
    fn feed_word(&mut self) {
        if let Some(feed) = self.feed {
            let mut written = self.written_feed;
            self.out.feed(feed, &mut written);
            self.written_feed = written;
        }
    }

    /// ` M…` of the waiting M functions and of `m`.
    fn m_words(&mut self, m: &[&'static str]) {
        let pending = self.pending.take().map(|(_, words)| words).unwrap_or_default();
        for word in pending.iter().chain(m) {
            self.out.text.push(' ');
            self.out.text.push_str(word);
        }
    }

    /// Writes the waiting M functions on `L Z… R0 FMAX`, where the tool already is.
    ///
    /// # Errors
    /// `E_GCODE_UNSUPPORTED` naming the line that asked for them when the program has set no Z.
    fn flush_pending(&mut self) -> Result<(), SolverError> {
        let Some((line, words)) = &self.pending else { return Ok(()) };
        let Some(z) = self.position[2] else {
            let what =
                format!("{} before any Z position (Klartext writes M functions on a positioning block)", words[0]);
            return Err(self.refuse(*line, &what));
        };
        self.out.begin();
        self.out.text.push('L');
        self.length('Z', z);
        self.out.text.push_str(" R0 FMAX");
        self.m_words(&[]);
        self.out.text.push('\n');
        Ok(())
    }

    /// The straight feed blocks of a re-cut run (from source line `line`): `points` in mm,
    /// `feed_word` (as the source wrote it) its feed.
    ///
    /// # Errors
    /// `E_GCODE_UNSUPPORTED` naming `line` for a run in other units than the program's.
    pub(super) fn feed_blocks(
        &mut self,
        line: usize,
        points: &[[f64; 3]],
        units: Units,
        feed_word: Option<&str>,
    ) -> Result<(), SolverError> {
        if units != self.units {
            return Err(self.refuse(line, "a change of units within the program (a Klartext program has one)"));
        }
        if let Some(feed) = feed_word.and_then(|word| word.get(1..)).and_then(|value| value.parse().ok()) {
            self.feed = Some(feed);
        }
        for point in points {
            self.out.begin();
            self.out.text.push('L');
            for (letter, value) in ['X', 'Y', 'Z'].into_iter().zip(point) {
                self.length(letter, *value);
            }
            self.out.text.push_str(" R0");
            self.feed_word();
            self.m_words(&[]);
            self.out.text.push('\n');
        }
        if let Some(last) = points.last() {
            self.position = last.map(Some);
        }
        Ok(())
    }

    /// Re-posts source line `number` (without its line end); `read` is its move, if it has one.
    ///
    /// # Errors
    /// `E_GCODE_UNSUPPORTED` naming the line and the code that Klartext cannot say;
    /// `E_GCODE_SYNTAX` for text that is not G-code.
    #[allow(clippy::too_many_lines)]
    pub(super) fn line(&mut self, number: usize, raw: &str, read: Option<&ReadMove>) -> Result<(), SolverError> {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let trimmed = line.trim();
        if trimmed.is_empty() || trimmed.starts_with('%') {
            return Ok(());
        }
        let (delete, code) = match trimmed.strip_prefix('/') {
            Some(rest) => (true, rest),
            None => (false, trimmed),
        };
        let items = read_items(number, code, self.field)?;
        let words = words_in(&items);
        let has = |letter: u8, value: f64| has_word(&words, letter, value);
        let changes_tool = has(b'M', 6.0);
        let mut m: Vec<&'static str> = Vec::new();
        let (mut stop, mut speed, mut axes) = (false, None, [false; 3]);
        for word in &words {
            let code = (word.value * 10.0).round() as i64;
            let exact = ((word.value * 10.0) - code as f64).abs() < 1e-6;
            match word.letter {
                b'N' | b'O' => {}
                b'G' if exact => match code {
                    // Motion, plane, distance mode and arc-centre mode: the reader's positions
                    // and centres are absolute, as every Klartext word here is.
                    0 | 10 | 20 | 30 | 170 | 180 | 190 | 900 | 910 | 901 | 911 | 940 => {}
                    200 | 210 if (code == 200) == (self.units == Units::Inch) => {}
                    200 | 210 => {
                        return Err(self.refuse(
                            number,
                            &format!(
                                "G{} (a change of units within the program; a Klartext program has one)",
                                code / 10
                            ),
                        ));
                    }
                    950 => return Err(self.refuse(number, "feed per revolution (G95)")),
                    // No radius compensation (every L is R0), the length offset applied by the
                    // tool call, no canned cycle, the active preset, the control's own blending.
                    400 | 430 | 490 | 800 | 540 | 610 | 640 => {}
                    _ => return Err(self.refuse(number, &format!("G{}", word.text))),
                },
                b'M' if exact => match code {
                    30 => m.push("M3"),
                    40 => m.push("M4"),
                    50 => m.push("M5"),
                    80 => m.push("M8"),
                    70 => m.push("M7"),
                    90 => m.push("M9"),
                    10 => m.push("M1"),
                    20 => m.push("M2"),
                    300 => m.push("M30"),
                    0 => stop = true,
                    60 => {}
                    _ => return Err(self.refuse(number, &format!("M{}", word.text))),
                },
                b'T' => match word.text.parse::<u32>() {
                    Ok(tool) => self.tool = Some(tool),
                    Err(_) => return Err(self.refuse(number, &format!("tool T{}", word.text))),
                },
                b'H' if has(b'G', 43.0) => {}
                b'P' if has(b'G', 64.0) => {}
                b'X' => axes[0] = true,
                b'Y' => axes[1] = true,
                b'Z' => axes[2] = true,
                b'I' | b'J' | b'K' | b'R' if read.is_some_and(|r| matches!(r.kind, MoveKind::Arc { .. })) => {}
                b'F' => self.feed = Some(word.value),
                b'S' => speed = Some(word.value),
                _ => return Err(self.refuse(number, &format!("{}{}", word.letter as char, word.text))),
            }
        }
        let prefix = if delete { "/" } else { "" };
        if let Some(rpm) = speed {
            self.spindle_rpm = Some(rpm);
        }
        if changes_tool {
            let Some(tool) = self.tool else {
                return Err(self.refuse(number, "M6 without a tool (T)"));
            };
            self.flush_pending()?;
            self.out.begin();
            self.out.text.push_str(prefix);
            let _ = write!(self.out.text, "TOOL CALL {tool} Z");
            if let Some(rpm) = self.spindle_rpm {
                self.out.text.push_str(" S");
                number::push_whole(&mut self.out.text.0, rpm.round());
            }
            self.out.text.push('\n');
            // The feed is written again after a tool change.
            self.written_feed = None;
        } else if let Some(rpm) = speed {
            // A tool call without a tool keeps the tool and sets the speed.
            self.out.begin();
            self.out.text.push_str(prefix);
            self.out.text.push_str("TOOL CALL Z S");
            number::push_whole(&mut self.out.text.0, rpm.round());
            self.out.text.push('\n');
        }
        match read {
            Some(read) => self.motion(number, prefix, read, axes, &m)?,
            None if !m.is_empty() => {
                // On a block of their own where the tool is; before any Z, on the next move.
                self.pending.get_or_insert((number, Vec::new())).1.extend(&m);
                if self.position[2].is_some() {
                    self.flush_pending()?;
                }
            }
            None => {}
        }
        if stop {
            self.flush_pending()?;
            self.out.block(&format!("{prefix}STOP"));
        }
        for item in &items {
            if let Item::Comment(text) = item {
                self.out.comment(text);
            }
        }
        Ok(())
    }

    /// The blocks of a move: `L … R0 FMAX` (rapid), `L … R0 F…`, `CC` and `C … DR±` for an arc in
    /// the XY plane (a helical one as straight blocks within [`HELIX_TOLERANCE_MM`]), each with
    /// the line's M functions `m`.
    fn motion(
        &mut self,
        number: usize,
        prefix: &str,
        read: &ReadMove,
        axes: [bool; 3],
        m: &[&'static str],
    ) -> Result<(), SolverError> {
        let to = read.to;
        match read.kind {
            MoveKind::Rapid | MoveKind::Linear => {
                self.out.begin();
                self.out.text.push_str(prefix);
                self.out.text.push('L');
                let named = if axes.iter().any(|a| *a) { axes } else { to.map(|v| v.is_some()) };
                for (axis, letter) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                    if let (true, Some(value)) = (named[axis], to[axis]) {
                        self.length(letter, value);
                    }
                }
                self.out.text.push_str(" R0");
                if read.kind == MoveKind::Rapid {
                    self.out.text.push_str(" FMAX");
                } else {
                    self.feed_word();
                }
                self.m_words(m);
                self.out.text.push('\n');
            }
            MoveKind::Arc { centre, clockwise, extra_turns } => {
                if read.modal.plane != Plane::Xy {
                    return Err(self.refuse(number, "an arc outside the XY plane (G18/G19)"));
                }
                if extra_turns > 0 {
                    return Err(self.refuse(number, "an arc of more than one turn"));
                }
                let (Some(from), Some(end)) = (read.from_xyz(), read.to_xyz()) else {
                    return Err(self.refuse(number, "an arc from a position the program has not set"));
                };
                let scale = self.units.scale();
                let flat = number::prints_equal(from[2] / scale, end[2] / scale, DECIMALS);
                if flat {
                    self.out.begin();
                    self.out.text.push_str(prefix);
                    self.out.text.push_str("CC");
                    self.length('X', centre[0]);
                    self.length('Y', centre[1]);
                    self.out.text.push('\n');
                    self.out.begin();
                    self.out.text.push_str(prefix);
                    self.out.text.push('C');
                    self.length('X', end[0]);
                    self.length('Y', end[1]);
                    self.out.text.push_str(if clockwise { " DR-" } else { " DR+" });
                    self.feed_word();
                    self.m_words(m);
                    self.out.text.push('\n');
                } else {
                    let [start, stop, middle] = [from, end, centre].map(|p| Vec3::new(p[0], p[1], p[2]));
                    let points = helix_points(start, stop, middle, clockwise, HELIX_TOLERANCE_MM);
                    for (index, point) in points.iter().enumerate() {
                        self.out.begin();
                        self.out.text.push_str(prefix);
                        self.out.text.push('L');
                        self.length('X', point.x);
                        self.length('Y', point.y);
                        self.length('Z', point.z);
                        self.out.text.push_str(" R0");
                        self.feed_word();
                        if index == 0 {
                            self.m_words(m);
                        }
                        self.out.text.push('\n');
                    }
                }
            }
        }
        for (axis, value) in to.iter().enumerate() {
            if value.is_some() {
                self.position[axis] = *value;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::path::Toolpath;

    #[test]
    fn inch_programs_give_feeds_in_tenths_of_an_inch_per_minute() {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(0.0, 0.0, 25.4));
        // 254 mm/min is 10 in/min: F100 in an INCH program, F254 in an MM one.
        path.linear(Vec3::new(25.4, 0.0, 25.4), 254.0);
        let program = |units| Program {
            dialect: Dialect::Heidenhain,
            number: 1000,
            title: "feeds",
            comments: Vec::new(),
            tool: ToolCall::Table(1),
            spindle_rpm: 1000.0,
            spindle_direction: SpindleDirection::Cw,
            safe_z: 25.4,
            blend_tolerance: 0.01,
            plunges: None,
            path: &path,
            units,
        };
        let inch = super::super::write(&program(crate::units::Units::Inch));
        assert!(inch.starts_with("0 BEGIN PGM KERF1000 INCH\n"), "{inch}");
        assert!(inch.contains(" L X+1.0000 Y+0.0000 Z+1.0000 R0 F100\n"), "{inch}");
        let mm = super::super::write(&program(crate::units::Units::Mm));
        assert!(mm.contains(" L X+25.4000 Y+0.0000 Z+25.4000 R0 F254\n"), "{mm}");
    }
}
