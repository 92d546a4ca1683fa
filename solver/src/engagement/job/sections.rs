//! [`EngagementRequest::validate`]: every field of the request checked, section by section, into
//! a [`Job`] (docs/spec/engagement.md §2, §9).

use super::super::heights::CORNER_BANDS;
use super::super::limits::natural_frequencies;
use super::super::request::{EngagementRequest, Engine, PathInput};
use super::super::stock::Base;
use super::super::{
    DEFAULT_BURR_DISENGAGE_DEG, DEFAULT_CHIPPING_DISENGAGE_DEG, MAX_BITMAP_CROSSINGS, MAX_CANDIDATES, MAX_CHORDS,
    MAX_DOT_ROWS, MAX_FLUTES, MAX_SAMPLES,
};
use super::candidates::{path_depth, program_level};
use super::limits::check_grid;
use super::path::read_path_levels;
use super::physics::force_model;
use super::stock::read_stock;
use super::{CandidateJob, FeedMode, ForceModel, Job, Physics, PlanJob, bounded, optional, too_large};
use crate::error::{ErrorCode, SolverError, Warning};
use crate::machine::{BlockRule, MachineProfile, RuleSettings};
use crate::tool::Tool;
use crate::validate::{MAX_COORDINATE, finite, non_negative, positive};

