//! Property tests of the deburr solver on random valid geometry (docs/spec/deburr.md §2.9 identities): for
//! the tangent method every centre is at the ball radius from both band edges of its own section,
//! the band is W wide and the centre lies in the normal plane; for both methods the ridge point
//! lies on both surfaces, the centre polyline stays within TA of the method's ideal centre path
//! (63 samples per interval), and the loop closes. (The exact method's swept chamfer is checked
//! in `deburr/swept.rs`; its centres do not satisfy the one-section identities.) Frames are computed here
//! independently from the spec's conventions (§1.3), not from the solver.

use kerf_solver::deburr::{self, CentreDistance, DeburrRequest, Direction, Edge, Hole, HoleShape, Method, Workpiece};
use kerf_solver::tool::{Tool, ToolKind, ToolRef};
use proptest::prelude::*;

type V = [f64; 3];

fn sub(a: V, b: V) -> V {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn dot(a: V, b: V) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn norm(a: V) -> f64 {
    dot(a, a).sqrt()
}
fn distance_to_segment(p: V, a: V, b: V) -> f64 {
    let ab = sub(b, a);
    let t = (dot(sub(p, a), ab) / dot(ab, ab)).clamp(0.0, 1.0);
    norm(sub(p, [a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]]))
}

#[derive(Debug, Clone)]
struct Case {
    request: DeburrRequest,
    tool: Tool,
    cylinder_radius: f64,
    width: f64,
}

fn case() -> impl Strategy<Value = Case> {
    (
        (any::<bool>(), 0_usize..3, 20.0_f64..120.0, 0.08_f64..0.3, -0.25_f64..0.25),
        (0.0_f64..1.5, 0.0_f64..0.3, 0.2_f64..0.7, 0.1_f64..0.6, 0.002_f64..0.05),
        (-180.0_f64..180.0, -25.0_f64..25.0, prop::array::uniform3(-200.0_f64..200.0), any::<bool>(), 0_u8..8),
    )
        .prop_map(|(shape_part, size_part, placement)| {
            let (inner, shape, r1, r2_ratio, f_ratio) = shape_part;
            let (along_ratio, across_ratio, ball_ratio, width_ratio, tolerance) = size_part;
            let (arrangement, penetration, origin, clockwise, method_pick) = placement;
            let radius = r1 * r2_ratio;
            let (centre_distance, across) = match shape {
                0 => (None, 0.0),
                1 => (Some(CentreDistance::Along(radius * along_ratio * 2.0)), 0.0),
                _ => {
                    let across = r1 * across_ratio * 0.5;
                    (Some(CentreDistance::AcrossAlong([across, radius * along_ratio * 2.0])), across)
                }
            };
            // Keep the hole inside 80 % of the smaller radius so the ridge exists.
            let reach_limit = 0.8 * if inner { r1 } else { r1 * 0.7 };
            let eccentricity = (f_ratio * r1)
                .clamp(-(reach_limit - radius - across / 2.0).max(0.0), (reach_limit - radius - across / 2.0).max(0.0));
            let ball = (radius * ball_ratio).clamp(0.3, 8.0);
            let width = ball * width_ratio;
            let workpiece = if inner {
                Workpiece::tube(origin, arrangement, r1, r1 * 1.5)
            } else {
                Workpiece::tube(origin, arrangement, r1 * 0.7, r1)
            };
            let shape = [HoleShape::Round, HoleShape::Slot, HoleShape::RoundedRect][shape];
            let tool = Tool::new(ToolKind::Ball, ball);
            let request = DeburrRequest {
                tool: ToolRef::Inline(tool.clone()),
                workpiece,
                hole: Some(Hole {
                    shape,
                    radius: Some(radius),
                    diameter: None,
                    centre_distance,
                    eccentricity: Some(eccentricity),
                    penetration_angle_deg: penetration,
                    axis_point: None,
                }),
                holes: None,
                pattern: None,
                edge: if inner { Edge::Inner } else { Edge::Outer },
                inner_tool: None,
                cut_amount: None,
                width: Some(width),
                tolerance: Some(tolerance),
                method: if method_pick == 0 { Method::Exact } else { Method::Tangent },
                start_deg: 0.0,
                direction: if clockwise { Direction::Cw } else { Direction::Ccw },
                feed: None,
                spindle_rpm: None,
                clearance: None,
                lead_distance: None,
                safe_z: None,
                machine: None,
                block_time_ms: None,
                verification: None,
                units: None,
            };
            Case { request, tool, cylinder_radius: r1, width }
        })
}

