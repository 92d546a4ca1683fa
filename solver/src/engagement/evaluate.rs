//! One candidate path end to end (docs/spec/engagement.md §5): contact at every sample from the
//! chosen engine, the per-sample quantities and flags (§5.4, §5.5, §5.10), the diagnostics of §9
//! (`diagnostics`), and the per-flute results, recommendation and feed plan. The engines' contact
//! at each sample is `contact`'s.

use super::answer::{
    ArcDetail, EngagementSample, ForceInfo, GridInfo, PathEngagement, PostData, RouteData, SampleArcDetails,
    SampleFlag, SampleFlags,
};
use super::arcfeed::ArcFeed;
use super::arcs::{self, Arc};
use super::contact::{Contact, DotsOutput, run_dots, run_exact, same_arcs};
use super::force::{SampleTorque, power_kw};
use super::job::{CandidateJob, Job};
use super::request::Engine;
use super::segments::Station;
use super::series::{self, Series};
use super::stock::{Base, Region};
use super::teeth::ToothSums;
use super::{MAX_CONTACT_DOTS, diagnostics, feed, flutes};
use crate::capability::Control;
use crate::error::{SolverError, Warning};
use crate::tool::{Tool, ToolKind};
use crate::validate::Measure;

/// Engagement on the back half deeper than this (degrees) marks `back_contact` (§9 W_PLUNGE).
const BACK_TOLERANCE_DEG: f64 = 1.0;

/// What a sample's arcs alone decide: a_e, Φ, the arc ends and their flags, the mean chip
/// thickness ratio without the arc-feed factor. Kept for the previous sample and reused while
/// the arcs stay the same to the bit, which along a straight cut at constant engagement is
/// nearly every sample (95 % in the 1 m bench): every value is a pure function of the arcs, so
/// reusing it changes nothing, and it saves the sines and cosines of the arc ends.
#[derive(Debug, Default)]
struct ArcValues {
    /// The arcs these values are for (`None` before the first sample).
    arcs: Option<Vec<Arc>>,
    radial_depth: f64,
    engaged_deg: f64,
    details: SampleArcDetails,
    /// Some arc disengages at or beyond ψ_B (§5.10).
    burr: bool,
    /// Some arc disengages at or below ψ_C.
    chipping: bool,
    /// Engagement on the back half deeper than [`BACK_TOLERANCE_DEG`].
    behind: bool,
    mean_thickness_ratio: f64,
}

impl ArcValues {
    /// The values for `arcs`, recomputed only when they differ from the last call's.
    fn of(&mut self, arcs: &[Arc], job: &Job, radius: f64) -> &Self {
        if self.arcs.as_deref().is_some_and(|last| same_arcs(last, arcs)) {
            return self;
        }
        let last = self.arcs.get_or_insert_with(Vec::new);
        last.clear();
        last.extend_from_slice(arcs);
        self.radial_depth = arcs::radial_depth(arcs, radius);
        self.engaged_deg = arcs::engaged_deg(arcs);
        self.mean_thickness_ratio = arcs::mean_thickness_ratio(arcs);
        let (mut burr, mut chipping) = (false, false);
        self.details = arcs
            .iter()
            .map(|arc| {
                let ends = arcs::arc_ends(arc, job.direction);
                burr |= ends.disengage >= job.burr_disengage;
                chipping |= ends.disengage <= job.chipping_disengage;
                ArcDetail {
                    entry_deg: ends.entry,
                    exit_deg: ends.exit,
                    engage_deg: ends.engage,
                    disengage_deg: ends.disengage,
                    entry_thickness_ratio: ends.entry_ratio,
                    exit_thickness_ratio: ends.exit_ratio,
                    mode: ends.mode,
                }
            })
            .collect();
        self.burr = burr;
        self.chipping = chipping;
        self.behind = arcs.iter().any(|a| a.from < -BACK_TOLERANCE_DEG || a.to > 180.0 + BACK_TOLERANCE_DEG);
        self
    }
}

