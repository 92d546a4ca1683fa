//! The deburr request as clients send it (docs/spec/api.md, Deburr): the wire types and their defaults.
//! `job` validates it into the model the solver works on.

pub use crate::geometry::Direction;
use serde::{Deserialize, Serialize};

use crate::error::SolverError;
use crate::tool::ToolRef;
use crate::validate::finite;

/// Default tolerance TA in mm (docs/spec/deburr.md §1.4, proposed value).
pub const DEFAULT_TOLERANCE: f64 = 0.01;
/// Default feed in mm/min for the deburring loop.
pub const DEFAULT_FEED: f64 = 300.0;
/// Default spindle speed in rpm.
pub const DEFAULT_SPINDLE_RPM: f64 = 6000.0;
/// Default clearance in mm above the part for the clearance plane.
pub const DEFAULT_CLEARANCE: f64 = 5.0;
/// Default lead distance in mm: how far the outer-edge approach starts back along the bisector.
pub const DEFAULT_LEAD_DISTANCE: f64 = 1.0;
/// Smallest tolerance accepted (docs/spec/deburr.md §4, `E_TOL`).
pub const MIN_TOLERANCE: f64 = 1e-6;

/// The part carrying the cylindrical surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Workpiece {
    /// A thick-walled tube: both the outer and the inner ridge exist.
    Tube {
        /// A point on the tube axis A1 at the hole station, machine/work coordinates.
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
        origin: [f64; 3],
        /// θ_A: angle of A1 from +Y in the XY plane, counter-clockwise seen from +Z (docs/spec/deburr.md §1.3).
        #[serde(default)]
        arrangement_angle_deg: f64,
        /// RN, the bore's radius, mm. Give this or `inner_diameter`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        inner_radius: Option<f64>,
        /// ID, the bore's diameter (2·RN) as a drawing gives it, mm. Give this or `inner_radius`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        inner_diameter: Option<f64>,
        /// RT, the tube's outer radius, mm. Give this or `outer_diameter`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        outer_radius: Option<f64>,
        /// OD, the tube's outer diameter (2·RT) as a drawing gives it, mm. Give this or `outer_radius`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        outer_diameter: Option<f64>,
    },
    /// A block with a cylindrical bore (manifold block): only the inner ridge exists.
    BoreBlock {
        /// A point on the bore axis A1 at the hole station.
        #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
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

/// A size as the client gave it: as a radius or as a diameter, in the field it came in. Errors
/// about it quote that field and the value typed there.
#[derive(Debug, Clone, PartialEq)]
pub struct GivenSize {
    /// The field's path, e.g. `workpiece.outer_diameter`.
    pub field: String,
    /// The value as typed in that field, mm.
    pub value: f64,
    /// Whether `value` is a diameter (else a radius).
    pub diameter: bool,
}

impl GivenSize {
    /// The field's own name, without its path (`outer_diameter`).
    pub fn name(&self) -> &str {
        self.field.rsplit('.').next().unwrap_or(&self.field)
    }

    /// The radius the size gives, mm.
    pub fn radius(&self) -> f64 {
        if self.diameter { self.value / 2.0 } else { self.value }
    }
}

/// Normalises a size given as a radius or a diameter (`{prefix}.{radius_name}` or
/// `{prefix}.{diameter_name}`): exactly one of them, else `E_INPUT` naming both.
fn radius_or_diameter(
    prefix: &str,
    (radius_name, radius): (&str, Option<f64>),
    (diameter_name, diameter): (&str, Option<f64>),
) -> Result<GivenSize, SolverError> {
    let field = |name: &str| format!("{prefix}.{name}");
    match (radius, diameter) {
        (Some(value), None) => Ok(GivenSize { field: field(radius_name), value, diameter: false }),
        (None, Some(value)) => Ok(GivenSize { field: field(diameter_name), value, diameter: true }),
        (Some(_), Some(_)) => {
            Err(SolverError::input(field(diameter_name), format!("give {radius_name} or {diameter_name}, not both")))
        }
        (None, None) => Err(SolverError::input(field(radius_name), format!("give {radius_name} or {diameter_name}"))),
    }
}

impl Workpiece {
    /// A tube given by its radii RN and RT.
    pub fn tube(origin: [f64; 3], arrangement_angle_deg: f64, inner_radius: f64, outer_radius: f64) -> Self {
        Workpiece::Tube {
            origin,
            arrangement_angle_deg,
            inner_radius: Some(inner_radius),
            inner_diameter: None,
            outer_radius: Some(outer_radius),
            outer_diameter: None,
        }
    }
}

/// A tube's bore and outer sizes (RN or ID, RT or OD) as given in `workpiece`.
///
/// # Errors
/// `E_INPUT` naming both fields when a size is given both ways or not at all.
pub fn tube_sizes(
    (inner_radius, inner_diameter): (Option<f64>, Option<f64>),
    (outer_radius, outer_diameter): (Option<f64>, Option<f64>),
) -> Result<(GivenSize, GivenSize), SolverError> {
    let inner = radius_or_diameter("workpiece", ("inner_radius", inner_radius), ("inner_diameter", inner_diameter))?;
    let outer = radius_or_diameter("workpiece", ("outer_radius", outer_radius), ("outer_diameter", outer_diameter))?;
    Ok((inner, outer))
}

impl Hole {
    /// The hole's R2 or Ø as given, in the fields under `prefix` (`hole`).
    ///
    /// # Errors
    /// `E_INPUT` naming both fields when it is given both ways or not at all.
    pub fn size(&self, prefix: &str) -> Result<GivenSize, SolverError> {
        radius_or_diameter(prefix, ("radius", self.radius), ("diameter", self.diameter))
    }
}

/// Cross-section of the through hole seen along its axis (docs/spec/deburr.md §1.2).
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

/// The through hole and where its axis A2 lies relative to A1 (docs/spec/deburr.md §1.2–1.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct Hole {
    /// `round`, `slot` or `rounded_rect`.
    pub shape: HoleShape,
    /// R2: hole radius, slot half-width or corner radius, mm. Give this or `diameter`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Ø = 2·R2: hole diameter, slot width or corner diameter as a drawing gives it, mm. Give
    /// this or `radius`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<f64>,
    /// Slot: L_s (a number); rounded rectangle: `[across, along]`. Not used for round holes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_distance: Option<CentreDistance>,
    /// f: signed distance of A2 from A1 along x_L, mm (default 0, or from `axis_point`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eccentricity: Option<f64>,
    /// θ_P: angle of A2 from +Z, a rotation about A1 (docs/spec/deburr.md §1.3).
    #[serde(default)]
    pub penetration_angle_deg: f64,
    /// Any point on the hole axis A2 (the patent's "third position"): its station along A1 moves
    /// the origin there, and it fixes f (which must agree if also given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[cfg_attr(feature = "schema", schema(min_items = 3, max_items = 3))]
    pub axis_point: Option<[f64; 3]>,
}

