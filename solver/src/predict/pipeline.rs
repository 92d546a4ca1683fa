//! The per-pass prediction of docs/spec/predict.md §3.1 (S1–S11) and its run over all passes in
//! parallel (rayon, results in pass order): prediction position (§3.3), cutting region and force
//! (§3.6–3.7), deflection (§3.8), finished surface and generation point by sampling (§6.6) or by
//! the depth buffer with view correction (§3.9–3.11), and the errors (§3.12).

use crate::error::ErrorCode;
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use nalgebra::Matrix3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::answer::{PassFlag, PassHistory, PassStatus};
use super::dynamics::{self, Compliance};
use super::exclusion;
use super::force::{self, EdgeGrid, Engagement};
use super::job::Job;
use super::merge;
use super::passes::PathModel;
use super::render::{self, Image, Window};
use super::request::Method;
use super::sampling::{self, Band};
use super::scene::{self, PieceOrder, Scene, Scratch};
use super::shape;
use crate::capability::Control;
use crate::error::SolverError;
use crate::geometry::{Vec3, optional_vec3};

/// Most prediction positions tried along one pass (§3.3).
const MAX_STATIONS: usize = 17;
/// Fewest finished pixels before the view is corrected (§5 E5).
const MIN_FINISHED_PIXELS: usize = 4;

/// What one pass gives; serialised (vectors as arrays, angles in radians, every number exactly
/// as computed) between a split prediction's parts and its finish step.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) struct Outcome {
    pub(crate) status: PassStatus,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(crate) flags: Vec<PassFlag>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) position: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none", with = "optional_vec3")]
    pub(crate) centre: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) error: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) error_deflection: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) error_shape: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) contact_angle: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) azimuth: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) rotation_angle: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none", with = "optional_vec3")]
    pub(crate) point: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none", with = "optional_vec3")]
    pub(crate) normal: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) deflection: Option<[f64; 2]>,
    /// With merging: how far e_D moves while ψ_c moves by the rotation angle the generation
    /// point is located to (one sample either way), mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) deflection_spread: Option<f64>,
    #[serde(default)]
    pub(crate) cut_count: usize,
    #[serde(default)]
    pub(crate) finished_count: usize,
    #[serde(default, skip_serializing_if = "Option::is_none", with = "optional_vec3")]
    pub(crate) view: Option<Vec3>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) history: Option<PassHistory>,
    /// Merged: the simulated pass whose result this is, and the bound on the difference.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) merged_with: Option<usize>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub(crate) merge_bound: Option<f64>,
}

impl Outcome {
    /// A pass with `status` and nothing predicted.
    pub(crate) fn empty(status: PassStatus) -> Self {
        Self {
            status,
            flags: Vec::new(),
            position: None,
            centre: None,
            error: None,
            error_deflection: None,
            error_shape: None,
            contact_angle: None,
            azimuth: None,
            rotation_angle: None,
            point: None,
            normal: None,
            deflection: None,
            deflection_spread: None,
            cut_count: 0,
            finished_count: 0,
            view: None,
            history: None,
            merged_with: None,
            merge_bound: None,
        }
    }
}

/// Everything shared by the passes of one round.
pub(crate) struct Context<'a> {
    pub(crate) job: &'a Job,
    grids: [Option<EdgeGrid>; 2],
    kernels: HashMap<u64, SpindleKernels>,
}

/// Impulse responses in X and Y at one spindle speed, and whether a harmonic left the table.
struct SpindleKernels {
    kernels: (Vec<f64>, Vec<f64>),
    outside: bool,
}

/// The slot of a spindle direction in per-direction tables: 0 clockwise (−1), 1 counter-clockwise (+1).
fn sign_slot(sign: f64) -> usize {
    usize::from(sign > 0.0)
}

