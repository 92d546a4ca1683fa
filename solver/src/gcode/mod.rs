//! G-code posts: turns a [`Toolpath`] into a complete program for the control a machine runs
//! (docs/spec/api.md, G-code conventions; docs/guide/gcode.md).
//!
//! Every post prints every coordinate with 4 decimals in mm (never `-0.0000`), absolute mode,
//! feed per minute, and starts with a safety line, the tool call with its length offset and the
//! spindle, and ends with spindle stop and the program end. Where controls differ only in words
//! (program start and end, comments, tool call, spindle and coolant codes, arc centres, line
//! numbers, decimal format, longest line) the post is a row of the post table
//! ([`table::PostTable`]): Fanuc (also Mazak and Okuma in ISO mode), Haas, LinuxCNC, Siemens
//! Sinumerik 840D, Heidenhain ISO and grbl. Heidenhain's conversational Klartext differs in
//! structure and is code of its own (module `klartext`). The program is written into one buffer, its
//! numbers from scaled integers ([`number`]).

pub mod job;
mod klartext;
pub mod number;
pub mod reader;
#[cfg(test)]
pub(crate) mod reference;
pub(crate) mod renumber;
pub mod repost;
pub mod table;

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use self::table::{ArcCentre, Blending, CommentStyle, Heading, PostTable, ToolChange};
use crate::control::Control;
use crate::error::SolverError;
use crate::geometry::Vec3;
use crate::path::{Motion, Toolpath};
use crate::units::{Scale, Scaling, Units};

/// The control the program is written for: the post.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Dialect {
    /// Fanuc 0i/30i (also Mazak and Okuma in their ISO mode): `%`, `O` number, `T M06` with
    /// `G43 H`.
    #[default]
    Fanuc,
    /// Haas: as Fanuc with a five-digit `O` number; `G187` only when the machine's
    /// `haas_smoothing` asks ([`with_haas_smoothing`]), else the control's setting applies.
    Haas,
    /// LinuxCNC (rs274ngc): adds `G64 P` blending tolerance.
    Linuxcnc,
    /// Siemens Sinumerik 840D: `;` comments, `G71` (mm), `G642` blending, `T D1` with `M6`.
    Sinumerik,
    /// Heidenhain TNC conversational (Klartext): `BEGIN PGM`, `TOOL CALL`, `L`, `CC`/`C`,
    /// `END PGM`.
    Heidenhain,
    /// Heidenhain TNC ISO: numbered blocks ending in `*`, `T G17` tool call, arc centre as an
    /// absolute `I J` block.
    HeidenhainIso,
    /// grbl: no tool changer (the program pauses with `M0` and a comment), no `G43`, lines of at
    /// most 80 characters.
    Grbl,
}

impl Dialect {
    /// Every post, in the order the page lists them.
    pub const ALL: [Self; 7] =
        [Self::Fanuc, Self::Haas, Self::Linuxcnc, Self::Sinumerik, Self::Heidenhain, Self::HeidenhainIso, Self::Grbl];

    /// The name used in JSON and `?dialect=`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Fanuc => "fanuc",
            Self::Haas => "haas",
            Self::Linuxcnc => "linuxcnc",
            Self::Sinumerik => "sinumerik",
            Self::Heidenhain => "heidenhain",
            Self::HeidenhainIso => "heidenhain_iso",
            Self::Grbl => "grbl",
        }
    }

    /// The extension of a program file for the control: `mpf` (Sinumerik main program), `h`
    /// (Heidenhain conversational), `i` (Heidenhain ISO), else `nc`.
    pub fn file_extension(self) -> &'static str {
        match self {
            Self::Sinumerik => "mpf",
            Self::Heidenhain => "h",
            Self::HeidenhainIso => "i",
            Self::Fanuc | Self::Haas | Self::Linuxcnc | Self::Grbl => "nc",
        }
    }
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
    /// A tool from the machine's table that has a name: Sinumerik's tool management calls it
    /// by name (`T="NAME"`), every other post by its number as [`ToolCall::Table`].
    Named {
        /// Its number in the table.
        number: u32,
        /// Its name as Sinumerik takes it (see [`ToolCall::for_tool`]).
        name: String,
    },
    /// A tool given inline, unknown to the control: the program stops (`M00`) and asks the
    /// operator to load it and activate its length offset.
    Manual(String),
}

impl ToolCall {
    /// The call for `tool`: from the table when it has a number, otherwise a manual change.
    pub fn for_tool(tool: &crate::tool::Tool) -> Self {
        match (tool.number, tool.name.as_deref().map(sinumerik_tool_name).filter(|n| !n.is_empty())) {
            (Some(number), Some(name)) => Self::Named { number, name },
            (Some(number), None) => Self::Table(number),
            (None, _) => Self::Manual(format!("{} radius {} mm", tool.kind.as_str(), mm(tool.radius))),
        }
    }

    /// The call with a manual change's description (which quotes the tool's radius in mm)
    /// restated in the units of `scaling` ([`Scaling::restate`]).
    #[must_use]
    pub fn restated(&self, scaling: Scaling) -> Self {
        match self {
            Self::Manual(description) => Self::Manual(scaling.restate(description)),
            other => other.clone(),
        }
    }

    /// The tool's number in the machine's table, if it is from the table.
    pub fn number(&self) -> Option<u32> {
        match self {
            Self::Table(number) | Self::Named { number, .. } => Some(*number),
            Self::Manual(_) => None,
        }
    }
}