/// One hole of `holes`: a [`Hole`] and where it lies on the workpiece.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct PlacedHole {
    /// `round`, `slot` or `rounded_rect`.
    pub shape: HoleShape,
    /// R2, mm. Give this or `diameter`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// Ø = 2·R2, mm. Give this or `radius`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<f64>,
    /// As in [`Hole`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centre_distance: Option<CentreDistance>,
    /// As in [`Hole`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub eccentricity: Option<f64>,
    /// θ_P: where around the cylinder axis the hole lies (from +Z), degrees.
    #[serde(default)]
    pub penetration_angle_deg: f64,
    /// θ_A of this hole, overriding the workpiece's, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arrangement_angle_deg: Option<f64>,
    /// Position along the cylinder axis from `workpiece.origin`, mm (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_position: Option<f64>,
}

/// Copies of `hole`: at each of `around_deg` (penetration angles about the cylinder axis; default
/// the hole's own) and at `count` stations `pitch` apart along the axis from the origin (default
/// one station).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct HolePattern {
    /// Penetration angles θ_P of the copies around the cylinder, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub around_deg: Option<Vec<f64>>,
    /// Distance between stations along the cylinder axis, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch: Option<f64>,
    /// Stations along the axis (1–100, default 1; more than one needs `pitch`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<usize>,
}