impl<'a> Context<'a> {
    /// What every pass of `job` shares: an edge grid per spindle direction used and, with a
    /// force model and stiffness, the deflection kernels per spindle speed.
    pub(crate) fn new(job: &'a Job) -> Self {
        let helix = job.helix.tan();
        let mut grids = [None, None];
        for pass in &job.path.passes {
            let slot = sign_slot(pass.source.rotation_sign);
            if grids[slot].is_none() {
                grids[slot] = Some(EdgeGrid::new(
                    job.edge_elements,
                    job.steps,
                    job.flutes,
                    pass.source.rotation_sign,
                    job.flute_zero,
                    |theta| (1.0 - theta.cos()) * helix,
                ));
            }
        }
        let mut kernels = HashMap::new();
        if job.deflection.is_none()
            && job.cutting.is_some()
            && let Some(stiffness) = &job.stiffness
        {
            let (cx, cy) = Compliance::pair(stiffness);
            for &rpm in &job.spindle_speeds {
                let (kx, out_x) = dynamics::kernel(&cx, rpm, job.steps);
                let (ky, out_y) = dynamics::kernel(&cy, rpm, job.steps);
                kernels.insert(rpm.to_bits(), SpindleKernels { kernels: (kx, ky), outside: out_x || out_y });
            }
        }
        Self { job, grids, kernels }
    }
}

/// Runs every pass of `path` in parallel; `None` when cancelled.
pub(crate) fn run_round(
    context: &Context<'_>,
    path: &PathModel,
    control: &Control<'_>,
    done: &AtomicUsize,
    total_work: usize,
    charge: &(dyn Fn(&Outcome) -> Result<(), SolverError> + Sync),
) -> Result<Vec<Outcome>, SolverError> {
    let refused: std::sync::Mutex<Option<SolverError>> = std::sync::Mutex::new(None);
    let charged = |outcome: &Outcome| match charge(outcome) {
        Ok(()) => true,
        Err(error) => {
            refused.lock().unwrap_or_else(std::sync::PoisonError::into_inner).get_or_insert(error);
            false
        }
    };
    round_outcomes(context, path, control, done, total_work, &charged).ok_or_else(|| {
        refused.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner).unwrap_or_else(cancelled)
    })
}

/// [`run_round`]'s outcomes, each handed to `charged` as it is made; `None` once cancelled or
/// once `charged` refuses one.
fn round_outcomes(
    context: &Context<'_>,
    path: &PathModel,
    control: &Control<'_>,
    done: &AtomicUsize,
    total_work: usize,
    charged: &(dyn Fn(&Outcome) -> bool + Sync),
) -> Option<Vec<Outcome>> {
    let cancelled = AtomicBool::new(false);
    let report_every = (total_work / 200).max(1);
    let report = |finished: usize| {
        if let Some(progress) = control.progress
            && (finished.is_multiple_of(report_every) || finished == total_work)
        {
            progress(finished as f64 / total_work as f64);
        }
    };
    let range = context.job.pass_range.clone();
    // Claim 8: θ_max per pass from one global view, only when a threshold is given.
    let skipped: Vec<bool> = match context.job.exclusion {
        Some(threshold) => exclusion::max_contact_angles(context.job, path)
            .into_iter()
            .map(|angle| angle.is_some_and(|a| a <= threshold))
            .collect(),
        None => Vec::new(),
    };
    let is_skipped = |index: usize| skipped.get(index).copied().unwrap_or(false);
    let simulate = |indices: &[usize]| -> Option<Vec<Outcome>> {
        let outcomes: Vec<Option<Outcome>> = indices
            .par_iter()
            .map_init(Scratch::default, |scratch, &index| {
                if control.cancelled() || cancelled.load(Ordering::Relaxed) {
                    cancelled.store(true, Ordering::Relaxed);
                    return None;
                }
                let outcome = if is_skipped(index) {
                    if context.job.exclusion_shape_error {
                        shape_error_only(context, path, index, scratch)
                    } else {
                        Outcome::empty(PassStatus::SkippedSmallAngle)
                    }
                } else {
                    predict_pass(context, path, index, scratch)
                };
                report(done.fetch_add(1, Ordering::Relaxed) + 1);
                if !charged(&outcome) {
                    cancelled.store(true, Ordering::Relaxed);
                    return None;
                }
                Some(outcome)
            })
            .collect();
        if cancelled.load(Ordering::Relaxed) { None } else { outcomes.into_iter().collect() }
    };
    let indices: Vec<usize> = range.clone().collect();
    let predicted: Vec<Outcome> = match context.job.merge_tolerance {
        None => simulate(&indices)?,
        Some(tolerance) => {
            let links = merge_links(context, path, &range, &is_skipped, &cancelled, control)?;
            let (outcomes, merged) =
                merge::run(path, &indices, &links, tolerance, merge::Resolution::new(context.job), |batch| {
                    simulate(batch)
                })?;
            report(done.fetch_add(merged, Ordering::Relaxed) + merged);
            outcomes
        }
    };
    let mut predicted = predicted.into_iter();
    (0..path.passes.len())
        .map(|index| {
            if range.contains(&index) {
                predicted.next()
            } else {
                let outcome = Outcome::empty(PassStatus::NotPredicted);
                charged(&outcome).then_some(outcome)
            }
        })
        .collect()
}

