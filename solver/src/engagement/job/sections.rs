//! [`EngagementRequest::validate`]: every field of the request checked, section by section, into
//! a [`Job`] (docs/spec/engagement.md §2, §9). The sections are checked in a fixed order, so a
//! request with several faults is always refused at the same field.

use super::super::limits::natural_frequencies;
use super::super::request::{EngagementRequest, Engine, FeedPlanRequest};
use super::super::{DEFAULT_BURR_DISENGAGE_DEG, DEFAULT_CHIPPING_DISENGAGE_DEG, MAX_FLUTES};
use super::candidates::Heights;
use super::limits::check_work;
use super::stock::read_stock;
use super::{FeedMode, Job, Physics, PlanJob, optional, too_large, z_value};
use crate::error::{SolverError, Warning};
use crate::machine::{BlockRule, MachineProfile, RuleSettings};
use crate::tool::Tool;
use crate::validate::{MAX_COORDINATE, Measure, finite, non_negative, positive, positive_at_most};

/// The tool and cutting conditions of a request: what every sample is evaluated at.
struct Cutting {
    radius: f64,
    spindle_rpm: f64,
    feed_mode: FeedMode,
    flute_counts: Vec<u32>,
}

/// The thresholds of the per-sample flags and the feed plan's lowest feed per tooth.
struct Flags {
    burr_disengage: f64,
    chipping_disengage: f64,
    radial_depth_min: Option<f64>,
    radial_depth_max: Option<f64>,
    spike_threshold: Option<f64>,
    min_feed_per_tooth: Option<f64>,
}

impl EngagementRequest {
    /// Validates the request against `tool` (already resolved from `self.tool`).
    /// Checks every field, with `machine` resolved from `self.machine`.
    pub(crate) fn validate(
        &self,
        tool: &Tool,
        machine: Option<&MachineProfile>,
        physics: &Physics,
    ) -> Result<Job, SolverError> {
        let Cutting { radius, spindle_rpm, feed_mode, flute_counts } = self.cutting(tool)?;
        let thickness_limit = optional("thickness_limit", self.thickness_limit, positive, Measure::Length)?;
        let time_limit = optional("time_limit_s", self.time_limit_s, positive, Measure::Number)?;
        let (step, grid) = self.sampling(radius)?;
        let flags = self.flags()?;
        let axial_depth = self
            .axial_depth
            .map(|d| positive_at_most("axial_depth", d, MAX_COORDINATE, Measure::Length))
            .transpose()?;
        let (kienzle, spindle) = self.kienzle(physics)?;
        let stock_top_z = z_value("stock_top_z", self.stock_top_z.unwrap_or(0.0))?;
        let clearance = positive_at_most("clearance", self.clearance.unwrap_or(5.0), MAX_COORDINATE, Measure::Length)?;
        // Warnings of the whole request, repeated in every candidate's answer.
        let mut shared_warnings = Vec::new();
        let plan = self.feed_plan.as_ref().map(|plan| feed_plan(plan, machine, &mut shared_warnings)).transpose()?;
        let rule = if self.block_time_ms.is_some() || machine.is_some() {
            // The program never runs faster than the machine's max feed (see `program_feed`).
            let feed = machine.map_or(f64::INFINITY, |m| m.max_feed).min(feed_mode.feed(tool.flutes, spindle_rpm));
            let settings =
                RuleSettings { feed: Some(feed), block_time_ms: self.block_time_ms, ..RuleSettings::default() };
            let (rule, warnings) = BlockRule::resolve(&settings, machine)?;
            shared_warnings.extend(warnings);
            Some(rule)
        } else {
            None
        };
        let (region, _) = read_stock(&self.stock, radius, &mut shared_warnings)?;
        let heights = Heights { axial_depth, stock_top_z, top_given: self.stock_top_z.is_some() };
        let candidates = self.candidates(tool, radius, step, &heights, kienzle)?;
        if let Some(index) = self.candidate
            && index >= candidates.jobs.len()
        {
            let count = candidates.jobs.len();
            return Err(SolverError::input("candidate", format!("candidate {index} does not exist ({count} path(s))")));
        }
        let job = Job {
            radius,
            flute_counts,
            tool_flutes: tool.flutes,
            spindle_rpm,
            feed_mode,
            thickness_limit,
            time_limit,
            representative: self.representative,
            direction: self.spindle_direction,
            engine: self.engine,
            step,
            grid,
            burr_disengage: flags.burr_disengage,
            chipping_disengage: flags.chipping_disengage,
            radial_depth_min: flags.radial_depth_min,
            radial_depth_max: flags.radial_depth_max,
            spike_threshold: flags.spike_threshold,
            min_feed_per_tooth: flags.min_feed_per_tooth,
            stock_top_z,
            clearance,
            plan,
            rule,
            arc_feed: self.arc_feed_correction,
            spindle,
            machine_feed: machine.map(|m| m.max_feed),
            machine_speed: machine.and_then(|m| m.max_spindle_rpm),
            natural: natural_frequencies(tool),
            contact_dots: self.contact_dots,
            region,
            shared_warnings,
            candidates: candidates.jobs,
            single: self.path.is_some(),
        };
        check_work(&job, candidates.total_samples, candidates.section_radii)?;
        Ok(job)
    }

