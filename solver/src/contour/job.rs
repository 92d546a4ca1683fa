//! A contour request validated into a [`Job`] (docs/spec/contour.md §1.4 inputs, §3.1 preparation, §5 input
//! codes).

use crate::error::ErrorCode;

use super::element::Chording;
use super::prepare::{self, Contour};
use super::request::{
    ContourRequest, CornerLoop, CutDirection, DEFAULT_CLEARANCE, DEFAULT_MAX_ANGLE_DEG, DEFAULT_RAMP_ANGLE_DEG,
    DEFAULT_SPINDLE_RPM, DEFAULT_TOLERANCE, Join, LoopStyle, MAX_LAYERS, MAX_PASSES, MAX_TILT_DEG, MIN_TOLERANCE,
    Relief, Side, TboneEdge, Tilt,
};
use crate::capability::Control;
use crate::error::{SolverError, Warning};
use crate::machine::{BlockRule, MachineProfile, RuleSettings, cap_feed};
use crate::tool::{Tool, ToolKind};
use crate::validate::{Measure, coordinate, finite, non_negative, positive};

/// A validated pass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PassJob {
    pub allowance: f64,
    pub loops: bool,
    pub join: Join,
}

/// Loop sizing, every value resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LoopConfig {
    pub style: LoopStyle,
    pub radius: f64,
    pub leg: f64,
    pub min_leg: f64,
    pub max_leg: f64,
    pub min_radius: f64,
    pub max_radius: f64,
    /// ψ_min: the smallest turn that gets a loop, radians.
    pub min_turn: f64,
}

/// Per prepared vertex: loop override, relief and T-bone edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CornerChoice {
    pub loops: Option<bool>,
    pub relief: Relief,
    pub tbone_edge: TboneEdge,
}

/// A validated contour job.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Job {
    pub tool: Tool,
    pub radius: f64,
    pub contour: Contour,
    pub side: Side,
    pub direction: CutDirection,
    /// Prepared edge index of the start edge.
    pub start_edge: usize,
    pub layers: Vec<f64>,
    pub top: f64,
    pub bottom: f64,
    pub passes: Vec<PassJob>,
    pub loop_config: LoopConfig,
    pub choices: Vec<CornerChoice>,
    pub feed: f64,
    pub loop_feed: Option<f64>,
    pub safe_z: f64,
    pub lead: f64,
    pub tolerance: f64,
    /// How arcs become chords: `tolerance`, or the block-time rule within it.
    pub chording: Chording,
    pub spindle_rpm: f64,
    /// Feed of plunges and ramps: the request's, else the tool's, else the machine's (`None`:
    /// half the cutting feed).
    pub plunge_feed: Option<f64>,
    /// Ramp angle of layer entries, radians, when the tool does not cut at its centre.
    pub ramp: Option<f64>,
    pub stock_allowance: Option<f64>,
    /// Tilt per prepared edge, radians; `None` when every wall is vertical.
    pub tilt: Option<Vec<f64>>,
    pub blend_radius: Option<f64>,
    pub servo_time_constant_s: Option<f64>,
    pub warnings: Vec<Warning>,
}

