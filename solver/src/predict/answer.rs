//! What a prediction request answers (docs/spec/api.md, Error prediction): one record per pass in path
//! order, statistics, warnings, and (not serialised) what the corrected program needs.

use serde::{Deserialize, Serialize};

use super::job::NodeSource;
use super::request::Method;
use crate::error::Warning;
use crate::geometry::Vec3;

/// What happened at a pass (§5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum PassStatus {
    /// Predicted.
    Ok,
    /// The pass removes nothing (air, or already cut) at every position tried (E1, E3).
    NoCut,
    /// It cuts, but later motion removes everything it leaves (E4).
    NoSurface,
    /// The ball never reaches the stock's footprint (E10).
    OutsideStock,
    /// Outside the requested `pass_range`.
    NotPredicted,
    /// Its finished surface lies only at contact angles up to `exclusion_deg` (claim 8, §3.4).
    SkippedSmallAngle,
}

/// Remarks on a pass's prediction (§5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum PassFlag {
    /// The depth buffer looked from the rotated (or zoomed) view (E5, E6).
    ViewCorrected,
    /// The finished region touches the outermost ring of pixels (E5).
    RimLimited,
    /// Fewer than 4 pixels or samples, or rim-limited (E5).
    LowConfidence,
    /// Generation at the tip: azimuth and rotation angle undefined (E7).
    AtTip,
    /// The finished surface has several disjoint pieces; the largest is reported (E8).
    SeveralRegions,
    /// Retraced motion: the surface is credited to this (later) pass (E11).
    Retraced,
    /// The surface survives but the cutting force is zero (E12).
    NoLoad,
    /// No deflection data (stiffness and cutting coefficients, or a prescribed history): the
    /// error is the shape error alone (E13).
    NoDeflection,
    /// The contact angle is outside the shape-error table; its end value was used (E14).
    Extrapolated,
    /// Some force harmonic is outside the measured compliance table (E21).
    OutsideFrfBand,
    /// The correction of the pass's end node was clamped (E20).
    CorrectionClamped,
    /// The neighbouring errors cancel: the end node was not moved.
    CorrectionAmbiguous,
}

/// Force and deflection over one revolution (§1.3 O2).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PassHistory {
    /// Rotation step, degrees (ψ_m = m·step).
    pub step_deg: f64,
    /// Force on the tool (F_x, F_y, F_z), N, per step.
    pub force: Vec<[f64; 3]>,
    /// Tool-tip deflection (D_x, D_y), mm, per step.
    pub deflection: Vec<[f64; 2]>,
}

/// The prediction for one pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PredictedPass {
    /// Pass index (feed moves and arc chords in path order, from 0).
    pub index: usize,
    /// NC line (1-based) of G-code paths.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    /// `N` number of that block.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block_number: Option<u64>,
    /// Outcome.
    pub status: PassStatus,
    /// Remarks.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub flags: Vec<PassFlag>,
    /// Distance of the prediction position from the pass start, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<f64>,
    /// Ball centre O at the prediction position.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub centre: Option<[f64; 3]>,
    /// e = e_D + e_S, mm along the normal; > 0 leaves material (undercut), < 0 overcuts.
    pub error: Option<f64>,
    /// e_D: from the deflection at the generation instant, mm.
    pub error_deflection: Option<f64>,
    /// e_S = −δ(θ_c): from the shape error, mm.
    pub error_shape: Option<f64>,
    /// θ_c: angle between C→O and the tool axis, degrees (0 at the tip).
    pub contact_angle_deg: Option<f64>,
    /// φ_c: azimuth of C about the tool axis, degrees counter-clockwise from +X.
    pub azimuth_deg: Option<f64>,
    /// ψ_c: rotation angle of flute 0 when it generates C, degrees.
    pub rotation_angle_deg: Option<f64>,
    /// Generation point C.
    pub generation_point: Option<[f64; 3]>,
    /// Unit surface normal n = (O − C)/R, out of the material.
    pub normal: Option<[f64; 3]>,
    /// Tool deflection (D_x, D_y) at the generation instant, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub deflection: Option<[f64; 2]>,
    /// Pixels (depth buffer) or surface samples (sampling) of the cutting region K.
    pub cut_count: usize,
    /// Pixels or samples of the finished region S.
    pub finished_count: usize,
    /// View direction of the final depth-buffer view.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub view: Option<[f64; 3]>,
    /// Predicted error of the once-corrected path (with `iterations` ≥ 2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_error: Option<f64>,
    /// Move of the pass's end node, mm.
    pub correction: [f64; 3],
    /// Corrected end point of the pass (programmed point, in the request's reference).
    pub corrected: [f64; 3],
    /// Force and deflection over one revolution, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub history: Option<PassHistory>,
    /// With `merge_similar_passes`: the simulated pass whose result this pass carries (absent for
    /// simulated passes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub merged_with: Option<usize>,
    /// The error of the merge, mm: how much `error` can differ from simulating this pass (the
    /// spread of the errors of the simulated passes on either side plus twice the resolution of
    /// one prediction, which includes how far the deflection moves over the rotation angles the
    /// generation point's sample spans).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub merge_bound: Option<f64>,
}

