//! Output negotiation shared by every path-producing endpoint (docs/spec/api.md, Conventions: G-code):
//! JSON by default; G-code with `?format=gcode` or an `Accept` that ranks `text/x-gcode` above
//! `application/json` (q-values, RFC 9110 §12.5.1), in `?dialect=` (`fanuc` default, or the
//! machine's) with `?reference=tip|centre` and `?arcs=g2g3|chords`. Each endpoint's program route
//! (`POST /api/v1/{name}/program`) answers the program only, so a generated client has one
//! answer type per operation.

use axum::http::{HeaderMap, header};
use kerf_solver::capability::OutputOptions;
use kerf_solver::gcode::{Arcs, Dialect, Reference};
use serde::Deserialize;
use utoipa::IntoParams;

/// Media type of G-code answers.
pub const GCODE_MEDIA_TYPE: &str = "text/x-gcode";

/// The `Content-Disposition` of a program `name` (a capability's, `job-{id}` for a job's) in
/// `dialect`: an attachment named `kerf-{name}.{extension}` with the post's file extension
/// (`.nc`, `.mpf` for Sinumerik, `.h` for Heidenhain conversational, `.i` for Heidenhain ISO);
/// every program download is named by it.
pub fn program_disposition(name: &str, dialect: Dialect) -> axum::http::HeaderValue {
    let file = format!("attachment; filename=\"kerf-{name}.{}\"", dialect.file_extension());
    axum::http::HeaderValue::from_str(&file).unwrap_or_else(|_| axum::http::HeaderValue::from_static("attachment"))
}

/// `json` or `gcode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Format {
    /// The JSON answer (default).
    Json,
    /// A complete G-code program.
    Gcode,
}

/// Query parameters of path-producing endpoints (not in the OpenAPI document, which documents
/// the program routes' [`ProgramQuery`] instead).
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputQuery {
    /// `json` (default) or `gcode`; without it, an `Accept` that ranks `text/x-gcode` above
    /// `application/json` selects G-code.
    pub format: Option<Format>,
    /// G-code dialect (the post): `fanuc` (default; also Mazak and Okuma in ISO mode), `haas`,
    /// `linuxcnc`, `sinumerik` (840D), `heidenhain` (Klartext), `heidenhain_iso` or `grbl`; default
    /// the named machine's `dialect`, else `fanuc`.
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
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CandidateQuery {
    /// `json` (default) or `gcode`; without it, an `Accept` that ranks `text/x-gcode` above
    /// `application/json` selects G-code.
    pub format: Option<Format>,
    /// G-code dialect (the post): `fanuc`, `haas`, `linuxcnc`, `sinumerik`, `heidenhain`,
    /// `heidenhain_iso` or `grbl` (default: the named machine's, else `fanuc`).
    pub dialect: Option<Dialect>,
    /// Programmed point: `tip` (default; length offset to the tool tip) or `centre` (the centre
    /// of the tool's end rounding: the ball centre, the bull-nose corner centre, the tip for a
    /// flat end mill).
    pub reference: Option<Reference>,
    /// G-code only: which entry of `paths` to program (0-based; default the request's
    /// `candidate`, else 0); a request with `path` has only candidate 0. The candidate
    /// programmed is the one the verification cuts, so its program carries its own findings.
    pub candidate: Option<usize>,
    /// Arc segments of the path: `g2g3` (G02/G03 with I/J, end points those of the chords) or
    /// `chords` (G01 within 0.001 mm, or by the block-time rule); default the machine's `arcs`,
    /// else `chords`.
    pub arcs: Option<Arcs>,
}

/// Query parameters of a program route (`POST /api/v1/{name}/program`): how the program is
/// written. The route answers G-code only, so it takes no `format`.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct ProgramQuery {
    /// G-code dialect (the post): `fanuc`, `haas`, `linuxcnc`, `sinumerik`, `heidenhain`, `heidenhain_iso` or `grbl`
    /// (default: the named machine's, else `fanuc`).
    pub dialect: Option<Dialect>,
    /// Programmed point: `tip` (default; length offset to the tool tip) or `centre`.
    pub reference: Option<Reference>,
    /// Circular moves: `g2g3` (G02/G03 with I/J in the XY plane, end points those of the chords)
    /// or `chords` (G01 within the tolerance); default the named machine's `arcs`, else `chords`.
    /// Ellipses, NURBS and polylines stay chords.
    pub arcs: Option<Arcs>,
}

