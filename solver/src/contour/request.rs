//! The contour request as clients send it (docs/spec/api.md, Contour): the wire types and their defaults.
//! `job` validates it into the model the solver works on.

use serde::{Deserialize, Serialize};

use crate::tool::ToolRef;

/// Most contour points accepted (`E_TOO_MANY_POINTS`).
pub const MAX_POINTS: usize = 200_000;
/// Most layers accepted (`E_TOO_MANY_LAYERS`).
pub const MAX_LAYERS: usize = 10_000;
/// Most passes per layer (`E_INPUT` at `passes`).
pub const MAX_PASSES: usize = 100;
/// Most moves in one answer, all layers together (`E_TOO_MANY_MOVES`): 56 bytes each, so at
/// most about 340 MB.
pub const MAX_MOVES: usize = 6_000_000;
/// Default height of the clearance plane above `depths.top`, mm.
pub const DEFAULT_CLEARANCE: f64 = 5.0;
/// Default chord tolerance for arcs (loops, round joins), mm.
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Smallest chord tolerance accepted, mm.
pub const MIN_TOLERANCE: f64 = 1e-6;
/// Default spindle speed, rpm.
pub const DEFAULT_SPINDLE_RPM: f64 = 6000.0;
/// Steepest descent of a ramp entry unless the request says, degrees: within what flat end mills
/// that do not cut at the centre are usually ramped at (2–5°).
pub const DEFAULT_RAMP_ANGLE_DEG: f64 = 3.0;
/// Default largest material angle that still gets a loop (docs/spec/contour.md §1.4 `alpha_max`), degrees.
pub const DEFAULT_MAX_ANGLE_DEG: f64 = 170.0;
/// Largest wall tilt accepted, degrees.
pub const MAX_TILT_DEG: f64 = 80.0;

/// Which side of the contour the tool runs on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The material is inside the polygon (islands, outer profiles); the tool runs outside it.
    Outside,
    /// The material is outside the polygon (pockets, inner profiles); the tool runs inside it.
    Inside,
}

/// Climb or conventional milling with a clockwise spindle (M03): fixes the travel direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum CutDirection {
    /// Material on the right of travel: clockwise around islands, counter-clockwise in pockets.
    #[default]
    Climb,
    /// Material on the left of travel (docs/spec/contour.md σ = +1 for an island, as in its cases).
    Conventional,
}

/// The layers: from `top` down to `bottom` in equal steps of at most `step`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Depths {
    /// Z of the stock top, mm (the first layer is one step below it).
    pub top: f64,
    /// Z of the last layer, mm (not above `top`; equal to it gives one layer at that height).
    pub bottom: f64,
    /// Largest depth of cut per layer, mm (> 0).
    pub step: f64,
}

/// The shape of the corner loops.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum LoopStyle {
    /// Straight exit and entry legs joined by a circular arc (claim 4, docs/spec/contour.md §3.5.1).
    #[default]
    Arc,
    /// Exit, one straight connecting segment, entry (claim 5, §3.5.2).
    Triangle,
    /// Exit, two straight segments parallel to the faces, entry (claim 5, §3.5.3).
    Parallelogram,
    /// No loops: a conventional join at every corner.
    None,
}

/// Corner loop style and sizing (docs/spec/contour.md §3.5.4).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CornerLoop {
    /// `arc` (default), `triangle`, `parallelogram` or `none`.
    #[serde(default)]
    pub style: LoopStyle,
    /// Arc loop radius ρ0, mm (default: the tool radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Leg length L of triangle and parallelogram loops, mm (default: the tool radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leg: Option<f64>,
    /// Shortest leg, mm (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_leg: Option<f64>,
    /// Longest leg, mm (default 10 × tool radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_leg: Option<f64>,
    /// Smallest arc radius before falling back to a parallelogram, mm (default 0.1 × tool radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_radius: Option<f64>,
    /// Largest arc radius before falling back to a parallelogram, mm (default 5 × tool radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_radius: Option<f64>,
    /// Loop only corners whose material angle is at most this, degrees in (0, 180) (default 170:
    /// nearly straight corners gain almost nothing from a loop).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_angle_deg: Option<f64>,
}

/// How a pass joins the faces at corners that get no loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Join {
    /// Straight to the offset-line intersection and on (a sharp turn the control may blend).
    #[default]
    Miter,
    /// An arc about the vertex (the tool rolls round the corner).
    Round,
}

