//! Operations split into parts (PostgreSQL): how large a part should be, and the
//! parts' outputs as a finish step reads them back. The capabilities decide how their work
//! divides and how parts merge (`Capability::split`, `solve_part`, `finish`); the queue
//! (`store::jobs::split`, `claim`) runs the parts on any workers and the finish step after the
//! last of them.

use std::io::Read;

use flate2::read::GzDecoder;
use kerf_solver::capability::{PartSource, Sizing};
use kerf_solver::{ErrorCode, SolverError};
use serde::de::DeserializeOwned;

/// Core-seconds of work per part, by default: a part takes a few seconds on a worker (about 5 s
/// on a 2-core worker running one chunk at a time, 10 s running two: docs/guide/performance.md, "Split cost models").
pub const PART_SECONDS: f64 = 8.0;
/// Most parts one operation is split into.
pub const MAX_PARTS: usize = 1000;
/// The environment variable that sets the core-seconds per part instead of [`PART_SECONDS`] (on
/// the workers: the one that claims an operation splits it).
pub const PART_SECONDS_VARIABLE: &str = "KERF_JOB_PART_S";

/// How large parts are: about [`PART_SECONDS`] core-seconds of the reference machine each (or
/// `KERF_JOB_PART_S`), at most [`MAX_PARTS`] per operation. The capabilities' cost models
/// (docs/guide/performance.md, "Split cost models") turn a request into core-seconds.
pub fn sizing() -> Sizing {
    static PART: std::sync::OnceLock<f64> = std::sync::OnceLock::new();
    let part_seconds = *PART.get_or_init(|| {
        std::env::var(PART_SECONDS_VARIABLE)
            .ok()
            .and_then(|value| value.trim().parse::<f64>().ok())
            .filter(|seconds| seconds.is_finite() && *seconds > 0.0)
            .unwrap_or(PART_SECONDS)
    });
    Sizing { part_seconds, max_parts: MAX_PARTS }
}

/// The stored outputs of an operation's parts (gzip-compressed CBOR, in order), each
/// decompressed only when the finish step reads it.
#[derive(Debug)]
pub struct StoredParts {
    parts: std::vec::IntoIter<Vec<u8>>,
    count: usize,
}

impl StoredParts {
    /// The parts' outputs, in order.
    pub fn new(parts: Vec<Vec<u8>>) -> Self {
        Self { count: parts.len(), parts: parts.into_iter() }
    }
}

impl PartSource for StoredParts {
    fn count(&self) -> usize {
        self.count
    }

    fn next_part<T: DeserializeOwned>(&mut self) -> Option<Result<T, SolverError>> {
        let compressed = self.parts.next()?;
        let unreadable = |error: &dyn std::fmt::Display| {
            SolverError::new(ErrorCode::Internal, format!("a part's output is unreadable: {error}"))
        };
        let mut bytes = Vec::new();
        if let Err(error) = GzDecoder::new(compressed.as_slice()).read_to_end(&mut bytes) {
            return Some(Err(unreadable(&error)));
        }
        Some(ciborium::from_reader(bytes.as_slice()).map_err(|error| unreadable(&error)))
    }
}