/// The samples of one path and what the passes after the sample loop read of them.
pub(super) struct Sampled {
    pub samples: Vec<EngagementSample>,
    pub series: Series,
    /// Whether each sample enters the statistics: engaged, not the first, not a plunge, not a rapid.
    pub statistic: Vec<bool>,
    /// Where the tool starts cutting already in material, as [s, s] intervals.
    pub plunges: Vec<[f64; 2]>,
    /// Where the back half of the tool engages.
    pub back: Vec<f64>,
    /// Where a rapid passes through material.
    pub collisions: Vec<f64>,
}

/// Evaluates one candidate path: the engine's contacts, the samples, the diagnostics, the
/// per-flute results and feed plan, in that order.
pub(crate) fn evaluate(
    job: &Job,
    candidate: &CandidateJob,
    tool: &Tool,
    control: Control<'_>,
) -> Result<PathEngagement, SolverError> {
    let route = &candidate.route;
    let stations = route.stations(job.step);
    let (contacts, dots) = match (job.engine, job.grid) {
        (Engine::Dots, Some(cell)) => {
            let (contacts, output) = run_dots(job, route, &stations, cell, control)?;
            (contacts, Some(output))
        }
        _ => (run_exact(job, candidate, &stations, control)?, None),
    };

    let time_flutes = job.tool_flutes;
    let nominal_feed = job.feed_mode.feed(time_flutes, job.spindle_rpm);
    let mut warnings = job.shared_warnings.clone();
    warnings.extend(candidate.warnings.iter().cloned());
    let sampled = sample_all(job, candidate, &stations, &contacts, nominal_feed, control)?;
    let Sampled { samples, series, statistic, .. } = &sampled;

    let engaged_intervals = series.runs(|i| series.arc_count[i] > 0 && !series.marked(i, series::RAPID));
    diagnostics::sampling(&mut warnings, job, &sampled, &engaged_intervals);
    diagnostics::vertices(&mut warnings, route);
    diagnostics::dots(&mut warnings, job);
    diagnostics::force_model(&mut warnings, job, candidate, tool);
    let flutes::Judged { results: flute_results, recommended, warnings: flute_warnings } =
        flutes::results(job, candidate.force.as_ref(), samples, series, statistic, route.feed_length, control)?;
    warnings.extend(flute_warnings);
    let program_flutes = program_flute_count(job, &recommended, &mut warnings);
    let feed_plan = job
        .plan
        .as_ref()
        .map(|plan| {
            feed::plan(job, candidate.force.as_ref(), plan, program_flutes, route, &stations, &contacts, control)
        })
        .transpose()?;
    let program_feed = program_feed(job, program_flutes, &mut warnings);

    let (max_engaged_deg, max_engaged_at_s) = (series.engaged_deg.iter().zip(&series.s))
        .zip(statistic)
        .filter(|(_, s)| **s)
        .map(|((&phi, &s), _)| (phi, s))
        .fold((0.0, 0.0), |best, (phi, s)| if phi > best.0 { (phi, s) } else { best });
    let max_radial_depth =
        series.radial_depth.iter().zip(statistic).filter(|(_, s)| **s).map(|(&depth, _)| depth).fold(0.0, f64::max);
    let (contact_dots, grid) = contact_dots(job, dots, &mut warnings);
    Ok(PathEngagement {
        name: candidate.name.clone(),
        max_mrr: candidate.axial_depth.map(|depth| depth * max_radial_depth * nominal_feed),
        samples: sampled.samples,
        flutes: flute_results,
        recommended,
        path_length: route.length,
        feed_length: route.feed_length,
        time_flute_count: time_flutes,
        program_flute_count: program_flutes,
        engine: job.engine,
        step: job.step,
        grid,
        engaged_intervals,
        max_engaged_deg,
        max_engaged_at_s,
        max_radial_depth,
        contact_dots,
        forces: candidate.force.as_ref().map(|model| ForceInfo {
            kc11: model.kc11,
            mc: model.mc,
            radial_ratio: model.radial_ratio,
            axial_depth: model.axial_depth,
            helix_lag_deg: model.lag_deg,
            height_sections: contacts.iter().filter_map(|c| c.slices.as_ref()).map(|b| b.sections.len()).max(),
            spindle_power_kw: job.spindle.spindle_power_kw,
            spindle_torque_nm: job.spindle.spindle_torque_nm,
            natural_frequencies_hz: job.natural.iter().map(|(f, _)| *f).collect(),
        }),
        feed_plan,
        blocks: None,
        warnings,
        post: post_data(job, candidate, tool, program_flutes, program_feed),
    })
}

