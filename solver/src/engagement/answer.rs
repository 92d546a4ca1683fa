//! What an engagement request answers (docs/spec/api.md, Engagement: `samples`, `flutes`, `recommended`;
//! docs/spec/engagement.md §3.1 outputs and the [X] extras).

use serde::{Deserialize, Serialize};
use smallvec::SmallVec;
use std::sync::Arc;

use super::arcs::MillingMode;
use super::request::{Engine, FeedBasis};
use super::segments::Route;
use crate::error::Warning;

/// One engaged arc with its entry and exit (docs/spec/engagement.md §5.4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ArcDetail {
    /// θ_in: where a tooth enters the material, degrees.
    pub entry_deg: f64,
    /// θ_out: where it leaves, degrees.
    pub exit_deg: f64,
    /// φ = acos(sin θ_in): angle between the radius to the entry point and the travel direction.
    pub engage_deg: f64,
    /// ψ = acos(sin θ_out).
    pub disengage_deg: f64,
    /// h_in / f_z = max(0, sin θ_in).
    pub entry_thickness_ratio: f64,
    /// h_out / f_z = max(0, sin θ_out).
    pub exit_thickness_ratio: f64,
    /// `slot`, `climb` (down), `conventional` (up) or `interior`.
    pub mode: MillingMode,
}

/// Marks on one sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum SampleFlag {
    /// An exit with ψ ≥ ψ_B: the tooth leaves where the chip is thin (§5.10).
    BurrRisk,
    /// An exit with ψ ≤ ψ_C: the tooth leaves where the chip is thick (§5.10).
    ChippingRisk,
    /// The tool is in material where it starts cutting (path start or after a rapid); the
    /// sample is left out of the statistics.
    Plunge,
    /// Engagement on the back half of the circle mid-path (ramp, reversal into stock).
    BackContact,
    /// a_e above `radial_depth_max`.
    VibrationRisk,
    /// 0 < a_e below `radial_depth_min`.
    RubbingRisk,
    /// On a rapid segment: not cutting, not timed.
    Rapid,
    /// A rapid segment passes through material.
    Collision,
}

/// A sample's engaged arcs: inline up to two (nearly every sample), on the heap beyond.
pub type SampleArcs = SmallVec<[[f64; 2]; 2]>;

/// One value per flute count of the request (`flutes`): inline up to four, on the heap beyond.
pub type PerFluteCount<T> = SmallVec<[T; 4]>;

/// The entry and exit of a sample's arcs, in the order of its arcs: shared by the samples whose
/// arcs are the same (nearly every sample along a straight cut), not copied into each.
pub type SampleArcDetails = Arc<[ArcDetail]>;

fn no_details(details: &SampleArcDetails) -> bool {
    details.is_empty()
}

/// A sample's risk and state marks (inline up to four).
pub type SampleFlags = SmallVec<[SampleFlag; 4]>;