/// Most holes one request deburrs.
pub const MAX_HOLES: usize = 100;

/// One loop of a several-loop request (several holes, or both edges), as a single-hole,
/// single-edge request.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// Where its fields are in the request: `holes[i]`, or `hole` for a pattern's copies and a
    /// single hole.
    pub field: String,
    /// Its place in the request's holes: `i` of `holes[i]`, the copy of a pattern (station by
    /// station, every angle at each), 0 for a single hole.
    pub index: usize,
    /// The request field naming its tool: `tool`, or `inner_tool` for an inside ridge when given.
    pub tool_field: &'static str,
    /// Whether the tube is turned 180° about its axis for it: a hole of a tube whose axis points
    /// downward (θ_P more than 90° from +Z) cannot be reached by a vertical tool from above, so
    /// `request` places it turned up (θ_P − 180°).
    pub turned: bool,
    /// Its penetration angle, arrangement angle and axial position, as placed.
    pub penetration_angle_deg: f64,
    /// θ_A, degrees.
    pub arrangement_angle_deg: f64,
    /// Along the cylinder axis from `workpiece.origin`, mm.
    pub axial_position: f64,
    /// The single-hole request (its `edge` is `outer` or `inner`).
    pub request: DeburrRequest,
}

impl DeburrRequest {
    /// Whether the request deburrs more than one loop (`holes`, `pattern` or `edge: both`).
    pub fn is_several(&self) -> bool {
        self.holes.is_some() || self.pattern.is_some() || self.edge == Edge::Both
    }

    /// The edges each hole is deburred at, in order: the outer ridge before the inner.
    fn edges(&self) -> Result<Vec<Edge>, SolverError> {
        if self.inner_tool.is_some() && self.edge != Edge::Both {
            return Err(SolverError::input(
                "inner_tool",
                "inner_tool is the tool of the inside ridge when both edges are deburred: give it with edge \"both\"",
            ));
        }
        match (self.edge, &self.workpiece) {
            (Edge::Both, Workpiece::BoreBlock { .. }) => Err(SolverError::input(
                "edge",
                "a bore_block has only an inner edge (edge: \"inner\"), so not \"both\"",
            )),
            (Edge::Both, Workpiece::Tube { .. }) => Ok(vec![Edge::Outer, Edge::Inner]),
            (edge, _) => Ok(vec![edge]),
        }
    }

    /// Every loop as a single-hole, single-edge request, hole by hole in request order (each
    /// hole's outer ridge, then its inner one, with `edge: both`); a tube's hole that points
    /// downward is placed as the tube turned half a turn about its axis shows it (`turned`).
    ///
    /// # Errors
    /// `E_INPUT` naming `hole`, `holes`, `pattern`, `edge` or `inner_tool` when the combination or a
    /// placement is wrong.
    pub fn placements(&self) -> Result<Vec<Placement>, SolverError> {
        let edges = self.edges()?;
        let (origin, arrangement) = match &self.workpiece {
            Workpiece::Tube { origin, arrangement_angle_deg, .. }
            | Workpiece::BoreBlock { origin, arrangement_angle_deg, .. } => (*origin, *arrangement_angle_deg),
        };
        let placed = self.holes_to_place()?;
        let mut placements = Vec::with_capacity(placed.len() * edges.len());
        for (index, (field, hole, own_arrangement, axial)) in placed.into_iter().enumerate() {
            let arrangement = own_arrangement.unwrap_or(arrangement);
            let theta = finite(&format!("{field}.arrangement_angle_deg"), arrangement)?.to_radians();
            let workpiece = self.moved_workpiece(origin, theta, arrangement, axial);
            // A hole pointing down is deburred with the tube turned half a turn about its axis.
            let turned = matches!(self.workpiece, Workpiece::Tube { .. })
                && finite(&format!("{field}.penetration_angle_deg"), hole.penetration_angle_deg)?.to_radians().cos()
                    < -1e-9;
            let programmed = if turned {
                Hole { penetration_angle_deg: hole.penetration_angle_deg - 180.0, ..hole.clone() }
            } else {
                hole.clone()
            };
            for edge in &edges {
                let tool_field = if *edge == Edge::Inner && self.inner_tool.is_some() { "inner_tool" } else { "tool" };
                placements.push(Placement {
                    field: field.clone(),
                    index,
                    tool_field,
                    turned,
                    penetration_angle_deg: hole.penetration_angle_deg,
                    arrangement_angle_deg: arrangement,
                    axial_position: axial,
                    request: DeburrRequest {
                        workpiece: workpiece.clone(),
                        hole: Some(programmed.clone()),
                        holes: None,
                        pattern: None,
                        edge: *edge,
                        inner_tool: None,
                        ..self.clone()
                    },
                });
            }
        }
        Ok(placements)
    }