/// The flute count the feed plan and the program are for: `feed_plan.flute_count` when given,
/// else the fastest recommended count, else the tool's; `W_PROGRAM_FLUTE_COUNT` when it is not
/// the tool's, so nobody runs a program for four flutes with a two-flute cutter unawares.
fn program_flute_count(job: &Job, recommended: &[u32], warnings: &mut Vec<Warning>) -> u32 {
    let chosen = job.plan.as_ref().and_then(|plan| plan.flute_count);
    let (count, why) = match (chosen, recommended.first()) {
        (Some(count), _) => (count, "feed_plan.flute_count"),
        (None, Some(&count)) => (count, "the fastest recommended flute count"),
        (None, None) => (job.tool_flutes, "the tool's"),
    };
    if count != job.tool_flutes {
        warnings.push(Warning::new(
            "W_PROGRAM_FLUTE_COUNT",
            format!(
                "the feed plan and the program are for {count} flutes ({why}); the tool has {}: run them with a \
                 {count}-flute cutter, or set feed_plan.flute_count to {}",
                job.tool_flutes, job.tool_flutes
            ),
        ));
    }
    count
}

/// The program's feed where no feed plan sets one: the nominal feed of `flutes` teeth, capped by
/// the feed plan's and the machine's max feed (`W_FEED_CAPPED` when it is lowered).
fn program_feed(job: &Job, flutes: u32, warnings: &mut Vec<Warning>) -> f64 {
    let nominal = job.feed_mode.feed(flutes, job.spindle_rpm);
    let caps = [
        job.plan.as_ref().map(|plan| (plan.max_feed, "feed_plan.max_feed")),
        job.machine_feed.map(|feed| (feed, "the machine's max_feed")),
    ];
    let Some((cap, by)) = caps.into_iter().flatten().min_by(|a, b| a.0.total_cmp(&b.0)) else { return nominal };
    if nominal <= cap {
        return nominal;
    }
    warnings.push(Warning::new(
        "W_FEED_CAPPED",
        format!(
            "the nominal feed of {flutes} flutes, {nominal:.0} mm/min, is above {by}: the program runs at {cap} mm/min"
        ),
    ));
    cap
}

