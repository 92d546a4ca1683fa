//! One program per job (docs/spec/api.md Jobs; docs/guide/jobs.md): the programs of a
//! job's operations, each written by [`super::write`], joined into one program a control runs from
//! start to end: one program number, one header listing the operations with their tools and
//! estimated times, each operation with its tool change, spindle and coolant, a retract to the
//! job's clearance height between operations, and one program end.
//!
//! The operations' programs are kept as text (a job stores them as its endpoints write them), so
//! [`Section::parse`] reads back exactly the layout [`super::write`] produces; a program of any
//! other layout (predict's corrected copy of a caller's own program) is not a section and is
//! listed in the header as not included.

use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use super::table::{ArcCentre, Blending, CommentStyle, Heading, PostTable, ToolChange};
use super::{Blocks, Dialect, comment, mm};
use crate::error::SolverError;
use crate::units::Units;

/// Lowest and highest program number a job may ask for: Fanuc's `O1`–`O7999` (8000–9999 hold
/// the machine builder's protected programs and macros).
pub const PROGRAM_NUMBERS: std::ops::RangeInclusive<u32> = 1..=7999;

/// Job programs numbered from the job id use `O2000`–`O7999`, clear of the `O1000` and `O1001`
/// of the single-operation programs.
const FIRST_JOB_NUMBER: u32 = 2000;

/// The default program number of job `id`: `2000 + (id − 1) mod 6000`, so the last 6000 jobs of
/// a service never share one and none equals a single-operation program's.
pub fn number_for_job(id: i64) -> u32 {
    let span = i64::from(*PROGRAM_NUMBERS.end() - FIRST_JOB_NUMBER + 1);
    FIRST_JOB_NUMBER + u32::try_from((id - 1).rem_euclid(span)).unwrap_or(0)
}

/// Checks a program number asked for in a job file.
///
/// # Errors
/// `E_INPUT` at `field` outside [`PROGRAM_NUMBERS`].
pub fn check_number(field: &str, number: u32) -> Result<(), SolverError> {
    if PROGRAM_NUMBERS.contains(&number) {
        Ok(())
    } else {
        Err(SolverError::input(
            field,
            format!(
                "program number {number} is outside {}–{} (8000–9999 are the control's protected programs)",
                PROGRAM_NUMBERS.start(),
                PROGRAM_NUMBERS.end()
            ),
        ))
    }
}

/// Coolant for every operation of a job program (the post's codes: `M08`/`M07` on, `M09` off
/// on Fanuc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Coolant {
    /// No coolant code (the operator's choice at the machine).
    #[default]
    Off,
    /// `M08` after the spindle starts, `M09` after it stops.
    Flood,
    /// `M07` after the spindle starts, `M09` after it stops.
    Mist,
}

/// One operation of a job as the job program needs it.
#[derive(Debug, Clone, Copy)]
pub struct Operation<'a> {
    /// The capability's name (`deburr`, ...).
    pub name: &'a str,
    /// Its program, if one was written.
    pub program: Option<&'a str>,
    /// Why none was written, if so.
    pub problem: Option<&'a str>,
    /// The tool in words with its lengths in mm (`ball radius 3.0000 mm`), if the operation has
    /// one; an inch job program restates them.
    pub tool: Option<&'a str>,
    /// Rapid feed of its machine, mm/min (for the time estimate; rapids untimed without it).
    pub rapid_feed: Option<f64>,
    /// Time of a tool change on its machine, s.
    pub tool_change_s: Option<f64>,
}

/// What the job program is called and how it is written.
#[derive(Debug, Clone)]
pub struct Job<'a> {
    /// Dialect of the job program.
    pub dialect: Dialect,
    /// Program number (`O` word for Fanuc; named in the title comment for LinuxCNC).
    pub number: u32,
    /// Title, e.g. `kerf job 42 tube`.
    pub title: &'a str,
    /// Coolant of every operation.
    pub coolant: Coolant,
    /// The job's machine's Haas smoothing level (`G187 P…` after the safety block, as in every
    /// Haas program; [`super::with_haas_smoothing`]).
    pub haas_smoothing: Option<u8>,
}

/// One operation's program, read back into its parts (line numbers and block ends taken off).
#[derive(Debug, Clone, PartialEq)]
pub struct Section<'a> {
    /// The program's title comment (`(KERF DEBURR)`).
    pub title: &'a str,
    /// Its header comment lines.
    pub comments: Vec<&'a str>,
    /// The units of its lengths and feeds, from its safety block (G21 or G20, and the like).
    pub units: Units,
    /// The blending line (LinuxCNC's `G64 P…`, Sinumerik's `G642`), if written.
    pub blend: Option<&'a str>,
    /// The tool number of the tool call (`T n M06`); `None` for a manual change.
    pub tool_number: Option<u32>,
    /// The tool-change lines up to the length offset, without the clearance move.
    pub tool_change: Vec<&'a str>,
    /// The clearance move's words before its Z (`G00 G43 H7`).
    pub clearance_words: &'a str,
    /// Z of the operation's clearance plane.
    pub safe_z: f64,
    /// The spindle line (`S6000 M03`).
    pub spindle: &'a str,
    /// The moves, up to the spindle stop, with the tool changes between them (written by
    /// [`super::write_changing`]).
    pub moves: Vec<&'a str>,
    /// The tools the moves change to, in order (`None`: a manual change).
    pub changes: Vec<Option<u32>>,
    /// The line (from 1) of the first of `moves` in the operation's program, which its warnings'
    /// `AT LINE` count (0 without moves).
    pub first_move_line: usize,
}

