//! The stable error codes of kerf's answers (docs/spec/api.md, Errors; each spec's edge-case table): one
//! type, so no code is compared as a string and the OpenAPI document lists them all.

use serde::{Deserialize, Serialize};

/// Declares the codes: variant and wire form.
macro_rules! error_codes {
    ($($variant:ident => $code:literal,)+) => {
        /// A stable, machine-readable error code (`E_HOLE_TOO_LARGE`, ...): the solvers' refusals
        /// and the service's own (bad JSON, unknown resource, busy, ...).
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
        #[non_exhaustive]
        pub enum ErrorCode {
            $(
                #[doc = concat!("`", $code, "`")]
                #[serde(rename = $code)]
                $variant,
            )+
        }

        impl ErrorCode {
            /// Every code, in the order declared.
            pub const ALL: &'static [ErrorCode] = &[$(Self::$variant,)+];

            /// The code as it is written in answers.
            pub fn as_str(self) -> &'static str {
                match self {
                    $(Self::$variant => $code,)+
                }
            }

            /// The code written `text`, if there is one.
            pub fn parse(text: &str) -> Option<Self> {
                match text {
                    $($code => Some(Self::$variant),)+
                    _ => None,
                }
            }
        }
    };
}

error_codes! {
    ArcNotClosed => "E_ARC_NOT_CLOSED",
    ArcRadius => "E_ARC_RADIUS",
    BallMissesEdge => "E_BALL_MISSES_EDGE",
    Body => "E_BODY",
    Busy => "E_BUSY",
    Cancelled => "E_CANCELLED",
    Conflict => "E_CONFLICT",
    ContentType => "E_CONTENT_TYPE",
    Degenerate => "E_DEGENERATE",
    DegenerateCurve => "E_DEGENERATE_CURVE",
    DuplicatePoint => "E_DUPLICATE_POINT",
    ExactNoSolution => "E_EXACT_NO_SOLUTION",
    FarGouge => "E_FAR_GOUGE",
    GcodePosition => "E_GCODE_POSITION",
    GcodeSyntax => "E_GCODE_SYNTAX",
    GcodeUnsupported => "E_GCODE_UNSUPPORTED",
    GridMemory => "E_GRID_MEMORY",
    GridTooLarge => "E_GRID_TOO_LARGE",
    HoleTooLarge => "E_HOLE_TOO_LARGE",
    InconsistentEcc => "E_INCONSISTENT_ECC",
    InfeasibleFeedForRadius => "E_INFEASIBLE_FEED_FOR_RADIUS",
    Input => "E_INPUT",
    Internal => "E_INTERNAL",
    Interrupted => "E_INTERRUPTED",
    JobFailed => "E_JOB_FAILED",
    JobFile => "E_JOB_FILE",
    JobStoreFull => "E_JOB_STORE_FULL",
    Json => "E_JSON",
    MeshEmpty => "E_MESH_EMPTY",
    MeshFormat => "E_MESH_FORMAT",
    MeshNotClosed => "E_MESH_NOT_CLOSED",
    MeshTooLarge => "E_MESH_TOO_LARGE",
    Method => "E_METHOD",
    Multipart => "E_MULTIPART",
    NeckCollision => "E_NECK_COLLISION",
    NotFound => "E_NOT_FOUND",
    NotThrough => "E_NOT_THROUGH",
    NoApproach => "E_NO_APPROACH",
    NoClearancePlane => "E_NO_CLEARANCE_PLANE",
    NoFeed => "E_NO_FEED",
    NoPasses => "E_NO_PASSES",
    NoProgram => "E_NO_PROGRAM",
    NoShapeError => "E_NO_SHAPE_ERROR",
    NoSpindle => "E_NO_SPINDLE",
    NumericFailure => "E_NUMERIC_FAILURE",
    OffsetCollapse => "E_OFFSET_COLLAPSE",
    OffsetSelfIntersection => "E_OFFSET_SELF_INTERSECTION",
    Orientation => "E_ORIENTATION",
    Path => "E_PATH",
    PreconditionFailed => "E_PRECONDITION_FAILED",
    Query => "E_QUERY",
    ResolutionLimit => "E_RESOLUTION_LIMIT",
    ResultTooLarge => "E_RESULT_TOO_LARGE",
    SelfIntersection => "E_SELF_INTERSECTION",
    Stock => "E_STOCK",
    StorageFull => "E_STORAGE_FULL",
    TiltNeeds5Axis => "E_TILT_NEEDS_5_AXIS",
    Timeout => "E_TIMEOUT",
    Tol => "E_TOL",
    ToolKind => "E_TOOL_KIND",
    TooComplex => "E_TOO_COMPLEX",
    TooLarge => "E_TOO_LARGE",
    TooLargeAnswer => "E_TOO_LARGE_ANSWER",
    TooManyBlocks => "E_TOO_MANY_BLOCKS",
    TooManyLayers => "E_TOO_MANY_LAYERS",
    TooManyLines => "E_TOO_MANY_LINES",
    TooManyMoves => "E_TOO_MANY_MOVES",
    TooManyPasses => "E_TOO_MANY_PASSES",
    TooManyPoints => "E_TOO_MANY_POINTS",
    TooManySamples => "E_TOO_MANY_SAMPLES",
    TooManySpindleSpeeds => "E_TOO_MANY_SPINDLE_SPEEDS",
    Unauthorized => "E_UNAUTHORIZED",
    Unavailable => "E_UNAVAILABLE",
    WidthVsBall => "E_WIDTH_VS_BALL",
    WorkLimit => "E_WORK_LIMIT",
}

/// In the OpenAPI document: a string, one of the codes (written by hand because the derive does not
/// see the renames the declaring macro writes).
#[cfg(feature = "schema")]
impl utoipa::PartialSchema for ErrorCode {
    fn schema() -> utoipa::openapi::RefOr<utoipa::openapi::schema::Schema> {
        utoipa::openapi::ObjectBuilder::new()
            .schema_type(utoipa::openapi::schema::Type::String)
            .description(Some(
                "A stable, machine-readable error code: the solvers' refusals (each spec's edge-case table) and the \
                 service's own (bad JSON, unknown resource, busy, ...).",
            ))
            .enum_values(Some(Self::ALL.iter().map(|code| code.as_str())))
            .into()
    }
}

#[cfg(feature = "schema")]
impl utoipa::ToSchema for ErrorCode {}

impl std::fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Compares with the wire form, for clients and tests that hold the code as text.
impl PartialEq<&str> for ErrorCode {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

#[cfg(test)]
mod tests {
    use super::ErrorCode;

    #[test]
    fn every_code_reads_back_and_is_unique() {
        let mut seen = std::collections::HashSet::new();
        for code in ErrorCode::ALL {
            assert!(code.as_str().starts_with("E_"), "{code}");
            assert_eq!(ErrorCode::parse(code.as_str()), Some(*code));
            assert!(seen.insert(code.as_str()), "{code} twice");
            assert_eq!(serde_json::to_string(code).unwrap(), format!("\"{code}\""));
        }
        assert_eq!(ErrorCode::parse("E_NO_SUCH_CODE"), None);
    }
}