/// One pass of the contour in every layer (claim 7, docs/spec/contour.md §3.8).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct PassSpec {
    /// Radial stock left on the wall by this pass, mm (≥ 0, not larger than the previous pass's).
    pub allowance: f64,
    /// Whether this pass makes corner loops (default: only the last pass does).
    #[serde(default, rename = "loop", skip_serializing_if = "Option::is_none")]
    pub loops: Option<bool>,
    /// Join at corners without a loop: `miter` (default) or `round`.
    #[serde(default)]
    pub join: Join,
}

/// Relief cut into inside corners, which a round tool otherwise leaves with a fillet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Relief {
    /// No relief: the corner keeps a fillet of the tool radius (reported).
    #[default]
    None,
    /// Along the bisector until the tool reaches the vertex.
    Dogbone,
    /// Along one edge until the tool reaches the vertex (`tbone_edge` says which).
    Tbone,
}

/// The edge a T-bone relief runs along.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum TboneEdge {
    /// The longer of the two edges at the corner (the cut goes into the shorter face).
    #[default]
    Longer,
    /// The shorter edge.
    Shorter,
    /// The edge from `contour[k−1]` to `contour[k]` (request order).
    Previous,
    /// The edge from `contour[k]` to `contour[k+1]` (request order).
    Next,
}

/// A per-corner choice that overrides the request-wide settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CornerOverride {
    /// The corner: an index into `contour`.
    pub index: usize,
    /// Force (`true`) or skip (`false`) the loop at this convex corner on looping passes.
    #[serde(default, rename = "loop", skip_serializing_if = "Option::is_none")]
    pub loops: Option<bool>,
    /// Relief at this inside corner.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relief: Option<Relief>,
    /// Edge of a T-bone relief at this corner.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tbone_edge: Option<TboneEdge>,
}

/// Wall tilt (claim 3): one angle for every wall, or one per contour edge.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(untagged)]
pub enum Tilt {
    /// The same tilt for every wall, degrees.
    All(f64),
    /// Tilt of the wall on edge k (from `contour[k]` to `contour[k+1]`), degrees.
    PerEdge(Vec<f64>),
}

/// An optional model of the control, used only to predict the over-cut at corners and to check
/// the allowances of passes without loops (docs/spec/contour.md §3.8 E1, §3.10 M1/M2).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct ControllerModel {
    /// M1: the control blends every line-to-line corner with a tangent arc of this radius, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blend_radius: Option<f64>,
    /// M2: servo time constant T, ms; arcs of radius R run with their radius shrunk by
    /// Δ = v²T²/(2R) at the cutting feed v.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub servo_time_constant_ms: Option<f64>,
}