/// The cylinder axis A1 through the origin with direction (−sin θ_A, cos θ_A, 0) (§1.3).
fn distance_from_axis(case: &Case, p: V) -> f64 {
    let (origin, arrangement) = match &case.request.workpiece {
        Workpiece::Tube { origin, arrangement_angle_deg, .. }
        | Workpiece::BoreBlock { origin, arrangement_angle_deg, .. } => (*origin, arrangement_angle_deg.to_radians()),
    };
    let axis = [-arrangement.sin(), arrangement.cos(), 0.0];
    let relative = sub(p, origin);
    let along = dot(relative, axis);
    norm(sub(relative, [along * axis[0], along * axis[1], along * axis[2]]))
}

const ALLOWED_REFUSALS: [&str; 4] = ["E_FAR_GOUGE", "E_BALL_MISSES_EDGE", "E_EXACT_NO_SOLUTION", "E_TOO_MANY_POINTS"];

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn centres_satisfy_the_construction_and_the_tolerance(case in case()) {
        let result = match deburr::solve(&case.request, &case.tool) {
            Ok(result) => result,
            Err(error) => {
                prop_assert!(ALLOWED_REFUSALS.contains(&error.code().as_str()), "unexpected refusal {}: {}", error.code().as_str(), error.message());
                return Ok(());
            }
        };
        let points = &result.points;
        let ball = case.tool.radius;
        let scale = case.cylinder_radius.max(100.0);
        prop_assert_eq!(points.first().unwrap().centre, points.last().unwrap().centre, "the loop closes");
        prop_assert_eq!(result.summary.count, points.len() - 1);
        let exact = case.request.method == Method::Exact;
        let tolerance = case.request.tolerance.unwrap();

        let at = |segment: &str, s: f64| deburr::construction_at(&case.request, &case.tool, segment, s).unwrap();
        let stride = (points.len() / 16).max(1);
        for point in points.iter().step_by(stride) {
            let c = at(point.segment, point.parameter);
            prop_assert!(norm(sub(c.target, point.target)) < 1e-9);
            prop_assert!((distance_from_axis(&case, c.target) - case.cylinder_radius).abs() < 1e-9 * scale, "P on the cylinder");
            let tip = point.tip;
            prop_assert!((point.centre[2] - tip[2] - ball).abs() < 1e-12);
            if exact {
                // The exact centre stays in the normal plane up to its interpolation between nodes.
                prop_assert!(dot(sub(point.centre, c.target), c.ridge_tangent).abs() < 1e-5 * scale, "C in the normal plane");
                continue;
            }
            let (centre, g1, g2) = (c.centre, c.band_edge_cylinder, c.band_edge_wall);
            prop_assert!(norm(sub(centre, point.centre)) < 1e-9 * scale, "answer centre is the construction's");
            prop_assert!((norm(sub(centre, g1)) - ball).abs() < 1e-9 * scale, "|C - G1| = D");
            prop_assert!((norm(sub(centre, g2)) - ball).abs() < 1e-9 * scale, "|C - G2| = D");
            prop_assert!((norm(sub(g1, g2)) - case.width).abs() < 1e-9 * scale, "|G1 - G2| = W");
            prop_assert!((norm(sub(g1, c.target)) - norm(sub(g2, c.target))).abs() < 1e-9 * scale, "equal legs");
            prop_assert!(dot(sub(centre, c.target), c.ridge_tangent).abs() < 1e-9 * scale, "C in the normal plane");
            prop_assert!(dot(sub(g1, c.target), c.cylinder_normal).abs() < 1e-9 * scale, "G1 on the cylinder tangent");
            prop_assert!(dot(sub(g2, c.target), c.wall_normal).abs() < 1e-9 * scale, "G2 on the wall tangent");
        }

        // Dense check of the tolerance: 63 samples per interval against its chord, on the
        // method's ideal centre path.
        let ordered: Vec<_> = if case.request.direction == Direction::Cw { points.iter().rev().collect() } else { points.iter().collect() };
        let mut places = Vec::new();
        for pair in ordered.windows(2) {
            let (previous, current) = (pair[0], pair[1]);
            let start = if previous.segment == current.segment { previous.parameter } else { 0.0 };
            for j in 1..64 {
                places.push((current.segment, start + f64::from(j) / 64.0 * (current.parameter - start)));
            }
        }
        let ideal = deburr::ideal_centres(&case.request, &case.tool, &places).unwrap();
        let mut worst = 0.0_f64;
        for (pair, ideal) in ordered.windows(2).zip(ideal.chunks(63)) {
            for centre in ideal {
                worst = worst.max(distance_to_segment(*centre, pair[0].centre, pair[1].centre));
            }
        }
        prop_assert!(worst <= tolerance * (1.0 + 1e-6), "deviation {worst} over TA {tolerance}");
        prop_assert!((result.summary.max_deviation - worst).abs() <= 0.02 * tolerance, "summary {} vs dense {worst}", result.summary.max_deviation);
    }
}

