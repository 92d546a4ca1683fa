//! The prediction request as clients send it (docs/spec/api.md, Error prediction): the wire types, their
//! defaults and limits. `job` validates it into the model the solver works on.

pub use crate::gcode::SpindleDirection;
use serde::{Deserialize, Serialize};

use super::force::CuttingCoefficients;
use crate::gcode::Reference;
use crate::stock::Stock;
use crate::tool::ToolRef;

/// Default pixels per side N (the patent's 512 × 512).
pub const DEFAULT_RESOLUTION: u32 = 512;
/// Largest N for the surface-sampling method.
pub const MAX_SAMPLING_RESOLUTION: u32 = 8192;
/// Memory one worker may use for a depth buffer, bytes.
pub const MAX_DEPTH_BUFFER_BYTES: u64 = 256 << 20;
/// Worst-case bytes per pixel of the depth buffer (finished-pixel records and their index).
pub const DEPTH_BUFFER_BYTES_PER_PIXEL: u64 = 64;
/// Default rotation steps per revolution N_t (§3.7).
pub const DEFAULT_STEPS: u32 = 360;
/// Default edge elements N_θ (§3.7).
pub const DEFAULT_EDGE_ELEMENTS: u32 = 90;
/// Default chord tolerance for arcs, mm.
pub const DEFAULT_ARC_TOLERANCE: f64 = 0.001;
/// Default view-correction threshold θ_v, degrees (§3.10).
pub const DEFAULT_VIEW_CORRECTION_DEG: f64 = 60.0;
/// Default largest node correction, mm (§3.14 clamp).
pub const DEFAULT_MAX_CORRECTION: f64 = 0.1;
/// Most passes a request may have.
pub const MAX_PASSES: usize = 2_000_000;
/// Most passes whose force and deflection history a request may ask for.
pub const MAX_HISTORIES: usize = 100;
/// Default tolerance of `merge_similar_passes`, mm.
pub const DEFAULT_MERGE_TOLERANCE: f64 = 0.001;
/// Largest `merge_tolerance`, mm.
pub const MAX_MERGE_TOLERANCE: f64 = 0.1;
/// Most distinct spindle speeds in one program.
pub const MAX_SPINDLE_SPEEDS: usize = 1000;

/// The tool path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PathInput {
    /// Points of the programmed point in cutting order, joined by feed moves at `feed`.
    Points {
        /// `[x, y, z]`, mm; at least 2, at most 2 000 000.
        points: Vec<[f64; 3]>,
    },
    /// A G-code program (G0/G1/G2/G3, G17–G19, G20/G21, G90/G91, F, S, M3/M4/M5; see the
    /// reader's documentation). Feed moves are the passes; inch programs are converted.
    Gcode {
        /// The program text.
        program: String,
    },
}

/// How the finished surface and the generation point are found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from deburr's method in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = PredictMethod))]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Resolution-free surface sampling with area weighting (§6.6): the default, as accurate or
    /// more at every contact angle and needing no view correction.
    #[default]
    Sampling,
    /// The patent's depth buffer from below with the view correction of §3.10.
    DepthBuffer,
}

/// A deflection history prescribed instead of the force model (what-if studies, §7 cases B, C).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct PrescribedDeflection {
    /// D_x at equal steps of flute 0's rotation angle ψ over one revolution (ψ = 360°·k/len),
    /// mm; one value means constant. 1–100 000 values.
    pub x: Vec<f64>,
    /// D_y, same steps as `x`.
    pub y: Vec<f64>,
}

/// Path-correction settings (§3.14).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CorrectionOptions {
    /// Largest move of one node, mm (default 0.1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_correction: Option<f64>,
    /// Prediction rounds: 1 (the patent's single correction, default), 2 or 3 (predict again on
    /// the corrected path and correct the rest).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iterations: Option<u32>,
}

