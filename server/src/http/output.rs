//! Output negotiation shared by every path-producing endpoint (api.md, Conventions: G-code):
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
