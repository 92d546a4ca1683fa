//! The G-code reader's blocks (docs/spec/predict.md §8, engagement.md §11): one block's words
//! turned into what the block asks for (motion, plane, units, distance mode, feed, spindle, tool),
//! with two codes of one modal group refused.

use super::lexer::{Word, g_group, g_tenths, syntax, unsupported};
use super::{Distance, Plane, Spindle, Units};
use crate::error::SolverError;

/// Everything one block asks for, before it is executed.
#[derive(Debug, Default)]
pub(super) struct Block {
    pub(super) block_number: Option<u64>,
    pub(super) motion: Option<u32>,
    pub(super) plane: Option<Plane>,
    pub(super) units: Option<Units>,
    pub(super) distance: Option<Distance>,
    pub(super) arc_centre_absolute: Option<bool>,
    pub(super) feed_per_rev: Option<bool>,
    /// `G4`, `G10`, `G28`, `G30`, `G53`: axis words are not a move of the modal motion.
    pub(super) non_modal: Option<u32>,
    pub(super) axes: [Option<Word>; 3],
    pub(super) offsets: [Option<Word>; 3],
    pub(super) radius: Option<Word>,
    pub(super) turns: Option<Word>,
    pub(super) feed: Option<f64>,
    pub(super) spindle_rpm: Option<f64>,
    pub(super) tool: Option<u32>,
    pub(super) spindle: Option<Spindle>,
    pub(super) tool_change: bool,
    pub(super) end: bool,
}

pub(super) fn parse_block(words: &[Word], line: usize, field: &str) -> Result<Block, SolverError> {
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

pub(super) fn apply_g(block: &mut Block, code: u32, line: usize, field: &str) -> Result<(), SolverError> {
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

pub(super) fn format_code(tenths: u32) -> String {
    if tenths.is_multiple_of(10) { format!("{}", tenths / 10) } else { format!("{}.{}", tenths / 10, tenths % 10) }
}
