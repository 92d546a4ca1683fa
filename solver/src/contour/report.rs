//! The answer's reports (docs/spec/contour.md §3.10 material, §3.8 E1 allowances): per corner its
//! action and material, the warnings about corners and loops, per pass its lengths, the cycle
//! time and the program's description.

use super::answer::{
    ContourCorner, ContourLayer, ContourSummary, Convexity, CornerAction, LoopReport, MaterialReport, MoveKind,
    PassReport, ReliefReport,
};
use super::element::ElementKind;
use super::job::Job;
use super::layer::Layer;
use super::material::{self, Material};
use super::pass::{Action, PassPlan};
use super::prepare::list_indices;
use super::request::{CutDirection, LoopStyle, Side};
use crate::error::Warning;
use crate::geometry::Vec3;
use crate::machine::MachineProfile;
use crate::planar::array2;
use crate::validate::Measure;

/// Material angle below which a corner is reported as a fragile tip (`W_ACUTE_TIP`), degrees.
const ACUTE_TIP_DEG: f64 = 15.0;

/// The cycle time of the program of `layers` on `machine` (None without its `max_accel`):
/// cuts in the material, loops and links in the air, plunges at the plunge feed as the program
/// writes them.
pub(super) fn contour_cycle_time(
    layers: &[ContourLayer],
    machine: &MachineProfile,
    tool_plunge_feed: Option<f64>,
) -> Option<crate::machine::cycle::CycleTime> {
    use crate::machine::cycle::{Step, cycle_time};
    let dynamics = machine.dynamics()?;
    let plunge = tool_plunge_feed.or(machine.plunge_feed);
    let first = layers.first()?.moves.first()?;
    let mut here = Vec3::from(first.to);
    let mut steps = Vec::new();
    for step in layers.iter().flat_map(|layer| &layer.moves) {
        let to = Vec3::from(step.to);
        steps.push(match (step.kind, step.feed) {
            (MoveKind::Rapid, _) | (_, None) => Step::Rapid(to),
            (kind, Some(feed)) => {
                let down = to.z < here.z && (to.x - here.x).abs() <= 1e-9 && (to.y - here.y).abs() <= 1e-9;
                let feed = if down { crate::gcode::plunge_feed(feed, plunge) } else { feed };
                Step::Feed { to, feed, air: kind != MoveKind::Cut }
            }
        });
        here = to;
    }
    Some(cycle_time(Vec3::from(first.to), &steps, &dynamics, 1))
}

fn corner_action(action: Action) -> CornerAction {
    match action {
        Action::LoopArc => CornerAction::LoopArc,
        Action::LoopTriangle => CornerAction::LoopTriangle,
        Action::LoopParallelogram => CornerAction::LoopParallelogram,
        Action::Miter => CornerAction::Miter,
        Action::Round => CornerAction::Round,
        Action::Reflex => CornerAction::Reflex,
        Action::Unreached => CornerAction::Unreached,
        Action::Dogbone => CornerAction::Dogbone,
        Action::Tbone => CornerAction::Tbone,
    }
}

fn material_report(material: &Material) -> MaterialReport {
    MaterialReport {
        left_area: material.left_area,
        left_depth: material.left_depth,
        overcut_area: material.overcut_area,
        overcut_depth: material.overcut_depth,
    }
}