/// The line (from 1) of `text` on which `part`, a slice of it, starts.
fn line_of(text: &str, part: &str) -> usize {
    let at = (part.as_ptr() as usize).saturating_sub(text.as_ptr() as usize).min(text.len());
    text.as_bytes()[..at].iter().filter(|&&byte| byte == b'\n').count() + 1
}

/// A block without its line number and block end.
fn bare<'t>(line: &'t str, table: &PostTable) -> &'t str {
    let line = match (table.line_numbers, line.strip_prefix('N')) {
        (Some(_), Some(rest)) => rest
            .split_once(' ')
            .map_or(line, |(number, rest)| if number.bytes().all(|b| b.is_ascii_digit()) { rest } else { line }),
        _ => line,
    };
    if table.block_end.is_empty() { line } else { line.strip_suffix(table.block_end).unwrap_or(line) }
}

/// Whether a line is a comment of `table`'s style.
fn is_comment(line: &str, table: &PostTable) -> bool {
    match table.comment {
        CommentStyle::Parentheses => line.starts_with('(') && line.ends_with(')'),
        CommentStyle::Semicolon => line.starts_with(';'),
    }
}

/// The tool number a tool-call line of `table` names.
fn tool_call_number(line: &str, table: &PostTable) -> Option<u32> {
    let call = match table.tool_change {
        ToolChange::M06WithG43 => line.strip_prefix('T')?.strip_suffix(" M06")?,
        // A call by name carries its number as a comment (`T="NAME" D1 ; T7`).
        ToolChange::SinumerikD1 if line.starts_with("T=\"") => line.rsplit_once(" D1 ; T")?.1,
        ToolChange::SinumerikD1 => line.strip_prefix('T')?.strip_suffix(" D1")?,
        ToolChange::HeidenhainIso => line.strip_prefix('T')?.strip_suffix(" G17")?,
        ToolChange::Pause => {
            let text = line.strip_prefix("(LOAD TOOL T")?;
            &text[..text.find(' ')?]
        }
    };
    call.parse().ok()
}

impl<'a> Section<'a> {
    /// Reads a program written by [`super::write`] for a post of `table`'s words; `None` for any
    /// other layout.
    pub fn parse(text: &'a str, table: &PostTable) -> Option<Self> {
        let mut lines = text
            .lines()
            .filter(|line| *line != "%" && !(line.starts_with('%') || line.starts_with("N99999999 %")))
            .map(|line| bare(line, table))
            .peekable();
        let first = lines.next()?;
        let title = match first.strip_prefix('O') {
            Some(rest) => rest.split_once(' ')?.1,
            None => first,
        };
        is_comment(title, table).then_some(())?;
        let mut comments = Vec::new();
        while let Some(line) = lines.next_if(|line| is_comment(line, table)) {
            comments.push(line);
        }
        let safety = lines.next()?;
        let units = match (safety == table.safety, safety == table.inch_safety) {
            // Heidenhain ISO says its units in the `%` line (G70 inch, G71 mm), not in the block.
            (true, true) => match text.lines().next()?.split(' ').find(|word| matches!(*word, "G70" | "G71"))? {
                "G70" => Units::Inch,
                _ => Units::Mm,
            },
            (true, false) => Units::Mm,
            (false, true) => Units::Inch,
            (false, false) => return None,
        };
        // Haas smoothing, which the joined program sets once for the job.
        lines.next_if(|line| line.starts_with("G187 P"));
        let blend = lines.next_if(|line| match table.blending {
            Blending::Word(word) => *line == word,
            _ => line.starts_with("G64 "),
        });
        let mut tool_change = Vec::new();
        let rapid = table.motion[0];
        let mut tool_number = None;
        while let Some(line) = lines.next_if(|line| !line.starts_with(rapid)) {
            if let Some(number) = tool_call_number(line, table) {
                tool_number = Some(number);
            }
            tool_change.push(line);
        }
        let (clearance_words, clearance) = lines.next()?.rsplit_once(" Z")?;
        let safe_z: f64 = clearance.parse().ok()?;
        let spindle = lines.next()?;
        let spindle_on = |line: &str| {
            line.starts_with('S')
                && table.spindle[..2].iter().any(|code| line.strip_suffix(code).is_some_and(|s| s.ends_with(' ')))
        };
        spindle_on(spindle).then_some(())?;
        let rest: Vec<&str> = lines.collect();
        let lift = format!("{rapid} Z{clearance}");
        let tail = [table.spindle[2], &lift, table.end];
        let body = rest.len().checked_sub(tail.len())?;
        (rest[body..] == tail).then_some(())?;
        let moves = rest[..body].to_vec();
        let is_move = |line: &str| {
            table.motion.iter().any(|word| line.strip_prefix(word).is_some_and(|rest| rest.starts_with(" X")))
                || (table.arcs == ArcCentre::AbsoluteBlock && line.starts_with('I') && line.contains(" J"))
        };
        let is_change = |line: &str| {
            line == table.spindle[2]
                || line == table.pause
                || is_comment(line, table)
                || line.starts_with(&format!("{rapid} "))
                || tool_call_number(line, table).is_some()
                || line == "M6"
                || spindle_on(line)
        };
        moves.iter().all(|line| is_move(line) || is_change(line)).then_some(())?;
        let mut changes = Vec::new();
        for line in &moves {
            if let Some(number) = tool_call_number(line, table) {
                changes.push(Some(number));
            } else if line.contains("TOOL NOT IN THE TOOL TABLE") {
                changes.push(None);
            }
        }
        Some(Self {
            title,
            comments,
            units,
            blend,
            tool_number,
            tool_change,
            clearance_words,
            safe_z,
            spindle,
            first_move_line: moves.first().map_or(0, |first| line_of(text, first)),
            moves,
            changes,
        })
    }

