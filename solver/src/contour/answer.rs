//! What a contour request answers (docs/spec/api.md, Contour: `layers`, `corners`, `warnings`, plus the
//! per-pass figures and a summary).

use serde::{Deserialize, Serialize};

use super::request::{CutDirection, Join, LoopStyle, Relief, Side};
use crate::error::Warning;
use crate::tool::ToolKind;

/// What a move does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum MoveKind {
    /// Cutting at the feed: along the contour, the loops' straight exit and entry legs, reliefs.
    Cut,
    /// The turn of a corner loop, in the air (at `loop_feed` where it clears the stock).
    Loop,
    /// A feed move that does not follow the contour: plunge, lead-in, lead-out.
    Link,
    /// Positioning at rapid traverse (G00), above the part or in cut air.
    Rapid,
}

/// One move of the tool tip (the programmed point with the length offset to the tip).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ContourMove {
    /// `cut`, `loop`, `link` or `rapid`.
    pub kind: MoveKind,
    /// End point `[x, y, z]`, mm: the tool centre in the layer plane (the tip of a vertical tool).
    pub to: [f64; 3],
    /// Feed, mm/min (absent for rapids).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// Unit tool axis at the end point (only with tilted walls; boxed to keep the common move
    /// small).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub axis: Option<Box<[f64; 3]>>,
}

/// One layer: its height and every move made there, from the clearance plane back to it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ContourLayer {
    /// Z of the layer, mm.
    pub z: f64,
    /// The moves in order.
    pub moves: Vec<ContourMove>,
    /// The arcs among the moves, for a program that writes them as G02/G03.
    #[serde(skip)]
    pub(crate) arcs: Vec<ArcSpan>,
}

/// The chord moves `first..=last` of a layer run one arc of the tool-centre path from `start` to
/// `end` about `centre` (sweep in radians, counter-clockwise positive), all in the layer plane.
/// Under the block-time rule the move before `first` may have been lengthened to the first
/// circumscribed vertex (and the arc's last chord joined to the move after it): the exact
/// `start` and `end` lie on those straight moves.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(crate) struct ArcSpan {
    pub first: usize,
    pub last: usize,
    pub start: [f64; 2],
    pub end: [f64; 2],
    pub centre: [f64; 2],
    pub sweep: f64,
}

/// Whether the material protrudes at a corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Convexity {
    /// Material angle below 180°: the loop keeps it sharp.
    Convex,
    /// Material angle above 180° (an inside corner): a round tool leaves a fillet.
    Concave,
}

/// What the final pass does at a corner.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum CornerAction {
    /// Arc loop.
    LoopArc,
    /// Triangle loop.
    LoopTriangle,
    /// Parallelogram loop.
    LoopParallelogram,
    /// Sharp turn at the miter point.
    Miter,
    /// Arc about the vertex.
    Round,
    /// Inside corner without relief.
    Reflex,
    /// On a stretch of short edges the tool cannot follow: cut past at one merged corner point,
    /// material left (reported at the stretch's first corner).
    Unreached,
    /// Inside corner with a dogbone relief.
    Dogbone,
    /// Inside corner with a T-bone relief.
    Tbone,
}

/// A corner loop as built on the final pass of the first layer.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct LoopReport {
    /// `arc`, `triangle` or `parallelogram`.
    pub style: LoopStyle,
    /// Leg length L, mm.
    pub leg: f64,
    /// Arc radius ρ, mm (arc loops).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// A: end of the exit leg.
    pub exit_end: [f64; 2],
    /// B: start of the entry leg.
    pub entry_start: [f64; 2],
    /// C: arc centre (arc loops).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub centre: Option<[f64; 2]>,
    /// M: far corner (parallelogram loops).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub far_corner: Option<[f64; 2]>,
    /// Signed sweep of the arc, degrees (arc loops; negative: clockwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sweep_deg: Option<f64>,
    /// Extra path of exit, loop and entry, mm.
    pub length: f64,
    /// Smallest distance of the loop's moves to the contour minus the tool radius, mm.
    pub clearance: f64,
    /// Whether the loop proper runs at `loop_feed` (it clears the stock).
    pub at_loop_feed: bool,
}

/// A relief cut into an inside corner.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ReliefReport {
    /// `dogbone` or `tbone`.
    pub style: Relief,
    /// Where the tool centre turns back, `[x, y]`.
    pub target: [f64; 2],
    /// T-bone: index into `contour` of the start of the edge it runs along (request order).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub along_edge: Option<usize>,
}

/// Material left in and cut beyond an ideal sharp corner.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct MaterialReport {
    /// Area of material left where the contour says air, mm².
    pub left_area: f64,
    /// Distance from the vertex to the cut surface, mm (0 when the vertex is reached).
    pub left_depth: f64,
    /// Area of material cut where the contour says material, mm².
    pub overcut_area: f64,
    /// Deepest cut beyond the faces, mm.
    pub overcut_depth: f64,
}

