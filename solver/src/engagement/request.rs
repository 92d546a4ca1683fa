//! The engagement request as clients send it (docs/spec/api.md, Engagement; docs/spec/engagement.md §2): the wire
//! types and their defaults. `job` validates it into the model the solver works on.

pub use crate::geometry::Direction;
use std::fmt;

use serde::de::{self, MapAccess, SeqAccess, Visitor};
use serde::{Deserialize, Deserializer, Serialize};

use super::arcs::SpindleDirection;
use crate::material::Kienzle;
use crate::tool::ToolRef;

/// One move of a path given as `start` + `segments` (docs/spec/engagement.md §2.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum SegmentInput {
    /// Straight move to `to` (G1; G0 when `rapid`).
    Line {
        /// End point [x, y], mm.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
        to: [f64; 2],
        /// A positioning move (G0): it does not cut and is not timed; touching material is
        /// reported as a collision (docs/spec/engagement.md §5.8).
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        rapid: bool,
    },
    /// Circular move to `to` about `center` (G2 `cw` / G3 `ccw`); `to` equal to the start point
    /// makes a full circle.
    Arc {
        /// End point [x, y], mm.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
        to: [f64; 2],
        /// Arc centre [x, y], mm; its distances to the start and end points must agree within
        /// 1e-6·r.
        #[serde(alias = "centre")]
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
        center: [f64; 2],
        /// `ccw` (G3) or `cw` (G2).
        #[serde(alias = "direction")]
        dir: Direction,
    },
}

/// A path given as a start point and line/arc segments, or as G-code text.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct PathSegments {
    /// Start point of the tool centre [x, y], mm (required with `segments`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
    pub start: Option<[f64; 2]>,
    /// The moves in order (at least one of non-zero length).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segments: Option<Vec<SegmentInput>>,
    /// The path as a G-code program instead of `start`/`segments` (G0/G1/G2/G3 in G17, G20/G21,
    /// G90/G91): its XY moves from the first fully known position on; Z moves and F words do not
    /// matter here (the feed is the request's). Errors name the line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gcode: Option<String>,
}

/// A tool-centre path in the plane of the stock: a list of points joined by feed moves
/// (`[[x, y], ...]`, as in docs/spec/api.md), or `{"start": [x, y], "segments": [...]}` with lines, arcs
/// and rapids.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from `predict`'s own path input in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = EngagementPath))]
#[serde(untagged)]
pub enum PathInput {
    /// Feed moves (G1) through the points in order.
    Points(Vec<[f64; 2]>),
    /// Start point and line/arc segments.
    Segments(PathSegments),
}

// Hand-written so that a bad segment reports its own error instead of serde's "did not match
// any variant"; a future `{"gcode": "..."}` form is one more field of the map form.
impl<'de> Deserialize<'de> for PathInput {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct PathVisitor;

        impl<'de> Visitor<'de> for PathVisitor {
            type Value = PathInput;

            fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str("a list of points [[x, y], ...] or {\"start\": [x, y], \"segments\": [...]}")
            }

            fn visit_seq<S: SeqAccess<'de>>(self, seq: S) -> Result<PathInput, S::Error> {
                Vec::<[f64; 2]>::deserialize(de::value::SeqAccessDeserializer::new(seq)).map(PathInput::Points)
            }

            fn visit_map<M: MapAccess<'de>>(self, map: M) -> Result<PathInput, M::Error> {
                PathSegments::deserialize(de::value::MapAccessDeserializer::new(map)).map(PathInput::Segments)
            }
        }

        deserializer.deserialize_any(PathVisitor)
    }
}

/// One candidate path of a comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Candidate {
    /// Label shown beside the results (e.g. `straight`, `two bends`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The tool-centre path.
    pub path: PathInput,
    /// a_p of this path, mm: replaces the request's `axial_depth` for it (removal rate, forces,
    /// the program's cutting Z), so paths at different depths compare side by side.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_depth: Option<f64>,
    /// Z of the tool tip along this path, mm: replaces the request's `cut_z` for it (a_p =
    /// `stock_top_z` − cut_z where no `axial_depth` is given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_z: Option<f64>,
}