    /// The feed time of the moves (every feed move at its feed) and their rapid length, s and the
    /// section's units.
    fn feed_time_and_rapids(&self, table: &PostTable) -> (f64, f64) {
        let (mut feed_s, mut rapid_mm) = (0.0, 0.0);
        let mut at: Option<[f64; 3]> = None;
        let mut feed = 0.0;
        let mut centre: Option<[f64; 2]> = None;
        for line in &self.moves {
            let words = Words::of(line, table);
            if words.code.is_none() || words.x.is_none() {
                if let (Some(i), Some(j)) = (words.i, words.j) {
                    // Heidenhain ISO's absolute centre block.
                    centre = Some([i, j]);
                } else if line.starts_with(table.motion[0])
                    && let (Some(z), Some(here)) = (words.z, at.as_mut())
                {
                    // A tool change: the tool goes up (or comes down to the offset) where it is.
                    here[2] = z;
                }
                continue;
            }
            let code = words.code.unwrap_or(0);
            if let Some(f) = words.f {
                feed = f;
            }
            let to = [words.x.unwrap_or(0.0), words.y.unwrap_or(0.0), words.z.unwrap_or(0.0)];
            let Some(from) = at.replace(to) else { continue };
            let straight = ((to[0] - from[0]).powi(2) + (to[1] - from[1]).powi(2) + (to[2] - from[2]).powi(2)).sqrt();
            let arc_centre = match (table.arcs, words.i, words.j) {
                (ArcCentre::Relative, Some(i), Some(j)) => Some([from[0] + i, from[1] + j]),
                (ArcCentre::AbsoluteBlock, ..) => centre,
                _ => None,
            };
            let length = match (code, arc_centre) {
                (2 | 3, Some(centre)) => arc_length(from, to, centre, code == 2),
                _ => straight,
            };
            if code == 0 {
                rapid_mm += length;
            } else if feed > 0.0 {
                feed_s += length / feed * 60.0;
            }
        }
        (feed_s, rapid_mm)
    }
}

/// The words of one motion block.
struct Words {
    /// 0 rapid, 1 linear, 2 clockwise, 3 counter-clockwise; `None`: not a motion block.
    code: Option<usize>,
    x: Option<f64>,
    y: Option<f64>,
    z: Option<f64>,
    i: Option<f64>,
    j: Option<f64>,
    f: Option<f64>,
}

impl Words {
    fn of(line: &str, table: &PostTable) -> Self {
        let mut words = line.split(' ').peekable();
        let code = words.peek().and_then(|first| table.motion.iter().position(|word| word == first));
        if code.is_some() {
            words.next();
        }
        let mut read = Self { code, x: None, y: None, z: None, i: None, j: None, f: None };
        for word in words {
            let value = word.get(1..).and_then(|v| v.parse().ok());
            match word.as_bytes().first() {
                Some(b'X') => read.x = value,
                Some(b'Y') => read.y = value,
                Some(b'Z') => read.z = value,
                Some(b'I') => read.i = value,
                Some(b'J') => read.j = value,
                Some(b'F') => read.f = value,
                _ => {}
            }
        }
        read
    }
}

/// Length of a helical arc in XY about `centre` from `from` to `to` (at most a full turn).
fn arc_length(from: [f64; 3], to: [f64; 3], centre: [f64; 2], clockwise: bool) -> f64 {
    let radius = (from[0] - centre[0]).hypot(from[1] - centre[1]);
    let start = (from[1] - centre[1]).atan2(from[0] - centre[0]);
    let end = (to[1] - centre[1]).atan2(to[0] - centre[0]);
    let mut sweep = if clockwise { start - end } else { end - start };
    if sweep <= 0.0 {
        sweep += std::f64::consts::TAU;
    }
    (radius * sweep).hypot(to[2] - from[2])
}

/// The estimated time of one operation, s: feed moves at their feed, rapids at the machine's
/// rapid feed, one tool change at the machine's tool-change time.
fn estimated_time_s(section: &Section<'_>, operation: &Operation<'_>, table: &PostTable) -> f64 {
    let (feed_s, rapid_length) = section.feed_time_and_rapids(table);
    let rapid_mm = rapid_length * section.units.mm_per_unit();
    let rapid_s = operation.rapid_feed.filter(|f| *f > 0.0).map_or(0.0, |f| rapid_mm / f * 60.0);
    let changes = usize::from(section.tool_number.is_some()) + section.changes.iter().flatten().count();
    let change_s = operation.tool_change_s.unwrap_or(0.0) * changes as f64;
    feed_s + rapid_s + change_s
}

