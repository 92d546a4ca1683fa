//! The deburr request as clients send it (api.md, Deburr): the wire types and their defaults.
//! [`super::job`] validates it into the model the solver works on.

pub use crate::geometry::Direction;
use serde::{Deserialize, Serialize};

use crate::tool::ToolRef;

/// Default tolerance TA in mm (deburr.md §1.4, proposed value).
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Default feed in mm/min for the deburring loop.
pub const DEFAULT_FEED: f64 = 300.0;
/// Default spindle speed in rpm.
pub const DEFAULT_SPINDLE_RPM: f64 = 6000.0;
/// Default clearance in mm above the part for the clearance plane.
pub const DEFAULT_CLEARANCE: f64 = 5.0;
/// Default lead distance in mm: how far the outer-edge approach starts back along the bisector.
pub const DEFAULT_LEAD_DISTANCE: f64 = 1.0;
/// Smallest tolerance accepted (deburr.md §4, `E_TOL`).
pub const MIN_TOLERANCE: f64 = 1e-6;

/// The part carrying the cylindrical surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Workpiece {
    /// A thick-walled tube: both the outer and the inner ridge exist.
    Tube {
        /// A point on the tube axis A1 at the hole station, machine/work coordinates.
        origin: [f64; 3],
        /// θ_A: angle of A1 from +Y in the XY plane, counter-clockwise seen from +Z (deburr.md §1.3).
        #[serde(default)]
        arrangement_angle_deg: f64,
        /// RN, mm.
        inner_radius: f64,
        /// RT, mm.
        outer_radius: f64,
    },
    /// A block with a cylindrical bore (manifold block): only the inner ridge exists.
    BoreBlock {
        /// A point on the bore axis A1 at the hole station.
        origin: [f64; 3],
        /// θ_A as for the tube.
        #[serde(default)]
        arrangement_angle_deg: f64,
        /// Bore radius, mm.
        bore_radius: f64,
        /// Distance from A1 to the block face the hole enters through, along the hole axis, mm.
        /// Places the clearance plane for the approach; needed for G-code unless `safe_z` is given.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        face_distance: Option<f64>,
    },
}

/// Cross-section of the through hole seen along its axis (deburr.md §1.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum HoleShape {
    /// Round hole of `radius` R2.
    Round,
    /// Slot: two half circles of `radius` joined by sides parallel to A1, `centre_distance` L_s apart.
    Slot,
    /// Rounded rectangle: four quarter circles of `radius`, sides parallel to x_L and A1,
    /// `centre_distance` `[across, along]` between corner-circle centres.
    RoundedRect,
}

/// Distance between a slot's end circles (a number) or a rounded rectangle's corner circles
/// (`[across, along]`), mm.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(untagged)]
pub enum CentreDistance {
    /// Slot: L_s along A1.
    Along(f64),
    /// Rounded rectangle: `[across, along]` = [2a, 2b].
    AcrossAlong([f64; 2]),
}

/// The through hole and where its axis A2 lies relative to A1 (deburr.md §1.2–1.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Hole {
    /// `round`, `slot` or `rounded_rect`.
    pub shape: HoleShape,
    /// R2: hole radius, slot half-width or corner radius, mm.
    pub radius: f64,
    /// Slot: L_s (a number); rounded rectangle: `[across, along]`. Not used for round holes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_distance: Option<CentreDistance>,
    /// f: signed distance of A2 from A1 along x_L, mm (default 0, or from `axis_point`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eccentricity: Option<f64>,
    /// θ_P: angle of A2 from +Z, a rotation about A1 (deburr.md §1.3).
    #[serde(default)]
    pub penetration_angle_deg: f64,
    /// Any point on the hole axis A2 (the seed's "third position"): its station along A1 moves
    /// the origin there, and it fixes f (which must agree if also given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_point: Option<[f64; 3]>,
}

/// Which ridge is deburred.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Edge {
    /// Hole wall × outer surface of the tube (RLT).
    Outer,
    /// Hole wall × inner surface (bore) (RLN).
    Inner,
}

/// How the band edges are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from predict's method in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = DeburrMethod))]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// The seed's closed form: band edges on the tangent lines at P (deburr.md §2.5).
    #[default]
    Tangent,
    /// Band edges on the true surfaces, and the chamfer the ball sweeps along the moves is W wide
    /// there (within max(0.005 mm, `tolerance`), else `W_WIDTH_OFF`).
    Exact,
}

/// `POST /api/v1/deburr`: deburr one ridge of a cross hole with a ball end mill.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct DeburrRequest {
    /// A registered tool number or an inline ball tool.
    pub tool: ToolRef,
    /// The tube or bored block.
    pub workpiece: Workpiece,
    /// The through hole.
    pub hole: Hole,
    /// Which ridge.
    pub edge: Edge,
    /// Q, the amount of cutting (W = √2·Q), mm. Give this or `width`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_amount: Option<f64>,
    /// W, the chamfer width, mm. Give this or `cut_amount`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<f64>,
    /// TA: largest distance of the centre polyline from the ideal centre path, mm (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// `tangent` (default, the seed) or `exact`.
    #[serde(default)]
    pub method: Method,
    /// φ_0: where a round hole's loop starts, degrees from +x_L (round holes only).
    #[serde(default)]
    pub start_deg: f64,
    /// Travel seen from +z_L (outside the hole, looking down its axis): `ccw` (default,
    /// increasing φ: climb milling with M03 on both ridges) or `cw` (conventional milling).
    #[serde(default)]
    pub direction: Direction,
    /// Cutting feed, mm/min (default 300).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// Spindle speed, rpm (default 6000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_rpm: Option<f64>,
    /// Height of the clearance plane above the part, mm (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<f64>,
    /// Outer edge: how far back along the bisector the approach starts, mm (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lead_distance: Option<f64>,
    /// Absolute Z of the clearance plane of the ball centre, overriding the computed one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safe_z: Option<f64>,
    /// A registered machine (controller profile): its block time, margin and minimum chord error
    /// make the points follow the block-time rule (like `block_time_ms`), its dialect is the
    /// G-code default. Its `max_feed` is not the deburring feed (`feed` keeps its default).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// T_b: the control's block processing time, ms (default: the machine's). With it the points
    /// are spaced by the block-time rule (chord.md): per interval the chord error that keeps its
    /// block at least `feed` × `block_time_ms` long on the local radius of the centre path, never
    /// coarser than `tolerance`; the summary then reports the blocks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_time_ms: Option<f64>,
}