/// The state at one sample of the path (docs/spec/api.md: `s`, `t`, `arcs`, `engaged_deg`, `radial_depth`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct EngagementSample {
    /// Path length from the start, mm.
    pub s: f64,
    /// Time from the start at the nominal feed of `time_flute_count` teeth, s (rapids untimed).
    pub t: f64,
    /// Tool centre [x, y], mm.
    pub position: [f64; 2],
    /// Direction of travel, degrees from +X (counter-clockwise).
    pub heading_deg: f64,
    /// Index of the path segment (for a point list, the segment from point `segment`; for a
    /// G-code path, the program line of the move).
    pub segment: usize,
    /// Engaged arcs `[[from_deg, to_deg], ...]`, tool angle of docs/spec/engagement.md §4.1 (90° ahead,
    /// 0° right, 180° left of travel); from in [−180, 180), to in (from, from + 360], sorted.
    #[cfg_attr(feature = "schema", schema(value_type = Vec<[f64; 2]>))]
    pub arcs: SampleArcs,
    /// Φ: total engaged angle, degrees.
    pub engaged_deg: f64,
    /// a_e: radial depth of cut, the measure of the arcs' lateral projection, mm.
    pub radial_depth: f64,
    /// Entry, exit and mode of each arc, in the order of `arcs`.
    #[serde(default, skip_serializing_if = "no_details")]
    #[cfg_attr(feature = "schema", schema(value_type = Vec<ArcDetail>))]
    pub arc_details: SampleArcDetails,
    /// Mean undeformed chip thickness over the engaged angles at the feed per tooth of
    /// `time_flute_count` teeth, mm (side milling: f_z·(a_e/R)/φ).
    pub mean_chip_thickness: f64,
    /// H_k, the largest summed chip thickness over the tooth phase, per flute count in the
    /// order of `flutes`, mm.
    #[cfg_attr(feature = "schema", schema(value_type = Vec<f64>))]
    pub thickness: PerFluteCount<f64>,
    /// n_k, the most teeth strictly inside the arcs at once, per flute count.
    #[cfg_attr(feature = "schema", schema(value_type = Vec<u32>))]
    pub teeth: PerFluteCount<u32>,
    /// Spindle torque averaged over the tooth phase, N·m, per flute count in the order of
    /// `flutes` (with `kienzle` or `material`): R·Σ k_c1.1·a_p·h^(1−m_c); the load the
    /// machine's `spindle_torque_nm` is compared with.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub torque_nm: Vec<f64>,
    /// Largest spindle torque over the tooth phase, N·m, per flute count (with `kienzle`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub peak_torque_nm: Vec<f64>,
    /// Spindle power 2πN·`torque_nm`/60, kW, per flute count (with `kienzle`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub power_kw: Vec<f64>,
    /// Largest resultant cutting force on the tool over the tooth phase (tangential and radial
    /// parts of every tooth in the cut, summed as vectors), N, per flute count (with `kienzle`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub peak_force_n: Vec<f64>,
    /// Material removal rate a_p·a_e·V_f at the nominal feed, mm³/min (with `axial_depth`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mrr: Option<f64>,
    /// Risk and state marks.
    #[serde(default, skip_serializing_if = "SmallVec::is_empty")]
    #[cfg_attr(feature = "schema", schema(value_type = Vec<SampleFlag>))]
    pub flags: SampleFlags,
}

/// Results for one flute count (docs/spec/api.md: `max_thickness`, `mean_thickness`, `min_thickness`,
/// `time_s`, `recommended`; docs/spec/engagement.md §5.7–§5.9).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct FluteResult {
    /// k.
    pub flute_count: u32,
    /// f_z,k, mm/tooth.
    pub feed_per_tooth: f64,
    /// V_f,k, mm/min.
    pub feed: f64,
    /// Largest H_k over the engaged samples, mm.
    pub max_thickness: f64,
    /// Length-weighted mean of H_k over the engaged samples, mm.
    pub mean_thickness: f64,
    /// Smallest H_k over the engaged samples, mm (sampling dependent).
    pub min_thickness: f64,
    /// Median of H_k over the engaged samples, mm.
    pub median_thickness: f64,
    /// P_k = 60·L_feed/V_f,k, s.
    pub time_s: f64,
    /// Meets the given limits.
    pub recommended: bool,
    /// T1 minus the representative thickness, mm (negative: over the limit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thickness_margin: Option<f64>,
    /// T2 minus the time, s (negative: too slow).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_margin_s: Option<f64>,
    /// Every limit this flute count misses, with its value and the limit: the chip thickness
    /// (T1, the representative statistic) and time (T2) limits, and the machine's spindle torque
    /// and power (the highest phase-mean value over the engaged samples, as the torque chart
    /// draws them; with `kienzle` or `material`), spindle speed and max feed. A flute count that
    /// misses any is not recommended.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub over_limits: Vec<OverLimit>,
    /// Most teeth in the cut at once anywhere on the path.
    pub max_teeth: u32,
    /// Path intervals `[[s_from, s_to], ...]` (sample positions) where two or more teeth cut at
    /// once.
    pub multi_tooth_intervals: Vec<[f64; 2]>,
    /// Spindle torque averaged over the tooth phase and the engaged samples (length-weighted),
    /// N·m (with `kienzle` or `material`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_torque_nm: Option<f64>,
    /// Largest torque over the tooth phase and the path, N·m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_torque_nm: Option<f64>,
    /// 2πN·`mean_torque_nm`/60, kW.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mean_power_kw: Option<f64>,
    /// 2πN·`peak_torque_nm`/60, kW.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_power_kw: Option<f64>,
    /// Largest resultant cutting force on the tool over the tooth phase and the path, N.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_force_n: Option<f64>,
    /// Tooth-passing frequency N·k/60, Hz (with `kienzle` or `material`); `W_TOOTH_PASSING`
    /// when it lies within 5 % of a natural frequency of the tool's `stiffness`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tooth_passing_hz: Option<f64>,
}

