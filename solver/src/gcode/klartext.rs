//! Heidenhain TNC conversational programs (Klartext): numbered blocks from `0 BEGIN PGM … MM` to
//! `END PGM … MM`, `TOOL CALL n Z S…` (the tool's length applies with the call), straight moves
//! `L X… Y… Z… R0 F…` (`FMAX` for rapids), arcs as the centre `CC X… Y…` followed by
//! `C X… Y… DR±`, and `;` comments. A helical arc (its Z changing) becomes straight moves within
//! the program's path tolerance. Its structure differs from the word-for-word posts of the post
//! table, so it is written here.

use std::fmt::Write as _;

use super::table::CommentStyle;
use super::{
    Buffer, MOVES_PER_CHECK, Program, ProgramStop, SpindleDirection, ToolCall, helix_points, is_plunge, number,
    plunge_feed, push_comment, same_printed,
};
use crate::geometry::Vec3;
use crate::path::Motion;

/// Decimals of lengths, mm.
const DECIMALS: usize = 4;

/// A Klartext program being written.
struct Klartext {
    text: Buffer,
    line: u32,
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
            number::push_feed(&mut self.text.0, feed);
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
    let mut out = Klartext { text: Buffer::with_capacity(256 + program.path.moves.len() * 48), line: 0 };
    let name = format!("KERF{}", program.number);
    // Feeds in inch programs are inch/min, as lengths are inches.
    let units = match program.units {
        crate::units::Units::Mm => "MM",
        crate::units::Units::Inch => "INCH",
    };
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
                let feed = match (program.plunges, position) {
                    (Some(plunges), Some(from)) if is_plunge(from, step.to) => plunge_feed(feed, plunges.feed),
                    _ => feed,
                };
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
