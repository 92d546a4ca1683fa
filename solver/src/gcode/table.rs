//! The post table: what the posts of controls that differ only in words write (program start and
//! end, comments, tool call and length offset, spindle, coolant, arcs, line numbers, decimal
//! format, longest line). The controls whose programs differ in structure (Heidenhain's
//! conversational Klartext) have code of their own (module `gcode::klartext`).

use super::Dialect;

/// How a program is named at its start.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Heading {
    /// The title as a comment, no number (LinuxCNC reads an `O` word as a subroutine label;
    /// Sinumerik and grbl name programs by their file).
    Title,
    /// `%` on a line of its own, then `O` and the number with this many digits and the title
    /// as a comment (Fanuc `O1000`, Haas `O01000`); `%` again after the end.
    Percent(usize),
    /// Heidenhain ISO: `%KERF1000 G71 *` first and `N99999999 %KERF1000 G71 *` last, the title
    /// as a comment.
    HeidenhainIso,
}

/// How comments are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CommentStyle {
    /// `(TEXT)`.
    Parentheses,
    /// `; TEXT` (Sinumerik, Heidenhain).
    Semicolon,
}

/// How the control keeps the path within its tolerance while blending blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Blending {
    /// Nothing written: the control's setting applies (Fanuc, Haas, grbl, Heidenhain ISO).
    None,
    /// LinuxCNC's `G64 P` with the program's blend tolerance.
    Tolerance,
    /// A fixed word (Sinumerik's `G642`: blending within the axes' tolerances).
    Word(&'static str),
}

/// How a tool from the machine's table is called and its length offset activated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolChange {
    /// `T7 M06`, then `G00 G43 H7 Z…` (Fanuc, Haas, LinuxCNC).
    M06WithG43,
    /// `T7 D1`, `M6`, then `G0 Z…` (Sinumerik: the offset is the tool's cutting edge D1).
    SinumerikD1,
    /// `T7 G17`, then `G00 G40 G90 Z…` (Heidenhain ISO: the length is applied with the call).
    HeidenhainIso,
    /// No changer: a comment asks the operator to load the tool and set its length, `M0`
    /// pauses, then `G0 Z…` (grbl, which has no `G43` either).
    Pause,
}

/// How the centre of a circular move is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArcCentre {
    /// `I`/`J` relative to the start in the G02/G03 block (Fanuc, LinuxCNC, Sinumerik, grbl).
    Relative,
    /// A block `I… J…` with the absolute centre before the G02/G03 block (Heidenhain ISO).
    AbsoluteBlock,
}

/// The words of a post (module documentation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PostTable {
    /// Program start and end.
    pub heading: Heading,
    /// Comment style.
    pub comment: CommentStyle,
    /// The safety block: units, plane, absolute, no compensation, feed per minute.
    pub safety: &'static str,
    /// The safety block of an inch program (G20, Sinumerik's G700: inch lengths and feeds).
    pub inch_safety: &'static str,
    /// Path blending.
    pub blending: Blending,
    /// Tool call and length offset.
    pub tool_change: ToolChange,
    /// Rapid, linear, clockwise and counter-clockwise motion words.
    pub motion: [&'static str; 4],
    /// Spindle clockwise, counter-clockwise and stop.
    pub spindle: [&'static str; 3],
    /// Coolant flood, mist and off.
    pub coolant: [&'static str; 3],
    /// Program stop for the operator.
    pub pause: &'static str,
    /// Program end.
    pub end: &'static str,
    /// Arc centre words.
    pub arcs: ArcCentre,
    /// Line numbers `N…` in steps of this, if written.
    pub line_numbers: Option<u32>,
    /// What ends a block besides the line feed (Heidenhain ISO's ` *`).
    pub block_end: &'static str,
    /// Decimals of lengths (4: 0.0001 mm, and 0.0001 in in an inch program).
    pub decimals: usize,
    /// Whether positive numbers carry a `+` (Heidenhain).
    pub plus_sign: bool,
    /// Longest line the control takes, characters (comments are cut to fit).
    pub max_line: Option<usize>,
}

/// Fanuc 0i/30i (also Mazak and Okuma in their ISO mode).
pub const FANUC: PostTable = PostTable {
    heading: Heading::Percent(4),
    comment: CommentStyle::Parentheses,
    safety: "G21 G17 G90 G40 G49 G80 G94",
    inch_safety: "G20 G17 G90 G40 G49 G80 G94",
    blending: Blending::None,
    tool_change: ToolChange::M06WithG43,
    motion: ["G00", "G01", "G02", "G03"],
    spindle: ["M03", "M04", "M05"],
    coolant: ["M08", "M07", "M09"],
    pause: "M00",
    end: "M30",
    arcs: ArcCentre::Relative,
    line_numbers: None,
    block_end: "",
    decimals: 4,
    plus_sign: false,
    max_line: None,
};

impl Dialect {
    /// The words of this post; `None` for Heidenhain's Klartext, which is written by code of
    /// its own.
    pub fn table(self) -> Option<PostTable> {
        Some(match self {
            Self::Fanuc => FANUC,
            Self::Haas => PostTable { heading: Heading::Percent(5), ..FANUC },
            Self::Linuxcnc => PostTable { heading: Heading::Title, blending: Blending::Tolerance, ..FANUC },
            Self::Sinumerik => PostTable {
                heading: Heading::Title,
                comment: CommentStyle::Semicolon,
                safety: "G71 G17 G90 G40 G94",
                inch_safety: "G700 G17 G90 G40 G94",
                blending: Blending::Word("G642"),
                tool_change: ToolChange::SinumerikD1,
                motion: ["G0", "G1", "G2", "G3"],
                spindle: ["M3", "M4", "M5"],
                coolant: ["M8", "M7", "M9"],
                pause: "M0",
                ..FANUC
            },
            Self::HeidenhainIso => PostTable {
                heading: Heading::HeidenhainIso,
                comment: CommentStyle::Semicolon,
                safety: "G17 G40 G90",
                inch_safety: "G17 G40 G90",
                tool_change: ToolChange::HeidenhainIso,
                arcs: ArcCentre::AbsoluteBlock,
                line_numbers: Some(10),
                block_end: " *",
                plus_sign: true,
                ..FANUC
            },
            Self::Grbl => PostTable {
                heading: Heading::Title,
                safety: "G21 G17 G90 G94",
                inch_safety: "G20 G17 G90 G94",
                tool_change: ToolChange::Pause,
                motion: ["G0", "G1", "G2", "G3"],
                spindle: ["M3", "M4", "M5"],
                coolant: ["M8", "M7", "M9"],
                pause: "M0",
                // grbl's line buffer (LINE_BUFFER_SIZE).
                max_line: Some(80),
                ..FANUC
            },
            Self::Heidenhain => return None,
        })
    }
}