/// The one program of a job: every operation that has a program of [`super::write`]'s layout
/// for the job's post, in order. Operations without one are named in the header as not
/// included.
///
/// # Errors
/// `E_NO_PROGRAM` when no operation has a program, or the post is Heidenhain's Klartext (whose
/// operations run as programs of their own, called by `CALL PGM`).
pub fn write(job: &Job<'_>, operations: &[Operation<'_>]) -> Result<String, SolverError> {
    let Some(table) = job.dialect.table() else {
        return Err(SolverError::new(
            crate::error::ErrorCode::NoProgram,
            "a job's operations are not joined into one Heidenhain Klartext program: run each operation's \
             program (CALL PGM from a main program)",
        ));
    };
    let mut sections: Vec<Option<Section<'_>>> =
        operations.iter().map(|operation| operation.program.and_then(|text| Section::parse(text, &table))).collect();
    // One program runs in one unit system: the first joined operation's. An operation written in
    // the other is left out (named in the header) rather than switched to mid-program, where a
    // machinist restarting at an operation could run it in the wrong units.
    let Some(units) = sections.iter().flatten().map(|section| section.units).next() else {
        return Err(SolverError::new(
            crate::error::ErrorCode::NoProgram,
            "no operation of this job has a program to join",
        ));
    };
    let mut left_out: Vec<Option<String>> = operations
        .iter()
        .map(|operation| {
            Some(
                operation
                    .problem
                    .unwrap_or("its program keeps the layout of the program it corrects: run its own file")
                    .to_owned(),
            )
        })
        .collect();
    for (section, reason) in sections.iter_mut().zip(&mut left_out) {
        match section {
            Some(joined) if joined.units != units => {
                *reason = Some(format!(
                    "its program is in {}, this program in {}: run its own file",
                    joined.units.as_str(),
                    units.as_str()
                ));
                *section = None;
            }
            Some(_) => *reason = None,
            None => {}
        }
    }
    let clearance = sections.iter().flatten().map(|s| s.safe_z).fold(f64::NEG_INFINITY, f64::max);
    let mut out = Blocks::new(table, 0);
    write_header(&mut out, job, operations, &sections, &left_out, units, clearance);
    // Haas smoothing adds its line to the header once the program is written.
    let smoothing_line = usize::from(job.dialect == Dialect::Haas && job.haas_smoothing.is_some());
    let mut lines = LineCount { bytes: 0, lines: smoothing_line };
    for (index, (section, operation)) in sections.iter().zip(operations).enumerate() {
        let Some(section) = section else { continue };
        write_section(&mut out, job, index, operation, section, clearance, &mut lines);
    }
    out.block(table.end);
    match table.heading {
        Heading::HeidenhainIso => {
            let _ = writeln!(out.text, "N99999999 %KERF{} {} *", job.number, super::iso_units(units));
        }
        Heading::Percent(_) => out.text.push_str("%\n"),
        Heading::Title if job.dialect == Dialect::Linuxcnc => out.text.push_str("%\n"),
        Heading::Title => {}
    }
    Ok(super::with_haas_smoothing(out.text.into_string(), job.dialect, job.haas_smoothing))
}

