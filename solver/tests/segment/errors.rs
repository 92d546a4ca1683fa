//! Every error code of the segment solver with the field it names (docs/spec/segment.md §4: E3, E6, E16 and
//! the curve checks), machine defaults and overrides, warnings of the edge-case table (E1, E4,
//! E5, E8–E10, E12, E13) and the G-code program in both dialects.

use kerf_solver::gcode::{Dialect, Post, ToolCall};
use kerf_solver::machine::MachineProfile;
use kerf_solver::segment::{self, CommandPoint, SegmentRequest, SegmentSolution, WindowStatus};
use serde_json::{Value, json};

fn parse(request: Value) -> SegmentRequest {
    serde_json::from_value(request).unwrap()
}

fn circle() -> Value {
    json!({"kind": "circle", "centre": [0, 0], "radius": 50})
}

fn with(mut base: Value, field: &str, value: Value) -> Value {
    base[field] = value;
    base
}

fn base() -> Value {
    json!({"curve": circle(), "feed": 10000, "block_time_ms": 4})
}

fn error(request: Value) -> (String, Option<String>, String) {
    let error = segment::solve(&parse(request), None).unwrap_err();
    (error.code().as_str().to_owned(), error.field().map(str::to_owned), error.message().to_owned())
}

fn ok(request: Value) -> SegmentSolution {
    segment::solve(&parse(request), None).unwrap()
}

/// The command points as their coordinate lists, `[x, y]` or `[x, y, z]`.
fn coordinates(answer: &SegmentSolution) -> Vec<&[f64]> {
    answer.points.iter().map(CommandPoint::as_slice).collect()
}

fn codes(answer: &SegmentSolution) -> Vec<&'static str> {
    answer.warnings.iter().map(|w| w.code).collect()
}

#[test]
fn bad_numbers_name_their_field() {
    let cases = [
        (with(base(), "feed", json!(0)), "feed"),
        (with(base(), "feed", json!(-100)), "feed"),
        (with(base(), "block_time_ms", json!(0)), "block_time_ms"),
        (with(base(), "block_time_ms", json!(-4)), "block_time_ms"),
        (with(base(), "margin", json!(0.9)), "margin"),
        (with(base(), "chord_error_factor", json!(0.95)), "chord_error_factor"),
        (with(base(), "block_time_factor", json!(0.5)), "block_time_factor"),
        (with(base(), "radius_factor", json!(1.2)), "radius_factor"),
        (with(base(), "radius_factor", json!(0)), "radius_factor"),
        (with(base(), "min_chord_error", json!(-0.001)), "min_chord_error"),
        (with(base(), "tolerance", json!(1e-9)), "tolerance"),
        (with(base(), "compare_tolerance", json!(0)), "compare_tolerance"),
        (with(base(), "window", json!(0)), "window"),
        (with(base(), "spindle_rpm", json!(0)), "spindle_rpm"),
        (with(base(), "rule", json!("max")), "rule"),
        (with(base(), "min_radius", json!(25)), "min_radius"),
        (with(with(base(), "mode", json!("curve")), "window", json!(5)), "window"),
        (with(with(base(), "mode", json!("curve")), "radius_estimate", json!("minimum")), "radius_estimate"),
        (with(with(base(), "mode", json!("curve")), "min_radius", json!(-1)), "min_radius"),
        (with(base(), "safe_z", json!(-1)), "safe_z"),
        (json!({"curve": circle(), "block_time_ms": 4}), "feed"),
        (json!({"curve": circle(), "feed": 10000}), "block_time_ms"),
    ];
    for (request, field) in cases {
        let (code, at, message) = error(request);
        assert_eq!(code, "E_INPUT", "{field}: {message}");
        assert_eq!(at.as_deref(), Some(field), "{message}");
    }
}

#[test]
fn nan_is_refused_not_propagated() {
    let mut request = parse(base());
    request.feed = Some(f64::NAN);
    assert_eq!(segment::solve(&request, None).unwrap_err().field(), Some("feed"));
    let mut request = parse(base());
    request.curve = segment::Curve::Circle {
        centre: vec![0.0, f64::NAN],
        radius: 50.0,
        start_deg: 0.0,
        direction: segment::Direction::Ccw,
    };
    assert_eq!(segment::solve(&request, None).unwrap_err().field(), Some("curve.centre[1]"));
    let mut request = parse(base());
    request.margin = Some(f64::INFINITY);
    assert_eq!(segment::solve(&request, None).unwrap_err().field(), Some("margin"));
}