    /// The tool's radius, the spindle speed, the feed (per tooth or per minute, not both) and the
    /// flute counts to compare (the tool's own when none are given).
    fn cutting(&self, tool: &Tool) -> Result<Cutting, SolverError> {
        tool.validate("tool.")?;
        let radius = positive_at_most("tool.radius", tool.radius, MAX_COORDINATE, Measure::Length)?;
        let spindle_rpm = positive_at_most("spindle_rpm", self.spindle_rpm, 1e6, Measure::Number)?;
        let feed_mode = match (self.feed_per_tooth, self.feed) {
            (Some(fz), None) => FeedMode::PerTooth(positive_at_most("feed_per_tooth", fz, 1e3, Measure::FeedPerTooth)?),
            (None, Some(vf)) => FeedMode::Rate(positive_at_most("feed", vf, 1e7, Measure::Feed)?),
            (Some(_), Some(_)) => {
                return Err(SolverError::input(
                    "feed",
                    "give feed_per_tooth (constant f_z) or feed (constant V_f), not both",
                ));
            }
            (None, None) => {
                return Err(SolverError::input(
                    "feed_per_tooth",
                    "feed_per_tooth (mm/tooth) or feed (mm/min) is required",
                ));
            }
        };
        let flute_counts = match &self.flute_counts {
            None => vec![tool.flutes],
            Some(counts) => {
                if counts.is_empty() {
                    return Err(SolverError::input("flute_counts", "flute_counts needs at least one flute count"));
                }
                if counts.len() > MAX_FLUTES as usize {
                    return Err(too_large("flute_counts", "flute counts", counts.len(), MAX_FLUTES as usize));
                }
                for (index, k) in counts.iter().enumerate() {
                    let field = format!("flute_counts[{index}]");
                    if !(1..=MAX_FLUTES).contains(k) {
                        return Err(SolverError::input(
                            field,
                            format!("a flute count must be 1 to {MAX_FLUTES} (got {k})"),
                        ));
                    }
                    if counts[..index].contains(k) {
                        return Err(SolverError::input(field, format!("flute count {k} is listed twice")));
                    }
                }
                counts.clone()
            }
        };
        Ok(Cutting { radius, spindle_rpm, feed_mode, flute_counts })
    }

    /// The sample step along the path and the `dots` engine's grid (a bitmap stock's cell by
    /// default); `grid` is refused with the exact engine.
    fn sampling(&self, radius: f64) -> Result<(f64, Option<f64>), SolverError> {
        let step = match self.step {
            Some(step) => positive_at_most("step", step, MAX_COORDINATE, Measure::Length)?,
            None => 2.0 * radius / 50.0,
        };
        let grid = match (self.engine, self.grid) {
            (Engine::Exact, Some(_)) => {
                return Err(SolverError::input("grid", "grid applies only to engine \"dots\""));
            }
            (Engine::Exact, None) => None,
            (Engine::Dots, Some(g)) => Some(positive_at_most("grid", g, MAX_COORDINATE, Measure::Length)?),
            (Engine::Dots, None) => Some(match &self.stock.bitmap {
                Some(bitmap) if bitmap.cell.is_finite() && bitmap.cell > 0.0 => bitmap.cell,
                _ => 2.0 * radius / 200.0,
            }),
        };
        Ok((step, grid))
    }

