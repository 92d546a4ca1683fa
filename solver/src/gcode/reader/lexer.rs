//! The lexer of the G-code reader (docs/spec/predict.md §8, engagement.md §11): a line split into words (letter, value, where the number
//! sits), and the `G` code numbering and modal groups.

use super::WordSpan;
use crate::error::ErrorCode;
use crate::error::SolverError;

/// One word of a block: letter, value and where its number sits in the line.
#[derive(Debug, Clone, Copy)]
pub(super) struct Word {
    pub(super) letter: u8,
    pub(super) value: f64,
    pub(super) span: WordSpan,
}

/// Splits a line into `words` and returns the byte offset after the last word.
pub(super) fn tokenize(
    line: &str,
    line_number: usize,
    field: &str,
    words: &mut Vec<Word>,
) -> Result<usize, SolverError> {
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

pub(super) fn syntax(field: &str, line: usize, message: impl std::fmt::Display) -> SolverError {
    SolverError::new(ErrorCode::GcodeSyntax, format!("line {line}: {message}")).at(field)
}

pub(super) fn unsupported(field: &str, line: usize, message: impl std::fmt::Display) -> SolverError {
    SolverError::new(ErrorCode::GcodeUnsupported, format!("line {line}: {message}")).at(field)
}

/// A `G` code as tenths (`G90.1` is 901, `G1` is 10), so codes compare exactly.
pub(super) fn g_tenths(value: f64) -> Option<u32> {
    let tenths = (value * 10.0).round();
    ((tenths - value * 10.0).abs() < 1e-6 && (0.0..100_000.0).contains(&tenths)).then_some(tenths as u32)
}

/// Modal groups of the `G` codes this reader knows, to refuse two codes of one group in a block.
pub(super) fn g_group(code: u32) -> Option<u8> {
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
