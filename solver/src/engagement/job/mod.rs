//! An engagement request validated into a [`Job`] before any heavy work (docs/spec/engagement.md §2,
//! §9 `E_INPUT`, `E_PATH`, and the size limits): the validated model the solver works on. Reading
//! the paths ([`path`]), the stock ([`stock`]) and each section of the request ([`sections`]) live
//! in the submodules.

mod candidates;
mod limits;
mod path;
mod physics;
mod sections;
mod stock;

pub(crate) use limits::grid_extent;

use super::P2;
use super::arcs::SpindleDirection;
use super::force::ForceModel;
use super::request::{Engine, FeedBasis, Representative};
use super::segments::Route;
use super::stock::Region;
use crate::error::{ErrorCode, SolverError, Warning};
use crate::machine::{BlockRule, SpindleLimits};
use crate::material::Kienzle;
use crate::validate::{self, MAX_COORDINATE, Measure};

/// How the flute counts share the feed (docs/spec/engagement.md §2.5).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum FeedMode {
    /// Constant f_z (mm/tooth).
    PerTooth(f64),
    /// Constant V_f (mm/min).
    Rate(f64),
}

/// A validated feed plan request.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PlanJob {
    pub target: f64,
    /// The highest feed of the plan: the request's, never above the machine's.
    pub max_feed: f64,
    /// The flute count the request chose for the plan and the program (else the recommended).
    pub flute_count: Option<u32>,
    pub basis: FeedBasis,
    pub tolerance: f64,
    pub min_block_length: f64,
}

/// One validated candidate path.
#[derive(Debug, Clone)]
pub(crate) struct CandidateJob {
    pub name: Option<String>,
    pub route: Route,
    pub warnings: Vec<Warning>,
    /// a_p of this path: its own, else the request's, else from its Z under the stock top.
    pub axial_depth: Option<f64>,
    /// The Z of the tool tip when a_p came from it (the program cuts there).
    pub cut_z: Option<f64>,
    /// Kienzle's force model at this path's a_p, with `kienzle` (or `material`).
    pub force: Option<ForceModel>,
}

/// A validated request: every number finite and in range, the geometry built.
#[derive(Debug, Clone)]
pub(crate) struct Job {
    pub radius: f64,
    pub flute_counts: Vec<u32>,
    pub tool_flutes: u32,
    pub spindle_rpm: f64,
    pub feed_mode: FeedMode,
    pub thickness_limit: Option<f64>,
    pub time_limit: Option<f64>,
    pub representative: Representative,
    pub direction: SpindleDirection,
    pub engine: Engine,
    pub step: f64,
    pub grid: Option<f64>,
    pub burr_disengage: f64,
    pub chipping_disengage: f64,
    pub radial_depth_min: Option<f64>,
    pub radial_depth_max: Option<f64>,
    pub spike_threshold: Option<f64>,
    pub min_feed_per_tooth: Option<f64>,
    pub stock_top_z: f64,
    pub clearance: f64,
    pub plan: Option<PlanJob>,
    /// The block-time rule of the program, at the nominal feed of the tool's flute count.
    pub rule: Option<BlockRule>,
    /// Apply the arc-feed correction on arcs of the path.
    pub arc_feed: bool,
    /// The machine's spindle limits (checked only with a force model).
    pub spindle: SpindleLimits,
    /// The machine's max feed, mm/min: no flute count whose feed exceeds it is recommended.
    pub machine_feed: Option<f64>,
    /// The machine's highest spindle speed, rpm: above it no flute count is recommended.
    pub machine_speed: Option<f64>,
    /// The tool's natural frequencies, Hz, and their directions.
    pub natural: Vec<(f64, &'static str)>,
    pub contact_dots: bool,
    pub region: Region,
    /// Warnings of the stock and the machine, for every candidate.
    pub shared_warnings: Vec<Warning>,
    pub candidates: Vec<CandidateJob>,
    pub single: bool,
}

impl FeedMode {
    /// f_z,k for `flutes` teeth at `spindle_rpm`.
    pub(crate) fn feed_per_tooth(self, flutes: u32, spindle_rpm: f64) -> f64 {
        match self {
            Self::PerTooth(fz) => fz,
            Self::Rate(vf) => vf / (f64::from(flutes) * spindle_rpm),
        }
    }

    /// The request's field the feeds come from: `feed_per_tooth` or `feed`.
    pub(crate) fn field(self) -> &'static str {
        match self {
            Self::PerTooth(_) => "feed_per_tooth",
            Self::Rate(_) => "feed",
        }
    }

    /// V_f,k for `flutes` teeth at `spindle_rpm`, mm/min.
    pub(crate) fn feed(self, flutes: u32, spindle_rpm: f64) -> f64 {
        match self {
            Self::PerTooth(fz) => f64::from(flutes) * fz * spindle_rpm,
            Self::Rate(vf) => vf,
        }
    }
}

fn point(field: &str, p: [f64; 2]) -> Result<P2, SolverError> {
    let [x, y] = validate::point(field, p, MAX_COORDINATE)?;
    Ok(P2::new(x, y))
}

fn optional(
    field: &str,
    value: Option<f64>,
    check: fn(&str, f64, Measure) -> Result<f64, SolverError>,
    measure: Measure,
) -> Result<Option<f64>, SolverError> {
    value.map(|v| check(field, v, measure)).transpose()
}

fn too_large(field: &str, what: &str, count: usize, limit: usize) -> SolverError {
    SolverError::new(ErrorCode::TooLarge, format!("{what}: {count} exceeds the limit of {limit}")).at(field)
}

/// A Z in the plane of the coordinates.
fn z_value(field: &str, z: f64) -> Result<f64, SolverError> {
    let z = validate::finite(field, z)?;
    if z.abs() > MAX_COORDINATE {
        return Err(SolverError::input(field, format!("{field} must lie within ±{MAX_COORDINATE} mm")));
    }
    Ok(z)
}

/// What the server resolves for an engagement request besides the tool and the machine: the
/// Kienzle values of the request's `material` and the spindle limits of its machine.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Physics {
    /// Kienzle values of the stored material the request names.
    pub material: Option<Kienzle>,
    /// The machine profile's spindle power and torque.
    pub spindle: SpindleLimits,
}
