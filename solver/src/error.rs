//! Solver failures and warnings, each with a stable code (deburr.md §4 and the other specs' edge-case tables).

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

/// A warning read back (the parts of a split request). Its code is kept once per distinct code
/// for the life of the process: the codes are a small fixed set.
impl<'de> Deserialize<'de> for Warning {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        struct Read {
            code: String,
            message: String,
        }
        static CODES: std::sync::Mutex<Vec<&'static str>> = std::sync::Mutex::new(Vec::new());
        let Read { code, message } = Read::deserialize(deserializer)?;
        let mut codes = CODES.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let code = match codes.iter().find(|known| **known == code) {
            Some(known) => known,
            None if codes.len() >= 1000 => {
                return Err(serde::de::Error::custom("more distinct warning codes than kerf has"));
            }
            None => {
                let known: &'static str = Box::leak(code.into_boxed_str());
                codes.push(known);
                known
            }
        };
        Ok(Self { code, message })
    }
}

impl Warning {
    /// A warning with its code and message.
    pub fn new(code: &'static str, message: impl Into<String>) -> Self {
        Self { code, message: message.into() }
    }
}