/// Every sample of the path from the engine's contacts: arcs, a_e, Φ, flags, the tooth sums of
/// every flute count, and with a force model the torque, power and peak force.
fn sample_all(
    job: &Job,
    candidate: &CandidateJob,
    stations: &[Station],
    contacts: &[Contact],
    nominal_feed: f64,
    control: Control<'_>,
) -> Result<Sampled, SolverError> {
    let route = &candidate.route;
    let radius = job.radius;
    let nominal_fz = job.feed_mode.feed_per_tooth(job.tool_flutes, job.spindle_rpm);
    let mut samples = Vec::with_capacity(stations.len());
    let mut series = Series::with_capacity(stations.len(), job.flute_counts.len());
    let mut statistic = Vec::with_capacity(stations.len());
    let mut marks = Marks::default();
    let mut tooth_sums = ToothSums::default();
    let mut arc_values = ArcValues::default();
    // The last tangent's bits and heading: along a line every sample has the same tangent.
    let mut last_heading: Option<([u64; 2], f64)> = None;
    for (index, (station, contact)) in stations.iter().zip(contacts).enumerate() {
        // With forces a sample costs up to milliseconds (every flute count's phase maximum).
        control.check()?;
        let rapid = route.pieces.get(station.piece).is_some_and(|p| p.rapid);
        let arcs: &[Arc] = &contact.arcs;
        let values = arc_values.of(arcs, job, radius);
        let radial_depth = values.radial_depth;
        let flags = marks.flags(job, values, contact, station, index > 0, rapid);
        let sums = tooth_sums.of(arcs, &job.flute_counts);
        let bits = [station.tangent.x.to_bits(), station.tangent.y.to_bits()];
        let heading_deg = match last_heading {
            Some((last, heading)) if last == bits => heading,
            _ => {
                let heading = station.tangent.y.atan2(station.tangent.x).to_degrees();
                last_heading = Some((bits, heading));
                heading
            }
        };
        let edge_feed = if job.arc_feed { ArcFeed::at(route, station, radius) } else { None };
        let (torques, forces) = sample_forces(job, candidate, contact, edge_feed.as_ref());
        statistic.push(index > 0 && !rapid && !arcs.is_empty() && !contact.plunge);
        samples.push(EngagementSample {
            s: station.s,
            t: 60.0 * station.feed_s / nominal_feed,
            position: [station.centre.x, station.centre.y],
            heading_deg,
            segment: route.pieces.get(station.piece).map_or(0, |p| p.source),
            arcs: arcs.iter().map(|a| [a.from, a.to]).collect(),
            engaged_deg: values.engaged_deg,
            radial_depth,
            arc_details: values.details.clone(),
            mean_chip_thickness: nominal_fz
                * edge_feed.as_ref().map_or(values.mean_thickness_ratio, |feed| feed.mean_ratio(arcs)),
            thickness: job
                .flute_counts
                .iter()
                .zip(sums)
                .map(|(&k, sum)| {
                    // H_k/f_z: the exact sinusoid of §5.6, or with the arc-feed factor numeric.
                    let ratio = edge_feed.as_ref().map_or(sum.ratio, |feed| feed.tooth_sum(arcs, k));
                    job.feed_mode.feed_per_tooth(k, job.spindle_rpm) * ratio
                })
                .collect(),
            teeth: sums.iter().map(|sum| sum.teeth).collect(),
            torque_nm: torques.iter().map(|t| t.mean).collect(),
            peak_torque_nm: torques.iter().map(|t| t.peak).collect(),
            power_kw: torques.iter().map(|t| power_kw(t.mean, job.spindle_rpm)).collect(),
            peak_force_n: forces,
            mrr: candidate.axial_depth.map(|depth| depth * radial_depth * nominal_feed),
            flags,
        });
        if let Some(sample) = samples.last() {
            series.push(sample);
        }
    }
    let Marks { plunges, back, collisions } = marks;
    Ok(Sampled { samples, series, statistic, plunges, back, collisions })
}

/// Where the flags that the diagnostics list by position were raised.
#[derive(Default)]
struct Marks {
    plunges: Vec<[f64; 2]>,
    back: Vec<f64>,
    collisions: Vec<f64>,
}

impl Marks {
    /// The flags of one sample (§5.10, §9), noting the positions of plunges, back contact and
    /// collisions; `after_first`: not the path's first sample.
    fn flags(
        &mut self,
        job: &Job,
        values: &ArcValues,
        contact: &Contact,
        station: &Station,
        after_first: bool,
        rapid: bool,
    ) -> SampleFlags {
        let radial_depth = values.radial_depth;
        let mut flags = SampleFlags::new();
        if values.burr {
            flags.push(SampleFlag::BurrRisk);
        }
        if values.chipping {
            flags.push(SampleFlag::ChippingRisk);
        }
        if contact.plunge {
            flags.push(SampleFlag::Plunge);
            self.plunges.push([station.s, station.s]);
        }
        if values.behind && !contact.plunge && after_first {
            flags.push(SampleFlag::BackContact);
            self.back.push(station.s);
        }
        if !contact.arcs.is_empty() {
            if job.radial_depth_max.is_some_and(|high| radial_depth > high) {
                flags.push(SampleFlag::VibrationRisk);
            }
            if job.radial_depth_min.is_some_and(|low| radial_depth < low) {
                flags.push(SampleFlag::RubbingRisk);
            }
        }
        if rapid {
            flags.push(SampleFlag::Rapid);
        }
        if contact.collision {
            flags.push(SampleFlag::Collision);
            self.collisions.push(station.s);
        }
        flags
    }
}

