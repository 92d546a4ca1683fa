//! Property tests of the contour solver on random simple polygons (star-shaped, so simple by
//! construction, with convex and concave corners from acute to reflex and short edges):
//!
//! * no tool move comes closer to the contour than the tool radius minus 1e-9, and no move end
//!   lies in the material (for `outside`, no tool-centre point inside the offset region);
//! * every looped corner point is passed twice, each time in a straight line (incoming and
//!   outgoing moves collinear, along one of the corner's faces, a different face each time);
//! * every pass and every layer is closed;
//! * the same request gives byte-identical answers;
//! * a tool that does not cut at its centre enters every layer on a ramp: no feed move goes down
//!   steeper than the ramp angle or faster than the plunge feed, and the ramp keeps the tool
//!   radius from the contour;
//!
//! each with and without the block-time rule (`block_time_ms`).
//!
//! Solver refusals are allowed only with the tool-fit codes (random polygons have notches the
//! tool cannot enter).

use std::f64::consts::TAU;

use kerf_solver::contour::{self, ContourRequest, ContourSolution, MoveKind};
use kerf_solver::planar::{Containment, Vec2, cross, point_in_polygon, segment_segment_distance, vec2};
use kerf_solver::tool::{Tool, ToolKind};
use proptest::prelude::*;
use serde_json::json;

const GOUGE: f64 = 1e-9;

fn star_polygon() -> impl Strategy<Value = Vec<[f64; 2]>> {
    (3usize..12)
        .prop_flat_map(|n| (prop::collection::vec(0.0f64..1.0, n), prop::collection::vec(2.0f64..10.0, n), 0.0f64..TAU))
        // Every angular gap below π keeps the polygon star-shaped about the origin, so simple
        // and counter-clockwise.
        .prop_filter("an angular gap of π or more", |(gaps, _, _)| {
            let total: f64 = gaps.iter().map(|g| 0.02 + g).sum();
            gaps.iter().all(|g| 0.02 + g < 0.45 * total)
        })
        .prop_map(|(gaps, radii, phase)| {
            let weights: Vec<f64> = gaps.iter().map(|g| 0.02 + g).collect();
            let total: f64 = weights.iter().sum();
            let mut angle = phase;
            weights
                .iter()
                .zip(&radii)
                .map(|(w, r)| {
                    let point = [r * angle.cos(), r * angle.sin()];
                    angle += TAU * w / total;
                    point
                })
                .collect()
        })
}

#[derive(Debug, Clone)]
struct Setup {
    contour: Vec<[f64; 2]>,
    radius: f64,
    outside: bool,
    climb: bool,
    style: &'static str,
    two_passes: bool,
    round: bool,
    max_angle_deg: f64,
    /// With the block-time rule (arcs chorded by it, their end segments merged).
    block_time: Option<f64>,
    /// Whether the flat tool cuts at its centre (else its layers enter on ramps).
    centre_cutting: bool,
    /// Ramp angle, degrees.
    ramp_angle_deg: f64,
}

fn setup() -> impl Strategy<Value = Setup> {
    (
        star_polygon(),
        0.02f64..0.4,
        any::<bool>(),
        any::<bool>(),
        prop::sample::select(vec!["arc", "triangle", "parallelogram"]),
        any::<bool>(),
        any::<bool>(),
        100.0f64..179.0,
        prop::option::of(0.5f64..8.0),
        (any::<bool>(), 0.5f64..45.0),
    )
        .prop_map(
            |(
                contour,
                radius,
                outside,
                climb,
                style,
                two_passes,
                round,
                max_angle_deg,
                block_time,
                (centre_cutting, ramp_angle_deg),
            )| Setup {
                contour,
                radius,
                outside,
                climb,
                style,
                two_passes,
                round,
                max_angle_deg,
                block_time,
                centre_cutting,
                ramp_angle_deg,
            },
        )
}

fn request(setup: &Setup) -> ContourRequest {
    let passes = if setup.two_passes {
        json!([
            {"allowance": 0.2, "join": if setup.round { "round" } else { "miter" }},
            {"allowance": 0.0}
        ])
    } else {
        json!([{"allowance": 0.0}])
    };
    let mut body = json!({
        "tool": {"kind": "flat", "radius": setup.radius},
        "contour": setup.contour,
        "side": if setup.outside { "outside" } else { "inside" },
        "direction": if setup.climb { "climb" } else { "conventional" },
        "depths": {"top": 0.0, "bottom": -2.0, "step": 1.0},
        "corner_loop": {"style": setup.style, "max_angle_deg": setup.max_angle_deg},
        "passes": passes,
        "feed": 600,
        "loop_feed": 2000,
        "tolerance": 0.005,
        "ramp_angle_deg": setup.ramp_angle_deg
    });
    if let Some(block_time) = setup.block_time {
        body["block_time_ms"] = json!(block_time);
    }
    serde_json::from_value(body).unwrap()
}