#[test]
fn unsafe_margins_need_an_explicit_override() {
    let answer = ok(with(with(base(), "margin", json!(0.9)), "allow_unsafe_margin", json!(true)));
    assert!(codes(&answer).contains(&"W_UNSAFE_MARGIN"));
    // Below the surface every block is shorter than F·T_b.
    assert!(answer.stats.short_blocks > 0);
    assert!(codes(&answer).contains(&"W_BLOCK_TIME_VIOLATION"));
}

#[test]
fn curves_are_checked_with_field_paths() {
    let cases = [
        (json!({"kind": "circle", "centre": [0, 0], "radius": 0}), "E_INPUT", "curve.radius"),
        (json!({"kind": "circle", "centre": [0, 0, 0, 0], "radius": 5}), "E_INPUT", "curve.centre"),
        (json!({"kind": "circle", "centre": [0], "radius": 5}), "E_INPUT", "curve.centre"),
        (json!({"kind": "circle", "centre": [2e6, 0], "radius": 5}), "E_INPUT", "curve.centre[0]"),
        (
            json!({"kind": "arc", "centre": [0, 0], "radius": 5, "start_deg": 30, "end_deg": 30}),
            "E_DEGENERATE_CURVE",
            "curve.end_deg",
        ),
        (json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [10, -1]}), "E_INPUT", "curve.semi_axes[1]"),
        // Found by fuzzing over HTTP: at 2⁶³ degrees the quarter-turn search could not advance.
        (
            json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 50], "start_deg": 9.223372036854776e18,
                   "end_deg": 90}),
            "E_INPUT",
            "curve.start_deg",
        ),
        (
            json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 50], "rotation_deg": -2e6}),
            "E_INPUT",
            "curve.rotation_deg",
        ),
        (
            json!({"kind": "arc", "centre": [0, 0], "radius": 5, "start_deg": 0, "end_deg": 1e7}),
            "E_INPUT",
            "curve.end_deg",
        ),
        (json!({"kind": "polyline", "points": [[0, 0], [1, 1, 1]]}), "E_INPUT", "curve.points[1]"),
        (json!({"kind": "polyline", "points": [[0, 0, 0, 1], [1, 1, 1, 1]]}), "E_INPUT", "curve.points[0]"),
        (json!({"kind": "polyline", "points": [[1, 1], [1, 1], [1, 1]]}), "E_DEGENERATE_CURVE", "curve.points"),
        (json!({"kind": "polyline", "points": [[1, 1]]}), "E_DEGENERATE_CURVE", "curve.points"),
        (
            json!({"kind": "polyline", "points": [[0, 0], [10, 0]], "corner_angle_deg": 180}),
            "E_INPUT",
            "curve.corner_angle_deg",
        ),
        (
            json!({"kind": "bspline", "degree": 3, "control_points": [[0, 0], [1, 1], [2, 0]]}),
            "E_INPUT",
            "curve.control_points",
        ),
        (json!({"kind": "bspline", "degree": 0, "control_points": [[0, 0], [1, 1]]}), "E_INPUT", "curve.degree"),
        (json!({"kind": "bspline", "degree": 6, "control_points": [[0, 0], [1, 1]]}), "E_INPUT", "curve.degree"),
        (
            json!({"kind": "bspline", "degree": 2, "control_points": [[0, 0], [5, 5], [10, 0]],
                   "knots": [0, 0, 0, 1, 1]}),
            "E_INPUT",
            "curve.knots",
        ),
        (
            json!({"kind": "bspline", "degree": 2, "control_points": [[0, 0], [5, 5], [10, 0], [15, 5]],
                   "knots": [0, 0, 0, 0.7, 0.4, 1, 1]}),
            "E_INPUT",
            "curve.knots[4]",
        ),
        (
            json!({"kind": "bspline", "degree": 2, "control_points": [[0, 0], [5, 5], [10, 0], [15, 5]],
                   "knots": [0, 0, 0.2, 0.5, 1, 1, 1]}),
            "E_INPUT",
            "curve.knots[2]",
        ),
        (
            json!({"kind": "bspline", "degree": 2, "control_points": [[0, 0], [5, 5], [10, 0]],
                   "weights": [1, -1, 1]}),
            "E_INPUT",
            "curve.weights[1]",
        ),
        (
            json!({"kind": "bspline", "degree": 2, "control_points": [[0, 0], [5, 5], [10, 0]],
                   "weights": [1, 1]}),
            "E_INPUT",
            "curve.weights",
        ),
        (
            json!({"kind": "bspline", "degree": 2, "control_points": [[3, 3], [3, 3], [3, 3]]}),
            "E_DEGENERATE_CURVE",
            "curve.control_points",
        ),
    ];
    for (curve, code, field) in cases {
        let (got, at, message) = error(with(base(), "curve", curve.clone()));
        assert_eq!(got, code, "{curve}: {message}");
        assert_eq!(at.as_deref(), Some(field), "{curve}: {message}");
    }
}