/// Query parameters of the program route of an endpoint whose answer holds several candidate
/// paths (engagement): [`ProgramQuery`] plus which candidate to program.
#[derive(Debug, Clone, Default, Deserialize, IntoParams)]
#[serde(deny_unknown_fields)]
#[into_params(parameter_in = Query)]
pub struct CandidateProgramQuery {
    /// G-code dialect (the post): `fanuc`, `haas`, `linuxcnc`, `sinumerik`, `heidenhain`, `heidenhain_iso` or `grbl`
    /// (default: the named machine's, else `fanuc`).
    pub dialect: Option<Dialect>,
    /// Programmed point: `tip` (default; length offset to the tool tip) or `centre` (the centre
    /// of the tool's end rounding: the ball centre, the bull-nose corner centre, the tip for a
    /// flat end mill).
    pub reference: Option<Reference>,
    /// Which entry of the answer's `paths` to program (0-based; default the request's
    /// `candidate`, else 0); a request with `path` has only candidate 0. The candidate
    /// programmed is the one the verification cuts, so its program carries its own findings.
    #[param(minimum = 0)]
    pub candidate: Option<usize>,
    /// Arc segments of the path: `g2g3` (G02/G03 with I/J, end points those of the chords) or
    /// `chords` (G01 within 0.001 mm, or by the block-time rule); default the machine's `arcs`,
    /// else `chords`.
    pub arcs: Option<Arcs>,
}

/// A query that says what the client asks for (with the `Accept` header).
pub trait Negotiate {
    /// The query of the same endpoint's program route.
    type Program: serde::de::DeserializeOwned + Send;
    /// What the client asked for; an explicit `format` wins over `Accept`.
    fn ask(&self, headers: &HeaderMap) -> Ask;
    /// What a program route's client asks for: the program, written as `query` says.
    fn program(query: Self::Program) -> Ask;
}

impl Negotiate for OutputQuery {
    type Program = ProgramQuery;

    fn ask(&self, headers: &HeaderMap) -> Ask {
        Ask::negotiate(headers, self)
    }

    fn program(query: ProgramQuery) -> Ask {
        Ask {
            gcode: true,
            output: OutputOptions {
                dialect: query.dialect,
                reference: query.reference,
                candidate: None,
                arcs: query.arcs,
                units: None,
            },
            timings: false,
        }
    }
}

impl Negotiate for CandidateQuery {
    type Program = CandidateProgramQuery;

    fn program(query: CandidateProgramQuery) -> Ask {
        Ask {
            gcode: true,
            output: OutputOptions {
                dialect: query.dialect,
                reference: query.reference,
                candidate: query.candidate,
                arcs: query.arcs,
                units: None,
            },
            timings: false,
        }
    }

    fn ask(&self, headers: &HeaderMap) -> Ask {
        Ask {
            gcode: wants_gcode(headers, self.format),
            output: OutputOptions {
                dialect: self.dialect,
                reference: self.reference,
                candidate: self.candidate,
                arcs: self.arcs,
                units: None,
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
                units: None,
            },
            timings: false,
        }
    }
}

/// Whether the client wants G-code: `format` if given, else the `Accept` header.
pub fn wants_gcode(headers: &HeaderMap, format: Option<Format>) -> bool {
    match format {
        Some(format) => format == Format::Gcode,
        None => accept_prefers_gcode(headers),
    }
}

/// Whether `Accept` ranks G-code above JSON (RFC 9110 §12.5.1): [`accept_prefers`].
fn accept_prefers_gcode(headers: &HeaderMap) -> bool {
    accept_prefers(headers, GCODE_MEDIA_TYPE)
}

/// Whether `Accept` ranks `media_type` above JSON (RFC 9110 §12.5.1). Each answer takes the
/// weight of the most specific range that matches it (`text/x-gcode` over `text/*` over `*/*`), 0
/// when none does; `media_type` only when its weight is higher, so a tie, a header that accepts
/// neither and no header give JSON (kerf answers JSON rather than 406 when nothing listed is what
/// it writes). An element that cannot be read (a bad range or q-value) counts as not sent.
pub fn accept_prefers(headers: &HeaderMap, media_type: &str) -> bool {
    let ranges: Vec<MediaRange> = headers
        .get_all(header::ACCEPT)
        .iter()
        .filter_map(|value| value.to_str().ok())
        .flat_map(|value| split_outside_quotes(value, ','))
        .filter_map(MediaRange::parse)
        .collect();
    let weight = |media_type: &str| {
        let (kind, subtype) = media_type.split_once('/').unwrap_or_default();
        ranges
            .iter()
            .filter_map(|range| range.specificity(kind, subtype).map(|specificity| (specificity, range.quality)))
            .max()
            .map_or(0, |(_, quality)| quality)
    };
    weight(media_type) > weight("application/json")
}

/// One element of `Accept`: `type/subtype` (either may be `*`) with its weight in thousandths.
#[derive(Debug, Clone, PartialEq, Eq)]
struct MediaRange {
    kind: String,
    subtype: String,
    quality: u16,
}

impl MediaRange {
    /// Reads `type/subtype *( OWS ";" OWS parameter )`; `None` for anything else.
    fn parse(element: &str) -> Option<Self> {
        let mut parts = split_outside_quotes(element, ';').into_iter().map(|part| part.trim_matches([' ', '\t']));
        let (kind, subtype) = parts.next()?.split_once('/')?;
        if !is_token(kind) || !is_token(subtype) || (kind == "*" && subtype != "*") {
            return None;
        }
        let mut quality = 1000;
        for parameter in parts {
            let (name, value) = parameter.split_once('=')?;
            if !is_token(name) {
                return None;
            }
            if name.eq_ignore_ascii_case("q") {
                quality = parse_qvalue(value)?;
            }
        }
        Some(Self { kind: kind.to_ascii_lowercase(), subtype: subtype.to_ascii_lowercase(), quality })
    }