fn solve(setup: &Setup) -> Option<ContourSolution> {
    let tool = Tool { centre_cutting: Some(setup.centre_cutting), ..Tool::new(ToolKind::Flat, setup.radius) };
    match contour::solve(&request(setup), &tool) {
        Ok(answer) => Some(answer),
        Err(error) => {
            assert!(
                matches!(error.code().as_str(), "E_OFFSET_COLLAPSE" | "E_OFFSET_SELF_INTERSECTION"),
                "unexpected refusal {}: {}",
                error.code().as_str(),
                error.message()
            );
            None
        }
    }
}

fn xy(point: [f64; 3]) -> Vec2 {
    Vec2::new(point[0], point[1])
}

/// Horizontal moves at the layer height: (from, to, kind).
fn layer_segments(z: f64, moves: &[contour::ContourMove]) -> Vec<(Vec2, Vec2, MoveKind)> {
    moves
        .windows(2)
        .filter(|pair| pair[0].to[2] == z && pair[1].to[2] == z)
        .map(|pair| (xy(pair[0].to), xy(pair[1].to), pair[1].kind))
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 160, ..ProptestConfig::default() })]

    #[test]
    fn moves_keep_the_tool_radius_from_the_contour(setup in setup()) {
        let Some(answer) = solve(&setup) else { return Ok(()); };
        let polygon: Vec<Vec2> = setup.contour.iter().copied().map(vec2).collect();
        let n = polygon.len();
        for layer in &answer.layers {
            for step in layer.moves.iter().filter(|m| m.to[2] == layer.z) {
                let inside = point_in_polygon(&xy(step.to), &polygon);
                let in_material = if setup.outside {
                    inside != Containment::Outside
                } else {
                    inside != Containment::Inside
                };
                prop_assert!(!in_material, "move end {:?} lies in the material", step.to);
            }
            for (a, b, _) in layer_segments(layer.z, &layer.moves) {
                for k in 0..n {
                    let distance = segment_segment_distance(&a, &b, &polygon[k], &polygon[(k + 1) % n]);
                    prop_assert!(
                        distance >= setup.radius - GOUGE,
                        "move {a:?}→{b:?} comes within {distance} of edge {k} (r = {})",
                        setup.radius
                    );
                }
            }
        }
    }

    #[test]
    fn looped_corner_points_are_passed_twice_in_straight_lines(setup in setup()) {
        let Some(answer) = solve(&setup) else { return Ok(()); };
        let polygon: Vec<Vec2> = setup.contour.iter().copied().map(vec2).collect();
        let n = polygon.len();
        let layer = &answer.layers[0];
        let loop_passes = answer.passes.iter().filter(|p| p.loops).count();
        for corner in answer.corners.iter().filter(|c| c.looped) {
            let p = vec2(corner.cl_point);
            let visits: Vec<usize> = layer
                .moves
                .iter()
                .enumerate()
                .filter(|(_, m)| m.to[2] == layer.z && (xy(m.to) - p).norm() < 1e-9)
                .map(|(i, _)| i)
                .collect();
            prop_assert!(visits.len() >= 2 * loop_passes.min(1), "corner {} visited {} times", corner.index, visits.len());
            let faces = [
                (polygon[corner.index] - polygon[(corner.index + n - 1) % n]).normalize(),
                (polygon[(corner.index + 1) % n] - polygon[corner.index]).normalize(),
            ];
            let mut faces_used = Vec::new();
            for &i in &visits {
                let (Some(before), Some(after)) = (layer.moves.get(i.wrapping_sub(1)), layer.moves.get(i + 1)) else {
                    continue;
                };
                let incoming = (p - xy(before.to)).normalize();
                let outgoing = (xy(after.to) - p).normalize();
                prop_assert!(cross(&incoming, &outgoing).abs() < 1e-9, "corner {}: turn at P", corner.index);
                prop_assert!(incoming.dot(&outgoing) > 0.0, "corner {}: reversal at P", corner.index);
                let face = faces.iter().position(|f| cross(f, &incoming).abs() < 1e-9);
                prop_assert!(face.is_some(), "corner {}: not along a face", corner.index);
                faces_used.extend(face);
            }
            prop_assert!(faces_used.contains(&0) && faces_used.contains(&1), "corner {}: faces {faces_used:?}", corner.index);
        }
    }

    #[test]
    fn passes_and_layers_are_closed_and_answers_repeat(setup in setup()) {
        let Some(answer) = solve(&setup) else { return Ok(()); };
        for layer in &answer.layers {
            // The layer ends where it began: up at the clearance plane.
            let last = layer.moves.last().unwrap();
            prop_assert_eq!(last.kind, MoveKind::Rapid);
            prop_assert_eq!(last.to[2], answer.summary.safe_z);
            // Each pass: the lead-in link ends at S, the pass's moves follow, and the last of them
            // returns to S before the lead-out link.
            let level: Vec<&contour::ContourMove> = layer.moves.iter().filter(|m| m.to[2] == layer.z).collect();
            let mut passes = 0;
            for (i, step) in level.iter().enumerate() {
                let starts_pass = step.kind == MoveKind::Link
                    && level.get(i + 1).is_some_and(|m| m.kind != MoveKind::Link);
                if !starts_pass {
                    continue;
                }
                let end = level[i + 1..]
                    .iter()
                    .position(|m| m.kind == MoveKind::Link)
                    .map_or(level.len() - 1, |p| p + i);
                prop_assert!((xy(level[end].to) - xy(step.to)).norm() < 1e-9, "pass not closed");
                passes += 1;
            }
            prop_assert_eq!(passes, answer.passes.len());
        }
        let again = solve(&setup).unwrap();
        prop_assert_eq!(serde_json::to_string(&answer).unwrap(), serde_json::to_string(&again).unwrap());
    }

    #[test]
    fn layers_of_a_tool_that_does_not_cut_at_its_centre_enter_on_ramps(setup in setup()) {
        check_ramps(&Setup { centre_cutting: false, ..setup })?;
    }
}