impl ContourRequest {
    /// Checks every field and prepares the contour, with `machine` resolved from `self.machine`.
    /// The sections are checked in a fixed order (tool, feeds, depths, chording, spindle and
    /// entry, heights, stock and passes, loops, contour and start edge, corners, tilt,
    /// controller): a request with several faults is refused for the first; `E_CANCELLED` once
    /// `control`'s cancel flag is set (a long contour takes a while to check).
    pub(crate) fn validate(
        &self,
        tool: &Tool,
        machine: Option<&MachineProfile>,
        control: Control<'_>,
    ) -> Result<Job, SolverError> {
        tool.validate("tool.")?;
        let radius = tool.radius;
        // The machine's max feed caps every feed the program writes (never raises one).
        let mut capped = Vec::new();
        let feed = cap_feed(machine, "feed", positive("feed", self.feed, Measure::Feed)?, &mut capped);
        let loop_feed = self
            .loop_feed
            .map(|f| positive("loop_feed", f, Measure::Feed).map(|f| cap_feed(machine, "loop_feed", f, &mut capped)))
            .transpose()?;
        let (top, bottom, layers) = self.layer_depths(radius)?;
        let (tolerance, chording, rule_warnings) = self.chording(feed, loop_feed, machine)?;
        let (spindle_rpm, plunge_feed, ramp) = self.spindle_and_entry(tool, machine)?;
        let plunge_feed = plunge_feed.map(|f| cap_feed(machine, "plunge_feed", f, &mut capped));
        let (safe_z, lead) = self.heights(top, radius)?;
        let (stock_allowance, passes) = self.stock_and_passes()?;
        let loop_config = self.corner_loop.config(radius)?;
        let (contour, mut warnings) = prepare::prepare(&self.contour, self.fix_orientation, control)?;
        warnings.extend(capped);
        warnings.extend(rule_warnings);
        let start_edge = self.prepared_start_edge(&contour)?;
        let choices = self.corner_choices(&contour)?;
        control.check()?;
        let tilt = self.tilt(&contour)?;
        let (blend_radius, servo_time_constant_s) = self.controller_model()?;
        if tilt.is_some() && tool.kind != ToolKind::Flat {
            warnings.push(Warning::new(
                "W_TILT_TOOL_KIND",
                format!("tilted walls are planned with the {} tool's full radius as a cylinder", tool.kind.as_str()),
            ));
        }
        Ok(Job {
            tool: tool.clone(),
            radius,
            contour,
            side: self.side,
            direction: self.direction,
            start_edge,
            layers,
            top,
            bottom,
            passes,
            loop_config,
            choices,
            feed,
            loop_feed,
            safe_z,
            lead,
            tolerance,
            chording,
            spindle_rpm,
            plunge_feed,
            ramp,
            stock_allowance,
            tilt,
            blend_radius,
            servo_time_constant_s,
            warnings,
        })
    }

    /// `depths`: top, bottom and the layer heights from top down (the tool radius is checked for
    /// size here too, as it bounds the coordinates like the depths).
    fn layer_depths(&self, radius: f64) -> Result<(f64, f64, Vec<f64>), SolverError> {
        let depths = &self.depths;
        let top = coordinate("depths.top", depths.top)?;
        let bottom = coordinate("depths.bottom", depths.bottom)?;
        let step = positive("depths.step", depths.step, Measure::Length)?;
        if radius > super::prepare::MAX_COORDINATE {
            return Err(SolverError::input("tool.radius", "the tool radius is implausibly large"));
        }
        if bottom > top {
            return Err(SolverError::input(
                "depths.bottom",
                format!(
                    "depths.bottom {} lies above depths.top {}",
                    Measure::Length.quote(bottom),
                    Measure::Length.quote(top)
                ),
            ));
        }
        Ok((top, bottom, layer_heights(top, bottom, step)?))
    }

    /// `tolerance`, and with `block_time_ms` or a machine the block-time rules of cutting and
    /// loop arcs (loops at the larger of the two feeds), with the rule's warnings.
    fn chording(
        &self,
        feed: f64,
        loop_feed: Option<f64>,
        machine: Option<&MachineProfile>,
    ) -> Result<(f64, Chording, Vec<Warning>), SolverError> {
        let tolerance = self.tolerance.unwrap_or(DEFAULT_TOLERANCE);
        if finite("tolerance", tolerance)? < MIN_TOLERANCE {
            return Err(SolverError::input(
                "tolerance",
                format!("tolerance must be at least {MIN_TOLERANCE} mm (got {})", Measure::Length.quote(tolerance)),
            ));
        }
        let mut rule_warnings = Vec::new();
        let rules = if self.block_time_ms.is_some() || machine.is_some() {
            let settings =
                RuleSettings { feed: Some(feed), block_time_ms: self.block_time_ms, ..RuleSettings::default() };
            let (rule, warnings) = BlockRule::resolve(&settings, machine)?;
            rule_warnings = warnings;
            let loops = BlockRule { feed: feed.max(loop_feed.unwrap_or(feed)), ..rule };
            Some((rule, loops))
        } else {
            None
        };
        Ok((tolerance, Chording { tolerance, rules }, rule_warnings))
    }

