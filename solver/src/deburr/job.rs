//! A deburr request validated into the model the solver works on, a [`Job`] (docs/spec/deburr.md §1.4
//! inputs, §4 `E_INPUT`/`E_NOT_THROUGH`/`E_INCONSISTENT_ECC`).

use super::frame::Frame;
use super::profile::Profile;
use crate::error::{ErrorCode, SolverError, Warning};
use crate::geometry::vec3;
use crate::machine::{BlockRule, MachineProfile, RuleSettings, cap_feed};
use crate::tool::{Tool, ToolKind};
use crate::validate::{self, Measure, finite, non_negative, optional_positive, positive};

use super::request::{
    CentreDistance, DEFAULT_CLEARANCE, DEFAULT_FEED, DEFAULT_LEAD_DISTANCE, DEFAULT_SPINDLE_RPM, DEFAULT_TOLERANCE,
    DeburrRequest, Direction, Edge, HoleShape, MIN_TOLERANCE, Method, Workpiece, tube_sizes,
};

/// A validated deburr job: every number finite and in range, the frame and profile built.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Job {
    pub frame: Frame,
    pub profile: Profile,
    pub edge: Edge,
    /// R1.
    pub cylinder_radius: f64,
    /// RN and RT when the workpiece is a tube.
    pub tube_radii: Option<(f64, f64)>,
    /// Distance from A1 to the part's top along the hole axis (RT, or the block face), if known.
    pub top_distance: Option<f64>,
    pub width: f64,
    pub cut_amount: f64,
    pub tolerance: f64,
    pub method: Method,
    pub direction: Direction,
    pub tool: Tool,
    pub feed: f64,
    pub spindle_rpm: f64,
    pub clearance: f64,
    pub lead_distance: f64,
    pub safe_z: Option<f64>,
    /// The block-time rule at `feed`, when a block time is known (request or machine).
    pub rule: Option<BlockRule>,
    /// Warnings from capping the feed to the machine's and resolving the rule (`W_FEED_ABOVE_MACHINE_MAX`).
    pub rule_warnings: Vec<Warning>,
}

/// Smallest radius, cut amount or width accepted, mm (0.1 µm: below any tool or feature).
pub const MIN_LENGTH: f64 = 1e-4;

/// A finite value within ±[`validate::MAX_COORDINATE`].
fn bounded(field: &str, value: f64) -> Result<f64, SolverError> {
    validate::coordinate(field, value)
}

/// A size: finite, from [`MIN_LENGTH`] to [`validate::MAX_COORDINATE`].
fn size(field: &str, value: f64) -> Result<f64, SolverError> {
    let value = bounded(field, positive(field, value, Measure::Length)?)?;
    if value < MIN_LENGTH {
        return Err(SolverError::input(
            field,
            format!("{field} must be at least {MIN_LENGTH} mm (got {})", Measure::Length.quote(value)),
        ));
    }
    Ok(value)
}

/// A point with every coordinate finite and within ±[`validate::MAX_COORDINATE`].
fn point(field: &str, p: [f64; 3]) -> Result<[f64; 3], SolverError> {
    validate::coordinates(field, p)
}

/// The workpiece section, checked: the placement of A1 and the radii.
struct Part {
    origin: crate::geometry::Vec3,
    arrangement: f64,
    /// R1: the radius of the cylinder the ridge lies on.
    cylinder_radius: f64,
    tube_radii: Option<(f64, f64)>,
    top_distance: Option<f64>,
}

/// The cutting and program settings, checked.
struct Conditions {
    safe_z: Option<f64>,
    feed: f64,
    rule: Option<BlockRule>,
    rule_warnings: Vec<Warning>,
    spindle_rpm: f64,
    clearance: f64,
    lead_distance: f64,
}

impl DeburrRequest {
    /// Validates the request against `tool` (already resolved from `self.tool`) and `machine`
    /// (resolved from `self.machine`).
    ///
    /// The sections are checked in a fixed order (tool, edge, workpiece, hole, chamfer,
    /// conditions), so a request with several faults is always refused for the same one.
    pub(crate) fn validate(&self, tool: &Tool, machine: Option<&MachineProfile>) -> Result<Job, SolverError> {
        check_tool(tool)?;
        if self.edge == Edge::Both {
            // The capability splits `both` into one request per ridge (`placements`).
            return Err(SolverError::input("edge", "one ridge at a time here: edge \"outer\" or \"inner\""));
        }
        let part = self.part()?;
        let (frame, profile) = self.hole_model(&part)?;
        let (width, cut_amount, tolerance) = self.chamfer()?;
        let conditions = self.conditions(machine)?;
        Ok(Job {
            frame,
            profile,
            edge: self.edge,
            cylinder_radius: part.cylinder_radius,
            tube_radii: part.tube_radii,
            top_distance: part.top_distance,
            width,
            cut_amount,
            tolerance,
            method: self.method,
            direction: self.direction,
            tool: tool.clone(),
            feed: conditions.feed,
            spindle_rpm: conditions.spindle_rpm,
            clearance: conditions.clearance,
            lead_distance: conditions.lead_distance,
            safe_z: conditions.safe_z,
            rule: conditions.rule,
            rule_warnings: conditions.rule_warnings,
        })
    }

