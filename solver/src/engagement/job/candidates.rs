//! The request's candidate paths (`path`, or `paths` to compare; docs/spec/engagement.md §2.3, §9)
//! read into routes, each with its axial depth (§11 item 4): given, or the stock top less the
//! path's Z (`cut_z`, a G-code path's own), checked against the flute length; and the sample
//! count over all of them against its limit.

use super::super::heights::CORNER_BANDS;
use super::super::request::{EngagementRequest, PathInput};
use super::super::{MAX_CANDIDATES, MAX_SAMPLES};
use super::path::read_path_levels;
use super::physics::force_model;
use super::{CandidateJob, ForceModel, too_large, z_value};
use crate::error::{ErrorCode, SolverError, Warning};
use crate::material::Kienzle;
use crate::tool::Tool;
use crate::validate::{MAX_COORDINATE, Measure, positive_at_most};

/// The request's heights every path's a_p may come from.
pub(super) struct Heights {
    /// `axial_depth`, checked.
    pub axial_depth: Option<f64>,
    /// `stock_top_z` (0 when not given), checked.
    pub stock_top_z: f64,
    /// Whether `stock_top_z` was given: only then does a G-code path's own Z count.
    pub top_given: bool,
}

/// The validated candidates and what the work limits need of them.
pub(super) struct Candidates {
    pub jobs: Vec<CandidateJob>,
    /// Samples over all candidates at the request's step.
    pub total_samples: f64,
    /// Radii of the extra sections a rounded end's force model intersects, mm (0 for a flat end).
    pub section_radii: f64,
}

/// One candidate as the request gives it: (name, path, its field, the field prefix of its own
/// a_p and cut_z, those values).
type Input<'a> = (Option<String>, &'a PathInput, String, String, Option<f64>, Option<f64>);

impl EngagementRequest {
    /// Every candidate path read and given its a_p and force model; refused past
    /// [`MAX_CANDIDATES`] paths or [`MAX_SAMPLES`] samples.
    pub(super) fn candidates(
        &self,
        tool: &Tool,
        radius: f64,
        step: f64,
        heights: &Heights,
        kienzle: Option<Kienzle>,
    ) -> Result<Candidates, SolverError> {
        let Heights { axial_depth, stock_top_z, top_given } = *heights;
        let cut_z = self.cut_z.map(|z| z_value("cut_z", z)).transpose()?;
        let inputs = self.inputs()?;
        let mut candidates = Vec::with_capacity(inputs.len());
        let mut total_samples = 0.0;
        let mut section_radii = 0.0_f64;
        for (name, input, field, prefix, own_depth, own_cut_z) in inputs {
            let own_depth = own_depth
                .map(|d| positive_at_most(&format!("{prefix}axial_depth"), d, MAX_COORDINATE, Measure::Length))
                .transpose()?;
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
        Ok(Candidates { jobs: candidates, total_samples, section_radii })
    }

    /// The request's `path`, or its `paths` (one to [`MAX_CANDIDATES`]), not both.
    fn inputs(&self) -> Result<Vec<Input<'_>>, SolverError> {
        Ok(match (&self.path, &self.paths) {
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
        })
    }
}

/// The one Z level of a G-code path's XY feed moves, with its field, for a_p from the stock
/// height (only when no explicit a_p wins: `wanted`); several levels give `W_AXIAL_DEPTH` and
/// none.
fn program_level(
    levels: &[(f64, usize)],
    field: &str,
    wanted: bool,
    warnings: &mut Vec<Warning>,
) -> Option<(f64, String)> {
    let (&(first, line), rest) = levels.split_first()?;
    let other = rest.iter().find(|(z, _)| (z - first).abs() > 1e-6);
    match other {
        None => Some((first, format!("{field} (Z of its feed moves, line {line})"))),
        Some((z, other_line)) => {
            if wanted {
                warnings.push(Warning::new(
                    "W_AXIAL_DEPTH",
                    format!(
                        "the program's XY feed moves run at several Z levels (Z {} at line {line}, Z {} at line {other_line}): no a_p from the stock height; the 2-D model takes one level per path, so give axial_depth or cut_z, or each level as its own entry of paths",
                        Measure::Length.quote(first),
                        Measure::Length.quote(*z)
                    ),
                ));
            }
            None
        }
    }
}

/// a_p of one path and the Z it runs at when a_p came from it: the explicit axial depth
/// (`explicit`, with its field) wins; else `top` − the path's Z (`height`, with its field),
/// 0 at or above the top. Both warn where they disagree; an a_p beyond the tool's flute length
/// is refused at the field that set it.
fn path_depth(
    explicit: Option<(f64, String)>,
    height: Option<(f64, String)>,
    top: f64,
    tool: &Tool,
    warnings: &mut Vec<Warning>,
) -> Result<(Option<f64>, Option<f64>), SolverError> {
    let reach = |depth: f64, field: &str, how: &str| -> Result<(), SolverError> {
        match tool.flute_length {
            Some(length) if depth > length => Err(SolverError::input(
                field,
                format!(
                    "{how} a_p = {depth} mm, more than the tool's flute_length {length} mm: the shank would cut (check the path's Z and the stock top)"
                ),
            )),
            _ => Ok(()),
        }
    };
    if let Some((depth, field)) = explicit {
        if let Some((z, z_field)) = &height
            && ((top - z).max(0.0) - depth).abs() > 1e-9
        {
            warnings.push(Warning::new(
                "W_AXIAL_DEPTH",
                format!(
                    "{field} = {depth} mm is used; the path's Z {z} mm ({z_field}) under the stock top {top} mm would give a_p = {} mm",
                    (top - z).max(0.0)
                ),
            ));
        }
        reach(depth, &field, &format!("{field} gives"))?;
        return Ok((Some(depth), None));
    }
    let Some((z, field)) = height else {
        return Ok((None, None));
    };
    let depth = top - z;
    if depth <= 0.0 {
        warnings.push(Warning::new(
            "W_AXIAL_DEPTH",
            format!(
                "the tool tip runs at Z {} ({field}), at or above the stock top {}: a_p = 0, the path cuts no chip (torque, power and removal rate are 0)",
                Measure::Length.quote(z),
                Measure::Length.quote(top)
            ),
        ));
        return Ok((Some(0.0), Some(z)));
    }
    let field_name = field.split(' ').next().unwrap_or(&field).to_owned();
    reach(
        depth,
        &field_name,
        &format!(
            "the stock top {} less the path's Z {} ({field}) gives",
            Measure::Length.quote(top),
            Measure::Length.quote(z)
        ),
    )?;
    Ok((Some(depth), Some(z)))
}