/// One worst pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct WorstPass {
    /// Pass index.
    pub index: usize,
    /// NC line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub line: Option<usize>,
    /// e, mm.
    pub error: f64,
}

/// Error statistics of one prediction round.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct RoundSummary {
    /// Passes with a predicted error.
    pub predicted: usize,
    /// Largest |e|, mm.
    pub max_abs_error: Option<f64>,
    /// Root mean square of e, mm.
    pub rms_error: Option<f64>,
}

/// Statistics over the whole path (no timings: the server measures time).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PredictSummary {
    /// Passes.
    pub passes: usize,
    /// Passes with status `ok`.
    pub predicted: usize,
    /// Passes with status `no_cut`.
    pub no_cut: usize,
    /// Passes with status `no_surface`.
    pub no_surface: usize,
    /// Passes with status `outside_stock`.
    pub outside_stock: usize,
    /// Passes with status `skipped_small_angle` (with `exclusion_deg`; absent when none).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub skipped_small_angle: Option<usize>,
    /// Smallest e, mm.
    pub min_error: Option<f64>,
    /// Largest e, mm.
    pub max_error: Option<f64>,
    /// Mean e, mm.
    pub mean_error: Option<f64>,
    /// Root mean square of e, mm.
    pub rms_error: Option<f64>,
    /// The 20 passes with the largest |e|, worst first.
    pub worst: Vec<WorstPass>,
    /// Largest node correction, mm.
    pub max_correction: f64,
    /// Nodes whose correction was clamped.
    pub clamped: usize,
    /// Per prediction round (1 to `iterations`).
    pub rounds: Vec<RoundSummary>,
    /// Method used.
    pub method: Method,
    /// N.
    pub resolution: u32,
    /// Pixel size (sample spacing) 2R/N, mm.
    pub pixel_size: f64,
    /// N_t used.
    pub samples_per_revolution: usize,
    /// N_θ used.
    pub edge_elements: usize,
    /// Merging of similar passes, with `merge_similar_passes`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub merge: Option<MergeSummary>,
}

/// How many passes were simulated and merged (`merge_similar_passes`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct MergeSummary {
    /// The tolerance used, mm.
    pub tolerance: f64,
    /// Passes simulated (in `pass_range`, first round).
    pub simulated: usize,
    /// Passes that carry a simulated pass's result.
    pub merged: usize,
    /// Largest `merge_bound`, mm.
    pub max_bound: f64,
}

/// The answer of `POST /api/v1/predict`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Predict {
    /// One record per pass, in path order.
    pub passes: Vec<PredictedPass>,
    /// Statistics.
    pub summary: PredictSummary,
    /// Things to know about the whole request.
    pub warnings: Vec<Warning>,
    #[serde(skip)]
    pub(crate) corrections: Corrections,
}

/// Node corrections and where the nodes came from, for [`super::corrected_program`].
#[derive(Debug, Clone, PartialEq, Default)]
pub(crate) struct Corrections {
    pub(crate) nodes: Vec<Vec3>,
    pub(crate) offsets: Vec<Vec3>,
    pub(crate) sources: Vec<NodeSource>,
    pub(crate) reference_offset: Vec3,
}

/// Most bytes a pass's record takes as JSON beyond its outcome's JSON (which skips what it does
/// not have): its index, line and block number, correction and corrected point, residual error,
/// the longer names of its angles and the `null`s of what was not predicted, every number at its
/// longest (24 characters; checked by `pass_json_is_within_its_bound`).
pub(crate) const RECORD_JSON_BYTES: u64 = 768;

/// Most bytes one pass takes in a program: its point's line, up to five words of up to
/// `-1000000.0000` (the coordinate range).
const PASS_PROGRAM_BYTES: u64 = 128;

/// The bytes one predicted pass takes for `purpose`: its outcome in memory (and its record, when
/// it is `delivered`: a pass of the last round), plus its record's JSON (the outcome's as written,
/// counted, not kept, and [`RECORD_JSON_BYTES`]), its program line, or for a job both.
pub(crate) fn pass_bytes(
    outcome: &super::pipeline::Outcome,
    purpose: crate::capability::Purpose,
    delivered: bool,
) -> u64 {
    use crate::capability::Purpose;
    let history = outcome.history.as_ref().map_or(0, |history| {
        (history.force.len() * std::mem::size_of::<[f64; 3]>()
            + history.deflection.len() * std::mem::size_of::<[f64; 2]>()) as u64
    });
    let memory = std::mem::size_of::<super::pipeline::Outcome>() as u64
        + (outcome.flags.len() * std::mem::size_of::<PassFlag>()) as u64
        + history;
    if !delivered {
        return memory;
    }
    let record =
        std::mem::size_of::<PredictedPass>() as u64 + memory - std::mem::size_of::<super::pipeline::Outcome>() as u64;
    let json = || crate::capability::json_bytes(outcome) + RECORD_JSON_BYTES;
    memory
        + record
        + match purpose {
            Purpose::Json => json(),
            Purpose::Program => PASS_PROGRAM_BYTES,
            Purpose::Job => json() + PASS_PROGRAM_BYTES,
        }
}