/// `links[k]`: whether pass `range.start + k + 1` is similar to the pass before it (merging,
/// [`merge::similar`]); excluded passes and passes with a history are never linked.
fn merge_links(
    context: &Context<'_>,
    path: &PathModel,
    range: &std::ops::Range<usize>,
    is_skipped: &(impl Fn(usize) -> bool + Sync),
    cancelled: &AtomicBool,
    control: &Control<'_>,
) -> Option<Vec<bool>> {
    const CHUNK: usize = 256;
    let job = context.job;
    let tolerance = job.merge_tolerance.unwrap_or(0.0);
    let free = |index: usize| !is_skipped(index) && !job.history.contains(&index);
    let pairs = range.len().saturating_sub(1);
    let chunks: Vec<Vec<bool>> = (0..pairs.div_ceil(CHUNK))
        .into_par_iter()
        .map_init(Scratch::default, |scratch, chunk| {
            if control.cancelled() {
                cancelled.store(true, Ordering::Relaxed);
                return Vec::new();
            }
            let first = range.start + chunk * CHUNK;
            let last = (first + CHUNK).min(range.start + pairs);
            let mut previous = merge::Neighbourhood::default();
            let mut previous_ok = free(first) && merge::neighbourhood(job, path, first, scratch, &mut previous);
            let mut current = merge::Neighbourhood::default();
            (first..last)
                .map(|a| {
                    let current_ok = free(a + 1) && merge::neighbourhood(job, path, a + 1, scratch, &mut current);
                    let linked = previous_ok
                        && current_ok
                        && merge::similar(path, a, &previous, &current, job.radius, tolerance);
                    std::mem::swap(&mut previous, &mut current);
                    previous_ok = current_ok;
                    linked
                })
                .collect()
        })
        .collect();
    if cancelled.load(Ordering::Relaxed) {
        return None;
    }
    Some(chunks.concat())
}

/// The cancellation error.
pub(crate) fn cancelled() -> SolverError {
    SolverError::new(ErrorCode::Cancelled, "the prediction was cancelled")
}

/// A pass excluded by claim 8 with `exclusion_shape_error` (§3.4, E15): the same prediction
/// position, finished surface and generation point as a full prediction, and e_S = −δ(θ_c), but
/// neither force nor deflection (the reason for the exclusion): e_D stays null and e = e_S. The
/// status stays `skipped_small_angle`.
fn shape_error_only(context: &Context<'_>, path: &PathModel, index: usize, scratch: &mut Scratch) -> Outcome {
    let mut outcome = predict_pass_with(context, path, index, scratch, false);
    if outcome.status == PassStatus::Ok {
        outcome.status = PassStatus::SkippedSmallAngle;
    } else {
        outcome = Outcome::empty(PassStatus::SkippedSmallAngle);
    }
    outcome
}

/// The full pipeline for one pass.
pub(crate) fn predict_pass(context: &Context<'_>, path: &PathModel, index: usize, scratch: &mut Scratch) -> Outcome {
    predict_pass_with(context, path, index, scratch, true)
}

/// One pass's geometry and conditions, as the pipeline's steps use them.
struct PassSetup {
    /// The pass's path segment, and the path's arclength at its start.
    segment: usize,
    sigma: f64,
    start: Vec3,
    length: f64,
    feed_direction: Vec3,
    tooth_feed: f64,
    /// g = n_g · f_t: T1 ends and T2 starts this far from the prediction position, mm.
    gap: f64,
}