/// Longest tool name Sinumerik's tool management takes, characters.
pub const SINUMERIK_TOOL_NAME_CHARS: usize = 32;

/// A tool's name as Sinumerik's `T="…"` takes it: printable ASCII without `"`, upper case as
/// the program's comments, at most [`SINUMERIK_TOOL_NAME_CHARS`] characters, trimmed.
fn sinumerik_tool_name(name: &str) -> String {
    let cleaned: String = name
        .chars()
        .map(|c| if c == '"' || c.is_control() || !c.is_ascii() { ' ' } else { c.to_ascii_uppercase() })
        .take(SINUMERIK_TOOL_NAME_CHARS)
        .collect();
    cleaned.trim().to_owned()
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
    /// The program's units: mm (G21) or inch (G20); the path stays in mm until it is written.
    pub units: Units,
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
        Self { dialect, reference, tool, arcs: Arcs::Chords, plunge_feed: None, units: Units::Mm }
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
    /// The units the program is written in; every length and feed above is in mm (mm/min) and
    /// converted as it is written.
    pub units: Units,
}

/// The least spindle speed a program writes other than `S0`, rpm: it writes whole rpm.
const LEAST_SPINDLE_RPM: f64 = 0.5;

/// The least feed a program writes other than `F0`, in its units per minute: it writes feeds to
/// 0.1 mm/min (0.1 in/min in inch).
const LEAST_FEED: f64 = 0.05;