    /// The holes to deburr, each with the field it came from, its own arrangement angle (if it
    /// has one) and its axial position along A1: the one `hole`, the listed `holes`, or the
    /// copies a `pattern` makes of `hole`.
    fn holes_to_place(&self) -> Result<Vec<ToPlace>, SolverError> {
        match (&self.hole, &self.holes, &self.pattern) {
            (Some(_), Some(_), _) => Err(SolverError::input("holes", "give hole or holes, not both")),
            (_, Some(_), Some(_)) => {
                Err(SolverError::input("pattern", "a pattern copies hole: give it with hole, not holes"))
            }
            (None, None, _) => Err(SolverError::input("hole", "give hole (or holes)")),
            (Some(hole), None, None) => Ok(vec![("hole".to_owned(), hole.clone(), None, 0.0)]),
            (None, Some(holes), None) => listed_holes(holes),
            (Some(hole), None, Some(pattern)) => pattern_holes(hole, pattern),
        }
    }

    /// The workpiece moved `axial` along A1 (A1 turned by `theta`, radians, about Z) and turned to
    /// `arrangement`, degrees.
    fn moved_workpiece(&self, origin: [f64; 3], theta: f64, arrangement: f64, axial: f64) -> Workpiece {
        // A1 points along +Y turned by θ_A about Z (docs/spec/deburr.md §1.3).
        let along = [-theta.sin(), theta.cos(), 0.0];
        let moved = [origin[0] + axial * along[0], origin[1] + axial * along[1], origin[2]];
        let mut workpiece = self.workpiece.clone();
        match &mut workpiece {
            Workpiece::Tube { origin, arrangement_angle_deg, .. }
            | Workpiece::BoreBlock { origin, arrangement_angle_deg, .. } => {
                *origin = moved;
                *arrangement_angle_deg = arrangement;
            }
        }
        workpiece
    }
}

/// A hole to deburr: the field it came from, the hole, its own arrangement angle (if it has one)
/// and its axial position along A1, mm.
type ToPlace = (String, Hole, Option<f64>, f64);

/// The listed `holes`, each with its own placement.
fn listed_holes(holes: &[PlacedHole]) -> Result<Vec<ToPlace>, SolverError> {
    if holes.is_empty() || holes.len() > MAX_HOLES {
        return Err(SolverError::input("holes", format!("give 1 to {MAX_HOLES} holes")));
    }
    holes
        .iter()
        .enumerate()
        .map(|(index, placed)| {
            let field = format!("holes[{index}]");
            let axial = finite(&format!("{field}.axial_position"), placed.axial_position.unwrap_or(0.0))?;
            let hole = Hole {
                shape: placed.shape,
                radius: placed.radius,
                diameter: placed.diameter,
                centre_distance: placed.centre_distance,
                eccentricity: placed.eccentricity,
                penetration_angle_deg: placed.penetration_angle_deg,
                axis_point: None,
            };
            Ok((field, hole, placed.arrangement_angle_deg, axial))
        })
        .collect::<Result<_, SolverError>>()
}