/// A prediction position on a pass: its arclength from the pass start, the ball centre, the
/// scene there (machine frame) and the tool's engagement.
struct Station {
    s: f64,
    centre: Vec3,
    below: Scene,
    engagement: Engagement,
}

/// The pipeline for one pass, with the force and deflection steps (S3, S4, S10) only when
/// `deflection` is set.
fn predict_pass_with(
    context: &Context<'_>,
    path: &PathModel,
    index: usize,
    scratch: &mut Scratch,
    deflection: bool,
) -> Outcome {
    let job = context.job;
    let radius = job.radius;
    let pass = path.passes[index];
    let segment = path.segments[pass.segment];
    let (start, end) = path.ends(pass.segment);
    let length = segment.length;
    if length <= 0.0 {
        return Outcome::empty(PassStatus::NoCut);
    }
    let (foot_lo, foot_hi) = job.stock.footprint();
    if start.x.min(end.x) - radius >= foot_hi[0]
        || start.x.max(end.x) + radius <= foot_lo[0]
        || start.y.min(end.y) - radius >= foot_hi[1]
        || start.y.max(end.y) + radius <= foot_lo[1]
    {
        return Outcome::empty(PassStatus::OutsideStock);
    }
    let feed_direction = (end - start) / length;
    let source = pass.source;
    let tooth_feed = source.feed / (source.spindle_rpm * job.flutes as f64);
    let gap = job.tooth_feed_gap * tooth_feed;
    let Some(grid) = context.grids[sign_slot(source.rotation_sign)].as_ref() else {
        return Outcome::empty(PassStatus::NoCut);
    };
    let coefficients = if job.deflection.is_none() && deflection { job.cutting.as_ref() } else { None };
    let setup =
        PassSetup { segment: pass.segment, sigma: segment.sigma, start, length, feed_direction, tooth_feed, gap };
    let Some((station, no_engagement)) = engaged_station(context, path, &setup, grid, coefficients, scratch) else {
        return Outcome::empty(PassStatus::NoCut);
    };
    let mut outcome = Outcome::empty(PassStatus::Ok);
    outcome.position = Some(station.s);
    outcome.centre = Some(station.centre);
    let centre = station.centre;

    // The finished surface and the generation point.
    let Some((point, tip)) = finished_surface(context, path, &setup, &station, no_engagement, &mut outcome, scratch)
    else {
        return Outcome::empty(PassStatus::NoCut);
    };
    let Some(point) = point else {
        outcome.status = PassStatus::NoSurface;
        return outcome;
    };

    // Angles and normal (§3.11), errors (§3.12).
    let contact = contact(job, tip, point, centre, source.rotation_sign, &mut outcome.flags);
    outcome.error_shape = Some(contact.error_shape);
    outcome.contact_angle = Some(contact.contact_angle);
    outcome.azimuth = contact.azimuth;
    outcome.rotation_angle = contact.rotation_angle;
    outcome.point = Some(contact.point);
    outcome.normal = Some(contact.normal);
    if !deflection {
        outcome.error = Some(contact.error_shape);
        return outcome;
    }
    let force_history = &station.engagement.force;
    let deflection_source = DeflectionSource::of(context, source.spindle_rpm, coefficients, force_history);
    let (deflection, history_deflection) =
        deflection_at_contact(context, index, deflection_source.as_ref(), contact.rotation_angle, &mut outcome);
    let normal = contact.normal;
    let error_deflection =
        deflection.map(|d| if contact.azimuth.is_none() { 0.0 } else { d[0] * normal.x + d[1] * normal.y });
    if job.merge_tolerance.is_some() {
        outcome.deflection_spread = deflection_source
            .as_ref()
            .and_then(|deflection_source| deflection_spread(job, deflection_source, &contact, error_deflection));
    }
    outcome.error_deflection = error_deflection;
    outcome.error = Some(contact.error_shape + error_deflection.unwrap_or(0.0));
    outcome.deflection = deflection;
    if job.history.contains(&index) && !force_history.is_empty() {
        outcome.history = Some(PassHistory {
            step_deg: 360.0 / force_history.len() as f64,
            force: force_history.clone(),
            deflection: history_deflection.unwrap_or_default(),
        });
    }
    outcome
}

