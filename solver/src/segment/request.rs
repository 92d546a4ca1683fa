//! The segment request as clients send it (docs/spec/api.md, Segment): the wire types and their defaults.
//! `job` validates it into the model the solver works on.

pub use crate::geometry::Direction;
use serde::{Deserialize, Serialize};

use crate::machine::Mode;
use crate::tool::ToolRef;

/// Most polyline points accepted.
pub const MAX_POLYLINE_POINTS: usize = 1_000_000;
pub use crate::validate::MAX_COORDINATE;
/// Smallest accuracy tolerance accepted, mm.
pub const MIN_TOLERANCE: f64 = 1e-6;
/// Default corner angle for polylines and splines, degrees.
pub const DEFAULT_CORNER_ANGLE_DEG: f64 = 20.0;
/// Default window length in target chords (docs/spec/segment.md §8 Q2: 3–5 chords per window).
pub const DEFAULT_WINDOW_CHORDS: f64 = 5.0;
/// Default spindle speed for the G-code program, rpm.
pub const DEFAULT_SPINDLE_RPM: f64 = 6000.0;
/// Default height of the clearance plane above the curve's highest point, mm.
pub const DEFAULT_CLEARANCE: f64 = 5.0;

/// The target curve. Points are `[x, y]` (the XY plane) or `[x, y, z]`; circles, arcs and
/// ellipses lie in a plane parallel to XY at the centre's z.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Curve {
    /// A full circle, starting and ending at `start_deg`.
    Circle {
        /// Centre, `[x, y]` or `[x, y, z]`.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 3))]
        centre: Vec<f64>,
        /// Radius, mm.
        radius: f64,
        /// Angle of the start point from +X, degrees (default 0).
        #[serde(default)]
        start_deg: f64,
        /// `ccw` (default) or `cw`.
        #[serde(default)]
        direction: Direction,
    },
    /// A circular arc from `start_deg` to `end_deg` in `direction` (equal angles 360° apart, or
    /// 0 and 360, make a full circle).
    Arc {
        /// Centre, `[x, y]` or `[x, y, z]`.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 3))]
        centre: Vec<f64>,
        /// Radius, mm.
        radius: f64,
        /// Angle of the start point from +X, degrees.
        start_deg: f64,
        /// Angle of the end point from +X, degrees.
        end_deg: f64,
        /// `ccw` (default) or `cw`.
        #[serde(default)]
        direction: Direction,
    },
    /// An elliptic arc x = a·cos t, y = b·sin t (in the ellipse's own axes), t from `start_deg`
    /// to `end_deg`: the parametric (eccentric) angle, not the polar angle of the point.
    Ellipse {
        /// Centre, `[x, y]` or `[x, y, z]`.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 3))]
        centre: Vec<f64>,
        /// `[a, b]`: semi-axis along the ellipse's first axis and across it, mm.
        #[cfg_attr(feature = "schema", schema(min_items = 2, max_items = 2))]
        semi_axes: [f64; 2],
        /// Start parameter t, degrees (default 0).
        #[serde(default)]
        start_deg: f64,
        /// End parameter t, degrees (default: a full turn after `start_deg`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        end_deg: Option<f64>,
        /// Angle of the first axis (of `a`) from +X, degrees (default 0).
        #[serde(default)]
        rotation_deg: f64,
        /// `ccw` (default, increasing t) or `cw`.
        #[serde(default)]
        direction: Direction,
    },
    /// Dense points of the target curve (2-D or 3-D), taken as the true curve: the chords end on
    /// its edges. Repeated consecutive points are dropped. Vertices where the direction turns by
    /// more than `corner_angle_deg` are corners: always command points, never inside a window.
    Polyline {
        /// The points in order, all with the same number of coordinates.
        points: Vec<Vec<f64>>,
        /// Smallest direction change that makes a corner, degrees (default 20).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        corner_angle_deg: Option<f64>,
    },
    /// A B-spline or NURBS curve (CAD output). Knots must be clamped (first and last knot
    /// `degree + 1` times, interior knots at most `degree` times).
    Bspline {
        /// Degree, 1 to 5.
        degree: usize,
        /// Control points, all `[x, y]` or all `[x, y, z]`.
        control_points: Vec<Vec<f64>>,
        /// Knot vector, `control_points + degree + 1` values (default: clamped uniform on [0, 1]).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        knots: Option<Vec<f64>>,
        /// Weights, one per control point, > 0 (default: all 1, a plain B-spline).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        weights: Option<Vec<f64>>,
        /// Smallest direction change at a knot of multiplicity ≥ degree that makes a corner,
        /// degrees (default 20).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        corner_angle_deg: Option<f64>,
    },
    /// The curve of the DXF file uploaded with the request in form part `drawing`
    /// (docs/spec/dxf.md §5): a drawing of one SPLINE is that NURBS exactly (as `bspline`), else
    /// the loop chosen (the outer boundary, or `island`) as a closed `polyline`.
    Drawing {
        /// Units of a drawing that does not say them (`$INSUNITS` 0 or missing).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        units: Option<crate::units::DrawingUnits>,
        /// Only the entities of this layer (default all).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        layer: Option<String>,
        /// Island n (from 1, as `POST /api/v1/dxf` lists them) instead of the outer boundary.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        island: Option<usize>,
        /// Largest gap between two entity ends joined, in the request's units (default 0.01 mm).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        join_tolerance: Option<f64>,
        /// Largest distance of a chord from its arc, bulge or ellipse, in the request's units (default
        /// 0.001 mm).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        chord_tolerance: Option<f64>,
        /// Smallest direction change that makes a corner, degrees (default 20).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        corner_angle_deg: Option<f64>,
    },
}