/// One region of a polygon stock.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct StockPolygon {
    /// Label (not used in the computation).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Outline [[x, y], ...], either orientation; the last point need not repeat the first.
    pub outer: Vec<[f64; 2]>,
    /// Holes, each a ring like `outer`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub holes: Vec<Vec<[f64; 2]>>,
}

/// A raster stock (docs/spec/engagement.md §2.2): cell (i, j) covers [x0 + i·cell, x0 + (i+1)·cell) ×
/// [y0 + j·cell, ...).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct StockBitmap {
    /// Corner [x0, y0] of cell (0, 0), mm.
    #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
    pub origin: [f64; 2],
    /// Cell side, mm.
    pub cell: f64,
    /// Cells per row.
    pub width: u32,
    /// Rows.
    pub height: u32,
    /// Base64 of the bits, row-major from row 0 (at y0) upwards, bit (i, j) = bit number
    /// j·width + i, most significant bit of each byte first, rows not padded; 1 = material.
    pub data: String,
}

/// Material already removed before this operation: everything within `radius` of `path`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct PreviousCut {
    /// Tool-centre path of the earlier operation (rapid segments do not cut).
    pub path: PathInput,
    /// Cutter radius of the earlier operation, mm.
    pub radius: f64,
}

/// The plan-view material W₀: give exactly one of `polygon` (with optional `holes`),
/// `polygons` or `bitmap`; `previous_cuts` remove material from it (the stock left by earlier
/// paths). Polygons use the even-odd rule with the boundary inclusive and must not cross.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from `predict`'s own stock in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = EngagementStock))]
#[serde(deny_unknown_fields)]
pub struct Stock {
    /// One outline [[x, y], ...] (docs/spec/api.md form).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygon: Option<Vec<[f64; 2]>>,
    /// Holes of `polygon`.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub holes: Vec<Vec<[f64; 2]>>,
    /// Several regions, each an outline with holes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub polygons: Option<Vec<StockPolygon>>,
    /// A raster of material cells.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bitmap: Option<StockBitmap>,
    /// Earlier cuts whose removed material is no longer there.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub previous_cuts: Vec<PreviousCut>,
}

/// Contact engine (docs/spec/engagement.md §5.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Engine {
    /// Engine B: the continuum definition evaluated against the real path and stock boundaries,
    /// with arc ends computed exactly (default; for numbers).
    #[default]
    Exact,
    /// Engine A, the patent's method: a grid of workpiece dots removed by the moving circle; also
    /// returns the contact dots for the scatter plot.
    Dots,
}

/// Statistic of H_k compared with `thickness_limit` (docs/spec/engagement.md §5.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum Representative {
    /// Largest summed chip thickness (default; the patent's).
    #[default]
    Max,
    /// Length-weighted mean over the engaged samples.
    Mean,
    /// Median over the engaged samples.
    Median,
}

/// What the chip-thinning compensation holds at the target (docs/spec/engagement.md §11 item 3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum FeedBasis {
    /// The thickest chip of one tooth: f_z' = h* / max sin θ over the engaged arcs (default).
    #[default]
    Tooth,
    /// The summed thickness of all teeth in the cut (torque proxy): f_z' = h*_Σ / (H_k/f_z).
    Sum,
}

/// Ask for the feed that holds a target chip thickness along the path (docs/spec/engagement.md §11 item 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct FeedPlanRequest {
    /// h*: the chip thickness to hold, mm (per tooth, or summed with `basis: sum`).
    pub target_thickness: f64,
    /// Highest programmable feed, mm/min. Required unless the request names a `machine`, whose
    /// `max_feed` the server puts here; a larger one is lowered to the machine's
    /// (`W_FEED_ABOVE_MACHINE_MAX`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_feed: Option<f64>,
    /// Flute count of the cutter that runs the program (default: the fastest recommended flute
    /// count, else the tool's `flutes`; the answer's `program_flute_count`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "schema", schema(minimum = 1, maximum = 32))]
    pub flute_count: Option<u32>,
    /// `tooth` (default) or `sum`.
    #[serde(default)]
    pub basis: FeedBasis,
    /// Largest relative feed spread inside one feed block before a new F word starts
    /// (default 0.05: blocks use the lowest feed they need, at most 5 % below the rest).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Shortest feed block, mm (default 0.5): shorter blocks merge into a neighbour at the lower
    /// feed, so the control is not starved of blocks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_block_length: Option<f64>,
}