    /// The workpiece: a tube (whose edge picks R1 from its radii) or a bore block (inner edge
    /// only, its face beyond the bore), and the placement of A1.
    fn part(&self) -> Result<Part, SolverError> {
        let (origin, arrangement, cylinder_radius, tube_radii, top_distance) = match &self.workpiece {
            Workpiece::Tube {
                origin,
                arrangement_angle_deg,
                inner_radius,
                inner_diameter,
                outer_radius,
                outer_diameter,
            } => {
                let (inner, outer) = tube_sizes((*inner_radius, *inner_diameter), (*outer_radius, *outer_diameter))?;
                size(&inner.field, inner.value)?;
                size(&outer.field, outer.value)?;
                if inner.radius() >= outer.radius() {
                    let radii = if inner.diameter == outer.diameter {
                        String::new()
                    } else {
                        format!(" (radii {} mm and {} mm)", inner.radius(), outer.radius())
                    };
                    return Err(SolverError::new(
                        ErrorCode::NotThrough,
                        format!(
                            "{} {} mm must be smaller than {} {} mm{radii}",
                            inner.name(),
                            inner.value,
                            outer.name(),
                            outer.value
                        ),
                    )
                    .at(&inner.field));
                }
                let (inner, outer) = (inner.radius(), outer.radius());
                let r1 = if self.edge == Edge::Inner { inner } else { outer };
                (origin, arrangement_angle_deg, r1, Some((inner, outer)), Some(outer))
            }
            Workpiece::BoreBlock { origin, arrangement_angle_deg, bore_radius, face_distance } => {
                let bore = size("workpiece.bore_radius", *bore_radius)?;
                if self.edge != Edge::Inner {
                    return Err(SolverError::input("edge", "a bore_block has only an inner edge (edge: \"inner\")"));
                }
                if let Some(face) = face_distance {
                    size("workpiece.face_distance", *face)?;
                    if *face <= bore {
                        return Err(SolverError::input(
                            "workpiece.face_distance",
                            format!("face_distance {face} mm must exceed bore_radius {bore} mm"),
                        ));
                    }
                }
                (origin, arrangement_angle_deg, bore, None, *face_distance)
            }
        };
        let origin = vec3(point("workpiece.origin", *origin)?);
        let arrangement = finite("workpiece.arrangement_angle_deg", *arrangement)?;
        Ok(Part { origin, arrangement, cylinder_radius, tube_radii, top_distance })
    }

    /// The hole: its frame on the part (§1.3) and its cross-section (§2.8).
    fn hole_model(&self, part: &Part) -> Result<(Frame, Profile), SolverError> {
        let hole = self.hole.as_ref().ok_or_else(|| SolverError::input("hole", "give hole (or holes)"))?;
        let given = hole.size("hole")?;
        size(&given.field, given.value)?;
        let radius = given.radius();
        let penetration = finite("hole.penetration_angle_deg", hole.penetration_angle_deg)?;
        let start = finite("start_deg", self.start_deg)?;
        if start != 0.0 && hole.shape != HoleShape::Round {
            return Err(SolverError::input("start_deg", "start_deg applies only to round holes"));
        }
        let eccentricity = hole.eccentricity.map(|f| bounded("hole.eccentricity", f)).transpose()?;
        let axis_point = hole.axis_point.map(|p| point("hole.axis_point", p)).transpose()?.map(vec3);
        let (frame, eccentricity) =
            Frame::resolve(part.origin, part.arrangement, penetration, axis_point, eccentricity)?;

        let profile = match (hole.shape, hole.centre_distance) {
            (HoleShape::Round, None) => Profile::round(radius, eccentricity, start.to_radians()),
            (HoleShape::Slot, Some(CentreDistance::Along(length))) => {
                let length =
                    bounded("hole.centre_distance", non_negative("hole.centre_distance", length, Measure::Length)?)?;
                Profile::rounded_rect(radius, eccentricity, 0.0, length / 2.0, true)
            }
            (HoleShape::RoundedRect, Some(CentreDistance::AcrossAlong([across, along]))) => {
                let across = bounded(
                    "hole.centre_distance[0]",
                    non_negative("hole.centre_distance[0]", across, Measure::Length)?,
                )?;
                let along = bounded(
                    "hole.centre_distance[1]",
                    non_negative("hole.centre_distance[1]", along, Measure::Length)?,
                )?;
                Profile::rounded_rect(radius, eccentricity, across / 2.0, along / 2.0, false)
            }
            (HoleShape::Round, Some(_)) => {
                return Err(SolverError::input("hole.centre_distance", "a round hole has no centre_distance"));
            }
            (HoleShape::Slot, _) => {
                return Err(SolverError::input(
                    "hole.centre_distance",
                    "a slot needs centre_distance: the distance L_s between its end circles along A1",
                ));
            }
            (HoleShape::RoundedRect, _) => {
                return Err(SolverError::input(
                    "hole.centre_distance",
                    "a rounded_rect needs centre_distance: [across, along] between its corner circles",
                ));
            }
        };
        Ok((frame, profile))
    }