/// A limit a flute count is judged against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum FluteLimit {
    /// T1, `thickness_limit`, mm.
    Thickness,
    /// T2, `time_limit_s`, s.
    Time,
    /// The machine's `spindle_torque_nm`, N·m.
    SpindleTorque,
    /// The machine's spindle power at the spindle speed (`spindle_power_kw`, its power curve),
    /// kW.
    SpindlePower,
    /// The machine's `max_spindle_rpm`, rpm.
    SpindleSpeed,
    /// The machine's `max_feed`, mm/min.
    MachineFeed,
}

impl FluteLimit {
    /// What the limit is, in words.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Thickness => "chip thickness",
            Self::Time => "time",
            Self::SpindleTorque => "spindle torque",
            Self::SpindlePower => "spindle power",
            Self::SpindleSpeed => "spindle speed",
            Self::MachineFeed => "feed",
        }
    }

    /// Its unit.
    #[must_use]
    pub fn unit(self) -> &'static str {
        match self {
            Self::Thickness => "mm",
            Self::Time => "s",
            Self::SpindleTorque => "N·m",
            Self::SpindlePower => "kW",
            Self::SpindleSpeed => "rpm",
            Self::MachineFeed => "mm/min",
        }
    }
}

/// A limit a flute count misses, and by how much.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct OverLimit {
    /// Which limit.
    pub limit: FluteLimit,
    /// The flute count's value, in the limit's unit.
    pub value: f64,
    /// The limit, in the same unit.
    pub allowed: f64,
}

impl OverLimit {
    /// "spindle torque 14.7 N·m > 10 N·m (+47 %)".
    #[must_use]
    pub fn describe(&self) -> String {
        let unit = self.limit.unit();
        format!(
            "{} {} {unit} > {} {unit} (+{:.0} %)",
            self.limit.name(),
            significant(self.value),
            self.allowed,
            100.0 * (self.value / self.allowed - 1.0)
        )
    }
}

/// A value with four significant digits, for messages.
fn significant(value: f64) -> String {
    let digits = (3 - value.abs().max(1e-12).log10().floor() as i32).clamp(0, 9) as usize;
    format!("{value:.digits$}")
}

/// Why a feed block has its feed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum FeedLimit {
    /// The target chip thickness.
    Thickness,
    /// The machine's maximum feed.
    Machine,
    /// The spindle's power (with `kienzle` and a machine's `spindle_power_kw` or power curve).
    Power,
    /// The spindle's rated torque.
    Torque,
    /// No contact: the tool moves through the air at the nominal feed of the plan's flute count.
    Air,
}

/// A stretch of the path programmed with one feed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct FeedBlock {
    /// Path segment the block lies on.
    pub segment: usize,
    /// Start, path length, mm.
    pub from_s: f64,
    /// End, path length, mm.
    pub to_s: f64,
    /// Feed, mm/min (whole numbers, rounded down); absent on a rapid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feed: Option<f64>,
    /// What sets the feed; absent on a rapid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limited_by: Option<FeedLimit>,
}