/// `POST /api/v1/engagement`: tool/workpiece contact along one path (`path`) or several
/// candidate paths compared side by side (`paths`), chip thickness per flute count, machining
/// time and the recommended flute counts (docs/spec/engagement.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct EngagementRequest {
    /// A registered tool number or an inline tool; only its radius (the apparent rotation
    /// circle) and `flutes` enter the 2-D model, and with `kienzle` its `helix_deg` (the helix
    /// lag) and the natural frequencies of its `stiffness` (the tooth-passing check).
    pub tool: ToolRef,
    /// The plan-view material.
    pub stock: Stock,
    /// The tool-centre path (give this or `paths`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub path: Option<PathInput>,
    /// Several candidate paths for the same stock and tool, evaluated independently (give this
    /// or `path`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub paths: Option<Vec<Candidate>>,
    /// Spindle speed N, rpm.
    pub spindle_rpm: f64,
    /// Feed of plunges (straight moves down the tool axis) in the program, mm/min
    /// (default the tool's `plunge_feed`, else the machine's, else half the cutting feed; never
    /// faster than the cutting feed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plunge_feed: Option<f64>,
    /// Feed per tooth f_z, mm/tooth, kept for every flute count (constant f_z: V_f = k·f_z·N).
    /// Give this or `feed`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed_per_tooth: Option<f64>,
    /// Feed rate V_f, mm/min, kept for every flute count (constant V_f: f_z = V_f/(k·N)).
    /// Give this or `feed_per_tooth`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// Candidate flute counts k (1–32, distinct; default: the tool's `flutes`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flute_counts: Option<Vec<u32>>,
    /// T1: upper limit on the representative summed chip thickness, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub thickness_limit: Option<f64>,
    /// T2: upper limit on the machining time, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_limit_s: Option<f64>,
    /// Statistic compared with T1: `max` (default), `mean` or `median`.
    #[serde(default)]
    pub representative: Representative,
    /// `cw` (default, M03; right-hand cutter, teeth run 180° → 90° → 0° of the tool angle, so
    /// material right of travel is climb cut) or `ccw` (M04; teeth run 0° → 90° → 180°). The
    /// G-code program starts the spindle this way.
    #[serde(default)]
    pub spindle_direction: SpindleDirection,
    /// `exact` (default) or `dots`.
    #[serde(default)]
    pub engine: Engine,
    /// Δs, the sample spacing along the path, mm (default: tool diameter / 50).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step: Option<f64>,
    /// g, the dot spacing of the `dots` engine, mm (default: tool diameter / 200, or the bitmap
    /// cell for a bitmap stock).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<f64>,
    /// ψ_B: an exit whose disengage angle ψ is at least this is flagged `burr_risk` (default 80°).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub burr_disengage_deg: Option<f64>,
    /// ψ_C: an exit whose disengage angle ψ is at most this is flagged `chipping_risk` (default 20°).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chipping_disengage_deg: Option<f64>,
    /// a_e below this is flagged `rubbing_risk`, mm (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_depth_min: Option<f64>,
    /// a_e above this is flagged `vibration_risk`, mm (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radial_depth_max: Option<f64>,
    /// Report `W_ENGAGEMENT_SPIKE` where the engaged angle jumps by more than this between
    /// samples, degrees (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spike_threshold_deg: Option<f64>,
    /// Report `W_TINY_FZ` for flute counts whose feed per tooth falls below this, mm (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_feed_per_tooth: Option<f64>,
    /// a_p, the axial depth of cut, mm: gives the removal rate (MRR), the cutting Z of the
    /// G-code program (stock top − a_p) and, with `kienzle`, the chip width of every tooth
    /// (an entry of `paths` may give its own). Without it a_p comes from the heights:
    /// `stock_top_z` − `cut_z` (see `cut_z`); given, it wins over them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_depth: Option<f64>,
    /// Z of the stock's top face, mm (default 0): the plan-view stock is material from its
    /// outline up to this height. The G-code program's clearance is above it, and a path whose
    /// tip runs at Z = `cut_z` (or a G-code path's Z, with `stock_top_z` given) cuts a_p =
    /// `stock_top_z` − Z.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stock_top_z: Option<f64>,
    /// Z of the tool tip along the path, mm (an entry of `paths` may give its own): without
    /// `axial_depth` the path cuts a_p = `stock_top_z` − cut_z, 0 when it runs at or above the
    /// top (`W_AXIAL_DEPTH`); an a_p beyond the tool's `flute_length` is refused. A G-code path
    /// gives its own Z when its XY feed moves share one level and `stock_top_z` is given (a
    /// program's Z0 is not always the stock top).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_z: Option<f64>,
    /// Height of the clearance plane above the stock top, mm (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clearance: Option<f64>,
    /// Compute the feed that holds a target chip thickness (per-segment feeds and G-code).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed_plan: Option<FeedPlanRequest>,
    /// `dots` engine: return the contact dots for the scatter plot (default true).
    #[serde(default = "yes")]
    pub contact_dots: bool,
    /// Block processing time of the control, ms (docs/spec/segment.md; default: the machine's). With it the
    /// G-code program chords arcs at the block-time rule's chord error for their radius and
    /// feed (chords of one block; never coarser than 0.001 mm), and with `axial_depth` the
    /// answer reports the program's `blocks`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_time_ms: Option<f64>,
    /// A stored machine profile, resolved by the server: its `max_feed` fills an absent
    /// `feed_plan.max_feed` and caps a larger one (`W_FEED_ABOVE_MACHINE_MAX`) and the program's
    /// nominal feed (`W_FEED_CAPPED`), its dialect is the G-code default; no flute count over its
    /// `max_feed`, `max_spindle_rpm` or (with `kienzle` or `material`) spindle power and torque
    /// is recommended.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// Which entry of `paths` the G-code program follows and the verification cuts (0-based,
    /// default 0; a request with `path` has only 0; past the last path: `E_INPUT`). The
    /// endpoint's `?candidate=` overrides it for the program it writes, which is then the one
    /// verified; a job's program uses it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub candidate: Option<usize>,
    /// Correct the chip thickness on arcs of the path for the feed at the cutting edge,
    /// f_z·ρ/r_path with ρ the edge's distance from the arc's centre ((r_path ± R)/r_path at the
    /// sides; docs/spec/engagement.md §11 item 6): thickness, mean chip, feed plan and forces (default
    /// false: the patent's h = f_z·sin θ everywhere).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub arc_feed_correction: bool,
    /// Kienzle values of the work material: with `axial_depth` the answer gives the spindle
    /// torque and power along the path (docs/spec/engagement.md §11 item 4). Give this or `material`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub kienzle: Option<Kienzle>,
    /// The name of a work material in the materials library (`/api/v1/materials/{name}`, or a
    /// job file's `materials`): its Kienzle values, as `kienzle` would give them (give this or
    /// `kienzle`; 404 naming `material` when unknown).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
    /// `mm` or `inch`: the units of every length (and, per minute, feed) in this request and its
    /// answer (default: the named machine's `units`, else `mm`); `kienzle` stays in N/mm² and mm,
    /// and a G-code path in its own G20/G21.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
    /// Cut the program of the request's `candidate` on the plan-view stock extruded
    /// (docs/spec/verify.md §9): default on; `{"enabled": false}` turns it off, `resolution`
    /// sets the dexel spacing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verification: Option<crate::verify::VerificationOptions>,
}

fn yes() -> bool {
    true
}