impl Program<'_> {
    /// Refuses a program whose spindle speed (or a stop's) would be written `S0`, or one of
    /// whose feeds (a plunge's slowed feed included) would be written `F0`, naming
    /// `spindle_field` or `feed_field`: `S0 M03` starts no spindle under the cutting moves that
    /// follow it, and no control runs a feed move at `F0`. Values are quoted in mm (a refusal
    /// is restated in the request's units at the edge).
    ///
    /// # Errors
    /// `E_INPUT` at `spindle_field` or `feed_field`.
    pub fn check_written(
        &self,
        stops: &[ProgramStop],
        spindle_field: &str,
        feed_field: &str,
    ) -> Result<(), SolverError> {
        let mut speeds = std::iter::once(self.spindle_rpm).chain(stops.iter().map(|stop| stop.spindle_rpm));
        if let Some(rpm) = speeds.find(|rpm| rpm.is_nan() || *rpm < LEAST_SPINDLE_RPM) {
            return Err(SolverError::input(
                spindle_field,
                format!(
                    "{spindle_field} must be at least {LEAST_SPINDLE_RPM} rpm: the program writes whole rpm, and S0 \
                     would start no spindle under its cutting moves (got {})",
                    crate::validate::quoted(rpm)
                ),
            ));
        }
        let least_mm = LEAST_FEED * self.units.mm_per_unit();
        let mut position = None;
        for step in &self.path.moves {
            let feed = match step.motion {
                Motion::Rapid => None,
                Motion::Arc { feed, .. } => Some((feed, false)),
                Motion::Linear { feed } => {
                    Some(self.plunge_feed_of(position, step.to, feed).map_or((feed, false), |slowed| (slowed, true)))
                }
            };
            position = Some(step.to);
            if let Some((feed, plunge)) = feed
                && (feed.is_nan() || feed < least_mm)
            {
                let which = if plunge { "a plunge's feed" } else { "a feed" };
                return Err(SolverError::input(
                    feed_field,
                    format!(
                        "{feed_field}: the program would write {which} of {} mm/min as F0 (it writes feeds to \
                         0.1 of its units per minute), which no control runs; the least it writes is {least_mm} mm/min",
                        crate::validate::quoted(feed)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The slowed feed of a straight move at `feed` from `from` to `to` when it is a plunge the
    /// program slows ([`Self::plunges`]), else `None` (it runs at `feed`).
    fn plunge_feed_of(&self, from: Option<Vec3>, to: Vec3, feed: f64) -> Option<f64> {
        match (self.plunges, from) {
            (Some(plunges), Some(from)) if is_plunge(from, to) => Some(plunge_feed(feed, plunges.feed)),
            _ => None,
        }
    }
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
    number::fixed(value, 4, false)
}

/// A comment in parentheses: upper case, no parentheses or control characters.
pub fn comment(text: &str) -> String {
    let mut out = Buffer::default();
    push_comment(&mut out, CommentStyle::Parentheses, text, None);
    out.into_string()
}

/// A program's text as it is written: bytes, each ASCII or from a whole `str`, so the text is
/// UTF-8; digits are copied in without a check per number.
#[derive(Debug, Default)]
struct Buffer(Vec<u8>);

impl Buffer {
    fn with_capacity(capacity: usize) -> Self {
        Self(Vec::with_capacity(capacity))
    }

    fn push_str(&mut self, text: &str) {
        self.0.extend_from_slice(text.as_bytes());
    }

    fn push(&mut self, c: char) {
        self.push_str(c.encode_utf8(&mut [0; 4]));
    }

    /// Where the current line starts.
    fn line_start(&self) -> usize {
        self.0.iter().rposition(|b| *b == b'\n').map_or(0, |at| at + 1)
    }

    fn into_string(self) -> String {
        number::text(self.0)
    }
}

impl std::fmt::Write for Buffer {
    fn write_str(&mut self, text: &str) -> std::fmt::Result {
        self.push_str(text);
        Ok(())
    }
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

/// `text`, a program of `dialect`'s post, with Haas smoothing `G187 P<level>` when the post is
/// Haas and `level` is given (a machine's `haas_smoothing`): after the post's safety block in a
/// program kerf wrote (a capability's, a job's joined program), else (a re-segmented program,
/// which keeps the source's heading) after the heading: the `%`, `O` and comment lines before
/// the first block of words. A program that sets its own smoothing (a `G187` word) stays as it
/// is, and so does every other post's.
pub fn with_haas_smoothing(text: String, dialect: Dialect, level: Option<u8>) -> String {
    let (Some(level), Dialect::Haas, Some(table)) = (level, dialect, dialect.table()) else { return text };
    // The safety block of either units: an inch program writes its own.
    let found = [table.safety, table.inch_safety]
        .into_iter()
        .find_map(|safety| text.find(&format!("\n{safety}\n")).map(|at| at + safety.len() + 2));
    let (at, ending) = match found {
        Some(end) => (end, "\n"),
        None => {
            if text.lines().any(|line| words_of(line).to_ascii_uppercase().contains("G187")) {
                return text;
            }
            let mut at = 0;
            for line in text.split_inclusive('\n') {
                let words = words_of(line);
                let words = words.trim();
                let heading = words.is_empty() || words.starts_with('%') || words.starts_with(['O', 'o']);
                if !heading {
                    break;
                }
                at += line.len();
            }
            (at, if text.contains("\r\n") { "\r\n" } else { "\n" })
        }
    };
    let mut out = String::with_capacity(text.len() + 10);
    out.push_str(&text[..at]);
    let _ = write!(out, "G187 P{level}{ending}");
    out.push_str(&text[at..]);
    out
}

/// A line without its comments (`( )` and from `;`).
fn words_of(line: &str) -> String {
    let code = line.split(';').next().unwrap_or_default();
    let mut words = String::with_capacity(code.len());
    let mut depth = 0usize;
    for c in code.chars() {
        match c {
            '(' => depth += 1,
            ')' => depth = depth.saturating_sub(1),
            _ if depth == 0 => words.push(c),
            _ => {}
        }
    }
    words
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

/// Bytes a program takes per move, about: the buffer is sized once for the whole program.
const BYTES_PER_MOVE: usize = 40;

fn write_checking<E>(
    program: &Program<'_>,
    stops: &[ProgramStop],
    check: impl FnMut() -> Result<(), E>,
) -> Result<String, E> {
    let Some(scaling) = program.units.from_mm() else { return write_words(program, stops, check) };
    // Converted once here, so every word below is written in the program's units as it is.
    let mut path = program.path.clone();
    for step in &mut path.moves {
        Scale::scale(&mut step.to, scaling);
        match &mut step.motion {
            Motion::Rapid => {}
            Motion::Linear { feed } => feed.scale(scaling),
            Motion::Arc { feed, centre, .. } => {
                feed.scale(scaling);
                Scale::scale(centre, scaling);
            }
        }
    }
    let plunges = program.plunges.map(|mut plunges| {
        plunges.feed.scale(scaling);
        plunges
    });
    // The header's sentences, the stops' notices and a manual tool change's description quote
    // lengths and feeds in mm: restated in the program's units.
    let comments = program.comments.iter().map(|comment| scaling.restate(comment)).collect();
    let stops: Vec<ProgramStop> = stops
        .iter()
        .map(|stop| ProgramStop {
            notice: stop.notice.as_deref().map(|notice| scaling.restate(notice)),
            tool: stop.tool.as_ref().map(|tool| tool.restated(scaling)),
            ..stop.clone()
        })
        .collect();
    let program = Program {
        comments,
        tool: program.tool.restated(scaling),
        safe_z: scaling.apply(program.safe_z),
        blend_tolerance: scaling.apply(program.blend_tolerance),
        plunges,
        path: &path,
        ..program.clone()
    };
    write_words(&program, &stops, check)
}

/// Writes `program`, its lengths and feeds already in its units.
fn write_words<E>(
    program: &Program<'_>,
    stops: &[ProgramStop],
    check: impl FnMut() -> Result<(), E>,
) -> Result<String, E> {
    match program.dialect.table() {
        Some(table) => {
            let mut out = Blocks::new(table, program.path.moves.len());
            out.program(program, stops, check)?;
            let text = out.text.into_string();
            #[cfg(test)]
            reference::check(program, stops, &text);
            Ok(text)
        }
        None => klartext::write(program, stops, check),
    }
}

/// A program being written by a post of the table: one buffer, line numbers, block ends.
struct Blocks {
    table: PostTable,
    text: Buffer,
    line: u32,
    /// Where the buffer already holds the words of recent end points.
    words: WordCache,
}

/// Most slots of [`WordCache::pairs`]: a layered program (a contour's layers repeat one plan at
/// other heights) returns to a few thousand X/Y pairs.
const PAIR_SLOTS: usize = 1 << 13;

/// Where the program's buffer already holds the ` X… Y…` words of an end point (by the bits of
/// its x and y, a slot per hash, the last written wins) and the ` Z…` word of the last height:
/// the text of a word depends only on its value and the post, so a repeated value copies its
/// text instead of formatting it again (a layered program repeats its X/Y pairs layer after
/// layer, and most of its moves share their layer's height).
struct WordCache {
    /// x bits, y bits, start and end of their text in the buffer (end 0: empty slot).
    pairs: Vec<(u64, u64, usize, usize)>,
    /// z bits, start and end of its text (end 0: none yet).
    z: (u64, usize, usize),
}

impl WordCache {
    /// A table of about a slot per move (a power of two, at most [`PAIR_SLOTS`]); none for a
    /// program of a few blocks (a job's section).
    fn new(moves: usize) -> Self {
        let slots = if moves < 16 { 0 } else { moves.next_power_of_two().min(PAIR_SLOTS) };
        Self { pairs: vec![(0, 0, 0, 0); slots], z: (0, 0, 0) }
    }

    /// The slot of the pair `(x, y)` (bits), when there is a table.
    fn slot(&self, x: u64, y: u64) -> Option<usize> {
        if self.pairs.is_empty() {
            return None;
        }
        let hash = (x ^ y.rotate_left(29)).wrapping_mul(0x9e37_79b9_7f4a_7c15);
        // The top bits, as many as the table has slots (a power of two).
        Some((hash >> (64 - self.pairs.len().trailing_zeros())) as usize)
    }
}

impl Blocks {
    fn new(table: PostTable, moves: usize) -> Self {
        Self { table, text: Buffer::with_capacity(256 + moves * BYTES_PER_MOVE), line: 0, words: WordCache::new(moves) }
    }

    /// Starts a block: its line number, if the post numbers lines.
    fn begin(&mut self) {
        if let Some(step) = self.table.line_numbers {
            self.line += step;
            self.text.push('N');
            number::push_whole(&mut self.text.0, f64::from(self.line));
            self.text.push(' ');
        }
    }

    /// Ends a block.
    fn end(&mut self) {
        self.text.push_str(self.table.block_end);
        self.text.push('\n');
    }

    /// One block of fixed words.
    fn block(&mut self, words: &str) {
        self.begin();
        self.text.push_str(words);
        self.end();
    }

    /// A comment block, cut to the longest line the control takes.
    fn comment(&mut self, text: &str) {
        self.begin();
        let room = self.table.max_line.map(|max| max.saturating_sub(self.text.0.len() - self.text.line_start()));
        push_comment(&mut self.text, self.table.comment, text, room);
        self.end();
    }

    /// ` X…` in the post's decimal format.
    fn word(&mut self, letter: char, value: f64) {
        self.text.push(' ');
        self.text.push(letter);
        number::push_fixed(&mut self.text.0, value, self.table.decimals, self.table.plus_sign);
    }

    /// `G00 Z…` (the rapid word of the post) to the clearance plane.
    fn rapid_z(&mut self, z: f64) {
        self.begin();
        self.text.push_str(self.table.motion[0]);
        self.word('Z', z);
        self.end();
    }

    /// The spindle speed and start.
    fn spindle(&mut self, rpm: f64, direction: SpindleDirection) {
        self.begin();
        self.text.push('S');
        number::push_whole(&mut self.text.0, rpm.round());
        self.text.push(' ');
        self.text.push_str(self.table.spindle[direction as usize]);
        self.end();
    }

    /// The tool call of `tool` with its length offset at `safe_z`.
    fn tool_call(&mut self, tool: &ToolCall, safe_z: f64) {
        if let (ToolCall::Named { number, name }, ToolChange::SinumerikD1) = (tool, self.table.tool_change) {
            // The number as a comment: the operator's and the job program's key to the table.
            self.block(&format!("T=\"{name}\" D1 ; T{number}"));
            self.block("M6");
            self.rapid_z(safe_z);
            return;
        }
        match tool {
            ToolCall::Table(number) | ToolCall::Named { number, .. } => match self.table.tool_change {
                ToolChange::M06WithG43 => {
                    self.block(&format!("T{number} M06"));
                    self.begin();
                    let _ = write!(self.text, "{} G43 H{number}", self.table.motion[0]);
                    self.word('Z', safe_z);
                    self.end();
                }
                ToolChange::SinumerikD1 => {
                    self.block(&format!("T{number} D1"));
                    self.block("M6");
                    self.rapid_z(safe_z);
                }
                ToolChange::HeidenhainIso => {
                    self.block(&format!("T{number} G17"));
                    self.begin();
                    let _ = write!(self.text, "{} G40 G90", self.table.motion[0]);
                    self.word('Z', safe_z);
                    self.end();
                }
                ToolChange::Pause => {
                    self.comment(&format!("load tool T{number} and set its length, then cycle start"));
                    self.block(self.table.pause);
                    self.rapid_z(safe_z);
                }
            },
            ToolCall::Manual(description) => {
                self.comment(&format!("TOOL NOT IN THE TOOL TABLE: {description}"));
                self.comment("LOAD IT, ACTIVATE ITS LENGTH OFFSET, THEN CYCLE START");
                self.block(self.table.pause);
                self.rapid_z(safe_z);
            }
        }
    }

    /// The program's start up to its first move.
    fn heading(&mut self, program: &Program<'_>) {
        match self.table.heading {
            Heading::Percent(digits) => {
                self.text.push_str("%\n");
                let _ = write!(self.text, "O{:0digits$} ", program.number);
                push_comment(&mut self.text, self.table.comment, program.title, None);
                self.text.push('\n');
            }
            Heading::Title => self.comment(program.title),
            Heading::HeidenhainIso => {
                let _ = writeln!(self.text, "%KERF{} {} *", program.number, iso_units(program.units));
                self.comment(program.title);
            }
        }
        for line in &program.comments {
            self.comment(line);
        }
        self.block(match program.units {
            Units::Mm => self.table.safety,
            Units::Inch => self.table.inch_safety,
        });
        match self.table.blending {
            Blending::None => {}
            Blending::Tolerance => {
                // `G64 P0` is LinuxCNC's `G64` without a tolerance (blend as far as the speed
                // asks): a tolerance finer than the program's least increment (0.0001 in, 0.00254
                // mm, in an inch program) is written as that increment, the tightest it can say.
                let tolerance = program.blend_tolerance.max(number::least_increment(self.table.decimals));
                self.begin();
                self.text.push_str("G64 P");
                number::push_fixed(&mut self.text.0, tolerance, self.table.decimals, false);
                self.end();
            }
            Blending::Word(word) => self.block(word),
        }
        self.tool_call(&program.tool, program.safe_z);
        self.spindle(program.spindle_rpm, program.spindle_direction);
    }

    /// A stop between moves.
    fn stop(&mut self, program: &Program<'_>, stop: &ProgramStop) {
        self.block(self.table.spindle[2]);
        self.rapid_z(program.safe_z);
        if let Some(notice) = &stop.notice {
            self.comment(notice);
            self.block(self.table.pause);
        }
        if let Some(tool) = &stop.tool {
            self.tool_call(tool, program.safe_z);
        }
        self.spindle(stop.spindle_rpm, program.spindle_direction);
    }

    /// The end: spindle stop, up to the clearance plane, program end.
    fn ending(&mut self, program: &Program<'_>) {
        self.block(self.table.spindle[2]);
        self.rapid_z(program.safe_z);
        self.block(self.table.end);
        match self.table.heading {
            Heading::Percent(_) => self.text.push_str("%\n"),
            Heading::Title => {}
            Heading::HeidenhainIso => {
                let _ = writeln!(self.text, "N99999999 %KERF{} {} *", program.number, iso_units(program.units));
            }
        }
    }

    fn program<E>(
        &mut self,
        program: &Program<'_>,
        stops: &[ProgramStop],
        mut check: impl FnMut() -> Result<(), E>,
    ) -> Result<(), E> {
        self.heading(program);
        let decimals = self.table.decimals;
        let mut current_feed: Option<f64> = None;
        let mut position: Option<Vec3> = None;
        let mut stops = stops.iter().peekable();
        for (index, step) in program.path.moves.iter().enumerate() {
            if index % MOVES_PER_CHECK == 0 {
                check()?;
            }
            while let Some(stop) = stops.next_if(|stop| stop.before <= index) {
                self.stop(program, stop);
                if let Some(at) = &mut position {
                    at.z = program.safe_z;
                }
                // The first feed move after the change states its feed again.
                current_feed = None;
            }
            let feed = match step.motion {
                Motion::Rapid => {
                    self.motion(0, step.to);
                    self.end();
                    position = Some(step.to);
                    continue;
                }
                // An arc needs its start; a path never starts with one (the post writes a
                // straight move there rather than a wrong centre). An arc whose printed end is its
                // printed start would be a full circle on one control and nothing on another:
                // written as the straight move it is meant to be (producers split full circles).
                Motion::Arc { feed, centre, clockwise }
                    if position.is_some_and(|start| !same_printed(start, step.to, decimals)) =>
                {
                    let start = position.unwrap_or_default();
                    if self.table.arcs == ArcCentre::AbsoluteBlock {
                        if !number::prints_equal(start.z, step.to.z, decimals) {
                            // Heidenhain ISO has no helix in Cartesian words: chords.
                            self.helix_chords(
                                start,
                                step.to,
                                centre,
                                clockwise,
                                feed,
                                program.blend_tolerance,
                                &mut current_feed,
                            );
                            position = Some(step.to);
                            continue;
                        }
                        self.begin();
                        self.text.push('I');
                        number::push_fixed(&mut self.text.0, centre.x, decimals, self.table.plus_sign);
                        self.word('J', centre.y);
                        self.end();
                    }
                    self.motion(if clockwise { 2 } else { 3 }, step.to);
                    if self.table.arcs == ArcCentre::Relative {
                        self.word('I', centre.x - start.x);
                        self.word('J', centre.y - start.y);
                    }
                    feed
                }
                Motion::Linear { feed } | Motion::Arc { feed, .. } => {
                    self.motion(1, step.to);
                    program.plunge_feed_of(position, step.to, feed).unwrap_or(feed)
                }
            };
            self.feed(feed, &mut current_feed);
            self.end();
            position = Some(step.to);
        }
        self.ending(program);
        Ok(())
    }

    /// Starts a motion block: its word (0 rapid, 1 linear, 2 clockwise, 3 counter-clockwise) and
    /// end point.
    fn motion(&mut self, word: usize, to: Vec3) {
        self.begin();
        self.text.push_str(self.table.motion[word]);
        let (x, y, z) = (to.x.to_bits(), to.y.to_bits(), to.z.to_bits());
        match self.words.slot(x, y) {
            Some(slot) => {
                let (x0, y0, start, end) = self.words.pairs[slot];
                if end > 0 && x0 == x && y0 == y {
                    self.text.0.extend_from_within(start..end);
                } else {
                    let start = self.text.0.len();
                    self.word('X', to.x);
                    self.word('Y', to.y);
                    self.words.pairs[slot] = (x, y, start, self.text.0.len());
                }
            }
            None => {
                self.word('X', to.x);
                self.word('Y', to.y);
            }
        }
        let (z0, start, end) = self.words.z;
        if end > 0 && z0 == z {
            self.text.0.extend_from_within(start..end);
        } else {
            let start = self.text.0.len();
            self.word('Z', to.z);
            self.words.z = (z, start, self.text.0.len());
        }
    }

    /// ` F…` when the feed changes.
    fn feed(&mut self, feed: f64, current: &mut Option<f64>) {
        if *current != Some(feed) {
            self.text.push_str(" F");
            number::push_feed(&mut self.text.0, feed);
            *current = Some(feed);
        }
    }

    /// A helical arc as straight feed moves within `tolerance` of it.
    #[allow(clippy::too_many_arguments)]
    fn helix_chords(
        &mut self,
        start: Vec3,
        end: Vec3,
        centre: Vec3,
        clockwise: bool,
        feed: f64,
        tolerance: f64,
        current_feed: &mut Option<f64>,
    ) {
        for point in helix_points(start, end, centre, clockwise, tolerance) {
            self.motion(1, point);
            self.feed(feed, current_feed);
            self.end();
        }
    }
}

/// The points ending the chords of a helical arc from `start` to `end` about `centre` (the arc
/// of at most a full turn in the given sense), each chord within `tolerance` of the arc; the last
/// is `end`.
pub(crate) fn helix_points(start: Vec3, end: Vec3, centre: Vec3, clockwise: bool, tolerance: f64) -> Vec<Vec3> {
    let radius = (start.x - centre.x).hypot(start.y - centre.y);
    let from = (start.y - centre.y).atan2(start.x - centre.x);
    let to = (end.y - centre.y).atan2(end.x - centre.x);
    let mut sweep = if clockwise { from - to } else { to - from };
    if sweep <= 0.0 {
        sweep += std::f64::consts::TAU;
    }
    let tolerance = tolerance.max(1e-6);
    let step = if radius > tolerance { 2.0 * (1.0 - tolerance / radius).acos() } else { sweep };
    let count = (sweep / step.max(1e-6)).ceil().clamp(1.0, 100_000.0) as usize;
    let sense = if clockwise { -1.0 } else { 1.0 };
    (1..=count)
        .map(|k| {
            if k == count {
                return end;
            }
            let t = k as f64 / count as f64;
            let angle = from + sense * sweep * t;
            Vec3::new(centre.x + radius * angle.cos(), centre.y + radius * angle.sin(), start.z + (end.z - start.z) * t)
        })
        .collect()
}

/// Appends a comment in `style` (upper case, no parentheses or control characters), its text cut
/// so the comment takes at most `room` characters.
fn push_comment(out: &mut Buffer, style: CommentStyle, text: &str, room: Option<usize>) {
    let cleaned = clean_comment(text);
    let (open, close) = match style {
        CommentStyle::Parentheses => ("(", ")"),
        CommentStyle::Semicolon => ("; ", ""),
    };
    let fits = room.map_or(cleaned.len(), |room| room.saturating_sub(open.len() + close.len()).min(cleaned.len()));
    out.push_str(open);
    out.push_str(cleaned[..fits].trim_end());
    out.push_str(close);
}

/// A comment's text: upper case ASCII, no parentheses or control characters, trimmed.
fn clean_comment(text: &str) -> String {
    let cleaned: String = text
        .chars()
        .map(|c| if c == '(' || c == ')' || c.is_control() || !c.is_ascii() { ' ' } else { c.to_ascii_uppercase() })
        .collect();
    cleaned.trim().to_owned()
}

/// Heidenhain ISO's units word: G71 mm, G70 inch.
pub(crate) fn iso_units(units: Units) -> &'static str {
    match units {
        Units::Mm => "G71",
        Units::Inch => "G70",
    }
}

/// Whether `a` and `b` print as the same X and Y.
pub(crate) fn same_printed(a: Vec3, b: Vec3, decimals: usize) -> bool {
    number::prints_equal(a.x, b.x, decimals) && number::prints_equal(a.y, b.y, decimals)
}

/// Whether the straight move from `from` to `to` goes straight down the tool axis.
fn is_plunge(from: Vec3, to: Vec3) -> bool {
    to.z < from.z - 1e-9 && (to.x - from.x).abs() <= 1e-9 && (to.y - from.y).abs() <= 1e-9
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
    fn haas_smoothing_is_written_only_on_haas_and_when_asked() {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(1.0, 2.0, 50.0));
        path.linear(Vec3::new(1.0, 2.0, 3.0), 300.0);
        let program = |dialect| Program {
            dialect,
            number: 1000,
            title: "smooth",
            comments: Vec::new(),
            tool: ToolCall::Table(7),
            spindle_rpm: 6000.0,
            spindle_direction: SpindleDirection::Cw,
            safe_z: 50.0,
            blend_tolerance: 0.01,
            plunges: None,
            units: Units::Mm,
            path: &path,
        };
        let haas = write(&program(Dialect::Haas));
        let smooth = with_haas_smoothing(haas.clone(), Dialect::Haas, Some(2));
        assert!(smooth.starts_with("%\nO01000 (SMOOTH)\nG21 G17 G90 G40 G49 G80 G94\nG187 P2\nT7 M06\n"), "{smooth}");
        assert_eq!(smooth.len(), haas.len() + "G187 P2\n".len());
        assert_eq!(with_haas_smoothing(haas.clone(), Dialect::Haas, None), haas);
        let inch = write(&Program { units: Units::Inch, ..program(Dialect::Haas) });
        let smooth_inch = with_haas_smoothing(inch, Dialect::Haas, Some(3));
        assert!(smooth_inch.contains("\nG20 G17 G90 G40 G49 G80 G94\nG187 P3\n"), "{smooth_inch}");
        let fanuc = write(&program(Dialect::Fanuc));
        assert_eq!(with_haas_smoothing(fanuc.clone(), Dialect::Fanuc, Some(2)), fanuc);
        // A program of another layout: after its heading, unless it sets its own smoothing.
        assert_eq!(with_haas_smoothing("G00 X1\n".to_owned(), Dialect::Haas, Some(3)), "G187 P3\nG00 X1\n");
        assert_eq!(
            with_haas_smoothing("%\r\nO1234 (CAM)\r\n(OP 1)\r\nG21 G90\r\n".to_owned(), Dialect::Haas, Some(1)),
            "%\r\nO1234 (CAM)\r\n(OP 1)\r\nG187 P1\r\nG21 G90\r\n"
        );
        let own = "%\nO1234\nG187 P3 E0.01\nG01 X1 F100\n".to_owned();
        assert_eq!(with_haas_smoothing(own.clone(), Dialect::Haas, Some(1)), own);
        let commented = "(NO G187 HERE)\nG01 X1 F100\n".to_owned();
        assert_eq!(with_haas_smoothing(commented, Dialect::Haas, Some(2)), "(NO G187 HERE)\nG187 P2\nG01 X1 F100\n");
    }

    #[test]
    fn a_manual_tool_change_quotes_the_radius_in_the_programs_units() {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(0.0, 0.0, 25.4));
        path.linear(Vec3::new(25.4, 0.0, -2.54), 254.0);
        path.linear(Vec3::new(50.8, 0.0, -2.54), 254.0);
        let tool = crate::tool::Tool::new(crate::tool::ToolKind::Flat, 3.175);
        let stop = ProgramStop {
            before: 2,
            notice: Some("check the 12.7 mm bore".to_owned()),
            tool: Some(ToolCall::for_tool(&tool)),
            spindle_rpm: 5000.0,
        };
        for (units, radius, notice) in [
            (Units::Mm, "RADIUS 3.1750 MM)", "(CHECK THE 12.7 MM BORE)"),
            (Units::Inch, "RADIUS 0.12500 IN)", "(CHECK THE 0.5000 IN BORE)"),
        ] {
            for dialect in Dialect::ALL {
                let program = Program {
                    dialect,
                    number: 1000,
                    title: "manual",
                    comments: Vec::new(),
                    tool: ToolCall::for_tool(&tool),
                    spindle_rpm: 6000.0,
                    spindle_direction: SpindleDirection::Cw,
                    safe_z: 25.4,
                    blend_tolerance: 0.01,
                    plunges: None,
                    units,
                    path: &path,
                };
                let text = write_changing(&program, std::slice::from_ref(&stop));
                let changes: Vec<&str> = text.lines().filter(|l| l.contains("TOOL NOT IN THE TOOL TABLE")).collect();
                assert_eq!(changes.len(), 2, "{text}");
                // The post's comment style around it (`(…)`, `; …`, line numbers, block ends).
                let bare = |line: &str| line.trim_end_matches(" *").trim_end_matches(')').to_owned() + ")";
                assert!(changes.iter().all(|line| bare(line).ends_with(radius)), "{dialect:?} {units:?}: {text}");
                let notice = notice.trim_matches(|c| c == '(' || c == ')');
                assert!(text.contains(notice), "{dialect:?} {units:?}: {text}");
            }
        }
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
            units: crate::units::Units::Mm,
        };
        let fanuc = write(&program);
        assert!(fanuc.starts_with("%\nO1000 (KERF TEST)\n(TOOL T7)\nG21"));
        assert!(fanuc.contains("T7 M06\nG00 G43 H7 Z50.0000\nS6000 M03\n"));
        assert!(fanuc.contains("G01 X1.0000 Y2.0000 Z3.0000 F300\nG01 X2.0000 Y2.0000 Z3.0000\n"));
        assert!(fanuc.ends_with("M05\nG00 Z50.0000\nM30\n%\n"));
        let linuxcnc = write(&Program { dialect: Dialect::Linuxcnc, ..program.clone() });
        assert!(linuxcnc.starts_with("(KERF TEST)\n"));
        assert!(linuxcnc.contains("G64 P0.0100\n"));
        assert!(!linuxcnc.contains('%'));
        // Finer than 0.0001 of the program's unit: the least increment, never `G64 P0.0000`
        // (no tolerance at all).
        for (tolerance, units, written) in [
            (0.001, Units::Inch, "G64 P0.0001\n"),
            (0.00004, Units::Mm, "G64 P0.0001\n"),
            (0.0002, Units::Mm, "G64 P0.0002\n"),
            (0.00254 * 3.0, Units::Inch, "G64 P0.0003\n"),
        ] {
            let text =
                write(&Program { dialect: Dialect::Linuxcnc, blend_tolerance: tolerance, units, ..program.clone() });
            assert!(text.contains(written), "{tolerance} mm in {units:?}:\n{text}");
        }
    }

    /// A layered path: the same X/Y pairs at four heights (more pairs than table slots, so pairs
    /// share slots), with values whose bits differ but whose text is the same (±0, a hair apart),
    /// ties of the rounding and repeated heights.
    fn layered_path() -> Toolpath {
        let mut draw = 0x2545_f491_4f6c_dd1du64;
        let mut unit = || {
            draw ^= draw >> 12;
            draw ^= draw << 25;
            draw ^= draw >> 27;
            (draw.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
        };
        let special = [0.0, -0.0, 0.00005, -0.00005, 1.00001, 1.00002, 12.0, -1e-7, 1.23455];
        let pairs: Vec<(f64, f64)> = (0..9000)
            .map(|k| match k % 5 {
                0 => (special[k % special.len()], special[(k / 5) % special.len()]),
                1 => ((unit() - 0.5) * 2000.0, (unit() - 0.5) * 1e-3),
                _ => ((unit() - 0.5) * 200.0, (unit() - 0.5) * 200.0),
            })
            .collect();
        let mut path = Toolpath::default();
        for (layer, z) in [-1.0, -2.0, -2.0, -0.0].into_iter().enumerate() {
            path.rapid(Vec3::new(pairs[0].0, pairs[0].1, 50.0));
            for (k, (x, y)) in pairs.iter().enumerate().skip(layer) {
                let z = if k % 97 == 0 { z - 0.5 } else { z };
                path.linear(Vec3::new(*x, *y, z), 1000.0 + (k % 3) as f64);
            }
        }
        path
    }

    #[test]
    fn repeated_end_points_are_written_as_formatted_afresh() {
        let path = layered_path();
        let before = reference::COMPARED.with(std::cell::Cell::get);
        for dialect in Dialect::ALL {
            let Some(table) = dialect.table() else { continue };
            let program = Program {
                dialect,
                number: 1000,
                title: "layers",
                comments: Vec::new(),
                tool: ToolCall::Table(3),
                spindle_rpm: 6000.0,
                spindle_direction: SpindleDirection::Cw,
                safe_z: 50.0,
                blend_tolerance: 0.01,
                plunges: Some(Plunges { feed: Some(300.0) }),
                units: Units::Mm,
                path: &path,
            };
            let cached = write(&program);
            // A writer sized for no moves keeps no table of written words: every word formatted.
            let mut fresh = Blocks::new(table, 0);
            assert!(fresh.words.pairs.is_empty());
            let Ok(()) = fresh.program(&program, &[], || Ok::<(), std::convert::Infallible>(()));
            assert_eq!(cached, fresh.text.into_string(), "{dialect:?}");
        }
        // Fanuc and LinuxCNC were also compared with the old writer (`reference::check`).
        assert_eq!(reference::COMPARED.with(std::cell::Cell::get), before + 2);
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
            units: crate::units::Units::Mm,
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

/// Every post's program of one small path (a plunge, a line, two half circles, a helical arc, a
/// stop turning the part with a change to a named tool, a manual tool), kept as golden files in
/// `solver/src/gcode/golden/` that a reviewer reads against the control's manual.
/// `KERF_UPDATE_GOLDEN=1` writes them anew.
#[cfg(test)]
mod golden {
    use super::*;

    fn path() -> Toolpath {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(10.0, 0.0, 30.0));
        path.linear(Vec3::new(10.0, 0.0, -1.0), 400.0);
        path.linear(Vec3::new(20.0, 0.0, -1.0), 400.0);
        let centre = Vec3::new(10.0, 0.0, -1.0);
        path.arc(Vec3::new(0.0, 0.0, -1.0), centre, false, 600.0);
        path.arc(Vec3::new(20.0, 0.0, -1.0), centre, false, 600.0);
        path.arc(Vec3::new(0.0, 0.0, -2.0), centre, true, 600.0);
        path.rapid(Vec3::new(0.0, 0.0, 30.0));
        path.rapid(Vec3::new(-5.0, 0.0, 30.0));
        path.linear(Vec3::new(-5.0, 0.0, -0.00001), 333.3);
        path.rapid(Vec3::new(-5.0, 0.0, 30.0));
        path
    }

    fn program(dialect: Dialect, path: &Toolpath, tool: ToolCall) -> Program<'_> {
        Program {
            dialect,
            number: 1000,
            title: "kerf golden (test)",
            comments: vec![
                "tool T7 ball R3.0000, a comment long enough to be cut where a control takes short lines only"
                    .to_owned(),
            ],
            tool,
            spindle_rpm: 6000.4,
            spindle_direction: SpindleDirection::Cw,
            safe_z: 30.0,
            blend_tolerance: 0.01,
            plunges: Some(Plunges { feed: None }),
            path,
            units: crate::units::Units::Mm,
        }
    }

    #[test]
    fn every_post_writes_its_golden_file() {
        let path = path();
        let stop = ProgramStop {
            before: 6,
            notice: Some("turn the part".to_owned()),
            // A named tool: Sinumerik calls it by name, the others by number.
            tool: Some(ToolCall::Named { number: 8, name: "BALL R3 LONG".to_owned() }),
            spindle_rpm: 5000.0,
        };
        let folder = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/gcode/golden");
        for dialect in Dialect::ALL {
            let mut text = write_changing(&program(dialect, &path, ToolCall::Table(7)), std::slice::from_ref(&stop));
            text.push_str(&write(&program(dialect, &path, ToolCall::Manual("ball radius 3.0000 mm".to_owned()))));
            let file = folder.join(format!("{}.nc", dialect.as_str()));
            if std::env::var("KERF_UPDATE_GOLDEN").is_ok_and(|v| v == "1") {
                std::fs::write(&file, &text).unwrap();
            }
            let golden = std::fs::read_to_string(&file).unwrap_or_default();
            assert_eq!(text, golden, "{} differs from {}", dialect.as_str(), file.display());
            if let Some(max) = dialect.table().and_then(|table| table.max_line) {
                assert!(text.lines().all(|line| line.len() <= max), "{text}");
            }
        }
    }
}