#[test]
fn unknown_fields_and_kinds_are_refused_by_serde() {
    for request in [
        with(base(), "speed", json!(1)),
        with(base(), "curve", json!({"kind": "spiral", "radius": 3})),
        with(base(), "curve", json!({"kind": "circle", "centre": [0, 0], "radius": 5, "r": 1})),
        with(base(), "mode", json!("global")),
    ] {
        assert!(serde_json::from_value::<SegmentRequest>(request).is_err());
    }
}

#[test]
fn infeasible_feed_gives_the_largest_feasible_feed() {
    // E3: r = 0.3 mm at 10 000 mm/min and 4 ms needs a 0.667 mm chord: at most 9000 mm/min.
    let small = json!({"kind": "circle", "centre": [0, 0], "radius": 0.3});
    for mode in ["window", "curve"] {
        let (code, field, message) = error(with(with(base(), "curve", small.clone()), "mode", json!(mode)));
        assert_eq!(code, "E_INFEASIBLE_FEED_FOR_RADIUS");
        assert_eq!(field.as_deref(), Some("feed"));
        assert!(message.contains("largest feasible feed is 9000 mm/min"), "{message}");
    }
    // At the feed it names, the same curve is cut.
    let answer = ok(with(with(base(), "curve", small.clone()), "feed", json!(9000)));
    assert_eq!(answer.feed_limit, Some(9000.0));
    // An ellipse: the limit comes from its smallest radius b²/a = 0.25 mm, even when the window
    // that failed saw a larger one.
    // An ellipse with radii from 0.25 to 16 mm: its 3-point windows (3.3 mm) see radii of 4 mm
    // at its sharp ends, but are held within 1.1 times the smallest radius in the window, so the
    // infeasibility is found with both estimates; the limit comes from b²/a = 0.25 mm.
    let ellipse = json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [4, 1]});
    for estimate in ["three_point", "minimum"] {
        let request = with(with(base(), "curve", ellipse.clone()), "radius_estimate", json!(estimate));
        let (code, _, message) = error(request.clone());
        assert_eq!(code, "E_INFEASIBLE_FEED_FOR_RADIUS");
        assert!(message.contains("largest feasible feed is 7500 mm/min"), "{message}");
        let answer = ok(with(request, "feed", json!(7500)));
        if estimate == "minimum" {
            assert_eq!(answer.stats.short_blocks, 0);
        } else {
            assert!(codes(&answer).contains(&"W_CURVATURE_ESTIMATE_UNRELIABLE"));
        }
    }
    // r_min read off the drawing: the error names that field.
    let (code, field, _) =
        error(with(with(with(base(), "mode", json!("curve")), "rule", json!("extremes")), "min_radius", json!(0.2)));
    assert_eq!(code, "E_INFEASIBLE_FEED_FOR_RADIUS");
    assert_eq!(field.as_deref(), Some("min_radius"));
}

#[test]
fn too_many_windows_are_refused_before_the_work() {
    let (code, field, _) =
        error(with(with(with(base(), "mode", json!("curve")), "rule", json!("max")), "window", json!(1e-5)));
    assert_eq!(code, "E_TOO_MANY_BLOCKS");
    assert_eq!(field.as_deref(), Some("window"));
}