    /// `spindle_rpm`, the plunge feed (the request's, else the tool's, else the machine's) and
    /// the ramp angle in radians for a tool that does not cut at its centre.
    fn spindle_and_entry(
        &self,
        tool: &Tool,
        machine: Option<&MachineProfile>,
    ) -> Result<(f64, Option<f64>, Option<f64>), SolverError> {
        let spindle_rpm = crate::machine::spindle_within(
            machine.and_then(|machine| machine.max_spindle_rpm),
            "spindle_rpm",
            positive("spindle_rpm", self.spindle_rpm.unwrap_or(DEFAULT_SPINDLE_RPM), Measure::Number)?,
        )?;
        let plunge_feed = self
            .plunge_feed
            .map(|f| positive("plunge_feed", f, Measure::Feed))
            .transpose()?
            .or(tool.plunge_feed)
            .or(machine.and_then(|m| m.plunge_feed));
        let ramp_angle = finite("ramp_angle_deg", self.ramp_angle_deg.unwrap_or(DEFAULT_RAMP_ANGLE_DEG))?;
        if !(ramp_angle > 0.0 && ramp_angle <= 45.0) {
            return Err(SolverError::input(
                "ramp_angle_deg",
                format!("ramp_angle_deg must be above 0 and at most 45 (got {ramp_angle})"),
            ));
        }
        let ramp = (!tool.cuts_at_centre()).then(|| ramp_angle.to_radians());
        Ok((spindle_rpm, plunge_feed, ramp))
    }

    /// The clearance plane (`safe_z`, else `clearance` above the top) and the `lead` length.
    fn heights(&self, top: f64, radius: f64) -> Result<(f64, f64), SolverError> {
        let clearance = coordinate(
            "clearance",
            non_negative("clearance", self.clearance.unwrap_or(DEFAULT_CLEARANCE), Measure::Length)?,
        )?;
        let safe_z = match self.safe_z {
            Some(z) => {
                if coordinate("safe_z", z)? <= top {
                    return Err(SolverError::input(
                        "safe_z",
                        format!(
                            "safe_z {} must lie above depths.top {}",
                            Measure::Length.quote(z),
                            Measure::Length.quote(top)
                        ),
                    ));
                }
                z
            }
            None => top + clearance.max(1e-3),
        };
        let lead = coordinate("lead", non_negative("lead", self.lead.unwrap_or(radius), Measure::Length)?)?;
        Ok((safe_z, lead))
    }

    /// `stock_allowance` and the passes; the stock must be at least the first pass's allowance.
    fn stock_and_passes(&self) -> Result<(Option<f64>, Vec<PassJob>), SolverError> {
        let stock_allowance =
            self.stock_allowance.map(|s| non_negative("stock_allowance", s, Measure::Length)).transpose()?;
        let passes = self.pass_jobs()?;
        if let (Some(stock), Some(first)) = (stock_allowance, passes.first())
            && stock < first.allowance
        {
            return Err(SolverError::input(
                "stock_allowance",
                format!(
                    "stock_allowance {} is smaller than the first pass's allowance {}",
                    Measure::Length.quote(stock),
                    Measure::Length.quote(first.allowance)
                ),
            ));
        }
        Ok((stock_allowance, passes))
    }

    /// The prepared edge holding `start_edge` (default: the edge from the first point).
    fn prepared_start_edge(&self, contour: &Contour) -> Result<usize, SolverError> {
        match self.start_edge {
            None => Ok(contour.edge_containing(0)),
            Some(k) if k < self.contour.len() => Ok(contour.edge_containing(k)),
            Some(k) => Err(SolverError::input(
                "start_edge",
                format!("start_edge {k} is not an index of contour (0 to {})", self.contour.len() - 1),
            )),
        }
    }

    /// The `controller` model: blend radius, mm, and servo time constant, s.
    fn controller_model(&self) -> Result<(Option<f64>, Option<f64>), SolverError> {
        Ok(match &self.controller {
            None => (None, None),
            Some(model) => (
                model.blend_radius.map(|b| non_negative("controller.blend_radius", b, Measure::Length)).transpose()?,
                model
                    .servo_time_constant_ms
                    .map(|t| non_negative("controller.servo_time_constant_ms", t, Measure::Number).map(|t| t / 1000.0))
                    .transpose()?,
            ),
        })
    }

