//! Job outputs as the store keeps them: each result and program gzip-compressed (a contour job's
//! JSON and G-code shrink about tenfold), with its uncompressed size; and reading back both those
//! and the plain text of rows stored before compression (migration 0004).

use std::io::{Read, Write};

use axum::body::Bytes;
use flate2::Compression;
use flate2::read::GzDecoder;
use flate2::write::GzEncoder;

use crate::error::{AppError, AppResult};

/// Bytes of a body handed to the connection at a time; a stored text is read back in pieces of
/// this size ([`StoredText::pieces`]), so the two match.
pub const PIECE: usize = 64 * 1024;

/// One operation's output, compressed for storage.
#[derive(Debug, Clone)]
pub struct Packed {
    /// The operation's name.
    pub operation: String,
    /// The result JSON, gzip-compressed.
    pub result_gz: Vec<u8>,
    /// The result JSON's length, bytes.
    pub result_bytes: usize,
    /// The program, gzip-compressed, when one could be written.
    pub gcode_gz: Option<Vec<u8>>,
    /// The program's length, bytes (0 without one).
    pub gcode_bytes: usize,
    /// Why no program could be written, if so.
    pub gcode_problem: Option<String>,
}

impl Packed {
    /// Operation `operation`'s `result` JSON and `gcode` program (or the `gcode_problem` why it
    /// has none) compressed (CPU work: call it on a blocking thread).
    pub fn new(operation: &str, result: &str, gcode: Option<&str>, gcode_problem: Option<&str>) -> Self {
        Self {
            operation: operation.to_owned(),
            result_gz: gzip(result.as_bytes()),
            result_bytes: result.len(),
            gcode_gz: gcode.map(|program| gzip(program.as_bytes())),
            gcode_bytes: gcode.map_or(0, str::len),
            gcode_problem: gcode_problem.map(str::to_owned),
        }
    }

    /// What it takes in the store, bytes.
    pub fn stored_bytes(&self) -> usize {
        self.result_gz.len() + self.gcode_gz.as_ref().map_or(0, Vec::len)
    }
}

/// `bytes` gzip-compressed at the default level.
pub(crate) fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut encoder = GzEncoder::new(Vec::with_capacity(bytes.len() / 8 + 64), Compression::default());
    // Writing to a Vec cannot fail.
    let _ = encoder.write_all(bytes);
    encoder.finish().unwrap_or_default()
}

/// A stored text: plain (rows from before compression) or gzip-compressed with its length.
#[derive(Debug, Clone)]
pub enum StoredText {
    /// Stored as text.
    Plain(String),
    /// Stored compressed.
    Gzip {
        /// The compressed bytes.
        compressed: Vec<u8>,
        /// The text's length, bytes.
        length: usize,
    },
}

impl StoredText {
    /// The text in a row's columns: the compressed one when present, else the plain one.
    pub fn from_columns(plain: Option<String>, compressed: Option<Vec<u8>>, length: i64) -> Option<Self> {
        match (compressed, plain) {
            (Some(compressed), _) => Some(Self::Gzip { compressed, length: usize::try_from(length).unwrap_or(0) }),
            (None, Some(text)) => Some(Self::Plain(text)),
            (None, None) => None,
        }
    }

    /// The text's length, bytes.
    pub fn length(&self) -> usize {
        match self {
            Self::Plain(text) => text.len(),
            Self::Gzip { length, .. } => *length,
        }
    }

    /// The bytes it holds in memory as it is.
    pub fn held(&self) -> usize {
        match self {
            Self::Plain(text) => text.len(),
            Self::Gzip { compressed, .. } => compressed.len(),
        }
    }

    /// The whole text (decompressed: CPU work, call it on a blocking thread).
    ///
    /// # Errors
    /// 500 when the stored bytes are not the gzip of UTF-8 text (a damaged store).
    pub fn into_string(self) -> AppResult<String> {
        match self {
            Self::Plain(text) => Ok(text),
            Self::Gzip { compressed, length } => {
                let mut text = String::with_capacity(length);
                GzDecoder::new(compressed.as_slice())
                    .read_to_string(&mut text)
                    .map_err(|error| AppError::Internal(anyhow::anyhow!("a stored result is unreadable: {error}")))?;
                Ok(text)
            }
        }
    }

    /// The text in pieces of at most [`PIECE`] bytes, decompressed one at a time as they are
    /// taken, so a large program is never whole in memory.
    pub fn pieces(self) -> impl Iterator<Item = std::io::Result<Bytes>> + Send + 'static {
        let mut source: Box<dyn Read + Send> = match self {
            Self::Plain(text) => Box::new(std::io::Cursor::new(text.into_bytes())),
            Self::Gzip { compressed, .. } => Box::new(GzDecoder::new(std::io::Cursor::new(compressed))),
        };
        let mut ended = false;
        std::iter::from_fn(move || {
            if ended {
                return None;
            }
            let mut piece = vec![0_u8; PIECE];
            let mut filled = 0;
            while filled < PIECE {
                match source.read(&mut piece[filled..]) {
                    Ok(0) => {
                        ended = true;
                        break;
                    }
                    Ok(read) => filled += read,
                    Err(error) if error.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(error) => {
                        ended = true;
                        return Some(Err(error));
                    }
                }
            }
            piece.truncate(filled);
            (filled > 0).then(|| Ok(Bytes::from(piece)))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compressed_text_reads_back_whole_and_in_pieces() {
        let text: String = (0..40_000).map(|k| format!("G01 X{k}.0000 Y-{k}.5000 Z-0.2500\n")).collect();
        let compressed = gzip(text.as_bytes());
        assert!(compressed.len() * 5 < text.len(), "{} of {}", compressed.len(), text.len());
        let stored = StoredText::Gzip { compressed, length: text.len() };
        let pieces: Vec<Bytes> = stored.clone().pieces().map(Result::unwrap).collect();
        assert!(pieces.len() > 1 && pieces.iter().all(|piece| piece.len() <= PIECE));
        assert_eq!(pieces.concat(), text.as_bytes());
        assert_eq!(stored.into_string().unwrap(), text);
        let plain: Vec<Bytes> = StoredText::Plain("G00\n".to_owned()).pieces().map(Result::unwrap).collect();
        assert_eq!(plain.concat(), b"G00\n");
        assert_eq!(StoredText::Plain(String::new()).pieces().count(), 0);
    }
}