/// `POST /api/v1/contour`: layered contour milling with sharp protruding corners (corner loops)
/// and optional inside-corner relief.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct ContourRequest {
    /// A registered tool number or an inline tool; its `radius` is the cutting radius.
    pub tool: ToolRef,
    /// The closed polygon `[[x, y], ...]`, counter-clockwise (the last point need not repeat the
    /// first). Curved faces are given as fine polylines. Left out with `drawing`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub contour: Vec<[f64; 2]>,
    /// The polygon read from the DXF file uploaded with the request in form part `drawing`
    /// (docs/spec/dxf.md §5) instead of `contour`: the outer boundary, or the island chosen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drawing: Option<crate::dxf::Drawing>,
    /// `outside` (material inside the polygon) or `inside` (a pocket: material outside it).
    pub side: Side,
    /// Layer heights.
    pub depths: Depths,
    /// Corner loop style and sizing (default `{"style": "arc"}`).
    #[serde(default)]
    pub corner_loop: CornerLoop,
    /// Cutting feed, mm/min.
    pub feed: f64,
    /// Feed of the loops proper (not their exit and entry legs) where they clear the stock,
    /// mm/min (default: `feed`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_feed: Option<f64>,
    /// `climb` (default) or `conventional`.
    #[serde(default)]
    pub direction: CutDirection,
    /// Accept a clockwise contour by reversing it (with a warning) instead of refusing it.
    #[serde(default)]
    pub fix_orientation: bool,
    /// Passes per layer, outermost first (default: one pass with allowance 0 and loops).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub passes: Option<Vec<PassSpec>>,
    /// Relief at inside corners: `none` (default), `dogbone` or `tbone`.
    #[serde(default)]
    pub inside_corner_relief: Relief,
    /// Edge of T-bone reliefs: `longer` (default), `shorter`, `previous` or `next`.
    #[serde(default)]
    pub tbone_edge: TboneEdge,
    /// Per-corner overrides of loops and reliefs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corner_overrides: Option<Vec<CornerOverride>>,
    /// Height of the clearance plane above `depths.top`, mm (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<f64>,
    /// Absolute Z of the clearance plane, overriding `clearance`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safe_z: Option<f64>,
    /// Length of the straight lead-in and lead-out along the normal of the start edge, mm
    /// (default: the tool radius; shortened if it would gouge).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lead: Option<f64>,
    /// The edge whose middle is the start and end point of every pass (index into `contour`,
    /// default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_edge: Option<usize>,
    /// Chord tolerance for arcs (loop arcs, round joins), mm (default 0.01). Arcs are chorded from
    /// outside, so the tool never cuts inside them. With `block_time_ms` it is the upper bound of
    /// the block-time rule's chord error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Block processing time of the control, ms (docs/spec/segment.md; default: the machine's). With it every
    /// arc is chorded at the chord error whose chords last one block time at the arc's feed
    /// (`feed`; loops at the larger of `feed` and `loop_feed`), never coarser than `tolerance`,
    /// and the summary reports the blocks (`summary.blocks`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_time_ms: Option<f64>,
    /// A registered machine (controller profile): its block time, margin and minimum chord error
    /// chord the arcs as `block_time_ms` does, its dialect is the G-code default, and its
    /// `max_feed` caps `feed`, `loop_feed` and `plunge_feed` (`W_FEED_ABOVE_MACHINE_MAX`). The
    /// server resolves it; the request's own `block_time_ms` wins.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// Spindle speed, rpm (default 6000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_rpm: Option<f64>,
    /// Feed of plunges and ramp entries, mm/min (default the tool's `plunge_feed`, else
    /// the machine's, else half of `feed`; never faster than `feed`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plunge_feed: Option<f64>,
    /// Steepest descent of a ramp entry, degrees (0 < angle ≤ 45, default 3). Layers enter on a
    /// ramp when the tool does not cut at its centre (`centre_cutting: false`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_angle_deg: Option<f64>,
    /// Radial stock on the wall before the first pass (left by roughing), mm. With it the first
    /// pass's loops may run at `loop_feed` where they clear that stock.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stock_allowance: Option<f64>,
    /// Wall tilt β in degrees (claim 3, positive: the wall moves towards the air as z rises), one
    /// value or one per edge. The contour is the wall's section at `depths.bottom`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt_deg: Option<Tilt>,
    /// Optional control model for predictions and allowance checks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerModel>,
    /// `mm` or `inch`: the units of every length (and, per minute, feed) in this request and its
    /// answer (default: the named machine's `units`, else `mm`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
    /// Cut the program on the contour's own model and answer `verification`
    /// (docs/spec/verify.md §9): default on; `{"enabled": false}` turns it off, `resolution` sets
    /// the dexel spacing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verification: Option<crate::verify::VerificationOptions>,
}

impl ContourRequest {
    /// The request with `contour` read from `upload`, the DXF file sent with it, when it has a
    /// `drawing`; `None` when it has none (and then no file may be sent).
    ///
    /// # Errors
    /// `E_INPUT`: a drawing with points too, a drawing without its file, a file without a
    /// drawing, the reader's refusals.
    pub fn from_upload(&self, upload: Option<&[u8]>) -> Result<Option<Self>, crate::error::SolverError> {
        match &self.drawing {
            Some(drawing) => {
                if !self.contour.is_empty() {
                    return Err(crate::error::SolverError::input(
                        "contour",
                        "give the polygon either as contour or as a drawing, not both",
                    ));
                }
                let contour = drawing.outline(upload, "drawing")?;
                Ok(Some(Self { contour, drawing: None, ..self.clone() }))
            }
            None if upload.is_some() => Err(crate::error::SolverError::input(
                "drawing",
                "a DXF file was uploaded but the request has no `drawing`",
            )),
            None => Ok(None),
        }
    }
}