    fn pass_jobs(&self) -> Result<Vec<PassJob>, SolverError> {
        let Some(passes) = &self.passes else {
            return Ok(vec![PassJob { allowance: 0.0, loops: true, join: Join::Miter }]);
        };
        if passes.is_empty() || passes.len() > MAX_PASSES {
            return Err(SolverError::input("passes", format!("give 1 to {MAX_PASSES} passes (got {})", passes.len())));
        }
        let mut previous = f64::INFINITY;
        let last = passes.len() - 1;
        passes
            .iter()
            .enumerate()
            .map(|(index, pass)| {
                let field = format!("passes[{index}].allowance");
                let allowance = non_negative(&field, pass.allowance, Measure::Length)?;
                if allowance > previous {
                    return Err(SolverError::input(
                        field,
                        format!(
                            "passes run from outside in: allowance {} exceeds the previous pass's {}",
                            Measure::Length.quote(allowance),
                            Measure::Length.quote(previous)
                        ),
                    ));
                }
                previous = allowance;
                Ok(PassJob { allowance, loops: pass.loops.unwrap_or(index == last), join: pass.join })
            })
            .collect()
    }

    fn corner_choices(&self, contour: &Contour) -> Result<Vec<CornerChoice>, SolverError> {
        let default = CornerChoice { loops: None, relief: self.inside_corner_relief, tbone_edge: self.tbone_edge };
        let mut choices = vec![default; contour.points.len()];
        for (position, item) in self.corner_overrides.iter().flatten().enumerate() {
            let field = format!("corner_overrides[{position}].index");
            if item.index >= self.contour.len() {
                return Err(SolverError::input(field, format!("{} is not an index of contour", item.index)));
            }
            let Some(vertex) = contour.vertex_of(item.index) else {
                return Err(SolverError::input(
                    field,
                    format!("contour[{}] was removed (a duplicate or collinear point): it is no corner", item.index),
                ));
            };
            let choice = &mut choices[vertex];
            choice.loops = item.loops.or(choice.loops);
            choice.relief = item.relief.unwrap_or(choice.relief);
            choice.tbone_edge = item.tbone_edge.unwrap_or(choice.tbone_edge);
        }
        Ok(choices)
    }

    /// Tilt per prepared edge, radians; an edge merged from several request edges must have one
    /// tilt.
    fn tilt(&self, contour: &Contour) -> Result<Option<Vec<f64>>, SolverError> {
        let check = |field: &str, value: f64| -> Result<f64, SolverError> {
            if finite(field, value)?.abs() > MAX_TILT_DEG {
                return Err(SolverError::input(field, format!("tilt must lie within ±{MAX_TILT_DEG}° (got {value})")));
            }
            Ok(value.to_radians())
        };
        match &self.tilt_deg {
            None => Ok(None),
            Some(Tilt::All(value)) => {
                let tilt = check("tilt_deg", *value)?;
                Ok((tilt != 0.0).then(|| vec![tilt; contour.points.len()]))
            }
            Some(Tilt::PerEdge(values)) => {
                if values.len() != self.contour.len() {
                    return Err(SolverError::input(
                        "tilt_deg",
                        format!(
                            "give one tilt per contour edge: {} values for {} edges",
                            values.len(),
                            self.contour.len()
                        ),
                    ));
                }
                let mut per_edge = Vec::with_capacity(contour.points.len());
                for edge in 0..contour.points.len() {
                    let members = contour.request_edges(edge, self.contour.len());
                    let mut tilt: Option<(f64, usize)> = None;
                    for k in members {
                        let field = format!("tilt_deg[{k}]");
                        let value = check(&field, values[k])?;
                        match tilt {
                            None => tilt = Some((value, k)),
                            Some((first, first_k)) if (first - value).abs() > 1e-12 => {
                                return Err(SolverError::input(
                                    field,
                                    format!("edges {first_k} and {k} lie on one straight wall and need the same tilt"),
                                ));
                            }
                            Some(_) => {}
                        }
                    }
                    per_edge.push(tilt.map_or(0.0, |(value, _)| value));
                }
                Ok(per_edge.iter().any(|t| *t != 0.0).then_some(per_edge))
            }
        }
    }
}