/// Where the finished surface is generated and what the shape error makes of it there.
struct Contact {
    /// Generation point C (world).
    point: Vec3,
    /// θ_c, radians.
    contact_angle: f64,
    /// φ_c, radians; `None` at the tip.
    azimuth: Option<f64>,
    /// n̂ at C, out of the material.
    normal: Vec3,
    /// ψ_c, radians; `None` at the tip.
    rotation_angle: Option<f64>,
    /// e_S = −δ(θ_c), mm.
    error_shape: f64,
}

/// The contact angles and normal at the generation point (§3.11) and the shape error there
/// (§3.12), flagging `AtTip` and an extrapolated shape-error table.
fn contact(job: &Job, tip: bool, point: Vec3, centre: Vec3, sign: f64, flags: &mut Vec<PassFlag>) -> Contact {
    let radius = job.radius;
    let (point, contact_angle, azimuth, normal) = if tip {
        flags.push(PassFlag::AtTip);
        (centre - radius * Vec3::z(), 0.0, None, Vec3::z())
    } else {
        let offset = point - centre;
        let theta = (-offset.z / radius).clamp(-1.0, 1.0).acos();
        (point, theta, Some(offset.y.atan2(offset.x)), -offset / radius)
    };
    let rotation_angle = azimuth.map(|phi| {
        (sign * (phi - job.flute_zero) + (1.0 - contact_angle.cos()) * job.helix.tan())
            .rem_euclid(std::f64::consts::TAU)
    });
    let (delta, extrapolated) = shape::delta(&job.shape_error, contact_angle.to_degrees());
    if extrapolated {
        flags.push(PassFlag::Extrapolated);
    }
    Contact { point, contact_angle, azimuth, normal, rotation_angle, error_shape: -delta }
}

/// The prediction position (§3.3): the middle of the pass first, then alternately ahead and
/// behind, up to [`MAX_STATIONS`], the first where the tool cuts; else the middle, flagged
/// `true` (no engagement: a retraced pass may still finish the surface there).
fn engaged_station(
    context: &Context<'_>,
    path: &PathModel,
    setup: &PassSetup,
    grid: &EdgeGrid,
    coefficients: Option<&force::CuttingCoefficients>,
    scratch: &mut Scratch,
) -> Option<(Station, bool)> {
    let job = context.job;
    let radius = job.radius;
    let PassSetup { length, tooth_feed, gap, start, feed_direction, .. } = *setup;
    let mut pieces = Vec::new();
    let step = tooth_feed.max(length / 16.0);
    let mut stations = vec![0.5 * length];
    for m in 1..MAX_STATIONS {
        let offset = step * m.div_ceil(2) as f64;
        let s = if m % 2 == 1 { 0.5 * length + offset } else { 0.5 * length - offset };
        if (0.0..=length).contains(&s) {
            stations.push(s);
        }
    }
    let mut retraced: Option<Station> = None;
    for (try_index, &s) in stations.iter().enumerate() {
        let centre = start + s * feed_direction;
        let sigma = setup.sigma + s;
        scene::gather(
            path,
            &scene::Query {
                centre,
                sigma,
                gap,
                radius,
                reach: 2.0 * radius,
                any_view: false,
                order: PieceOrder::Height,
                stock_top: job
                    .stock
                    .highest_top([centre.x - radius, centre.y - radius], [centre.x + radius, centre.y + radius]),
            },
            scratch,
            &mut pieces,
        );
        let below = Scene::new(&pieces, centre, Matrix3::identity(), radius);
        let engagement = force::engage(grid, &below, &job.stock, &feed_direction, tooth_feed, coefficients);
        if engagement.cut_elements > 0 {
            return Some((Station { s, centre, below, engagement }, false));
        }
        if try_index == 0 {
            retraced = Some(Station { s, centre, below, engagement });
        }
    }
    retraced.map(|station| (station, true))
}