/// The job program's head: number and title, the operations with their tools and times (or why
/// they are left out, `left_out`), the clearance height and the safety line of `units`.
fn write_header(
    out: &mut Blocks,
    job: &Job<'_>,
    operations: &[Operation<'_>],
    sections: &[Option<Section<'_>>],
    left_out: &[Option<String>],
    units: Units,
    clearance: f64,
) {
    let table = out.table;
    match table.heading {
        Heading::Percent(digits) => {
            let _ = writeln!(out.text, "%\nO{:0digits$} {}", job.number, comment(job.title));
        }
        Heading::HeidenhainIso => {
            let _ = writeln!(out.text, "%KERF{} {} *", job.number, super::iso_units(units));
            out.comment(&format!("O{} {}", job.number, job.title));
        }
        Heading::Title => {
            if job.dialect == Dialect::Linuxcnc {
                out.text.push_str("%\n");
            }
            // LinuxCNC reads an O word as a subroutine label: the number is in the title instead.
            out.comment(&format!("O{:04} {}", job.number, job.title));
        }
    }
    let included = sections.iter().flatten().count();
    let mut tools: Vec<u32> = sections
        .iter()
        .flatten()
        .flat_map(|s| s.tool_number.into_iter().chain(s.changes.iter().flatten().copied()))
        .collect();
    tools.sort_unstable();
    tools.dedup();
    let tools: Vec<String> = tools.iter().map(|n| format!("T{n}")).collect();
    let times: Vec<Option<f64>> = sections
        .iter()
        .zip(operations)
        .map(|(section, operation)| section.as_ref().map(|s| estimated_time_s(s, operation, &table)))
        .collect();
    let total: f64 = times.iter().flatten().sum();
    out.comment(&format!(
        "{} operations, {included} in this program, tools {}, estimated {total:.1} s",
        operations.len(),
        if tools.is_empty() { "manual".to_owned() } else { tools.join(" ") }
    ));
    for (index, (operation, time)) in operations.iter().zip(&times).enumerate() {
        let tool = operation.tool.unwrap_or("no tool");
        let line = match (time, &sections[index]) {
            (Some(time), Some(section)) => {
                let call = std::iter::once(section.tool_number)
                    .chain(section.changes.iter().copied())
                    .map(|number| number.map_or_else(|| "manual tool change".to_owned(), |n| format!("T{n}")))
                    .collect::<Vec<_>>()
                    .join(" then ");
                format!("{} {}: {call} {tool}, {time:.1} s", index + 1, operation.name)
            }
            _ => format!(
                "{} {}: not in this program: {}",
                index + 1,
                operation.name,
                left_out[index].as_deref().unwrap_or_default()
            ),
        };
        // The tools' and the reasons' lengths are written in mm: an inch program quotes inches.
        let line = match units.from_mm() {
            Some(scaling) => scaling.restate(&line),
            None => line,
        };
        out.comment(&line);
    }
    out.comment(&format!("clearance between operations Z{}", mm(clearance)));
    out.block(match units {
        Units::Mm => table.safety,
        Units::Inch => table.inch_safety,
    });
}

/// One operation (number `index` from 0) in the job program: its head and tool change, the
/// spindle and coolant on, across at the common clearance height to its first point, its moves,
/// and everything off and up again.
/// The lines of a program being written, counted as far as `bytes`.
struct LineCount {
    bytes: usize,
    lines: usize,
}

impl LineCount {
    /// The lines `text` holds, counting only what was added since the last call.
    fn of(&mut self, text: &[u8]) -> usize {
        self.lines += text[self.bytes..].iter().filter(|&&byte| byte == b'\n').count();
        self.bytes = text.len();
        self.lines
    }
}

fn write_section(
    out: &mut Blocks,
    job: &Job<'_>,
    index: usize,
    operation: &Operation<'_>,
    section: &Section<'_>,
    clearance: f64,
    lines: &mut LineCount,
) {
    let table = out.table;
    out.comment(&format!("operation {} {}", index + 1, operation.name));
    out.block(section.title);
    let comments_at = out.text.0.len();
    for line in &section.comments {
        out.block(line);
    }
    let comments_end = out.text.0.len();
    if job.dialect != Dialect::Fanuc
        && let Some(blend) = section.blend
    {
        out.block(blend);
    }
    for line in &section.tool_change {
        out.block(line);
    }
    out.begin();
    out.text.push_str(section.clearance_words);
    out.word('Z', clearance);
    out.end();
    out.block(section.spindle);
    let coolant = match job.coolant {
        Coolant::Off => None,
        Coolant::Flood => Some(table.coolant[0]),
        Coolant::Mist => Some(table.coolant[1]),
    };
    if let Some(code) = coolant {
        out.block(code);
    }
    // Across to the first point at the clearance height, then down as the operation goes.
    if let Some(first) = section.moves.first() {
        let words = Words::of(first, &table);
        if let (Some(x), Some(y)) = (words.x, words.y) {
            let mut across = Blocks::new(table, 0);
            across.text.push_str(table.motion[0]);
            across.word('X', x);
            across.word('Y', y);
            across.word('Z', clearance);
            if across.text.0 != first.as_bytes() {
                out.block(&across.text.into_string());
            }
        }
    }
    // The warnings count the lines of the operation's own program: here its moves start elsewhere.
    let first_move = lines.of(&out.text.0) + 1;
    let moves = section.first_move_line..section.first_move_line + section.moves.len();
    let comments = String::from_utf8_lossy(&out.text.0[comments_at..comments_end]).into_owned();
    let restated = super::renumber::restate_warnings(&comments, |line| {
        moves.contains(&line).then(|| first_move + (line - section.first_move_line))
    });
    if restated != comments {
        out.text.0.splice(comments_at..comments_end, restated.into_bytes());
        lines.bytes = out.text.0.len();
    }
    for line in &section.moves {
        out.block(line);
    }
    out.block(table.spindle[2]);
    if coolant.is_some() {
        out.block(table.coolant[2]);
    }
    out.rapid_z(clearance);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcode::table::FANUC;
    use crate::gcode::{Program, SpindleDirection, ToolCall};
    use crate::geometry::Vec3;
    use crate::path::Toolpath;

    fn program(dialect: Dialect, tool: ToolCall, safe_z: f64) -> String {
        program_in(dialect, tool, safe_z, crate::units::Units::Mm)
    }

    fn program_in(dialect: Dialect, tool: ToolCall, safe_z: f64, units: Units) -> String {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(1.0, 2.0, safe_z));
        path.linear(Vec3::new(1.0, 2.0, -1.0), 300.0);
        path.linear(Vec3::new(61.0, 2.0, -1.0), 600.0);
        path.rapid(Vec3::new(61.0, 2.0, safe_z));
        super::super::write(&Program {
            dialect,
            number: 1000,
            title: "kerf test",
            comments: vec!["a comment".to_owned()],
            tool,
            spindle_rpm: 6000.0,
            spindle_direction: SpindleDirection::Cw,
            safe_z,
            blend_tolerance: 0.01,
            plunges: Some(super::super::Plunges { feed: None }),
            path: &path,
            units,
        })
    }

    /// A contour operation of `text`, with no tool name, rapid feed or tool-change time.
    fn contour(text: &str) -> Operation<'_> {
        Operation {
            name: "contour",
            program: Some(text),
            problem: None,
            tool: None,
            rapid_feed: None,
            tool_change_s: None,
        }
    }

    #[test]
    fn sections_read_back_what_write_writes() {
        for dialect in Dialect::ALL {
            let Some(table) = dialect.table() else { continue };
            let text = program(dialect, ToolCall::Table(7), 30.0);
            let section = Section::parse(&text, &table).expect("a section");
            assert!(section.title.contains("KERF TEST"), "{text}");
            assert_eq!(section.tool_number, Some(7));
            assert_eq!(section.safe_z, 30.0);
            assert_eq!(section.moves.len(), 4);
            assert_eq!(section.blend.is_some(), matches!(dialect, Dialect::Linuxcnc | Dialect::Sinumerik));
            // 2 mm... the plunge: 31 mm at 150 mm/min, then 60 mm at 600 mm/min.
            let (feed_s, rapid_mm) = section.feed_time_and_rapids(&table);
            assert!((feed_s - (31.0 / 150.0 + 60.0 / 600.0) * 60.0).abs() < 1e-9, "{feed_s}");
            assert!((rapid_mm - 31.0).abs() < 1e-9);
            let manual = program(dialect, ToolCall::Manual("ball R3".to_owned()), 30.0);
            assert_eq!(Section::parse(&manual, &table).expect("a manual section").tool_number, None);
        }
        assert!(Section::parse("G0 X1\nM30\n", &FANUC).is_none());
    }

    #[test]
    fn every_word_post_joins_its_programs_and_klartext_is_refused() {
        for dialect in Dialect::ALL {
            let first = program(dialect, ToolCall::Table(7), 30.0);
            let second = program(dialect, ToolCall::Manual("ball R3".to_owned()), 5.0);
            let operation = |text| Operation {
                name: "deburr",
                program: Some(text),
                problem: None,
                tool: Some("ball R3"),
                rapid_feed: None,
                tool_change_s: None,
            };
            let job =
                Job { dialect, number: 2042, title: "kerf job 42", coolant: Coolant::Flood, haas_smoothing: None };
            let joined = write(&job, &[operation(&first), operation(&second)]);
            let Some(table) = dialect.table() else {
                assert_eq!(joined.unwrap_err().code(), crate::error::ErrorCode::NoProgram);
                continue;
            };
            let text = joined.unwrap();
            assert!(text.contains("2 OPERATIONS, 2 IN THIS PROGRAM"), "{dialect:?}: {text}");
            assert_eq!(
                text.lines().filter(|l| l.ends_with(table.end) || l.contains(&format!(" {} ", table.end))).count(),
                1,
                "{text}"
            );
            assert_eq!(text.matches(table.coolant[0]).count(), 2, "{text}");
            if let Some(step) = table.line_numbers {
                // Numbered again from the start: every block's number one step above the last.
                let numbers: Vec<u32> = text
                    .lines()
                    .filter_map(|l| l.strip_prefix('N')?.split(' ').next()?.parse().ok())
                    .filter(|n| *n != 99_999_999)
                    .collect();
                assert!(numbers.windows(2).all(|w| w[1] == w[0] + step), "{text}");
            }
            if let Some(max) = table.max_line {
                assert!(text.lines().all(|l| l.len() <= max), "{text}");
            }
        }
    }

    #[test]
    fn inch_operations_join_into_an_inch_program_and_the_other_units_are_left_out() {
        for dialect in Dialect::ALL {
            let Some(table) = dialect.table() else { continue };
            let inch = program_in(dialect, ToolCall::Table(7), 25.4, Units::Inch);
            let mm = program_in(dialect, ToolCall::Table(3), 30.0, Units::Mm);
            let operation = |text| Operation {
                name: "contour",
                program: Some(text),
                problem: None,
                tool: Some("ball radius 3.0000 mm"),
                rapid_feed: Some(25_400.0),
                tool_change_s: None,
            };
            let job = Job { dialect, number: 2042, title: "kerf job 42", coolant: Coolant::Off, haas_smoothing: None };
            let text = write(&job, &[operation(&inch), operation(&mm), operation(&inch)]).unwrap();
            let safety_blocks: Vec<&str> = text
                .lines()
                .map(|line| bare(line, &table))
                .filter(|line| [table.safety, table.inch_safety].contains(line))
                .collect();
            assert_eq!(safety_blocks, [table.inch_safety], "{dialect:?}: {text}");
            let upper = text.to_uppercase();
            assert!(upper.contains("3 OPERATIONS, 2 IN THIS PROGRAM"), "{dialect:?}: {text}");
            assert!(
                upper.contains("2 CONTOUR: NOT IN THIS PROGRAM: ITS PROGRAM IS IN MM, THIS PROGRAM IN INCH"),
                "{text}"
            );
            // The tools' lengths are restated in the program's units.
            assert!(upper.contains("BALL RADIUS 0.11811 IN"), "{dialect:?}: {text}");
            assert!(!upper.contains("3.0000 MM"), "{dialect:?}: {text}");
            if dialect == Dialect::HeidenhainIso {
                assert!(text.starts_with("%KERF2042 G70 *") && text.trim_end().ends_with("%KERF2042 G70 *"), "{text}");
            }
            // The rapids are read in inches (26.4 mm of them) and timed at the machine's mm/min.
            let section = Section::parse(&inch, &table).unwrap();
            assert_eq!(section.units, Units::Inch);
            let (feed_s, rapid_in) = section.feed_time_and_rapids(&table);
            assert!((rapid_in - 26.4 / 25.4).abs() < 2e-4, "{rapid_in}");
            let time = estimated_time_s(&section, &operation(&inch), &table);
            assert!((time - feed_s - rapid_in * 25.4 / 25_400.0 * 60.0).abs() < 1e-9, "{time}");
        }
    }

    #[test]
    fn a_job_program_has_one_number_one_end_and_a_change_per_operation() {
        let first = program(Dialect::Fanuc, ToolCall::Table(7), 30.0);
        let second = program(Dialect::Fanuc, ToolCall::Table(3), 5.0);
        let operation = |text| Operation {
            name: "deburr",
            program: Some(text),
            problem: None,
            tool: Some("ball R3"),
            rapid_feed: None,
            tool_change_s: None,
        };
        let missing = Operation { program: None, problem: Some("no path"), ..operation("") };
        let job = Job {
            dialect: Dialect::Fanuc,
            number: 2042,
            title: "kerf job 42",
            coolant: Coolant::Flood,
            haas_smoothing: Some(2),
        };
        let text = write(&job, &[operation(&first), missing, operation(&second)]).unwrap();
        assert!(text.starts_with("%\nO2042 (KERF JOB 42)\n"), "{text}");
        assert_eq!(text.lines().filter(|l| l.starts_with('O')).count(), 1);
        assert_eq!(text.matches("M06").count(), 2);
        assert_eq!(text.matches("M30").count(), 1);
        assert_eq!(text.matches("M08").count(), 2);
        assert!(text.contains("(2 DEBURR: NOT IN THIS PROGRAM: NO PATH)"), "{text}");
        // The second operation comes down from the highest clearance plane of the job.
        assert!(text.contains("T3 M06\nG00 G43 H3 Z30.0000\nS6000 M03\nM08\nG00 X1.0000 Y2.0000 Z30.0000\n"), "{text}");
        assert!(text.ends_with("M05\nM09\nG00 Z30.0000\nM30\n%\n"));
        let none = write(&job, &[missing]).unwrap_err();
        assert_eq!(none.code(), crate::error::ErrorCode::NoProgram);
    }

    /// An operation's warning names a line of its own program; in the job's program its moves
    /// come later, after the other operation's, and the warning names them there (with Haas's
    /// smoothing line in the head too); a line outside the moves (the retract the job writes
    /// anew) loses its number.
    #[test]
    fn an_operations_warnings_name_the_job_programs_lines() {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(1.0, 2.0, 30.0));
        path.linear(Vec3::new(1.0, 2.0, -1.0), 300.0);
        path.linear(Vec3::new(61.0, 2.0, -1.0), 600.0);
        path.rapid(Vec3::new(61.0, 2.0, 30.0));
        for (dialect, smoothing) in [(Dialect::Fanuc, None), (Dialect::Haas, Some(2)), (Dialect::HeidenhainIso, None)] {
            let written = |tool, comments: Vec<String>| {
                super::super::write(&Program {
                    dialect,
                    number: 1000,
                    title: "kerf test",
                    comments,
                    tool,
                    spindle_rpm: 6000.0,
                    spindle_direction: SpindleDirection::Cw,
                    safe_z: 30.0,
                    blend_tolerance: 0.01,
                    plunges: None,
                    path: &path,
                    units: Units::Mm,
                })
            };
            let warnings = |cut: usize, retract: usize| {
                vec![
                    format!("WARNING GOUGE AT LINE {cut}: 0.200 MM DEEP"),
                    format!("WARNING HOLDER CONTACT AT LINE {retract}: 1 MM DEEP"),
                ]
            };
            let draft = written(ToolCall::Table(7), warnings(0, 0));
            let draft_lines: Vec<&str> = draft.lines().collect();
            let cut = 1 + draft_lines.iter().position(|line| line.contains("X61") || line.contains("X+61")).unwrap();
            let retract =
                1 + draft_lines.iter().rposition(|line| line.contains("Z30") || line.contains("Z+30")).unwrap();
            let own = written(ToolCall::Table(7), warnings(cut, retract));
            let own_lines: Vec<&str> = own.lines().collect();
            let plain = written(ToolCall::Table(3), Vec::new());
            let job =
                Job { dialect, number: 2042, title: "kerf job", coolant: Coolant::Off, haas_smoothing: smoothing };
            let text = write(&job, &[contour(&plain), contour(&own)]).unwrap();
            let lines: Vec<&str> = text.lines().collect();
            let table = dialect.table().unwrap();
            let gouge = lines.iter().find(|line| line.contains("WARNING GOUGE")).unwrap();
            let named: usize = gouge.split(" AT LINE ").nth(1).unwrap().split(':').next().unwrap().parse().unwrap();
            assert_eq!(
                bare(lines[named - 1], &table),
                bare(own_lines[cut - 1], &table),
                "{dialect:?}: {named}:\n{text}"
            );
            assert!(named > cut + 5, "{dialect:?}: the second operation's moves come later: {named} (own {cut})");
            let holder = lines.iter().find(|line| line.contains("WARNING HOLDER CONTACT")).unwrap();
            assert!(
                !holder.contains("AT LINE") && holder.contains("HOLDER CONTACT: 1 MM DEEP"),
                "{dialect:?}: {holder}"
            );
        }
    }

    #[test]
    fn stops_inside_an_operation_are_kept_and_counted() {
        let mut path = Toolpath::default();
        path.rapid(Vec3::new(1.0, 2.0, 30.0));
        path.linear(Vec3::new(1.0, 2.0, 20.0), 300.0);
        path.rapid(Vec3::new(1.0, 2.0, 30.0));
        path.rapid(Vec3::new(5.0, 2.0, 30.0));
        path.linear(Vec3::new(5.0, 2.0, 20.0), 300.0);
        let program = Program {
            dialect: Dialect::Fanuc,
            number: 1000,
            title: "kerf deburr",
            comments: Vec::new(),
            tool: ToolCall::Table(7),
            spindle_rpm: 6000.0,
            spindle_direction: SpindleDirection::Cw,
            safe_z: 30.0,
            blend_tolerance: 0.01,
            plunges: None,
            path: &path,
            units: crate::units::Units::Mm,
        };
        let stop = crate::gcode::ProgramStop {
            before: 3,
            notice: Some("turn the tube".to_owned()),
            tool: Some(ToolCall::Table(8)),
            spindle_rpm: 5000.0,
        };
        let text = crate::gcode::write_changing(&program, &[stop]);
        assert!(
            text.contains("G00 X1.0000 Y2.0000 Z30.0000\nM05\nG00 Z30.0000\n(TURN THE TUBE)\nM00\nT8 M06\nG00 G43 H8 Z30.0000\nS5000 M03\nG00 X5.0000"),
            "{text}"
        );
        let section = Section::parse(&text, &FANUC).expect("a section with a stop");
        assert_eq!((section.tool_number, section.changes.clone()), (Some(7), vec![Some(8)]));
        // 10 mm down at 300 mm/min twice, the rapids up and across, two tool changes.
        let operation = Operation {
            name: "deburr",
            program: Some(&text),
            problem: None,
            tool: Some("ball R3"),
            rapid_feed: Some(6000.0),
            tool_change_s: Some(5.0),
        };
        let time = estimated_time_s(&section, &operation, &FANUC);
        assert!((time - (2.0 * 10.0 / 300.0 * 60.0 + 14.0 / 6000.0 * 60.0 + 10.0)).abs() < 1e-9, "{time}");
        let job = Job {
            dialect: Dialect::Fanuc,
            number: 2001,
            title: "kerf job",
            coolant: Coolant::Off,
            haas_smoothing: None,
        };
        let joined = write(&job, &[operation]).unwrap();
        assert!(joined.contains("TOOLS T7 T8,") && joined.contains("(1 DEBURR: T7 THEN T8 BALL R3"), "{joined}");
        assert_eq!(joined.matches("M06").count(), 2);
    }

    #[test]
    fn a_haas_job_sets_its_machines_smoothing_once_after_the_safety_block() {
        let smoothed = |text: String| super::super::with_haas_smoothing(text, Dialect::Haas, Some(3));
        // The operations' programs as a Haas machine with smoothing writes them.
        let first = smoothed(program(Dialect::Haas, ToolCall::Table(7), 30.0));
        let second = smoothed(program(Dialect::Haas, ToolCall::Table(3), 5.0));
        assert!(first.contains("\nG187 P3\nT7 M06\n"), "{first}");
        let job = |haas_smoothing| Job {
            dialect: Dialect::Haas,
            number: 2042,
            title: "kerf job 42",
            coolant: Coolant::Off,
            haas_smoothing,
        };
        let text = write(&job(Some(3)), &[contour(&first), contour(&second)]).unwrap();
        assert!(text.contains("\nG21 G17 G90 G40 G49 G80 G94\nG187 P3\n(OPERATION 1 CONTOUR)\n"), "{text}");
        assert_eq!(text.matches("G187").count(), 1, "{text}");
        assert!(text.contains("(2 CONTOUR: T3"), "both operations are joined: {text}");
        let plain = write(&job(None), &[contour(&first), contour(&second)]).unwrap();
        assert!(!plain.contains("G187"), "{plain}");
        assert_eq!(text.replacen("G187 P3\n", "", 1), plain);
        let fanuc = Job { dialect: Dialect::Fanuc, ..job(Some(3)) };
        let fanuc_text = write(&fanuc, &[contour(&program(Dialect::Fanuc, ToolCall::Table(7), 30.0))]).unwrap();
        assert!(!fanuc_text.contains("G187"), "{fanuc_text}");
    }

    #[test]
    fn default_numbers_stay_in_the_job_range() {
        assert_eq!(number_for_job(1), 2000);
        assert_eq!(number_for_job(6000), 7999);
        assert_eq!(number_for_job(6001), 2000);
        assert!(check_number("output.program_number", 9000).is_err());
        assert!(check_number("output.program_number", 0).is_err());
        assert!(check_number("output.program_number", 1234).is_ok());
    }
}