#[test]
fn machine_values_are_defaults_the_request_overrides() {
    let machine = MachineProfile {
        arcs: None,
        plunge_feed: None,
        max_accel: None,
        max_jerk: None,
        rapid_feed: None,
        tool_change_s: None,
        haas_smoothing: None,
        name: None,
        block_time_ms: 4.0,
        max_feed: 10_000.0,
        dialect: Dialect::Linuxcnc,
        margin: Some(1.1),
        min_chord_error: Some(0.001),
        description: None,
        mode: None,
        spindle_power_kw: None,
        spindle_torque_nm: None,
        max_spindle_rpm: None,
        spindle_power_curve: None,
        units: None,
    };
    let request = parse(json!({"curve": circle(), "machine": "hsc"}));
    let answer = segment::solve(&request, Some(&machine)).unwrap();
    assert_eq!((answer.feed, answer.block_time_ms, answer.margin, answer.min_chord_error), (10_000.0, 4.0, 1.1, 0.001));
    // k_f = 1.1 at r = 50: 0.0013445 mm, above the clamp.
    assert!((answer.chord_error - 0.001_344_5).abs() < 1e-6);
    let overridden = parse(json!({
        "curve": circle(), "machine": "hsc", "feed": 12000, "margin": 1.0, "min_chord_error": 0.002
    }));
    let answer = segment::solve(&overridden, Some(&machine)).unwrap();
    // The machine caps the request's feed (it never raises one).
    assert_eq!((answer.feed, answer.margin, answer.min_chord_error), (10_000.0, 1.0, 0.002));
    assert_eq!(answer.windows[0].status, WindowStatus::ClampedToMinChordError);
    assert!(codes(&answer).contains(&"W_FEED_ABOVE_MACHINE_MAX"));
    assert!(codes(&answer).contains(&"I_CLAMPED_TO_CEMIN"));
    // A corrupt stored profile is reported, not used.
    let broken = MachineProfile { block_time_ms: -1.0, ..machine };
    let error = segment::solve(&request, Some(&broken)).unwrap_err();
    assert_eq!(error.field(), Some("machine"));
}

#[test]
fn tolerance_never_coarser_with_feed_advice() {
    // E4: C_tol = 0.0005 at r = 50 mm: the rule wants 0.00111; 6708 mm/min would meet both.
    let answer = ok(with(base(), "tolerance", json!(0.0005)));
    assert!((answer.chord_error - 0.0005).abs() < 1e-15);
    assert!(answer.max_deviation <= 0.0005 + 2e-12);
    assert!(answer.windows.iter().all(|w| w.status == WindowStatus::LimitedByTolerance));
    assert_eq!(answer.tolerance_feed.map(f64::floor), Some(6708.0));
    // A tolerance above the rule's chord error changes nothing.
    let loose = ok(with(base(), "tolerance", json!(0.01)));
    assert_eq!(loose.points, ok(base()).points);
    assert!(!codes(&loose).contains(&"W_CHORD_ERROR_EXCEEDS_TOLERANCE"));
}

#[test]
fn straight_lines_are_one_block() {
    // E1: r = ∞, C_ep = 0: the chord runs to the end of the straight.
    let line = json!({"kind": "polyline", "points": [[0, 0, 0], [10, 0, 0], [20, 0, 0], [30, 0, 0]]});
    let answer = ok(with(base(), "curve", line.clone()));
    assert_eq!(answer.stats.blocks, 1);
    assert_eq!(answer.windows.iter().map(|w| w.status).collect::<Vec<_>>()[0], WindowStatus::Straight);
    assert!(codes(&answer).contains(&"I_STRAIGHT"));
    assert_eq!(coordinates(&answer), [[0.0, 0.0, 0.0], [30.0, 0.0, 0.0]]);
    // E12: a curve shorter than one block time.
    let short = json!({"kind": "polyline", "points": [[0, 0], [0.5, 0]]});
    let answer = ok(with(base(), "curve", short));
    assert_eq!(answer.stats.blocks, 1);
    assert_eq!(codes(&answer), ["I_STRAIGHT", "W_BLOCK_TIME_VIOLATION"]);
}

#[test]
fn corners_split_the_path_and_are_always_points() {
    // An L of two dense straights and a dense quarter circle: the corners are command points.
    let mut points = vec![[0.0, 0.0]];
    for k in 1..=100 {
        points.push([0.2 * f64::from(k), 0.0]);
    }
    for k in 1..=100 {
        points.push([20.0, 0.2 * f64::from(k)]);
    }
    let answer = ok(with(base(), "curve", json!({"kind": "polyline", "points": points})));
    assert_eq!(coordinates(&answer), [[0.0, 0.0], [20.0, 0.0], [20.0, 20.0]]);
    // A spline with a double knot (degree 2: C0) turning 90° is split there too.
    let spline = json!({"kind": "bspline", "degree": 2,
        "control_points": [[0, 0], [10, 0], [20, 0], [20, 10], [20, 20]],
        "knots": [0, 0, 0, 0.5, 0.5, 1, 1, 1]});
    let answer = ok(with(base(), "curve", spline));
    assert!(answer.points.iter().any(|p| (p[0] - 20.0).abs() < 1e-9 && p[1].abs() < 1e-9));
}