/// The finished surface at `station` by the request's method, with its counts and flags in
/// `outcome`: the generation point (if any surface is finished) and whether it is at the tip.
/// `None` when nothing is cut there after all (no engagement and nothing retraced).
fn finished_surface(
    context: &Context<'_>,
    path: &PathModel,
    setup: &PassSetup,
    station: &Station,
    no_engagement: bool,
    outcome: &mut Outcome,
    scratch: &mut Scratch,
) -> Option<(Option<Vec3>, bool)> {
    let job = context.job;
    let Station { s, centre, ref below, .. } = *station;
    let (feed_direction, gap) = (setup.feed_direction, setup.gap);
    let sigma = setup.sigma + s;
    let pixel = 2.0 * job.radius / f64::from(job.resolution);
    Some(match job.method {
        Method::Sampling => {
            let band = band(path, setup.segment, &centre, &feed_direction, sigma, gap, pixel);
            let surface = sampling::sample(below, &job.stock, &band);
            outcome.cut_count = surface.cut_samples;
            outcome.finished_count = surface.finished_samples;
            if surface.regions > 1 {
                outcome.flags.push(PassFlag::SeveralRegions);
            }
            if no_engagement && !surface.retraced {
                return None;
            }
            if surface.retraced {
                outcome.flags.push(PassFlag::Retraced);
            }
            if surface.finished_samples < MIN_FINISHED_PIXELS && surface.point.is_some() {
                outcome.flags.push(PassFlag::LowConfidence);
            }
            let tip = surface.point.is_some_and(|c| (c - centre).xy().norm() < 0.5 * pixel);
            (surface.point, tip)
        }
        Method::DepthBuffer => {
            let image = depth_buffer(context, path, below, &centre, &feed_direction, sigma, gap, outcome, scratch);
            if no_engagement && !image.retraced {
                return None;
            }
            if image.retraced {
                outcome.flags.push(PassFlag::Retraced);
            }
            let tip = !outcome.flags.contains(&PassFlag::ViewCorrected)
                && image.point.is_some()
                && image.centroid_offset < 0.5 * image.pixel;
            (image.point, tip)
        }
    })
}

/// Where D(ψ) comes from (§3.8): the request's prescribed history, or the pass's force history
/// through its spindle speed's kernels (with a force model).
enum DeflectionSource<'a> {
    Prescribed(&'a super::request::PrescribedDeflection),
    Force { spindle: &'a SpindleKernels, force_history: &'a [[f64; 3]] },
}

impl<'a> DeflectionSource<'a> {
    /// `None`: neither a prescribed history nor a force model with kernels for `spindle_rpm`.
    fn of(
        context: &'a Context<'_>,
        spindle_rpm: f64,
        coefficients: Option<&force::CuttingCoefficients>,
        force_history: &'a [[f64; 3]],
    ) -> Option<Self> {
        if let Some(prescribed) = &context.job.deflection {
            return Some(Self::Prescribed(prescribed));
        }
        let spindle = coefficients.and(context.kernels.get(&spindle_rpm.to_bits()))?;
        Some(Self::Force { spindle, force_history })
    }

    /// D(ψ), linear between the history's steps.
    fn at(&self, psi: f64) -> [f64; 2] {
        match self {
            Self::Prescribed(prescribed) => prescribed_at(prescribed, psi),
            Self::Force { spindle, force_history } => dynamics::deflection_at(&spindle.kernels, force_history, psi),
        }
    }

    /// Steps of the history per revolution.
    fn steps(&self) -> usize {
        match self {
            Self::Prescribed(prescribed) => prescribed.x.len(),
            Self::Force { force_history, .. } => force_history.len(),
        }
    }
}