/// The corner reports from the final pass of the first layer, in request order.
pub(super) fn corner_reports(
    job: &Job,
    request_order: bool,
    layer: &Layer,
    final_pass: &PassPlan,
) -> Vec<ContourCorner> {
    let lag_product = job.servo_time_constant_s.map(|t| (job.feed / 60.0 * t).powi(2));
    let model = job.blend_radius.is_some() || lag_product.is_some();
    let mut corners: Vec<ContourCorner> = final_pass
        .corners
        .iter()
        .map(|corner| {
            let ideal = if corner.action == Action::Unreached {
                if corner.chain_start == corner.k {
                    let chain: Vec<usize> =
                        final_pass.corners.iter().filter(|c| c.chain_start == corner.k).map(|c| c.k).collect();
                    material::unreached(layer, &corner.cl_point, &chain, job.radius)
                } else {
                    Material::default()
                }
            } else {
                material::ideal(layer, corner, job.radius)
            };
            let predicted = model.then(|| {
                material::predicted(corner, &ideal, job.radius, final_pass.offset, job.blend_radius, lag_product)
            });
            let corner_loop = corner.loop_shape.map(|shape| LoopReport {
                style: shape.style,
                leg: shape.leg,
                radius: shape.radius,
                exit_end: array2(&shape.exit_end),
                entry_start: array2(&shape.entry_start),
                centre: shape.centre.as_ref().map(array2),
                far_corner: shape.far_corner.as_ref().map(array2),
                sweep_deg: shape.sweep.map(f64::to_degrees),
                length: shape.length(),
                clearance: corner.clearance.unwrap_or(0.0),
                at_loop_feed: corner.loop_feed && job.loop_feed.is_some(),
            });
            let relief = corner.relief.map(|shape| ReliefReport {
                style: shape.style,
                target: array2(&shape.target),
                along_edge: shape.along_edge.map(|edge| {
                    let start = if request_order { edge } else { layer.next(edge) };
                    job.contour.source[layer.prepared_vertex[start]]
                }),
            });
            ContourCorner {
                index: corner.source,
                vertex: array2(&job.contour.points[layer.prepared_vertex[corner.k]]),
                angle_deg: corner.material_angle.to_degrees(),
                turn_deg: corner.turn.to_degrees(),
                convexity: if corner.convex { Convexity::Convex } else { Convexity::Concave },
                looped: corner.loop_shape.is_some(),
                action: corner_action(corner.action),
                cl_point: array2(&corner.cl_point),
                corner_loop,
                relief,
                material: material_report(&ideal),
                predicted: predicted.as_ref().map(material_report),
            }
        })
        .collect();
    corners.sort_by_key(|c| c.index);
    corners
}

/// Warnings about corners: acute tips, corners too flat to loop, inside corners, loops at the
/// cutting feed, and passes whose allowance does not protect the tip (E1).
pub(super) fn corner_warnings(job: &Job, passes: &[PassPlan], corners: &[ContourCorner]) -> Vec<Warning> {
    let mut warnings = Vec::new();
    shape_warnings(job, passes, corners, &mut warnings);
    loop_feed_warnings(job, passes, &mut warnings);
    allowance_warnings(job, passes, &mut warnings);
    warnings
}

/// Corners whose shape needs saying: acute tips, convex corners too flat to loop, inside
/// corners left with a fillet.
fn shape_warnings(job: &Job, passes: &[PassPlan], corners: &[ContourCorner], warnings: &mut Vec<Warning>) {
    let acute: Vec<usize> = corners
        .iter()
        .filter(|c| c.convexity == Convexity::Convex && c.angle_deg < ACUTE_TIP_DEG)
        .map(|c| c.index)
        .collect();
    if !acute.is_empty() {
        warnings.push(Warning::new(
            "W_ACUTE_TIP",
            format!(
                "{} corners are sharper than {ACUTE_TIP_DEG}°; the tip is fragile and the loop legs long: {}",
                acute.len(),
                list_indices(&acute)
            ),
        ));
    }
    if let Some(final_pass) = passes.last()
        && final_pass.loops
        && job.loop_config.style != LoopStyle::None
    {
        let flat: Vec<usize> = final_pass
            .corners
            .iter()
            .filter(|c| c.convex && c.turn.abs() < job.loop_config.min_turn && c.loop_shape.is_none())
            .map(|c| c.source)
            .collect();
        if !flat.is_empty() {
            warnings.push(Warning::new(
                "I_NEAR_STRAIGHT",
                format!(
                    "{} convex corners turn by less than {:.1}° and get no loop: {}",
                    flat.len(),
                    job.loop_config.min_turn.to_degrees(),
                    list_indices(&flat)
                ),
            ));
        }
    }
    let inside: Vec<&ContourCorner> = corners.iter().filter(|c| c.action == CornerAction::Reflex).collect();
    if !inside.is_empty() {
        let largest = inside.iter().map(|c| c.material.left_area).fold(0.0, f64::max);
        let indices: Vec<usize> = inside.iter().map(|c| c.index).collect();
        warnings.push(Warning::new(
            "W_INSIDE_CORNER",
            format!(
                "{} inside corners keep a fillet of radius {} (up to {largest:.6} mm² left; set inside_corner_relief to cut them): {}",
                inside.len(),
                Measure::Length.quote(job.radius),
                list_indices(&indices)
            ),
        ));
    }
}

