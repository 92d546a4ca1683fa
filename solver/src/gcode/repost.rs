//! Re-posting a program read as RS274/Fanuc (module `reader`) for another post, line by line
//! and in order: motion, units, plane, distance mode, tool calls with their length offset,
//! spindle, coolant, stops, program end and comments come out in the target's words
//! (docs/spec/resegment.md §4). A post of the table keeps the coordinates' units and digits as
//! written (with a `+` where the post signs every number); Heidenhain's Klartext, whose blocks
//! differ in structure, is written from what the reader made of each move (module `klartext`).
//! A code with no counterpart known here (a dwell, a home return, a machine's own M code,
//! smoothing words) cannot be translated honestly: the line is refused with
//! `E_GCODE_UNSUPPORTED` naming it.

use std::fmt::Write as _;

use super::table::{ArcCentre, Blending, CommentStyle, Heading, PostTable, ToolChange};
use super::{Buffer, Dialect, number, push_comment};
use crate::error::{ErrorCode, SolverError};
use crate::gcode::reader::{MoveKind, Plane, ReadMove, Units};

/// Decimals of the coordinates the re-poster computes (arc centres, re-cut blocks).
const DECIMALS: usize = 4;

/// A word of a source line: its letter and its number as written.
#[derive(Debug, Clone, Copy)]
pub(super) struct Word<'a> {
    pub(super) letter: u8,
    pub(super) text: &'a str,
    pub(super) value: f64,
}