/// The deflection D at the contact's rotation angle (§3.8), with D over the whole revolution
/// for the passes whose history is asked for; `None` (flagged) without a deflection source.
fn deflection_at_contact(
    context: &Context<'_>,
    index: usize,
    source: Option<&DeflectionSource<'_>>,
    rotation_angle: Option<f64>,
    outcome: &mut Outcome,
) -> (Option<[f64; 2]>, Option<Vec<[f64; 2]>>) {
    let mut history_deflection: Option<Vec<[f64; 2]>> = None;
    match source {
        Some(DeflectionSource::Force { spindle, force_history }) => {
            if spindle.outside {
                outcome.flags.push(PassFlag::OutsideFrfBand);
            }
            if force_history.iter().all(|f| f[0] == 0.0 && f[1] == 0.0 && f[2] == 0.0) {
                outcome.flags.push(PassFlag::NoLoad);
            }
            if context.job.history.contains(&index) {
                history_deflection = Some(dynamics::deflection_history(&spindle.kernels, force_history));
            }
        }
        Some(DeflectionSource::Prescribed(_)) => {}
        None => outcome.flags.push(PassFlag::NoDeflection),
    }
    let deflection = source.map(|source| rotation_angle.map_or([0.0, 0.0], |psi| source.at(psi)));
    (deflection, history_deflection)
}

/// How far e_D = D(ψ)·n moves while ψ moves over the rotation angles the generation point can
/// take within one sample Δ of where it was found: Δ moves the point's azimuth by Δ/(R sin θ_c)
/// and its contact angle by Δ/R, which the helix turns into Δ/R · sin θ_c · tan β of ψ. D is
/// linear between the history's steps, so the largest move over the window is at a step or an
/// end of it. `None` at the tip (e_D is 0 there).
fn deflection_spread(
    job: &Job,
    source: &DeflectionSource<'_>,
    contact: &Contact,
    error_deflection: Option<f64>,
) -> Option<f64> {
    let (psi, centre_value) = (contact.rotation_angle?, error_deflection?);
    let sample_angle = 2.0 / f64::from(job.resolution);
    let sin_theta = contact.contact_angle.sin();
    let half_width =
        (sample_angle / sin_theta + sample_angle * sin_theta * job.helix.tan().abs()).min(std::f64::consts::PI);
    let step = std::f64::consts::TAU / source.steps() as f64;
    let first = ((psi - half_width) / step).ceil();
    let last = ((psi + half_width) / step).floor();
    let angles = [psi - half_width, psi + half_width]
        .into_iter()
        .chain((0..(last - first + 1.0).max(0.0) as usize).map(|k| (first + k as f64) * step));
    let normal = contact.normal;
    Some(
        angles
            .map(|angle| source.at(angle))
            .map(|d| (d[0] * normal.x + d[1] * normal.y - centre_value).abs())
            .fold(0.0, f64::max),
    )
}

/// D(ψ) of a prescribed history, periodic, linear between samples.
fn prescribed_at(prescribed: &super::request::PrescribedDeflection, psi: f64) -> [f64; 2] {
    let n = prescribed.x.len();
    let position = psi.rem_euclid(std::f64::consts::TAU) / std::f64::consts::TAU * n as f64;
    let k0 = (position.floor() as usize).min(n - 1);
    let k1 = (k0 + 1) % n;
    let t = position - k0 as f64;
    [(1.0 - t) * prescribed.x[k0] + t * prescribed.x[k1], (1.0 - t) * prescribed.y[k0] + t * prescribed.y[k1]]
}

/// The sampling band: |a| ≤ g/2 on each side where the path runs straight through the gap end
/// (the ball there hides the rest), the whole zone range otherwise.
fn band(
    path: &PathModel,
    segment: usize,
    centre: &Vec3,
    feed_direction: &Vec3,
    sigma: f64,
    gap: f64,
    pixel: f64,
) -> Band {
    let radius_scale = centre.norm().max(1.0);
    let straight = |sign: f64| {
        path.point_at(segment, sigma + sign * gap)
            .is_some_and(|p| (p - (centre + sign * gap * feed_direction)).norm() <= 1e-9 * radius_scale)
    };
    let (back, front) = (straight(-1.0), straight(1.0));
    let both = back && front;
    Band {
        axis: *feed_direction,
        a_lo: if back { -0.5 * gap } else { f64::NEG_INFINITY },
        a_hi: if front { 0.5 * gap } else { f64::INFINITY },
        row_spacing: if both { pixel } else { (0.5 * gap).clamp(pixel, 4.0 * pixel) },
        spacing: pixel,
    }
}