/// Loops that run at the cutting feed although a faster loop feed is given, and why.
fn loop_feed_warnings(job: &Job, passes: &[PassPlan], warnings: &mut Vec<Warning>) {
    if job.loop_feed.is_some_and(|f| f != job.feed) {
        for pass in passes {
            let slow: Vec<usize> =
                pass.corners.iter().filter(|c| c.loop_shape.is_some() && !c.loop_feed).map(|c| c.source).collect();
            if !slow.is_empty() {
                let reason = if pass.index == 0 && job.stock_allowance.is_none() {
                    "the stock before the first pass is unknown (give stock_allowance)"
                } else {
                    "they may touch the stock left by the previous pass"
                };
                warnings.push(Warning::new(
                    "W_LOOP_STOCK_CONTACT",
                    format!(
                        "pass {}: {} loops run at the cutting feed because {reason}: {}",
                        pass.index + 1,
                        slow.len(),
                        list_indices(&slow)
                    ),
                ));
            }
        }
    }
}

/// Passes before the last whose allowance does not protect the final tips under the control
/// model (E1): miters against the blend radius, round joins against the servo lag.
fn allowance_warnings(job: &Job, passes: &[PassPlan], warnings: &mut Vec<Warning>) {
    let lag_product = job.servo_time_constant_s.map(|t| (job.feed / 60.0 * t).powi(2));
    for pass in passes.iter().take(passes.len().saturating_sub(1)) {
        let mut needed: f64 = 0.0;
        for corner in pass.corners.iter().filter(|c| c.convex) {
            let alpha = corner.material_angle;
            match corner.action {
                Action::Miter => {
                    if let Some(blend) = job.blend_radius {
                        needed = needed.max((blend - job.radius) * (1.0 - (0.5 * alpha).sin()));
                    }
                }
                Action::Round => {
                    if let Some(product) = lag_product {
                        needed = needed.max(product / (2.0 * pass.offset));
                    }
                }
                _ => {}
            }
        }
        if needed > pass.allowance {
            warnings.push(Warning::new(
                "W_EMBODIMENT1_UNSAFE",
                format!(
                    "pass {} (allowance {}) may cut into the final tips under the control model: it needs an allowance of at least {needed:.6} mm",
                    pass.index + 1,
                    Measure::Length.quote(pass.allowance)
                ),
            ));
        }
    }
}

pub(super) fn pass_report(pass: &PassPlan) -> PassReport {
    let length = |kinds: &[ElementKind]| -> f64 {
        pass.elements
            .iter()
            .filter(|e| kinds.contains(&e.kind()))
            .map(super::element::Element::length)
            .fold(0.0, |total, length| total + length)
    };
    PassReport {
        allowance: pass.allowance,
        offset: pass.offset,
        loops: pass.loops,
        join: pass.join,
        start: array2(&pass.start),
        looped_corners: pass.corners.iter().filter(|c| c.loop_shape.is_some()).count(),
        cut_length: length(&[ElementKind::Cut]),
        leg_length: length(&[ElementKind::Exit, ElementKind::Entry]),
        loop_length: length(&[ElementKind::Loop]),
        relief_length: length(&[ElementKind::Relief]),
        gouge_min_clearance: pass.gouge_min_clearance,
        stock_min_clearance: pass.stock_min_clearance,
    }
}

/// Header lines naming the job parameters for the G-code program.
pub(super) fn describe(job: &Job, summary: &ContourSummary) -> Vec<String> {
    let style = match job.loop_config.style {
        LoopStyle::Arc => "arc",
        LoopStyle::Triangle => "triangle",
        LoopStyle::Parallelogram => "parallelogram",
        LoopStyle::None => "none",
    };
    vec![
        format!(
            "contour {} {} milling, {} corners, {} layers from {} to {}",
            match job.side {
                Side::Outside => "outside",
                Side::Inside => "inside",
            },
            match job.direction {
                CutDirection::Climb => "climb",
                CutDirection::Conventional => "conventional",
            },
            summary.corners,
            summary.layers,
            Measure::Length.quote(job.top),
            Measure::Length.quote(job.bottom)
        ),
        format!(
            "{} R {} corner loops {style}, {} passes",
            job.tool.kind.as_str(),
            Measure::Length.quote(job.radius),
            summary.passes
        ),
        format!(
            "feed {} loop feed {} spindle {} rpm",
            Measure::Feed.quote(job.feed),
            Measure::Feed.quote(summary.loop_feed),
            job.spindle_rpm
        ),
    ]
}