fn wild() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e6_f64..1e6,
        -2.0_f64..2.0,
        Just(0.0),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(-f64::INFINITY),
        Just(1e-300),
        Just(1e300),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    /// Any numbers at all: the solver answers or refuses with a code, never panics, never
    /// returns a non-finite number.
    #[test]
    fn wild_numbers_never_panic(values in prop::collection::vec(wild(), 12), pick in 0_u8..6) {
        let tool = Tool::new(ToolKind::Ball, values[0]);
        let workpiece = if pick % 2 == 0 {
            Workpiece::tube([values[1], 0.0, 0.0], values[2], values[3], values[4])
        } else {
            Workpiece::BoreBlock { origin: [0.0, values[1], 0.0], arrangement_angle_deg: values[2], bore_radius: values[4], face_distance: None }
        };
        let (shape, centre_distance) = match pick % 3 {
            0 => (HoleShape::Round, None),
            1 => (HoleShape::Slot, Some(CentreDistance::Along(values[5]))),
            _ => (HoleShape::RoundedRect, Some(CentreDistance::AcrossAlong([values[5], values[6]]))),
        };
        let request = DeburrRequest {
            tool: ToolRef::Inline(tool.clone()),
            workpiece,
            hole: Some(Hole { shape, radius: Some(values[7]), diameter: None, centre_distance, eccentricity: Some(values[8]), penetration_angle_deg: values[9], axis_point: None }),
            holes: None,
            pattern: None,
            edge: if pick < 3 { Edge::Inner } else { Edge::Outer },
            inner_tool: None,
            cut_amount: Some(values[10]),
            width: None,
            tolerance: Some(values[11].abs().max(1e-3)),
            method: if pick == 5 { Method::Exact } else { Method::Tangent },
            start_deg: 0.0,
            direction: Direction::Ccw,
            feed: None,
            spindle_rpm: None,
            clearance: None,
            lead_distance: None,
            safe_z: None,
            machine: None,
            block_time_ms: None,
            verification: None,
            units: None,
        };
        match deburr::solve(&request, &tool) {
            Ok(result) => {
                let json = serde_json::to_string(&result).unwrap();
                prop_assert!(!json.contains("null") || result.points.iter().all(|p| p.centre.iter().all(|v| v.is_finite())));
                for point in &result.points {
                    prop_assert!(point.centre.iter().chain(&point.target).chain(&point.tip).all(|v| v.is_finite()));
                }
                prop_assert!(result.summary.max_deviation.is_finite() && result.summary.path_length.is_finite());
            }
            Err(error) => prop_assert!(error.code().as_str().starts_with("E_"), "{}", error.code().as_str()),
        }
    }
}