/// The whole-curve rule of `mode: curve`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum CurveRule {
    /// The largest window value along the curve (embodiment 3, Eq. 10).
    Max,
    /// From the smallest radius and the feed (embodiment 4, Eq. 13).
    #[default]
    Extremes,
    /// From the largest normal acceleration F²/r (embodiment 5, Eq. 15).
    NormalAccel,
}

/// How a window's radius of curvature is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum RadiusEstimate {
    /// Circle through the window's start, middle and end (docs/spec/segment.md §2.8, the patent), held
    /// within 1.1 times the smallest radius of curvature inside the window.
    #[default]
    ThreePoint,
    /// Smallest radius of curvature inside the window and the reach of its first chord: every
    /// block is then at least margin × feed × block time long, even where the curvature grows.
    Minimum,
}

/// `POST /api/v1/segment`: cut a curve into G01 blocks whose chord error follows the control's
/// block processing time (docs/spec/segment.md; patent 001).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct SegmentRequest {
    /// The target curve.
    pub curve: Curve,
    /// F: commanded feed, mm/min (default: the machine's `max_feed`, which also caps a larger one:
    /// `W_FEED_ABOVE_MACHINE_MAX`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// T_b: block processing time of the control, ms (default: the machine's).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_time_ms: Option<f64>,
    /// `window`, `curve` or `guarantee` (default: the machine's `mode`, else `window`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mode: Option<Mode>,
    /// Δs: window length for `mode: window` (and `rule: max`), mm (default 5 target chords).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<f64>,
    /// `mode: curve` only: `extremes` (default), `max` or `normal_accel`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rule: Option<CurveRule>,
    /// `rule: extremes` or `normal_accel` only: r_min read off the drawing, mm (default: computed
    /// from the curve).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_radius: Option<f64>,
    /// `three_point` (default) or `minimum`; `mode: window` and `rule: max` only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_estimate: Option<RadiusEstimate>,
    /// k_f: margin factor on the feed, ≥ 1 (default: the machine's, else 1). The blocks aim at
    /// margin × feed × block time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub margin: Option<f64>,
    /// k_ce: factor on the chord error, ≥ 1 (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chord_error_factor: Option<f64>,
    /// k_r: factor on the radius, in (0, 1] (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_factor: Option<f64>,
    /// k_Tb: factor on the block time, ≥ 1 (default 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_time_factor: Option<f64>,
    /// Accept factors on the unsafe side (below the surface) with a `W_UNSAFE_MARGIN` warning.
    #[serde(default)]
    pub allow_unsafe_margin: bool,
    /// Use the first-order sagitta h²/2r (Eq. 9) instead of the exact Eq. 8.
    #[serde(default)]
    pub sagitta_approximation: bool,
    /// C_emin: lower bound of the chord error, mm (default: the machine's, else 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_chord_error: Option<f64>,
    /// C_tol: accuracy bound, mm. The chord error is never coarser; where the rule wants more,
    /// blocks get shorter than feed × block time and `W_CHORD_ERROR_EXCEEDS_TOLERANCE` gives the
    /// feed that would meet both.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// Also cut the curve with this plain fixed chord error, mm, and report its figures side by
    /// side (`comparison`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub compare_tolerance: Option<f64>,
    /// A registered machine whose values are the defaults of this request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// The tool the G-code program calls (`T n M06`, `G43 H n`): a registered number or an
    /// inline tool. The curve is the programmed point, whatever the tool; without one the program
    /// stops (`M00`) for the operator to load it. Not used by the solver.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool: Option<ToolRef>,
    /// Spindle speed for the G-code program, rpm (default 6000).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_rpm: Option<f64>,
    /// Feed of plunges (straight moves down the tool axis) in the program, mm/min
    /// (default the tool's `plunge_feed`, else the machine's, else half the cutting feed; never
    /// faster than the cutting feed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub plunge_feed: Option<f64>,
    /// Z of the clearance plane for the G-code program, mm (default 5 above the curve's highest point).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub safe_z: Option<f64>,
    /// `mm` or `inch`: the units of every length (and, per minute, feed) in this request and its
    /// answer (default: the named machine's `units`, else `mm`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
}