/// Feeds that hold the target chip thickness (chip-thinning compensation, §11 item 3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct FeedPlan {
    /// Teeth of the cutter the feeds are for.
    pub flute_count: u32,
    /// h*, mm.
    pub target_thickness: f64,
    /// `tooth` or `sum`.
    pub basis: FeedBasis,
    /// Cap, mm/min.
    pub max_feed: f64,
    /// The path cut into blocks of one feed, in path order.
    pub blocks: Vec<FeedBlock>,
    /// Cutting time with these feeds, s.
    pub time_s: f64,
    /// Cutting time at the nominal feed of the same flute count, s.
    pub nominal_time_s: f64,
    /// Lowest and highest block feed, mm/min.
    pub feed_range: [f64; 2],
}

/// The cutting-force model of an answer (docs/spec/engagement.md §11 items 4, 5, 9).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct ForceInfo {
    /// k_c1.1 used, N/mm².
    pub kc11: f64,
    /// m_c used.
    pub mc: f64,
    /// a_p, mm: the chip width of every tooth.
    pub axial_depth: f64,
    /// F_r/F_t used.
    pub radial_ratio: f64,
    /// Helix lag 2a_p·tan λ/D over which each tooth's cut is spread, degrees (0 without the
    /// tool's `helix_deg`).
    pub helix_lag_deg: f64,
    /// Ball and bull-nose ends with engine `exact`: the most sections of the end (heights whose
    /// engaged arcs were found at their own radius, refined where the engagement changes with
    /// height, and the straight flank above the corner) summed at one sample (docs/spec/engagement.md §11
    /// item 5).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub height_sections: Option<usize>,
    /// The machine's rated power the path is checked against, kW.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spindle_power_kw: Option<f64>,
    /// The machine's rated torque the path is checked against, N·m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub spindle_torque_nm: Option<f64>,
    /// The tool's natural frequencies the tooth-passing frequencies are checked against, Hz.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub natural_frequencies_hz: Vec<f64>,
}

/// The dot grid of the `dots` engine.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct GridInfo {
    /// g, mm.
    pub cell: f64,
    /// Corner [x, y] of dot (0, 0)'s cell, mm.
    pub origin: [f64; 2],
    /// Dots across.
    pub width: usize,
    /// Dots up.
    pub height: usize,
    /// Memory of the bits, bytes.
    pub bytes: usize,
}

/// The answer for one path.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct PathEngagement {
    /// Candidate name, when given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The contact-position series.
    pub samples: Vec<EngagementSample>,
    /// Per flute count, in the request's order.
    pub flutes: Vec<FluteResult>,
    /// Flute counts meeting the limits, fastest first (ties: fewer teeth first).
    pub recommended: Vec<u32>,
    /// Path length L, mm.
    pub path_length: f64,
    /// Length of the feed moves (rapids excluded), mm.
    pub feed_length: f64,
    /// The flute count `t` and `mrr` are computed for (the tool's `flutes`).
    pub time_flute_count: u32,
    /// The flute count the feed plan and the G-code program are for: `feed_plan.flute_count`
    /// when given, else the first of `recommended`, else the tool's `flutes`
    /// (`W_PROGRAM_FLUTE_COUNT` when it is not the tool's).
    pub program_flute_count: u32,
    /// Engine used.
    pub engine: Engine,
    /// Δs used, mm.
    pub step: f64,
    /// The dot grid (`dots` engine).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid: Option<GridInfo>,
    /// Path intervals `[[s_from, s_to], ...]` (sample positions) with contact.
    pub engaged_intervals: Vec<[f64; 2]>,
    /// Largest Φ over the path, degrees, and where (s).
    pub max_engaged_deg: f64,
    /// s of the largest Φ, mm.
    pub max_engaged_at_s: f64,
    /// Largest a_e, mm.
    pub max_radial_depth: f64,
    /// Largest removal rate, mm³/min (with `axial_depth`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_mrr: Option<f64>,
    /// `dots` engine: removed dots as `[s, θ_deg]` (one per sample and 1° bin) for the scatter
    /// plot of the patent's contact graph.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_dots: Option<Vec<[f64; 2]>>,
    /// The force model and limits behind the torque and power fields (with `kienzle` or
    /// `material`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub forces: Option<ForceInfo>,
    /// Feeds holding the target chip thickness, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feed_plan: Option<FeedPlan>,
    /// With a block time (`block_time_ms` or a machine) and `axial_depth`: the blocks of this
    /// path's program, the shortest, the short ones and the block-limited time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub blocks: Option<crate::machine::PathBlocks>,
    /// Everything worth knowing that did not stop the computation.
    pub warnings: Vec<Warning>,
    /// What the G-code post needs (read back empty: a split request's finish step fills it in).
    #[serde(skip)]
    pub(crate) post: PostData,
}