/// What a source line holds, in order: words and comments.
pub(super) enum Item<'a> {
    Word(Word<'a>),
    Comment(&'a str),
}

/// A block the translation of a line adds after its own.
enum Extra {
    Block(String),
    Comment(String),
}

/// A program being re-posted: in the words of a post of the table, or as Heidenhain Klartext.
pub enum Reposter {
    /// A post of the table ([`PostTable`]).
    Words(WordReposter),
    /// Heidenhain's conversational post (module `klartext`).
    Klartext(super::klartext::Reposter),
}

impl Reposter {
    /// A re-poster for `dialect` of `source`, whose errors name `field`.
    pub fn new(dialect: Dialect, source: &str, field: &'static str) -> Self {
        match dialect.table() {
            Some(table) => Self::Words(WordReposter::new(dialect, table, source, field)),
            None => Self::Klartext(super::klartext::Reposter::new(source, field)),
        }
    }

    /// The straight feed blocks of a re-cut run: `points` in mm written in `units`, `feed_word`
    /// (as the source wrote it) on the first.
    ///
    /// # Errors
    /// `E_GCODE_UNSUPPORTED` naming `line` (the run's first) where the target cannot say them
    /// (Klartext: a run in other units than the program's).
    pub fn feed_blocks(
        &mut self,
        line: usize,
        points: &[[f64; 3]],
        units: Units,
        feed_word: Option<&str>,
    ) -> Result<(), SolverError> {
        match self {
            Self::Words(words) => {
                words.feed_blocks(points, units, feed_word);
                Ok(())
            }
            Self::Klartext(klartext) => klartext.feed_blocks(line, points, units, feed_word),
        }
    }

    /// Re-posts source line `number` (without its line end); `read` is its move, if it has one.
    ///
    /// # Errors
    /// `E_GCODE_UNSUPPORTED` naming the line and the code that has no counterpart in the
    /// target post; `E_GCODE_SYNTAX` for text that is not G-code (after the program end).
    pub fn line(&mut self, number: usize, raw: &str, read: Option<&ReadMove>) -> Result<(), SolverError> {
        match self {
            Self::Words(words) => words.line(number, raw, read),
            Self::Klartext(klartext) => klartext.line(number, raw, read),
        }
    }

    /// The program written.
    ///
    /// # Errors
    /// Klartext: `E_GCODE_UNSUPPORTED` naming the line of an M function left without a
    /// positioning block to carry it.
    pub fn finish(self, source: &str) -> Result<String, SolverError> {
        match self {
            Self::Words(words) => Ok(words.finish(source)),
            Self::Klartext(klartext) => klartext.finish(),
        }
    }
}

/// A program being re-posted for a post of the table.
pub struct WordReposter {
    dialect: Dialect,
    table: PostTable,
    out: Buffer,
    line: u32,
    /// The program number named by the heading (`O` word), for the posts that repeat it.
    number: u32,
    /// The tool the program last selected (`T`), for an `M6` on a line of its own.
    tool: Option<String>,
    field: &'static str,
}

impl WordReposter {
    /// A re-poster for `dialect`, a post of `table`, of `source`, whose errors name `field`.
    fn new(dialect: Dialect, table: PostTable, source: &str, field: &'static str) -> Self {
        let number = program_number(source);
        let mut reposter = Self {
            dialect,
            table,
            out: Buffer::with_capacity(source.len() + source.len() / 4),
            line: 0,
            number,
            tool: None,
            field,
        };
        if table.heading == Heading::HeidenhainIso {
            let units = if source_units(source) == Units::Inch { "G70" } else { "G71" };
            let _ = writeln!(reposter.out, "%KERF{} {units} *", reposter.number);
        }
        reposter
    }

    /// The program written.
    fn finish(mut self, source: &str) -> String {
        if self.table.heading == Heading::HeidenhainIso {
            let units = if source_units(source) == Units::Inch { "G70" } else { "G71" };
            let _ = writeln!(self.out, "N99999999 %KERF{} {units} *", self.number);
        }
        self.out.into_string()
    }

    /// Starts a block: its line number, if the post numbers lines.
    fn begin(&mut self) {
        if let Some(step) = self.table.line_numbers {
            self.line += step;
            self.out.push('N');
            number::push_whole(&mut self.out.0, f64::from(self.line));
            self.out.push(' ');
        }
    }

    fn end(&mut self) {
        self.out.push_str(self.table.block_end);
        self.out.push('\n');
    }

    fn block(&mut self, words: &str) {
        self.begin();
        self.out.push_str(words);
        self.end();
    }

    fn comment(&mut self, text: &str) {
        self.begin();
        let room = self.table.max_line.map(|max| max.saturating_sub(self.out.0.len() - self.out.line_start()));
        push_comment(&mut self.out, self.table.comment, text, room);
        self.end();
    }

    /// The straight feed blocks of a re-cut run: `points` in mm written in `units`, `feed_word`
    /// (as the source wrote it) on the first.
    fn feed_blocks(&mut self, points: &[[f64; 3]], units: Units, feed_word: Option<&str>) {
        let scale = units.scale();
        for (index, point) in points.iter().enumerate() {
            self.begin();
            self.out.push_str(self.table.motion[1]);
            for (letter, value) in ['X', 'Y', 'Z'].into_iter().zip(point) {
                self.out.push(' ');
                self.out.push(letter);
                number::push_fixed(&mut self.out.0, value / scale, DECIMALS, self.table.plus_sign);
            }
            if index == 0
                && let Some(word) = feed_word
            {
                self.out.push(' ');
                self.out.push_str(word);
            }
            self.end();
        }
    }

    fn line(&mut self, number: usize, raw: &str, read: Option<&ReadMove>) -> Result<(), SolverError> {
        let line = raw.strip_suffix('\r').unwrap_or(raw);
        let trimmed = line.trim();
        if trimmed.is_empty() {
            self.out.push('\n');
            return Ok(());
        }
        if trimmed.starts_with('%') {
            if matches!(self.table.heading, Heading::Percent(_)) {
                self.out.push_str("%\n");
            }
            return Ok(());
        }
        let (delete, code) = match trimmed.strip_prefix('/') {
            Some(rest) => (true, rest),
            None => (false, trimmed),
        };
        if delete && self.dialect == Dialect::Grbl {
            return Err(self.refuse(number, "block delete (/)"));
        }
        let items = read_items(number, code, self.field)?;
        self.translate(number, delete, &items, read)
    }

    fn refuse(&self, number: usize, what: &str) -> SolverError {
        refusal(self.dialect, self.field, number, what)
    }

    /// A number as the target writes it: the source's digits, signed where the post signs all.
    fn value(&self, text: &str) -> String {
        if self.table.plus_sign && !text.starts_with(['+', '-']) { format!("+{text}") } else { text.to_owned() }
    }

    #[allow(clippy::too_many_lines)]
    fn translate(
        &mut self,
        number: usize,
        delete: bool,
        items: &[Item<'_>],
        read: Option<&ReadMove>,
    ) -> Result<(), SolverError> {
        let table = self.table;
        let words = words_in(items);
        let has = |letter: u8, value: f64| has_word(&words, letter, value);
        let tool_word = words.iter().find(|w| w.letter == b'T').map(|w| w.text.to_owned());
        let changes_tool = has(b'M', 6.0);
        let relative_centres = read.is_some_and(|m| !m.modal.absolute_arc_centre);
        let arc = read.and_then(|m| match m.kind {
            MoveKind::Arc { centre, .. } => Some((m, centre)),
            _ => None,
        });
        if let Some(word) = &tool_word {
            self.tool = Some(word.clone());
        }
        let mut out: Vec<String> = Vec::new();
        let mut before: Vec<String> = Vec::new();
        let mut after: Vec<Extra> = Vec::new();
        let rs274 = matches!(self.dialect, Dialect::Fanuc | Dialect::Haas | Dialect::Linuxcnc);
        for word in &words {
            let code = (word.value * 10.0).round() as i64;
            let exact = ((word.value * 10.0) - code as f64).abs() < 1e-6;
            match word.letter {
                b'N' => {
                    if table.line_numbers.is_none() {
                        out.push(format!("N{}", word.text));
                    }
                }
                b'O' => {
                    if let Heading::Percent(digits) = table.heading {
                        out.push(format!("O{:0digits$}", word.value as u64));
                    }
                }
                b'G' if exact => match code {
                    0 | 10 | 20 | 30 => out.push(table.motion[(code / 10) as usize].to_owned()),
                    170 | 180 | 190 => out.push(format!("G{}", code / 10)),
                    200 | 210 => {
                        let inch = code == 200;
                        let metric_words = matches!(self.dialect, Dialect::Sinumerik | Dialect::HeidenhainIso);
                        out.push(match (metric_words, inch) {
                            (true, true) => "G70".to_owned(),
                            (true, false) => "G71".to_owned(),
                            (false, true) => "G20".to_owned(),
                            (false, false) => "G21".to_owned(),
                        });
                    }
                    900 | 910 => out.push(format!("G{}", code / 10)),
                    901 | 911 if rs274 => out.push(format!("G{}", word.text)),
                    911 => {}
                    901 => return Err(self.refuse(number, "absolute arc centres (G90.1)")),
                    940 if self.dialect != Dialect::HeidenhainIso => out.push("G94".to_owned()),
                    940 => {}
                    950 if matches!(self.dialect, Dialect::Grbl | Dialect::HeidenhainIso) => {
                        return Err(self.refuse(number, "feed per revolution (G95)"));
                    }
                    950 => out.push("G95".to_owned()),
                    400 => out.push("G40".to_owned()),
                    // The length offset: part of the tool call on the posts that apply it there.
                    430 if table.tool_change == ToolChange::M06WithG43 => out.push("G43".to_owned()),
                    430 => {}
                    490 | 800 if matches!(self.dialect, Dialect::Sinumerik | Dialect::HeidenhainIso) => {}
                    490 => out.push("G49".to_owned()),
                    800 => out.push("G80".to_owned()),
                    540 | 550 | 560 | 570 | 580 | 590 if self.dialect != Dialect::HeidenhainIso => {
                        out.push(format!("G{}", code / 10));
                    }
                    610 | 640 => match table.blending {
                        Blending::Tolerance => out.push(format!("G{}", code / 10)),
                        Blending::Word(word) if code == 640 => out.push(word.to_owned()),
                        Blending::Word(_) => out.push("G60".to_owned()),
                        Blending::None if rs274 => out.push(format!("G{}", code / 10)),
                        Blending::None => {}
                    },
                    _ => return Err(self.refuse(number, &format!("G{}", word.text))),
                },
                b'M' if exact => match code {
                    30 => out.push(table.spindle[0].to_owned()),
                    40 => out.push(table.spindle[1].to_owned()),
                    50 => out.push(table.spindle[2].to_owned()),
                    80 => out.push(table.coolant[0].to_owned()),
                    70 => out.push(table.coolant[1].to_owned()),
                    90 => out.push(table.coolant[2].to_owned()),
                    0 => out.push(table.pause.to_owned()),
                    10 => out.push(if table.pause == "M00" { "M01" } else { "M1" }.to_owned()),
                    20 | 300 => out.push(table.end.to_owned()),
                    60 => {
                        let Some(tool) = self.tool.clone() else {
                            return Err(self.refuse(number, "M6 without a tool (T)"));
                        };
                        match table.tool_change {
                            ToolChange::M06WithG43 => out.push(format!("T{tool} M06")),
                            ToolChange::SinumerikD1 => {
                                after.push(Extra::Block(format!("T{tool} D1")));
                                after.push(Extra::Block("M6".to_owned()));
                            }
                            ToolChange::HeidenhainIso => after.push(Extra::Block(format!("T{tool} G17"))),
                            ToolChange::Pause => {
                                after.push(Extra::Comment(format!(
                                    "load tool T{tool} and set its length, then cycle start"
                                )));
                                after.push(Extra::Block(table.pause.to_owned()));
                            }
                        }
                    }
                    _ => return Err(self.refuse(number, &format!("M{}", word.text))),
                },
                b'T' if changes_tool => {}
                b'T' => match self.dialect {
                    // A preselection: the posts without one leave it to the change.
                    Dialect::Grbl | Dialect::HeidenhainIso => {}
                    _ => out.push(format!("T{}", word.text)),
                },
                b'H' if has(b'G', 43.0) => {
                    if table.tool_change == ToolChange::M06WithG43 {
                        out.push(format!("H{}", word.text));
                    }
                }
                b'P' if has(b'G', 64.0) => {
                    if table.blending == Blending::Tolerance {
                        out.push(format!("P{}", word.text));
                    }
                }
                b'X' | b'Y' | b'Z' => out.push(format!("{}{}", word.letter as char, self.value(word.text))),
                b'F' | b'S' => out.push(format!("{}{}", word.letter as char, word.text)),
                b'I' | b'J' | b'K' | b'R' => match (table.arcs, arc) {
                    (ArcCentre::AbsoluteBlock, Some(_)) => {}
                    (ArcCentre::Relative, _) if word.letter == b'R' && self.dialect == Dialect::Sinumerik => {
                        out.push(format!("CR={}", word.text));
                    }
                    (ArcCentre::Relative, _) if rs274 || relative_centres || word.letter == b'R' => {
                        out.push(format!("{}{}", word.letter as char, word.text));
                    }
                    _ => return Err(self.refuse(number, &format!("{}{}", word.letter as char, word.text))),
                },
                _ => return Err(self.refuse(number, &format!("{}{}", word.letter as char, word.text))),
            }
        }
        if table.arcs == ArcCentre::AbsoluteBlock
            && let Some((read, centre)) = arc
        {
            let flat = read.from_xyz().zip(read.to_xyz()).is_some_and(|(a, b)| (a[2] - b[2]).abs() <= 1e-9);
            if read.modal.plane != Plane::Xy || !flat {
                return Err(self.refuse(number, "a helical or other-plane arc"));
            }
            let scale = read.modal.units.scale();
            let mut centre_block = Buffer::default();
            centre_block.push('I');
            number::push_fixed(&mut centre_block.0, centre[0] / scale, DECIMALS, true);
            centre_block.push_str(" J");
            number::push_fixed(&mut centre_block.0, centre[1] / scale, DECIMALS, true);
            before.push(centre_block.into_string());
        }
        let prefix = if delete { "/" } else { "" };
        for block in &before {
            self.block(&format!("{prefix}{block}"));
        }
        let comments: Vec<&str> = items
            .iter()
            .filter_map(|item| match item {
                Item::Comment(text) => Some(*text),
                Item::Word(_) => None,
            })
            .collect();
        if !out.is_empty() {
            self.begin();
            self.out.push_str(prefix);
            self.out.push_str(&out.join(" "));
            if table.comment == CommentStyle::Parentheses && table.max_line.is_none() {
                for text in &comments {
                    self.out.push(' ');
                    push_comment(&mut self.out, table.comment, text, None);
                }
            }
            self.end();
        }
        if out.is_empty() || table.comment != CommentStyle::Parentheses || table.max_line.is_some() {
            for text in &comments {
                self.comment(text);
            }
        }
        for extra in &after {
            match extra {
                Extra::Comment(text) => self.comment(text),
                Extra::Block(words) => self.block(&format!("{prefix}{words}")),
            }
        }
        Ok(())
    }
}

/// `E_GCODE_UNSUPPORTED` at `field`: line `number`'s `what` cannot be said in `dialect`'s post.
pub(super) fn refusal(dialect: Dialect, field: &'static str, number: usize, what: &str) -> SolverError {
    SolverError::new(
        ErrorCode::GcodeUnsupported,
        format!(
            "line {number}: {what} has no counterpart in the {} post: the program cannot be re-posted",
            dialect.as_str()
        ),
    )
    .at(field)
}

/// The words and comments of line `number`'s `code`.
///
/// # Errors
/// The words of a line's items, its comments left out.
pub(super) fn words_in<'a>(items: &[Item<'a>]) -> Vec<Word<'a>> {
    items
        .iter()
        .filter_map(|item| match item {
            Item::Word(word) => Some(*word),
            Item::Comment(_) => None,
        })
        .collect()
}

