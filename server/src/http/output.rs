//! Output negotiation shared by every path-producing endpoint (docs/spec/api.md, Conventions: G-code):
//! JSON by default; G-code with `Accept: text/x-gcode` or `?format=gcode`, in `?dialect=`
//! (`fanuc` default, or the machine's) with `?reference=tip|centre` and `?arcs=g2g3|chords`.

use axum::http::{HeaderMap, header};
use kerf_solver::capability::OutputOptions;
use kerf_solver::gcode::{Arcs, Dialect, Reference};
use serde::Deserialize;
use utoipa::{IntoParams, ToSchema};

/// Media type of G-code answers.
pub const GCODE_MEDIA_TYPE: &str = "text/x-gcode";

/// `json` or `gcode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum Format {
    /// The JSON answer (default).
    Json,
    /// A complete G-code program.
    Gcode,
}

/// Query parameters of path-producing endpoints.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct OutputQuery {
    /// `json` (default) or `gcode`; `Accept: text/x-gcode` also selects G-code.
    pub format: Option<Format>,
    /// G-code dialect: `fanuc` (default) or `linuxcnc`.
    pub dialect: Option<Dialect>,
    /// Programmed point: `tip` (default; length offset to the tool tip) or `centre`.
    pub reference: Option<Reference>,
    /// Circular moves: `g2g3` (G02/G03 with I/J in the XY plane, end points those of the chords)
    /// or `chords` (G01 within the tolerance); default the named machine's `arcs`, else `chords`.
    /// Ellipses, NURBS and polylines stay chords.
    pub arcs: Option<Arcs>,
}

/// Query parameters of an endpoint whose answer holds several candidate paths (engagement): the
/// output negotiation of [`OutputQuery`] plus which candidate to program.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct CandidateQuery {
    /// `json` (default) or `gcode`; `Accept: text/x-gcode` also selects G-code.
    pub format: Option<Format>,
    /// G-code dialect: `fanuc` or `linuxcnc` (default: the named machine's, else `fanuc`).
    pub dialect: Option<Dialect>,
    /// Programmed point: `tip` (default; length offset to the tool tip) or `centre` (the centre
    /// of the tool's end rounding: the ball centre, the bull-nose corner centre, the tip for a
    /// flat end mill).
    pub reference: Option<Reference>,
    /// G-code only: which entry of `paths` to program (0-based; default the request's
    /// `candidate`, else 0); a request with `path` has only candidate 0.
    pub candidate: Option<usize>,
    /// Arc segments of the path: `g2g3` (G02/G03 with I/J, end points those of the chords) or
    /// `chords` (G01 within 0.001 mm, or by the block-time rule); default the machine's `arcs`,
    /// else `chords`.
    pub arcs: Option<Arcs>,
}

/// A query that says what the client asks for (with the `Accept` header).
pub trait Negotiate {
    /// What the client asked for; an explicit `format` wins over `Accept`.
    fn ask(&self, headers: &HeaderMap) -> Ask;
}

impl Negotiate for OutputQuery {
    fn ask(&self, headers: &HeaderMap) -> Ask {
        Ask::negotiate(headers, self)
    }
}

impl Negotiate for CandidateQuery {
    fn ask(&self, headers: &HeaderMap) -> Ask {
        Ask {
            gcode: wants_gcode(headers, self.format),
            output: OutputOptions {
                dialect: self.dialect,
                reference: self.reference,
                candidate: self.candidate,
                arcs: self.arcs,
            },
            timings: false,
        }
    }
}

/// What the client asked for: JSON, or the program with its output options.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Ask {
    /// G-code instead of JSON.
    pub gcode: bool,
    /// How the program is written (what is left open takes the machine's or capability's default).
    pub output: OutputOptions,
    /// Add the solve time to answers that report it (`?timings=true`).
    pub timings: bool,
}

impl Ask {
    /// Reads the output query and the `Accept` header; an explicit `format` wins over `Accept`.
    pub fn negotiate(headers: &HeaderMap, query: &OutputQuery) -> Self {
        Self {
            gcode: wants_gcode(headers, query.format),
            output: OutputOptions {
                dialect: query.dialect,
                reference: query.reference,
                candidate: None,
                arcs: query.arcs,
            },
            timings: false,
        }
    }
}

/// Whether the client wants G-code: `format` if given, else the `Accept` header.
pub fn wants_gcode(headers: &HeaderMap, format: Option<Format>) -> bool {
    let accepts_gcode = headers
        .get_all(header::ACCEPT)
        .iter()
        .filter_map(|value| value.to_str().ok())
        .flat_map(|value| value.split(','))
        .any(|item| item.split(';').next().unwrap_or_default().trim().eq_ignore_ascii_case(GCODE_MEDIA_TYPE));
    match format {
        Some(format) => format == Format::Gcode,
        None => accepts_gcode,
    }
}