#[test]
fn unreliable_windows_and_resolution_are_reported() {
    // E10: a long window on an ellipse with a sharp end: the 3-point radius overshoots.
    let ellipse = json!({"kind": "ellipse", "centre": [0, 0], "semi_axes": [100, 10],
                         "start_deg": -60, "end_deg": 60});
    let answer = ok(with(with(base(), "curve", ellipse.clone()), "window", json!(20)));
    assert!(codes(&answer).contains(&"W_CURVATURE_ESTIMATE_UNRELIABLE"));
    // The conservative estimate keeps every block long enough there.
    let safe = ok(with(with(with(base(), "curve", ellipse), "window", json!(20)), "radius_estimate", json!("minimum")));
    assert_eq!(safe.stats.short_blocks, 0);
    assert!(!codes(&safe).contains(&"W_CURVATURE_ESTIMATE_UNRELIABLE"));
    // E13: chord errors below 5 increments of the 4-decimal G-code.
    let slow = ok(with(base(), "feed", json!(3000)));
    assert!(codes(&slow).contains(&"W_RESOLUTION_LIMITED"));
}

#[test]
fn the_answer_serialises_with_the_api_names() {
    let answer = ok(with(base(), "compare_tolerance", json!(0.01)));
    let value = serde_json::to_value(&answer).unwrap();
    for field in [
        "chord_error",
        "windows",
        "points",
        "blocks",
        "min_block_length",
        "short_blocks",
        "max_deviation",
        "estimated_time_s",
        "comparison",
        "warnings",
        "block_length",
    ] {
        assert!(value.get(field).is_some(), "{field}");
    }
    assert_eq!(value["comparison"]["blocks"], 158);
    assert_eq!(value["windows"][0]["status"], "ok");
    assert!(value["windows"][0]["radius"].as_f64().is_some());
}

#[test]
fn programs_in_both_dialects() {
    let helix: Vec<[f64; 3]> = (0..=400)
        .map(|k| {
            let t = f64::from(k) * 0.01;
            [20.0 * t.cos(), 20.0 * t.sin(), -1.0 - 0.5 * t]
        })
        .collect();
    let answer = ok(json!({
        "curve": {"kind": "polyline", "points": helix}, "feed": 2000, "block_time_ms": 2,
        "spindle_rpm": 8000
    }));
    let fanuc = segment::program(
        &answer,
        &Post {
            reference: kerf_solver::gcode::Reference::Tip,
            dialect: Dialect::Fanuc,
            tool: ToolCall::Table(3),
            arcs: kerf_solver::gcode::Arcs::Chords,
            plunge_feed: None,
            units: kerf_solver::units::Units::Mm,
        },
    )
    .unwrap();
    assert!(fanuc.starts_with("%\nO1001 (KERF SEGMENT)\n"));
    // Clearance 5 mm above the highest point (the start, z = -1); the plunge at half the feed.
    assert!(fanuc.contains(
        "T3 M06\nG00 G43 H3 Z4.0000\nS8000 M03\nG00 X20.0000 Y0.0000 Z4.0000\nG01 X20.0000 Y0.0000 Z-1.0000 F1000\n"
    ));
    let slow = segment::program(
        &answer,
        &Post {
            reference: kerf_solver::gcode::Reference::Tip,
            dialect: Dialect::Fanuc,
            tool: ToolCall::Table(3),
            arcs: kerf_solver::gcode::Arcs::Chords,
            plunge_feed: Some(120.0),
            units: kerf_solver::units::Units::Mm,
        },
    )
    .unwrap();
    assert!(slow.contains("G01 X20.0000 Y0.0000 Z-1.0000 F120\nG01 "), "the plunge feed given");
    assert!(fanuc.ends_with("M05\nG00 Z4.0000\nM30\n%\n"));
    let g01 = fanuc.lines().filter(|l| l.starts_with("G01")).count();
    assert_eq!(g01, answer.stats.blocks + 1);
    let linuxcnc = segment::program(
        &answer,
        &Post {
            reference: kerf_solver::gcode::Reference::Tip,
            dialect: Dialect::Linuxcnc,
            tool: ToolCall::Manual("as set up".to_owned()),
            arcs: kerf_solver::gcode::Arcs::Chords,
            plunge_feed: None,
            units: kerf_solver::units::Units::Mm,
        },
    )
    .unwrap();
    assert!(linuxcnc.starts_with("(KERF SEGMENT)\n"));
    assert!(linuxcnc.contains("G64 P"));
    assert!(linuxcnc.contains("M00\n"));
    assert!(!linuxcnc.contains('%'));
}