/// Several candidate paths side by side.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
// Named apart from segment's comparison with a fixed tolerance in the OpenAPI document.
#[cfg_attr(feature = "schema", schema(as = EngagementComparison))]
pub struct Comparison {
    /// One result per entry of `paths`, in order.
    pub candidates: Vec<PathEngagement>,
}

/// `POST /api/v1/engagement` answer: one path's result (request with `path`), or the candidates
/// side by side (request with `paths`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(untagged)]
pub enum EngagementSolution {
    /// The request gave `path`.
    Single(Box<PathEngagement>),
    /// The request gave `paths`.
    Comparison(Comparison),
}

impl EngagementSolution {
    /// The results in request order (one for `path`).
    pub fn candidates(&self) -> &[PathEngagement] {
        match self {
            Self::Single(result) => std::slice::from_ref(result.as_ref()),
            Self::Comparison(comparison) => &comparison.candidates,
        }
    }
}

/// The geometry and settings the G-code program needs, kept out of the JSON.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct PostData {
    pub route: RouteData,
    pub nominal_feed: f64,
    /// The request's field the feeds come from (`feed_per_tooth` or `feed`), named when the
    /// program cannot write them.
    pub feed_field: &'static str,
    pub spindle_rpm: f64,
    /// The machine's `max_spindle_rpm`: no program is written above it.
    pub max_spindle_rpm: Option<f64>,
    pub spindle_direction: crate::gcode::SpindleDirection,
    /// The block-time rule the program's arcs are chorded by (its feed replaced by each block's).
    pub rule: Option<crate::machine::BlockRule>,
    pub axial_depth: Option<f64>,
    /// The tip's Z when a_p came from it (the program cuts there instead of top − a_p).
    pub cut_z: Option<f64>,
    pub stock_top_z: f64,
    pub clearance: f64,
    pub tool_radius: f64,
    /// Height of the end's rounding centre above the tip (ball: radius, bull: corner radius).
    pub centre_height: f64,
    pub description: Vec<String>,
}

/// The route, comparable so the answer can derive `PartialEq`.
#[derive(Debug, Clone)]
pub(crate) struct RouteData(pub Route);

impl Default for PostData {
    /// Nothing to post: what an answer read back holds until its post data is rebuilt.
    fn default() -> Self {
        Self {
            route: RouteData(Route {
                pieces: Vec::new(),
                tree: super::bbox_tree::BoxTree::default(),
                length: 0.0,
                feed_length: 0.0,
            }),
            nominal_feed: 0.0,
            feed_field: "feed",
            max_spindle_rpm: None,
            spindle_rpm: 0.0,
            spindle_direction: crate::gcode::SpindleDirection::default(),
            rule: None,
            axial_depth: None,
            cut_z: None,
            stock_top_z: 0.0,
            clearance: 0.0,
            tool_radius: 0.0,
            centre_height: 0.0,
            description: Vec::new(),
        }
    }
}

impl PartialEq for RouteData {
    fn eq(&self, other: &Self) -> bool {
        self.0.pieces == other.0.pieces
    }
}