/// With a force model, the torque (phase mean and peak) and the peak force of every flute count
/// at one sample; nothing without.
fn sample_forces(
    job: &Job,
    candidate: &CandidateJob,
    contact: &Contact,
    edge_feed: Option<&ArcFeed>,
) -> (Vec<SampleTorque>, Vec<f64>) {
    let arcs: &[Arc] = &contact.arcs;
    candidate.force.as_ref().map_or_else(Default::default, |model| {
        let slices = contact.slices.as_ref();
        let integral = model.integral(arcs, edge_feed, slices);
        job.flute_counts
            .iter()
            .map(|&k| {
                let fz = job.feed_mode.feed_per_tooth(k, job.spindle_rpm);
                (
                    model.torque(arcs, edge_feed, slices, integral, k, fz),
                    model.peak_force(arcs, k, fz, edge_feed, slices),
                )
            })
            .unzip()
    })
}

/// The dots engine's contact dots for the scatter plot, decimated past [`MAX_CONTACT_DOTS`] with
/// `W_CONTACT_DOTS_DECIMATED` (when the request wants them), and its grid.
fn contact_dots(
    job: &Job,
    dots: Option<DotsOutput>,
    warnings: &mut Vec<Warning>,
) -> (Option<Vec<[f64; 2]>>, Option<GridInfo>) {
    let Some(output) = dots else { return (None, None) };
    let mut scatter = output.scatter;
    if scatter.len() > MAX_CONTACT_DOTS {
        let stride = scatter.len().div_ceil(MAX_CONTACT_DOTS);
        warnings.push(Warning::new(
            "W_CONTACT_DOTS_DECIMATED",
            format!(
                "{} contact dots exceed the limit of {MAX_CONTACT_DOTS}: every {stride}th is returned",
                scatter.len()
            ),
        ));
        scatter = scatter.into_iter().step_by(stride).collect();
    }
    (job.contact_dots.then_some(scatter), output.grid)
}

/// What the G-code program of the path needs besides the samples (docs/spec/engagement.md §3.2,
/// §11 item 12): the route, feeds, heights and the program's description lines.
fn post_data(job: &Job, candidate: &CandidateJob, tool: &Tool, flutes: u32, nominal_feed: f64) -> PostData {
    let route = &candidate.route;
    let centre_height = match tool.kind {
        ToolKind::Ball => tool.radius,
        ToolKind::Bull => tool.corner_radius.unwrap_or(0.0),
        ToolKind::Flat => 0.0,
    };
    let description = vec![
        format!(
            "engagement path{}: L {:.3} mm, feed length {:.3} mm",
            candidate.name.as_ref().map(|n| format!(" {n}")).unwrap_or_default(),
            route.length,
            route.feed_length
        ),
        stock_description(&job.region),
        format!("tool R {}, {} flutes, S {} rpm", Measure::Length.quote(tool.radius), tool.flutes, job.spindle_rpm),
        format!("feeds for {flutes} flutes, nominal F {nominal_feed:.0} mm/min"),
    ];
    PostData {
        route: RouteData(route.clone()),
        nominal_feed,
        feed_field: job.feed_mode.field(),
        max_spindle_rpm: job.machine_speed,
        spindle_rpm: job.spindle_rpm,
        spindle_direction: job.direction,
        rule: job.rule,
        axial_depth: candidate.axial_depth,
        cut_z: candidate.cut_z,
        stock_top_z: job.stock_top_z,
        clearance: job.clearance,
        tool_radius: tool.radius,
        centre_height,
        description,
    }
}

fn stock_description(region: &Region) -> String {
    match &region.base {
        Base::Polygons(outline) => {
            let rings = outline.rings();
            format!("stock: polygon rings {}, vertices {}", rings.len(), rings.iter().map(Vec::len).sum::<usize>())
        }
        Base::Bitmap(bitmap) => {
            format!(
                "stock: bitmap {} x {} cells of {}",
                bitmap.width,
                bitmap.height,
                Measure::Length.quote(bitmap.cell)
            )
        }
    }
}