    /// The chamfer: W and Q (one given, the other W = √2·Q) and the tolerance TA.
    fn chamfer(&self) -> Result<(f64, f64, f64), SolverError> {
        let (width, cut_amount) = match (self.cut_amount, self.width) {
            (Some(q), None) => {
                let q = size("cut_amount", q)?;
                (q * std::f64::consts::SQRT_2, q)
            }
            (None, Some(w)) => {
                let w = size("width", w)?;
                (w, w / std::f64::consts::SQRT_2)
            }
            (Some(_), Some(_)) => {
                return Err(SolverError::input("width", "give cut_amount or width, not both"));
            }
            (None, None) => {
                return Err(SolverError::input("cut_amount", "cut_amount (Q) or width (W) is required"));
            }
        };
        let tolerance = optional_positive("tolerance", self.tolerance, DEFAULT_TOLERANCE, Measure::Length)?;
        if tolerance < MIN_TOLERANCE {
            return Err(SolverError::new(
                ErrorCode::Tol,
                format!("tolerance {tolerance} mm is below the smallest reachable {MIN_TOLERANCE} mm"),
            )
            .at("tolerance"));
        }
        Ok((width, cut_amount, tolerance))
    }

    /// Feed, speed, the block-time rule (from the request or the machine) and the program's
    /// heights and distances.
    fn conditions(&self, machine: Option<&MachineProfile>) -> Result<Conditions, SolverError> {
        let safe_z = self.safe_z.map(|z| bounded("safe_z", z)).transpose()?;
        // The machine's max feed caps the deburring feed (never raises it).
        let mut rule_warnings = Vec::new();
        let feed = cap_feed(
            machine,
            "feed",
            optional_positive("feed", self.feed, DEFAULT_FEED, Measure::Feed)?,
            &mut rule_warnings,
        );
        let rule = if self.block_time_ms.is_some() || machine.is_some() {
            let settings =
                RuleSettings { feed: Some(feed), block_time_ms: self.block_time_ms, ..RuleSettings::default() };
            let (rule, warnings) = BlockRule::resolve(&settings, machine)?;
            rule_warnings.extend(warnings);
            Some(rule)
        } else {
            None
        };
        Ok(Conditions {
            safe_z,
            feed,
            rule,
            rule_warnings,
            spindle_rpm: crate::machine::spindle_within(
                machine.and_then(|machine| machine.max_spindle_rpm),
                "spindle_rpm",
                optional_positive("spindle_rpm", self.spindle_rpm, DEFAULT_SPINDLE_RPM, Measure::Number)?,
            )?,
            clearance: bounded(
                "clearance",
                optional_positive("clearance", self.clearance, DEFAULT_CLEARANCE, Measure::Length)?,
            )?,
            lead_distance: bounded(
                "lead_distance",
                optional_positive("lead_distance", self.lead_distance, DEFAULT_LEAD_DISTANCE, Measure::Length)?,
            )?,
        })
    }
}

/// The tool: a valid ball end mill of a usable radius.
fn check_tool(tool: &Tool) -> Result<(), SolverError> {
    tool.validate("tool.")?;
    size("tool.radius", tool.radius)?;
    if tool.kind != ToolKind::Ball {
        return Err(SolverError::new(
            ErrorCode::ToolKind,
            format!("deburring needs a ball end mill, but the tool is {}", tool.kind.as_str()),
        )
        .at("tool"));
    }
    Ok(())
}