/// One corner of the contour (a vertex kept after preparation).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ContourCorner {
    /// Index into the request's `contour`.
    pub index: usize,
    /// The vertex `[x, y]`.
    pub vertex: [f64; 2],
    /// Material angle α, degrees (below 180 convex, above concave).
    pub angle_deg: f64,
    /// Signed turn φ of the tool's travel, degrees (counter-clockwise positive).
    pub turn_deg: f64,
    /// `convex` or `concave`.
    pub convexity: Convexity,
    /// Whether the final pass loops round this corner.
    pub looped: bool,
    /// What the final pass does here.
    pub action: CornerAction,
    /// The final pass's CL corner point P `[x, y]` (first layer).
    pub cl_point: [f64; 2],
    /// The loop, when `looped`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub corner_loop: Option<LoopReport>,
    /// The relief, at relieved inside corners.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relief: Option<ReliefReport>,
    /// Material with ideal execution of the final pass.
    pub material: MaterialReport,
    /// Material predicted under the request's `controller` model.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted: Option<MaterialReport>,
}

/// Figures of one pass (per layer; the same in every layer unless walls are tilted).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PassReport {
    /// Allowance δ, mm.
    pub allowance: f64,
    /// Distance of the tool centre from a vertical wall, r + δ, mm.
    pub offset: f64,
    /// Whether the pass makes loops.
    pub loops: bool,
    /// Join where there is no loop.
    pub join: Join,
    /// Where the pass starts and ends `[x, y]`.
    pub start: [f64; 2],
    /// Number of looped corners.
    pub looped_corners: usize,
    /// Cutting length along the contour (with round joins), mm.
    pub cut_length: f64,
    /// Length of the loops' exit and entry legs, mm.
    pub leg_length: f64,
    /// Length of the loops proper, mm.
    pub loop_length: f64,
    /// Length of the relief moves, mm.
    pub relief_length: f64,
    /// Smallest loop clearance to the contour (minus r + δ), mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gouge_min_clearance: Option<f64>,
    /// Smallest clearance of exit, loop and entry moves to the stock before the pass (minus r),
    /// mm; absent when that stock is unknown.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stock_min_clearance: Option<f64>,
}

/// Counts and figures of the whole answer.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ContourSummary {
    /// `outside` or `inside`.
    pub side: Side,
    /// `climb` or `conventional`.
    pub direction: CutDirection,
    /// Tool radius r, mm.
    pub tool_radius: f64,
    /// Corners after preparation.
    pub corners: usize,
    /// Layers.
    pub layers: usize,
    /// Passes per layer.
    pub passes: usize,
    /// Moves in all layers.
    pub moves: usize,
    /// Length of all feed moves, mm.
    pub feed_length: f64,
    /// Cutting feed, mm/min.
    pub feed: f64,
    /// Feed of stock-free loops, mm/min.
    pub loop_feed: f64,
    /// Spindle speed, rpm.
    pub spindle_rpm: f64,
    /// Z of the clearance plane, mm.
    pub safe_z: f64,
    /// Lead-in length used, mm.
    pub lead: f64,
    /// Chord tolerance of arcs, mm.
    pub tolerance: f64,
    /// Time of the feed moves, s (rapids excluded).
    pub estimated_time_s: f64,
    /// With `block_time_ms`: the blocks, the shortest, the short ones and the block-limited time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blocks: Option<crate::machine::PathBlocks>,
    /// With a machine that has `max_accel`: the time the control would take for the program
    /// (trapezoidal feed profile, stops at sharp corners, plunges at the plunge feed, rapids at
    /// `rapid_feed`, one tool change) and its parts: cutting, air (loops, leads and links), rapid,
    /// tool change.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_time: Option<crate::machine::cycle::CycleTime>,
}

/// The answer of `POST /api/v1/contour`.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ContourSolution {
    /// The layers in machining order, each with its moves.
    pub layers: Vec<ContourLayer>,
    /// Every corner, in the request's point order.
    pub corners: Vec<ContourCorner>,
    /// Per pass, outermost first.
    pub passes: Vec<PassReport>,
    /// Counts and figures.
    pub summary: ContourSummary,
    /// Everything worth knowing that did not stop the computation.
    pub warnings: Vec<Warning>,
    /// Tool kind, for the G-code reference point.
    #[serde(skip)]
    pub(crate) tool_kind: ToolKind,
    /// Height of the tool's end rounding centre above its tip (ball radius, corner radius).
    #[serde(skip)]
    pub(crate) centre_height: f64,
    /// Header lines for the G-code program.
    #[serde(skip)]
    pub(crate) description: Vec<String>,
    /// Whether the moves need a tilted tool axis (no 3-axis G-code then).
    #[serde(skip)]
    pub(crate) tilted: bool,
}