impl EngagementRequest {
    /// Validates the request against `tool` (already resolved from `self.tool`).
    /// Checks every field, with `machine` resolved from `self.machine`.
    pub(crate) fn validate(
        &self,
        tool: &Tool,
        machine: Option<&MachineProfile>,
        physics: &Physics,
    ) -> Result<Job, SolverError> {
        tool.validate("tool.")?;
        let radius = bounded("tool.radius", tool.radius, MAX_COORDINATE)?;
        let spindle_rpm = bounded("spindle_rpm", self.spindle_rpm, 1e6)?;
        let feed_mode = match (self.feed_per_tooth, self.feed) {
            (Some(fz), None) => FeedMode::PerTooth(bounded("feed_per_tooth", fz, 1e3)?),
            (None, Some(vf)) => FeedMode::Rate(bounded("feed", vf, 1e7)?),
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
        let thickness_limit = optional("thickness_limit", self.thickness_limit, positive)?;
        let time_limit = optional("time_limit_s", self.time_limit_s, positive)?;
        let step = match self.step {
            Some(step) => bounded("step", step, MAX_COORDINATE)?,
            None => 2.0 * radius / 50.0,
        };
        let grid = match (self.engine, self.grid) {
            (Engine::Exact, Some(_)) => {
                return Err(SolverError::input("grid", "grid applies only to engine \"dots\""));
            }
            (Engine::Exact, None) => None,
            (Engine::Dots, Some(g)) => Some(bounded("grid", g, MAX_COORDINATE)?),
            (Engine::Dots, None) => Some(match &self.stock.bitmap {
                Some(bitmap) if bitmap.cell.is_finite() && bitmap.cell > 0.0 => bitmap.cell,
                _ => 2.0 * radius / 200.0,
            }),
        };
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
        let radial_depth_min = optional("radial_depth_min", self.radial_depth_min, non_negative)?;
        let radial_depth_max = optional("radial_depth_max", self.radial_depth_max, positive)?;
        if let (Some(low), Some(high)) = (radial_depth_min, radial_depth_max)
            && low > high
        {
            return Err(SolverError::input(
                "radial_depth_min",
                format!("radial_depth_min {low} exceeds radial_depth_max {high}"),
            ));
        }
        let spike_threshold = optional("spike_threshold_deg", self.spike_threshold_deg, positive)?;
        let min_feed_per_tooth = optional("min_feed_per_tooth", self.min_feed_per_tooth, positive)?;
        let axial_depth = self.axial_depth.map(|d| bounded("axial_depth", d, MAX_COORDINATE)).transpose()?;
        let (kienzle, spindle) = self.kienzle(physics)?;
        // A Z in the plane of the coordinates.
        let z_value = |field: &str, z: f64| -> Result<f64, SolverError> {
            let z = finite(field, z)?;
            if z.abs() > MAX_COORDINATE {
                return Err(SolverError::input(field, format!("{field} must lie within ±{MAX_COORDINATE} mm")));
            }
            Ok(z)
        };
        let stock_top_z = z_value("stock_top_z", self.stock_top_z.unwrap_or(0.0))?;
        let clearance = bounded("clearance", self.clearance.unwrap_or(5.0), MAX_COORDINATE)?;
        // Warnings of the whole request, repeated in every candidate's answer.
        let mut shared_warnings = Vec::new();
        let plan = self
            .feed_plan
            .as_ref()
            .map(|plan| -> Result<PlanJob, SolverError> {
                let target = bounded("feed_plan.target_thickness", plan.target_thickness, 1e3)?;
                let max_feed = plan.max_feed.or(machine.map(|m| m.max_feed)).ok_or_else(|| {
                    SolverError::input(
                        "feed_plan.max_feed",
                        "feed_plan.max_feed (mm/min) is required unless the request names a machine",
                    )
                })?;
                let max_feed = bounded("feed_plan.max_feed", max_feed, 1e7)?;
                if let Some(machine) = machine
                    && max_feed > machine.max_feed
                {
                    shared_warnings.push(Warning::new(
                        "W_FEED_ABOVE_MACHINE_MAX",
                        format!(
                            "feed_plan.max_feed {max_feed} mm/min is above the machine's max_feed {} mm/min: the \
                             control will not reach it",
                            machine.max_feed
                        ),
                    ));
                }
                let flute_count = plan.flute_count.unwrap_or(tool.flutes);
                if !(1..=MAX_FLUTES).contains(&flute_count) {
                    return Err(SolverError::input(
                        "feed_plan.flute_count",
                        format!("a flute count must be 1 to {MAX_FLUTES} (got {flute_count})"),
                    ));
                }
                let tolerance = non_negative("feed_plan.tolerance", plan.tolerance.unwrap_or(0.05))?;
                let min_block_length =
                    non_negative("feed_plan.min_block_length", plan.min_block_length.unwrap_or(0.5))?;
                Ok(PlanJob { target, max_feed, flute_count, basis: plan.basis, tolerance, min_block_length })
            })
            .transpose()?;

        let rule = if self.block_time_ms.is_some() || machine.is_some() {
            let feed = feed_mode.feed(tool.flutes, spindle_rpm);
            let settings =
                RuleSettings { feed: Some(feed), block_time_ms: self.block_time_ms, ..RuleSettings::default() };
            let (rule, warnings) = BlockRule::resolve(&settings, machine)?;
            shared_warnings.extend(warnings);
            Some(rule)
        } else {
            None
        };
        let (region, _) = read_stock(&self.stock, radius, &mut shared_warnings)?;

        let cut_z = self.cut_z.map(|z| z_value("cut_z", z)).transpose()?;
        // Where a G-code path's own Z counts: only with an explicit stock top.
        let top_given = self.stock_top_z.is_some();
        // (name, path, its field, the field prefix of its own a_p and cut_z, those values)
        type Input<'a> = (Option<String>, &'a PathInput, String, String, Option<f64>, Option<f64>);
        let inputs: Vec<Input<'_>> = match (&self.path, &self.paths) {
            (Some(path), None) => vec![(None, path, "path".to_owned(), String::new(), None, None)],
            (None, Some(paths)) => {
                if paths.is_empty() {
                    return Err(SolverError::new(ErrorCode::Path, "paths is empty").at("paths"));
                }
                if paths.len() > MAX_CANDIDATES {
                    return Err(too_large("paths", "candidate paths", paths.len(), MAX_CANDIDATES));
                }
                paths
                    .iter()
                    .enumerate()
                    .map(|(i, c)| {
                        (
                            c.name.clone(),
                            &c.path,
                            format!("paths[{i}].path"),
                            format!("paths[{i}]."),
                            c.axial_depth,
                            c.cut_z,
                        )
                    })
                    .collect()
            }
            (Some(_), Some(_)) => {
                return Err(SolverError::input("paths", "give path or paths, not both"));
            }
            (None, None) => {
                return Err(SolverError::new(ErrorCode::Path, "the request needs a path").at("path"));
            }
        };
        let mut candidates = Vec::with_capacity(inputs.len());
        let mut total_samples = 0.0;
        let mut section_radii = 0.0_f64;
        for (name, input, field, prefix, own_depth, own_cut_z) in inputs {
            let own_depth =
                own_depth.map(|d| bounded(&format!("{prefix}axial_depth"), d, MAX_COORDINATE)).transpose()?;
            let own_cut_z = own_cut_z.map(|z| z_value(&format!("{prefix}cut_z"), z)).transpose()?;
            let mut warnings = Vec::new();
            let mut levels = Vec::new();
            let route = read_path_levels(input, &field, &mut warnings, &mut levels)?;
            let explicit = own_depth
                .map(|d| (d, format!("{prefix}axial_depth")))
                .or_else(|| axial_depth.map(|d| (d, "axial_depth".to_owned())));
            let level = if own_cut_z.is_some() || cut_z.is_some() || !top_given {
                None
            } else {
                program_level(&levels, &format!("{field}.gcode"), explicit.is_none(), &mut warnings)
            };
            let height = own_cut_z
                .map(|z| (z, format!("{prefix}cut_z")))
                .or_else(|| cut_z.map(|z| (z, "cut_z".to_owned())))
                .or(level);
            let (depth, path_z) = path_depth(explicit, height, stock_top_z, tool, &mut warnings)?;
            let force = kienzle.map(|values| force_model(&values, tool, depth, self.spindle_direction)).transpose()?;
            if force.as_ref().is_some_and(ForceModel::rounded) {
                // The sections of a rounded end: about one circle per band edge.
                section_radii = (CORNER_BANDS + 1) as f64 * radius;
            }
            total_samples += route.station_count(step);
            if total_samples > MAX_SAMPLES as f64 {
                return Err(SolverError::new(
                    ErrorCode::TooManySamples,
                    format!(
                        "the path(s) would need about {total_samples:.0} samples at step {step} mm; the limit is {MAX_SAMPLES}: use a larger step"
                    ),
                )
                .at("step"));
            }
            candidates.push(CandidateJob { name, route, warnings, axial_depth: depth, cut_z: path_z, force });
        }
        if let Some(g) = grid {
            // The dots engine rasterises earlier cuts' arcs as chords within g/100.
            let chords: f64 =
                region.cuts.iter().flat_map(|cut| cut.shapes.iter()).map(|shape| shape.chord_count(g / 100.0)).sum();
            if chords > MAX_CHORDS {
                return Err(SolverError::new(
                    ErrorCode::WorkLimit,
                    format!(
                        "the earlier cuts' arcs need {chords:.2e} chords at grid {g} mm; the limit is {MAX_CHORDS:.0e}: use a larger grid or engine \"exact\""
                    ),
                )
                .at("stock.previous_cuts"));
            }
        }
        if let (Some(g), Some(stock_box)) = (grid, region.bbox()) {
            let mut rows = 0.0;
            for candidate in &candidates {
                let height = check_grid(&candidate.route, stock_box, region.anchor(), radius, g)?;
                // Each sample scans the grid rows across the tool.
                rows += candidate.route.station_count(step) * (2.0 * radius / g).min(height);
            }
            if rows > MAX_DOT_ROWS {
                return Err(SolverError::new(
                    ErrorCode::WorkLimit,
                    format!(
                        "the dots engine would scan about {rows:.2e} grid rows (samples × rows across the tool); the limit is {MAX_DOT_ROWS:.0e}: use a larger grid or step, or engine \"exact\""
                    ),
                )
                .at("grid"));
            }
        }
        if let (Engine::Exact, Base::Bitmap(bitmap)) = (self.engine, &region.base) {
            // Every sample intersects the circle with about 8R/cell cell edges, and the height
            // sections of a rounded end their own circles.
            let work = total_samples * 8.0 * (radius + section_radii) / bitmap.cell;
            if work > MAX_BITMAP_CROSSINGS {
                return Err(SolverError::new(
                    ErrorCode::TooManySamples,
                    format!(
                        "a bitmap with cell {} mm seen by a tool of radius {radius} mm needs about {work:.2e} edge tests over the samples; the limit is {:.0e}: use a larger step, a coarser bitmap or engine \"dots\"",
                        bitmap.cell,
                        MAX_BITMAP_CROSSINGS
                    ),
                )
                .at("step"));
            }
        }
        Ok(Job {
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
            burr_disengage,
            chipping_disengage,
            radial_depth_min,
            radial_depth_max,
            spike_threshold,
            min_feed_per_tooth,
            stock_top_z,
            clearance,
            plan,
            rule,
            arc_feed: self.arc_feed_correction,
            spindle,
            natural: natural_frequencies(tool),
            contact_dots: self.contact_dots,
            region,
            shared_warnings,
            candidates,
            single: self.path.is_some(),
        })
    }
}