/// `POST /api/v1/predict`: predict the machining error of a ball-end-mill finishing path from
/// the tool's shape error and deflection, and correct the path (docs/spec/predict.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct PredictRequest {
    /// A ball end mill carrying its `shape_error` table (and `stiffness` for the deflection).
    pub tool: ToolRef,
    /// The stock before this operation.
    pub stock: Stock,
    /// The tool path.
    pub path: PathInput,
    /// Which point of the tool the path coordinates describe: `tip` (default) or `centre`.
    #[serde(default)]
    pub reference: Reference,
    /// Spindle speed in rpm where the program sets none (needed for `points`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_rpm: Option<f64>,
    /// Spindle sense where the program sets none (default `cw`, M03).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_direction: Option<SpindleDirection>,
    /// Feed in mm/min where the program sets none (needed for `points`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// Cutting-force coefficients of the tool/material pair; with the tool's `stiffness` they give
    /// the deflection.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutting: Option<CuttingCoefficients>,
    /// A prescribed deflection history, used instead of force and stiffness.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deflection: Option<PrescribedDeflection>,
    /// `sampling` (default) or `depth_buffer`.
    #[serde(default)]
    pub method: Method,
    /// Pixels per side N over the tool diameter (default 512; pixel size 2R/N); for `sampling`
    /// the sample spacing is the same 2R/N.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution: Option<u32>,
    /// Tooth-feed gap n_g of T1/T2 (1–3, default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tooth_feed_gap: Option<u32>,
    /// Correct the view past the threshold (`depth_buffer` only; default true).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view_correction: Option<bool>,
    /// View-correction threshold θ_v in degrees (default 60).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub view_correction_deg: Option<f64>,
    /// Φ₀: azimuth of flute 0 at rotation angle 0, degrees counter-clockwise from +X (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flute_zero_deg: Option<f64>,
    /// Rotation steps per revolution N_t (36–4096, default 360; rounded up to a multiple of the
    /// flute count).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub samples_per_revolution: Option<u32>,
    /// Edge elements N_θ from tip to equator (9–720, default 90).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edge_elements: Option<u32>,
    /// Chord tolerance for G2/G3 arcs, mm (default 0.001).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arc_tolerance: Option<f64>,
    /// Skip G-code blocks starting with `/` (default false: they run).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_delete: Option<bool>,
    /// Path-correction settings.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correction: Option<CorrectionOptions>,
    /// Indices of passes whose force and deflection over one revolution are returned (at most
    /// 100).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub history: Option<Vec<usize>>,
    /// Predict only passes `[from, to)` (the whole path still sweeps the stock); the others get
    /// status `not_predicted`. Lets a long job run in chunks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pass_range: Option<[usize; 2]>,
    /// θ_x: do not predict passes whose largest contact angle on the finished surface is at most
    /// this, degrees (0–90; claim 8, docs/spec/predict.md §3.4, where the patent uses 30–60):
    /// they get status `skipped_small_angle`. Absent: every pass is predicted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exclusion_deg: Option<f64>,
    /// With `exclusion_deg`: still find the generation point of the excluded passes and report
    /// their shape-error term e_S (and e = e_S, e_D null; the path is corrected for it), without
    /// the force and deflection (§3.4, E15). Default false: excluded passes are skipped (the
    /// patent's default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub exclusion_shape_error: Option<bool>,
    /// Simulate only some of a run of near-identical consecutive passes (same feed, speed,
    /// length, direction and neighbourhood within `merge_tolerance`) and give the others the
    /// nearest simulated result with its `merge_bound` (§3.2; box, plane and grid stocks).
    /// Default false: every pass is simulated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub merge_similar_passes: Option<bool>,
    /// Tolerance of the merge, mm (default 0.001, at most 0.1): how far the geometry of merged
    /// passes may differ, and how far the errors of the simulated passes around them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub merge_tolerance: Option<f64>,
    /// `mm` (default) or `inch`: the units of every length and feed of the request and the
    /// answer, and of a `mesh` stock's STL file unless its `units` says otherwise (docs/spec/api.md,
    /// Units). A G-code path keeps its own G20/G21.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
    /// Cut the program the answer writes on the given stock (docs/spec/verify.md §9): default
    /// on; `{"enabled": false}` turns it off, `resolution` sets the dexel spacing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verification: Option<crate::verify::VerificationOptions>,
}