/// Layer heights from `top` to `bottom` in equal steps of at most `step`: `top − k·Δ`, k = 1..n.
pub(crate) fn layer_heights(top: f64, bottom: f64, step: f64) -> Result<Vec<f64>, SolverError> {
    let depth = top - bottom;
    if depth <= 0.0 {
        return Ok(vec![bottom]);
    }
    let count = (depth / step - 1e-9).ceil().max(1.0);
    if count > MAX_LAYERS as f64 {
        return Err(SolverError::new(
            ErrorCode::TooManyLayers,
            format!("{count} layers of at most {step} mm from {top} mm to {bottom} mm: the limit is {MAX_LAYERS}"),
        )
        .at("depths.step"));
    }
    // `count` is a whole number in 1..=MAX_LAYERS here.
    let count = count as usize;
    let delta = depth / count as f64;
    Ok((1..=count).map(|k| if k == count { bottom } else { top - k as f64 * delta }).collect())
}

impl CornerLoop {
    /// The sizing with every default resolved for a tool of `radius`.
    pub(crate) fn config(&self, radius: f64) -> Result<LoopConfig, SolverError> {
        let spec = self;
        let positive_or = |name: &str, value: Option<f64>, default: f64| {
            positive(&format!("corner_loop.{name}"), value.unwrap_or(default), Measure::Length)
        };
        let loop_radius = positive_or("radius", spec.radius, radius)?;
        let leg = positive_or("leg", spec.leg, radius)?;
        let min_leg = non_negative("corner_loop.min_leg", spec.min_leg.unwrap_or(0.0), Measure::Length)?;
        let max_leg = positive_or("max_leg", spec.max_leg, 10.0 * radius)?;
        let min_radius = positive_or("min_radius", spec.min_radius, 0.1 * radius)?;
        let max_radius = positive_or("max_radius", spec.max_radius, 5.0 * radius)?;
        if min_leg > max_leg {
            return Err(SolverError::input(
                "corner_loop.min_leg",
                format!(
                    "min_leg {} exceeds max_leg {}",
                    Measure::Length.quote(min_leg),
                    Measure::Length.quote(max_leg)
                ),
            ));
        }
        if min_radius > max_radius {
            return Err(SolverError::input(
                "corner_loop.min_radius",
                format!(
                    "min_radius {} exceeds max_radius {}",
                    Measure::Length.quote(min_radius),
                    Measure::Length.quote(max_radius)
                ),
            ));
        }
        let max_angle = spec.max_angle_deg.unwrap_or(DEFAULT_MAX_ANGLE_DEG);
        if !(finite("corner_loop.max_angle_deg", max_angle)? > 0.0 && max_angle < 180.0) {
            return Err(SolverError::input(
                "corner_loop.max_angle_deg",
                format!("max_angle_deg must lie strictly between 0 and 180 (got {max_angle})"),
            ));
        }
        Ok(LoopConfig {
            style: spec.style,
            radius: loop_radius,
            leg,
            min_leg,
            max_leg,
            min_radius,
            max_radius,
            min_turn: (180.0 - max_angle).to_radians(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layers_are_equal_steps_ending_at_the_bottom() {
        assert_eq!(layer_heights(0.0, -6.0, 2.0).unwrap(), vec![-2.0, -4.0, -6.0]);
        let layers = layer_heights(0.0, -5.0, 2.0).unwrap();
        assert_eq!(layers.len(), 3);
        assert!((layers[0] + 5.0 / 3.0).abs() < 1e-12);
        assert_eq!(layers[2], -5.0);
        assert_eq!(layer_heights(1.0, 1.0, 2.0).unwrap(), vec![1.0]);
        assert_eq!(layer_heights(0.0, -1e6, 1.0).unwrap_err().code(), ErrorCode::TooManyLayers);
    }
}
