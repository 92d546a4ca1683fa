//! What a deburr request answers (docs/spec/api.md, Deburr: answer 200).

use serde::{Deserialize, Serialize};

use super::request::{Edge, Method};
use crate::error::{SolverError, Warning};

/// One machining target with its ball centre, in machining order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct DeburrPoint {
    /// Ridge point P, machine coordinates.
    pub target: [f64; 3],
    /// Ball centre C.
    pub centre: [f64; 3],
    /// Lowest point of the ball along the tool axis (machine −Z): C − D·ẑ.
    pub tip: [f64; 3],
    /// Material wedge angle β at P, degrees.
    pub wedge_angle_deg: f64,
    /// Profile segment (`arc`; slot `line_y+x`, `arc_cs2`, `line_y-x`, `arc_cs1`; rounded
    /// rectangle `line_y+x`, `arc_q1`, `line_x+y`, `arc_q2`, `line_y-x`, `arc_q3`, `line_x-y`, `arc_q4`).
    #[serde(deserialize_with = "crate::error::interned")]
    #[cfg_attr(feature = "schema", schema(value_type = String))]
    pub segment: crate::error::Name,
    /// Parameter s ∈ [0, 1] along the segment.
    pub parameter: f64,
    /// φ on the segment's circle, degrees (arcs only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phi_deg: Option<f64>,
    /// CL: signed distance from P to C against the bisector (positive: C in the air). The cut
    /// depth along the bisector is D − CL.
    pub centre_offset: f64,
}

/// A move of the approach or the way out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct LeadMove {
    /// `rapid` (G00) or `feed` (G01).
    pub motion: LeadMotion,
    /// End point of the ball centre.
    pub centre: [f64; 3],
    /// End point of the tip.
    pub tip: [f64; 3],
}

/// Rapid or feed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum LeadMotion {
    /// G00.
    Rapid,
    /// G01 at the job's feed.
    Feed,
}

/// Figures a CAM engineer checks before running the job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct DeburrSummary {
    /// Distinct points of the closed loop (`points` has one more: the closing point).
    pub count: usize,
    /// Length of the closed centre polyline, mm.
    pub path_length: f64,
    /// Largest distance of the ideal centre path from the centre polyline, mm: the sampled
    /// deviation of every interval, measured densely where it comes within 10 % of TA.
    pub max_deviation: f64,
    /// TA used, mm.
    pub tolerance: f64,
    /// Q, mm.
    pub cut_amount: f64,
    /// W = √2·Q, the nominal chamfer width, mm.
    pub width: f64,
    /// Smallest and largest chamfer width cut by one ball section: where the ball at each emitted
    /// centre, cut by the ridge's normal plane, meets the true surfaces (at up to 1024 points,
    /// spread evenly, on denser loops), mm. The patent's single-section figure; the swept figures
    /// below are what the moves really cut.
    pub true_width_min: f64,
    /// See `true_width_min`.
    pub true_width_max: f64,
    /// Smallest and largest chamfer width swept by the ball along the emitted moves: in the
    /// ridge's normal plane at the targets and between them (up to 1024 intervals, spread evenly),
    /// the distance between where the true surfaces leave the swept volume, mm. `exact` keeps it
    /// within W ± max(0.005 mm, `tolerance`) or warns `W_WIDTH_OFF`.
    pub swept_width_min: f64,
    /// See `swept_width_min`.
    pub swept_width_max: f64,
    /// Smallest wedge angle β along the ridge, degrees.
    pub wedge_angle_min_deg: f64,
    /// Largest wedge angle β, degrees.
    pub wedge_angle_max_deg: f64,
    /// `exact` only: the largest distance between the patent's tangent-line centre and the exact
    /// centre of the same target, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_exact_offset: Option<f64>,
    /// Cutting feed, mm/min.
    pub feed: f64,
    /// Spindle speed, rpm.
    pub spindle_rpm: f64,
    /// Z of the ball centre at the clearance plane, if it is known.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub safe_centre_z: Option<f64>,
    /// Time of the feed moves (loop and leads) at `feed`, s; with a block time the block-limited
    /// time Σ max(Lᵢ/F, T_b) (docs/spec/segment.md §6.3).
    pub estimated_time_s: f64,
    /// With a block time (the request's or the machine's): the block processing time, ms.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block_time_ms: Option<f64>,
    /// With a block time: feed × block time, the shortest block the control digests at the feed, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub block_length: Option<f64>,
    /// With a block time: blocks of the loop.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blocks: Option<usize>,
    /// With a block time: the shortest block of the loop, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_block_length: Option<f64>,
    /// With a block time: blocks of the loop shorter than `block_length` (0 unless a warning says
    /// why: the tolerance, a radius too small for the feed, or a piece shorter than one block).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub short_blocks: Option<usize>,
}

/// The answer: the closed loop of centres, the approach and way out, a summary and warnings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct Deburr {
    /// The deburred ridge, echoed: choosing the wrong one gouges.
    pub edge: Edge,
    /// `tangent` or `exact`.
    pub method: Method,
    /// The targets in machining order; the last equals the first.
    pub points: Vec<DeburrPoint>,
    /// From the clearance plane to the first point (empty when no safe approach exists; see warnings).
    pub lead_in: Vec<LeadMove>,
    /// From the last point back to the clearance plane.
    pub lead_out: Vec<LeadMove>,
    /// Counts and figures.
    pub summary: DeburrSummary,
    /// Everything worth knowing that did not stop the computation.
    pub warnings: Vec<Warning>,
    /// What a G-code request must refuse with, when the approach is unsafe or unknown.
    #[serde(skip)]
    pub(crate) program_blocker: Option<SolverError>,
    /// Header lines for the G-code program.
    #[serde(skip)]
    pub(crate) description: Vec<String>,
    /// Ball radius D, mm.
    #[serde(skip)]
    pub(crate) ball_radius: f64,
}
