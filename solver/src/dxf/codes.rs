//! DXF group codes, ASCII and binary (docs/spec/dxf.md §1): a file as its (code, value) pairs.

use crate::error::SolverError;

/// The binary DXF sentinel.
const BINARY_SENTINEL: &[u8] = b"AutoCAD Binary DXF\r\n\x1a\x00";

/// One group: its code and its value as text (numbers of a binary file written out exactly).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Group {
    pub(super) code: i32,
    pub(super) value: String,
}

fn bad(field: &str, message: impl Into<String>) -> SolverError {
    SolverError::input(field, message)
}

/// The file's groups.
pub(super) fn groups(bytes: &[u8], field: &str) -> Result<Vec<Group>, SolverError> {
    match bytes.strip_prefix(BINARY_SENTINEL) {
        Some(rest) => binary(rest, field),
        None => ascii(bytes, field),
    }
}

fn ascii(bytes: &[u8], field: &str) -> Result<Vec<Group>, SolverError> {
    // Drawings from older tools are in a code page: the geometry is ASCII either way.
    let text = String::from_utf8_lossy(bytes);
    let mut lines = text.lines();
    let mut out = Vec::new();
    let mut number = 0;
    while let Some(code) = lines.next() {
        number += 1;
        let code = code.trim();
        if code.is_empty() && lines.clone().all(|l| l.trim().is_empty()) {
            break;
        }
        let Ok(code) = code.parse::<i32>() else {
            return Err(bad(field, format!("line {number}: \"{}\" is not a DXF group code", short(code))));
        };
        let Some(value) = lines.next() else {
            return Err(bad(field, format!("line {number}: group code {code} has no value")));
        };
        number += 1;
        out.push(Group { code, value: value.trim().to_owned() });
    }
    if out.is_empty() {
        return Err(bad(field, "the file is empty or not a DXF drawing"));
    }
    Ok(out)
}

fn short(text: &str) -> String {
    text.chars().take(40).collect()
}

/// How a binary group's value is stored, by its code (the DXF reference's group code ranges).
enum Kind {
    Text,
    Double,
    Int16,
    Int32,
    Int64,
    Bool,
    Chunk,
}

fn kind(code: i32) -> Kind {
    match code {
        10..=59 | 110..=149 | 210..=239 | 460..=469 | 1010..=1059 => Kind::Double,
        60..=79 | 170..=179 | 270..=289 | 370..=389 | 400..=409 | 1060..=1070 => Kind::Int16,
        90..=99 | 420..=429 | 440..=449 | 450..=459 | 1071 => Kind::Int32,
        160..=169 => Kind::Int64,
        290..=299 => Kind::Bool,
        310..=319 | 1004 => Kind::Chunk,
        _ => Kind::Text,
    }
}

fn binary(bytes: &[u8], field: &str) -> Result<Vec<Group>, SolverError> {
    // R12 writes one-byte codes (255 and two bytes for larger ones), later versions two bytes:
    // the first group is always 0 SECTION, which tells them apart.
    let wide = bytes.get(1) == Some(&0);
    let mut at = 0;
    let mut out = Vec::new();
    let truncated = |at: usize| bad(field, format!("the binary file ends inside a group at byte {}", at + 22));
    let take = |at: &mut usize, n: usize| -> Option<&[u8]> {
        let slice = bytes.get(*at..*at + n)?;
        *at += n;
        Some(slice)
    };
    while at < bytes.len() {
        let code = if wide {
            let b = take(&mut at, 2).ok_or_else(|| truncated(at))?;
            i32::from(i16::from_le_bytes([b[0], b[1]]))
        } else {
            let b = take(&mut at, 1).ok_or_else(|| truncated(at))?[0];
            if b == 255 {
                let b = take(&mut at, 2).ok_or_else(|| truncated(at))?;
                i32::from(i16::from_le_bytes([b[0], b[1]]))
            } else {
                i32::from(b)
            }
        };
        let value = match kind(code) {
            Kind::Text => {
                let end = bytes[at..].iter().position(|&b| b == 0).ok_or_else(|| truncated(at))?;
                let text = String::from_utf8_lossy(&bytes[at..at + end]).into_owned();
                at += end + 1;
                text
            }
            Kind::Double => {
                let b = take(&mut at, 8).ok_or_else(|| truncated(at))?;
                f64::from_le_bytes(b.try_into().unwrap_or_default()).to_string()
            }
            Kind::Int16 => {
                let b = take(&mut at, 2).ok_or_else(|| truncated(at))?;
                i16::from_le_bytes([b[0], b[1]]).to_string()
            }
            Kind::Int32 => {
                let b = take(&mut at, 4).ok_or_else(|| truncated(at))?;
                i32::from_le_bytes(b.try_into().unwrap_or_default()).to_string()
            }
            Kind::Int64 => {
                let b = take(&mut at, 8).ok_or_else(|| truncated(at))?;
                i64::from_le_bytes(b.try_into().unwrap_or_default()).to_string()
            }
            Kind::Bool => take(&mut at, 1).ok_or_else(|| truncated(at))?[0].to_string(),
            Kind::Chunk => {
                let n = usize::from(take(&mut at, 1).ok_or_else(|| truncated(at))?[0]);
                take(&mut at, n).ok_or_else(|| truncated(at))?;
                String::new()
            }
        };
        let end = code == 0 && value == "EOF";
        out.push(Group { code, value });
        if end {
            break;
        }
    }
    Ok(out)
}