/// No feed move of a tool that does not cut at its centre goes down steeper than the ramp angle
/// or faster than the plunge feed, none comes within the tool radius of the contour, and every
/// layer enters on a ramp.
fn check_ramps(setup: &Setup) -> Result<(), TestCaseError> {
    let Some(answer) = solve(setup) else { return Ok(()) };
    let slope = setup.ramp_angle_deg.to_radians().tan();
    let plunge_feed = 600.0 * kerf_solver::gcode::DEFAULT_PLUNGE_FRACTION;
    let polygon: Vec<Vec2> = setup.contour.iter().copied().map(vec2).collect();
    let mut ramps = 0;
    for layer in &answer.layers {
        for pair in layer.moves.windows(2) {
            let (from, to) = (pair[0].to, pair[1].to);
            let Some(feed) = pair[1].feed else { continue };
            if pair[1].kind == MoveKind::Rapid || to[2] >= from[2] {
                continue;
            }
            let run = (xy(to) - xy(from)).norm();
            let drop = from[2] - to[2];
            prop_assert!(run > 0.0, "a plunge straight down at {to:?}");
            prop_assert!(drop <= run * slope * (1.0 + 1e-9) + 1e-12, "{drop} down over {run} at {to:?}");
            prop_assert!(feed <= plunge_feed, "ramp at F{feed}");
            for k in 0..polygon.len() {
                let distance =
                    segment_segment_distance(&xy(from), &xy(to), &polygon[k], &polygon[(k + 1) % polygon.len()]);
                prop_assert!(distance >= setup.radius - GOUGE, "ramp {from:?}→{to:?} within {distance} of edge {k}");
            }
            ramps += 1;
        }
    }
    prop_assert!(ramps >= answer.layers.len(), "every layer enters on a ramp");
    Ok(())
}

/// A pass whose first chord is a few micrometres long (the middle of a tiny offset edge): at a
/// shallow ramp angle its legs along that chord alone would need more than the most legs a ramp
/// may have.
#[test]
fn a_ramp_whose_first_chord_is_very_short_keeps_its_angle() {
    let setup = Setup {
        contour: vec![
            [5.1328, 0.0],
            [8.0749, 1.0213],
            [2.2024, 0.9274],
            [-1.4454, 1.3824],
            [0.9214, -1.7751],
            [1.0528, -1.7005],
        ],
        radius: 0.24669,
        outside: false,
        climb: false,
        style: "arc",
        two_passes: false,
        round: false,
        max_angle_deg: 100.0,
        block_time: None,
        centre_cutting: false,
        ramp_angle_deg: 0.5,
    };
    assert!(solve(&setup).is_some(), "the contour is solved");
    if let Err(error) = check_ramps(&setup) {
        panic!("{error}");
    }
}
