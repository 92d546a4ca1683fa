//! Solver failures and warnings, each with a stable code (docs/spec/deburr.md §4 and the other specs' edge-case tables).

use serde::{Deserialize, Serialize};

pub use crate::error_code::ErrorCode;

/// Why a solver refused a request. `code` is stable and documented (e.g. `E_HOLE_TOO_LARGE`);
/// `field` names the request field at fault when there is one (a dotted JSON path such as
/// `hole.radius`), so the server can point the client at it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct SolverError {
    code: ErrorCode,
    field: Option<String>,
    message: String,
}

impl SolverError {
    /// An error with a code and a message, not tied to one field.
    pub fn new(code: ErrorCode, message: impl Into<String>) -> Self {
        Self { code, field: None, message: message.into() }
    }

    /// An `E_INPUT` error naming the field at fault.
    pub fn input(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::new(ErrorCode::Input, message).at(field)
    }

    /// The same error, tied to `field`.
    #[must_use]
    pub fn at(mut self, field: impl Into<String>) -> Self {
        self.field = Some(field.into());
        self
    }

    /// The stable error code.
    pub fn code(&self) -> ErrorCode {
        self.code
    }

    /// The request field at fault, if any.
    pub fn field(&self) -> Option<&str> {
        self.field.as_deref()
    }

    /// The human-readable explanation.
    pub fn message(&self) -> &str {
        &self.message
    }
}

/// Something the user should know about a result that was still computed.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Warning {
    /// Stable warning code, e.g. `W_CENTRE_IN_MATERIAL`.
    pub code: &'static str,
    /// What happened and where.
    pub message: String,
}

/// A warning read back (the parts of a split request).
impl<'de> Deserialize<'de> for Warning {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Read {
            #[serde(deserialize_with = "interned")]
            code: Name,
            message: String,
        }
        let Read { code, message } = Read::deserialize(deserializer)?;
        Ok(Self { code, message })
    }
}

/// A name from a small fixed set (a warning's code, a deburr point's segment). Spelled as an
/// alias so that serde's derive, which borrows a field typed `&str` from the input, reads it with
/// [`interned`] instead.
pub(crate) type Name = &'static str;

/// A [`Name`] read back (a warning's code, a deburr point's segment: the parts of a split
/// request). Each distinct text is kept once for the life of the process: they are names from a
/// small fixed set.
///
/// # Errors
/// When the text is not a string, or past 1000 distinct texts.
pub(crate) fn interned<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<&'static str, D::Error> {
    static KNOWN: std::sync::Mutex<Vec<&'static str>> = std::sync::Mutex::new(Vec::new());
    let text = String::deserialize(deserializer)?;
    let mut known = KNOWN.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    match known.iter().find(|name| **name == text) {
        Some(name) => Ok(name),
        None if known.len() >= 1000 => Err(serde::de::Error::custom("more distinct names than kerf has")),
        None => {
            let name: &'static str = Box::leak(text.into_boxed_str());
            known.push(name);
            Ok(name)
        }
    }
}

impl Warning {
    /// A warning with its code and message.
    pub fn new(code: &'static str, message: impl Into<String>) -> Self {
        Self { code, message: message.into() }
    }
}