    /// How closely the range names `kind/subtype`: 2 exactly, 1 as `kind/*`, 0 as `*/*`; `None`
    /// when it does not match.
    fn specificity(&self, kind: &str, subtype: &str) -> Option<u8> {
        match (self.kind.as_str(), self.subtype.as_str()) {
            ("*", "*") => Some(0),
            (k, "*") if k == kind => Some(1),
            (k, s) if k == kind && s == subtype => Some(2),
            _ => None,
        }
    }
}

/// `qvalue = ( "0" [ "." 0*3DIGIT ] ) / ( "1" [ "." 0*3("0") ] )` (RFC 9110 §12.4.2), in thousandths.
fn parse_qvalue(text: &str) -> Option<u16> {
    let (whole, fraction) = text.split_once('.').unwrap_or((text, ""));
    if fraction.len() > 3 || !fraction.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let thousandths = format!("{fraction:0<3}").parse::<u16>().ok()?;
    match whole {
        "0" => Some(thousandths),
        "1" if thousandths == 0 => Some(1000),
        _ => None,
    }
}

/// An RFC 9110 token (§5.6.2): one or more tchar.
fn is_token(text: &str) -> bool {
    !text.is_empty() && text.bytes().all(|b| b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b))
}

/// `text` cut at each `separator` that is not inside a quoted string (where `\` escapes).
fn split_outside_quotes(text: &str, separator: char) -> Vec<&str> {
    let mut pieces = Vec::new();
    let (mut start, mut quoted, mut escaped) = (0, false, false);
    for (index, character) in text.char_indices() {
        match character {
            _ if escaped => escaped = false,
            '\\' if quoted => escaped = true,
            '"' => quoted = !quoted,
            _ if character == separator && !quoted => {
                pieces.push(&text[start..index]);
                start = index + character.len_utf8();
            }
            _ => {}
        }
    }
    pieces.push(&text[start..]);
    pieces
}

#[cfg(test)]
mod tests {
    use super::{MediaRange, accept_prefers_gcode, parse_qvalue, split_outside_quotes};
    use axum::http::{HeaderMap, HeaderValue, header};

    fn gcode_for(accept: &[&str]) -> bool {
        let mut headers = HeaderMap::new();
        for value in accept {
            headers.append(header::ACCEPT, HeaderValue::from_str(value).unwrap());
        }
        accept_prefers_gcode(&headers)
    }

    #[test]
    fn qvalues_follow_the_grammar() {
        assert_eq!(parse_qvalue("0"), Some(0));
        assert_eq!(parse_qvalue("0.5"), Some(500));
        assert_eq!(parse_qvalue("0.125"), Some(125));
        assert_eq!(parse_qvalue("1"), Some(1000));
        assert_eq!(parse_qvalue("1.000"), Some(1000));
        assert_eq!(parse_qvalue("0."), Some(0), "\"0\" \".\" with no digits");
        for bad in ["", "1.5", "1.001", "0.1234", "2", ".5", "0,5", "-0", "high"] {
            assert_eq!(parse_qvalue(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn ranges_are_read_with_spaces_and_quoted_parameters() {
        let range = MediaRange::parse(" Text/X-Gcode ;\tcharset=\"a;b\" ; Q=0.25 ").unwrap();
        assert_eq!((range.kind.as_str(), range.subtype.as_str(), range.quality), ("text", "x-gcode", 250));
        assert_eq!(split_outside_quotes(r#"a;b="x,\"y";c"#, ','), [r#"a;b="x,\"y";c"#]);
        for bad in ["text", "*/json", "text/", "text/x gcode", "text/x-gcode;q", "text/x-gcode;q=2"] {
            assert_eq!(MediaRange::parse(bad), None, "{bad:?}");
        }
    }

    #[test]
    fn the_higher_weight_wins_and_a_tie_gives_json() {
        assert!(!gcode_for(&[]));
        assert!(gcode_for(&["text/x-gcode"]));
        assert!(!gcode_for(&["application/json, text/x-gcode;q=0.1"]));
        assert!(gcode_for(&["application/json;q=0.5, text/x-gcode"]));
        assert!(!gcode_for(&["text/x-gcode, application/json"]), "a tie keeps JSON");
        assert!(!gcode_for(&["text/x-gcode;q=0"]), "q=0 is not acceptable");
        assert!(gcode_for(&["text/*"]));
        assert!(!gcode_for(&["*/*"]));
        assert!(gcode_for(&["*/*;q=0.1, text/x-gcode"]));
        assert!(!gcode_for(&["text/*;q=0.9, application/*"]));
        assert!(!gcode_for(&["text/*, text/x-gcode;q=0"]), "the exact range overrides text/*");
        assert!(!gcode_for(&["text/html"]), "nothing kerf writes: JSON");
        assert!(!gcode_for(&["text/x-gcode;q=high"]), "an unreadable element counts as not sent");
        assert!(gcode_for(&["application/json;q=0.2", "text/x-gcode;q=0.3"]), "several header lines are one list");
    }
}