#[test]
fn cusps_of_coincident_control_points_are_corners() {
    // Three coincident control points of a cubic: the curve stops and turns 90° there.
    let spline = json!({"kind": "bspline", "degree": 3,
        "control_points": [[0, 0], [10, 0], [20, 10], [20, 10], [20, 10], [30, 0], [40, 0]]});
    let answer =
        ok(with(with(with(base(), "curve", spline), "feed", json!(5000)), "radius_estimate", json!("minimum")));
    let cusp = answer.points.iter().position(|p| (p[0] - 20.0).abs() < 1e-9 && (p[1] - 10.0).abs() < 1e-9);
    assert!(cusp.is_some(), "the cusp is a command point");
    assert_eq!(answer.stats.short_blocks, 0);
}

#[test]
fn slight_kinks_of_a_degree_one_nurbs_end_chords_exactly() {
    // A rational polyline whose kinks turn by less than the corner angle, straight between, with
    // no lower bound on the chord error: the straight pieces give a chord error of 0, so a chord
    // can only end at a kink. The search used to stop a rounding's width short of one and fail
    // there (E14); found by the property tests.
    let control = json!([
        [0.0, 0.0],
        [-1.1704469260882564, 9.543362084870154],
        [11.375169350133055, -1.274923222184214],
        [19.553489805329008, -14.496098002475502],
        [7.497014611099476, -0.7475753822931459],
        [-5.7316412841657405, 7.611826625788984]
    ]);
    let weights = json!([0.3, 0.3, 2.9013787588892597, 2.2104877404508745, 0.4671387817575172, 0.9563530493516416]);
    for mode in ["window", "curve", "guarantee"] {
        let answer = ok(json!({
            "curve": {"kind": "bspline", "degree": 1, "control_points": control, "weights": weights},
            "feed": 1000, "block_time_ms": 1, "mode": mode, "min_chord_error": 0
        }));
        assert_eq!(answer.points.len(), 6, "{mode}: one block per straight piece");
        for (point, expected) in answer.points.iter().zip(control.as_array().unwrap()) {
            for axis in 0..2 {
                assert!((point[axis] - expected[axis].as_f64().unwrap()).abs() < 1e-9, "{mode}: {point:?}");
            }
        }
    }
}

#[test]
fn a_sparse_polyline_is_warned_about_unless_its_long_edges_meet_at_corners() {
    // A circle of radius 50 through points 5 mm apart: far sparser than a quarter of the 0.7 mm
    // chord the rule aims at.
    let on_circle = |step: f64, count: u32| -> Vec<[f64; 2]> {
        (0..=count).map(|k| f64::from(k) * step).map(|angle| [50.0 * angle.cos(), 50.0 * angle.sin()]).collect()
    };
    let sparse = on_circle(0.1, 62);
    let request = json!({"curve": {"kind": "polyline", "points": sparse}, "feed": 10000, "block_time_ms": 4});
    assert!(codes(&ok(request)).contains(&"W_SPARSE_POLYLINE"));
    // The same density on a polyline whose only bends are corners (a square): nothing to warn of.
    let square = json!([[0, 0], [40, 0], [40, 40], [0, 40], [0, 0]]);
    let request = json!({"curve": {"kind": "polyline", "points": square}, "feed": 10000, "block_time_ms": 4});
    assert!(!codes(&ok(request)).contains(&"W_SPARSE_POLYLINE"));
    // Dense points, 0.05 mm apart on the same circle: none.
    let dense = on_circle(0.001, 6000);
    let request = json!({"curve": {"kind": "polyline", "points": dense}, "feed": 10000, "block_time_ms": 4});
    assert!(!codes(&ok(request)).contains(&"W_SPARSE_POLYLINE"));
}