/// The copies a `pattern` makes of `hole`: every angle around A1 at every station along it.
fn pattern_holes(hole: &Hole, pattern: &HolePattern) -> Result<Vec<ToPlace>, SolverError> {
    let angles = pattern.around_deg.clone().unwrap_or_else(|| vec![hole.penetration_angle_deg]);
    let count = pattern.count.unwrap_or(1);
    if angles.is_empty() || count == 0 || angles.len() * count > MAX_HOLES {
        return Err(SolverError::input(
            "pattern",
            format!("a pattern makes 1 to {MAX_HOLES} holes (around_deg × count)"),
        ));
    }
    let pitch = match (pattern.pitch, count) {
        (Some(pitch), _) => finite("pattern.pitch", pitch)?,
        (None, 1) => 0.0,
        (None, _) => return Err(SolverError::input("pattern.pitch", "count above 1 needs pitch")),
    };
    if hole.axis_point.is_some() {
        return Err(SolverError::input("hole.axis_point", "a pattern places its holes: no axis_point"));
    }
    let mut placed = Vec::with_capacity(angles.len() * count);
    for station in 0..count {
        for (index, angle) in angles.iter().enumerate() {
            let angle = finite(&format!("pattern.around_deg[{index}]"), *angle)?;
            let copy = Hole { penetration_angle_deg: angle, ..hole.clone() };
            placed.push(("hole".to_owned(), copy, None, pitch * station as f64));
        }
    }
    Ok(placed)
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
    /// Both ridges of a tube's holes in one program (a request's choice; each loop of the
    /// answer is `outer` or `inner`).
    Both,
}

/// How the band edges are placed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from predict's method in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = DeburrMethod))]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// The patent's closed form: band edges on the tangent lines at P (docs/spec/deburr.md §2.5).
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
    /// The through hole (or give `holes`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hole: Option<Hole>,
    /// Several holes deburred by one program, instead of `hole`: each with its own
    /// shape and, optionally, its own `arrangement_angle_deg` and `axial_position` along the
    /// cylinder axis from `workpiece.origin`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub holes: Option<Vec<PlacedHole>>,
    /// Copies of `hole` around the cylinder and along its axis.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pattern: Option<HolePattern>,
    /// Which ridge: `outer`, `inner` or `both` (a tube's; every hole's outer loop and inner
    /// loop, each an entry of the answer's `holes`).
    pub edge: Edge,
    /// With `edge: both`: the tool of the inside ridges, a registered tool number or an inline
    /// ball tool (default `tool`). The program changes tools once between them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_tool: Option<ToolRef>,
    /// Q, the amount of cutting (W = √2·Q), mm. Give this or `width`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cut_amount: Option<f64>,
    /// W, the chamfer width, mm. Give this or `cut_amount`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub width: Option<f64>,
    /// TA: largest distance of the centre polyline from the ideal centre path, mm (default 0.01).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
    /// `tangent` (default, the patent) or `exact`.
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
    /// G-code default. Its `max_feed` is not the deburring feed (`feed` keeps its default) but
    /// caps a larger one (`W_FEED_ABOVE_MACHINE_MAX`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub machine: Option<String>,
    /// T_b: the control's block processing time, ms (default: the machine's). With it the points
    /// are spaced by the block-time rule (docs/spec/segment.md): per interval the chord error that keeps its
    /// block at least `feed` × `block_time_ms` long on the local radius of the centre path, never
    /// coarser than `tolerance`; the summary then reports the blocks.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub block_time_ms: Option<f64>,
    /// Cut the program on the deburr's own model and answer `verification`
    /// (docs/spec/verify.md §9): default on; `{"enabled": false}` turns it off, `resolution` sets
    /// the dexel spacing.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub verification: Option<crate::verify::VerificationOptions>,
    /// `mm` or `inch`: the units of every length (and, per minute, feed) in this request and its
    /// answer (default: the named machine's `units`, else `mm`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub units: Option<crate::units::Units>,
}