/// Whether `words` hold `letter` with `value` (`M6`, `G0`), as a program's number may be written
/// `M06` or `M6.`.
pub(super) fn has_word(words: &[Word<'_>], letter: u8, value: f64) -> bool {
    words.iter().any(|w| w.letter == letter && (w.value - value).abs() < 1e-9)
}

/// `E_GCODE_SYNTAX` at `field` naming the line for text that is not G-code.
pub(super) fn read_items<'a>(number: usize, code: &'a str, field: &'static str) -> Result<Vec<Item<'a>>, SolverError> {
    items(code)
        .map_err(|message| SolverError::new(ErrorCode::GcodeSyntax, format!("line {number}: {message}")).at(field))
}

/// The program number the heading names (its first `O` word), else 1000.
pub(super) fn program_number(source: &str) -> u32 {
    source
        .lines()
        .map(str::trim_start)
        .find_map(|l| {
            let rest = l.strip_prefix(['O', 'o'])?;
            let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
            digits.parse().ok()
        })
        .unwrap_or(1000)
}

/// The units the program starts in: those of its first `G20`/`G21`, else mm.
pub(super) fn source_units(source: &str) -> Units {
    for line in source.lines() {
        let upper = line.to_ascii_uppercase();
        if upper.contains("G20") {
            return Units::Inch;
        }
        if upper.contains("G21") {
            return Units::Mm;
        }
    }
    Units::Mm
}

/// Splits the code of a line into words and comments.
fn items(code: &str) -> Result<Vec<Item<'_>>, String> {
    let bytes = code.as_bytes();
    let mut items = Vec::new();
    let mut index = 0;
    while index < bytes.len() {
        match bytes[index] {
            b' ' | b'\t' => index += 1,
            b'(' => {
                let close = code[index..].find(')').ok_or("comment opened with ( is not closed")?;
                items.push(Item::Comment(&code[index + 1..index + close]));
                index += close + 1;
            }
            b';' => {
                items.push(Item::Comment(&code[index + 1..]));
                break;
            }
            c if c.is_ascii_alphabetic() => {
                let letter = c.to_ascii_uppercase();
                index += 1;
                while index < bytes.len() && matches!(bytes[index], b' ' | b'\t') {
                    index += 1;
                }
                let start = index;
                while index < bytes.len() && matches!(bytes[index], b'0'..=b'9' | b'.' | b'+' | b'-') {
                    index += 1;
                }
                let text = &code[start..index];
                let value: f64 = text.parse().map_err(|_| format!("{}{text} is not a number", letter as char))?;
                items.push(Item::Word(Word { letter, text, value }));
            }
            _ => {
                let shown: String = code[index..].chars().next().into_iter().collect();
                return Err(format!("unexpected character '{shown}'"));
            }
        }
    }
    Ok(items)
}