/// The image-plane frame: rows ê₁, ê₂, v̂ with ê₂ the feed direction projected on the image
/// plane and ê₁ = ê₂ × v̂ (§3.5).
fn view_frame(view: &Vec3, feed_direction: &Vec3) -> Matrix3<f64> {
    let mut up = feed_direction - feed_direction.dot(view) * view;
    if up.norm() < 1e-9 {
        let helper = if view.x.abs() < 0.9 { Vec3::x() } else { Vec3::y() };
        up = helper - helper.dot(view) * view;
    }
    let up = up.normalize();
    let right = up.cross(view);
    Matrix3::from_rows(&[right.transpose(), up.transpose(), view.transpose()])
}

/// The depth-buffer method: from below, then the rotated and zoomed views when needed (§3.10).
/// `scene` is the engagement's, in the machine frame.
#[allow(clippy::too_many_arguments)]
fn depth_buffer(
    context: &Context<'_>,
    path: &PathModel,
    scene: &Scene,
    centre: &Vec3,
    feed_direction: &Vec3,
    sigma: f64,
    gap: f64,
    outcome: &mut Outcome,
    scratch: &mut Scratch,
) -> Image {
    let job = context.job;
    let radius = job.radius;
    let pixels = job.resolution as usize;
    let up = Vec3::z();
    let below_scene = scene.in_frame(view_frame(&up, feed_direction));
    let full = Window { centre: [0.0, 0.0], side: 2.0 * radius, pixels, area_weighted: false };
    let below = render::render(&below_scene, &job.stock, &full);
    outcome.cut_count = below.cut_pixels;
    outcome.finished_count = below.finished_pixels;
    outcome.view = Some(up);
    let theta = below.point.map(|c| (-(c - centre).z / radius).clamp(-1.0, 1.0).acos());
    let needs_correction = below.cut_pixels > 0
        && (below.point.is_none()
            || theta.is_some_and(|t| t > job.view_threshold)
            || below.rim
            || below.finished_pixels < MIN_FINISHED_PIXELS);
    if !needs_correction || !job.view_correction || below.cut_inward.norm() == 0.0 {
        if below.rim {
            outcome.flags.push(PassFlag::RimLimited);
        }
        if below.point.is_some() && (below.rim || below.finished_pixels < MIN_FINISHED_PIXELS) {
            outcome.flags.push(PassFlag::LowConfidence);
        }
        if below.regions > 1 {
            outcome.flags.push(PassFlag::SeveralRegions);
        }
        return below;
    }
    // (a) Look along the mean inward normal of the cutting region.
    let view = below.cut_inward.normalize();
    let mut wide = Vec::new();
    scene::gather(
        path,
        &scene::Query {
            centre: *centre,
            sigma,
            gap,
            radius,
            reach: 5.0 * radius,
            any_view: true,
            order: PieceOrder::Path,
            stock_top: f64::INFINITY,
        },
        scratch,
        &mut wide,
    );
    let rotated_scene = Scene::new(&wide, *centre, view_frame(&view, feed_direction), radius);
    let rotated_window = Window { area_weighted: true, ..full };
    let mut image = render::render(&rotated_scene, &job.stock, &rotated_window);
    outcome.flags.push(PassFlag::ViewCorrected);
    outcome.view = Some(view);
    // (b) Zoom on the cutting region, then halve the window up to three times.
    if image.point.is_none()
        && let Some(b) = image.cut_box
    {
        let margin = 2.0 * image.pixel;
        let mut window = Window {
            centre: [0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])],
            side: (b[2] - b[0]).max(b[3] - b[1]) + 2.0 * margin,
            pixels,
            area_weighted: true,
        };
        for _ in 0..4 {
            let zoomed = render::render(&rotated_scene, &job.stock, &window);
            let found = zoomed.point.is_some();
            image = zoomed;
            if found {
                break;
            }
            window.side *= 0.5;
        }
    }
    outcome.cut_count = image.cut_pixels;
    outcome.finished_count = image.finished_pixels;
    if image.rim {
        outcome.flags.push(PassFlag::RimLimited);
    }
    if image.point.is_some() && (image.rim || image.finished_pixels < MIN_FINISHED_PIXELS) {
        outcome.flags.push(PassFlag::LowConfidence);
    }
    if image.regions > 1 {
        outcome.flags.push(PassFlag::SeveralRegions);
    }
    image
}