    /// The burr and chipping disengagement angles (§5.10), the radial depth band, the spike
    /// threshold and the lowest feed per tooth.
    fn flags(&self) -> Result<Flags, SolverError> {
        let angle = |field: &str, value: Option<f64>, default: f64| -> Result<f64, SolverError> {
            let v = finite(field, value.unwrap_or(default))?;
            if (0.0..=180.0).contains(&v) {
                Ok(v)
            } else {
                Err(SolverError::input(field, format!("{field} must be in [0, 180] (got {v})")))
            }
        };
        let burr_disengage = angle("burr_disengage_deg", self.burr_disengage_deg, DEFAULT_BURR_DISENGAGE_DEG)?;
        let chipping_disengage =
            angle("chipping_disengage_deg", self.chipping_disengage_deg, DEFAULT_CHIPPING_DISENGAGE_DEG)?;
        let radial_depth_min = optional("radial_depth_min", self.radial_depth_min, non_negative, Measure::Length)?;
        let radial_depth_max = optional("radial_depth_max", self.radial_depth_max, positive, Measure::Length)?;
        if let (Some(low), Some(high)) = (radial_depth_min, radial_depth_max)
            && low > high
        {
            return Err(SolverError::input(
                "radial_depth_min",
                format!(
                    "radial_depth_min {} exceeds radial_depth_max {}",
                    Measure::Length.quote(low),
                    Measure::Length.quote(high)
                ),
            ));
        }
        let spike_threshold = optional("spike_threshold_deg", self.spike_threshold_deg, positive, Measure::Number)?;
        let min_feed_per_tooth =
            optional("min_feed_per_tooth", self.min_feed_per_tooth, positive, Measure::FeedPerTooth)?;
        Ok(Flags {
            burr_disengage,
            chipping_disengage,
            radial_depth_min,
            radial_depth_max,
            spike_threshold,
            min_feed_per_tooth,
        })
    }
}

/// The feed plan's request (§11 item 3): its `max_feed` defaults to the machine's, and one above
/// the machine's is lowered to it with `W_FEED_ABOVE_MACHINE_MAX` in `shared_warnings` (a
/// machine caps a user's feed, it never raises it).
fn feed_plan(
    plan: &FeedPlanRequest,
    machine: Option<&MachineProfile>,
    shared_warnings: &mut Vec<Warning>,
) -> Result<PlanJob, SolverError> {
    let target = positive_at_most("feed_plan.target_thickness", plan.target_thickness, 1e3, Measure::Length)?;
    let max_feed = plan.max_feed.or(machine.map(|m| m.max_feed)).ok_or_else(|| {
        SolverError::input(
            "feed_plan.max_feed",
            "feed_plan.max_feed (mm/min) is required unless the request names a machine",
        )
    })?;
    let mut max_feed = positive_at_most("feed_plan.max_feed", max_feed, 1e7, Measure::Feed)?;
    if let Some(machine) = machine
        && max_feed > machine.max_feed
    {
        shared_warnings.push(Warning::new(
            "W_FEED_ABOVE_MACHINE_MAX",
            format!(
                "feed_plan.max_feed {max_feed} mm/min is above the machine's max_feed {} mm/min: the feed plan \
                 uses {} mm/min",
                machine.max_feed, machine.max_feed
            ),
        ));
        max_feed = machine.max_feed;
    }
    if let Some(flute_count) = plan.flute_count
        && !(1..=MAX_FLUTES).contains(&flute_count)
    {
        return Err(SolverError::input(
            "feed_plan.flute_count",
            format!("a flute count must be 1 to {MAX_FLUTES} (got {flute_count})"),
        ));
    }
    let tolerance = non_negative("feed_plan.tolerance", plan.tolerance.unwrap_or(0.05), Measure::Length)?;
    let min_block_length =
        non_negative("feed_plan.min_block_length", plan.min_block_length.unwrap_or(0.5), Measure::Length)?;
    Ok(PlanJob { target, max_feed, flute_count: plan.flute_count, basis: plan.basis, tolerance, min_block_length })
}
