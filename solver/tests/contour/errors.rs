//! Bad contour requests: each refusal has its code and names the field at fault (docs/spec/api.md: a clear
//! error naming the field, never a panic).

use kerf_solver::contour::{self, ContourRequest};
use kerf_solver::tool::{Tool, ToolKind};
use serde_json::{Value, json};

fn base() -> Value {
    json!({
        "tool": {"kind": "flat", "radius": 1.0},
        "contour": [[0, 0], [40, 0], [40, 30], [0, 30]],
        "side": "outside",
        "depths": {"top": 0, "bottom": -6, "step": 2},
        "corner_loop": {"style": "arc"},
        "feed": 800
    })
}

fn with(changes: Value) -> Value {
    let mut body = base();
    for (key, value) in changes.as_object().unwrap() {
        body[key] = value.clone();
    }
    body
}

fn refusal(body: Value) -> (String, Option<String>) {
    let request: ContourRequest = serde_json::from_value(body).unwrap();
    let radius = match &request.tool {
        kerf_solver::tool::ToolRef::Inline(tool) => tool.radius,
        kerf_solver::tool::ToolRef::Number(_) => 1.0,
    };
    let Err(error) = contour::solve(&request, &Tool::new(ToolKind::Flat, radius)) else {
        panic!("accepted");
    };
    assert!(!error.message().is_empty());
    (error.code().as_str().to_owned(), error.field().map(str::to_owned))
}

fn assert_refused(name: &str, body: Value, code: &str, field: &str) {
    let (got_code, got_field) = refusal(body);
    assert_eq!(got_code, code, "{name}");
    assert_eq!(got_field.as_deref(), Some(field), "{name}");
}

#[test]
fn table_of_bad_inputs() {
    let neck = json!([
        [0, 0],
        [40, 0],
        [40, 30],
        [21.5, 30],
        [21.5, 20],
        [30, 20],
        [30, 5],
        [10, 5],
        [10, 20],
        [18.5, 20],
        [18.5, 30],
        [0, 30]
    ]);
    let notch = json!([[0, 0], [30, 0], [30, 20], [17, 20], [17, 10], [14, 10], [14, 20], [0, 20]]);
    let cases = [
        (
            "self-intersecting polygon",
            with(json!({"contour": [[0, 0], [10, 10], [10, 0], [0, 10]]})),
            "E_SELF_INTERSECTION",
            "contour[2]",
        ),
        ("fewer than 3 points", with(json!({"contour": [[0, 0], [10, 0]]})), "E_DEGENERATE", "contour"),
        ("3 points, 2 of them equal", with(json!({"contour": [[0, 0], [10, 0], [10, 0]]})), "E_DEGENERATE", "contour"),
        (
            "duplicate point",
            with(json!({"contour": [[0, 0], [20, 0], [10, 10], [20, 20], [0, 20], [10, 10]]})),
            "E_DUPLICATE_POINT",
            "contour[5]",
        ),
        ("zero area", with(json!({"contour": [[0, 0], [10, 0], [20, 0], [5, 0]]})), "E_DEGENERATE", "contour"),
        (
            "clockwise contour",
            with(json!({"contour": [[0, 0], [0, 30], [40, 30], [40, 0]]})),
            "E_ORIENTATION",
            "contour",
        ),
        (
            "tool too big for a notch",
            with(json!({"contour": notch, "tool": {"kind": "flat", "radius": 2}})),
            "E_OFFSET_COLLAPSE",
            "contour[4]",
        ),
        (
            "tool too big for a neck",
            with(json!({"contour": neck, "tool": {"kind": "flat", "radius": 2}})),
            "E_OFFSET_SELF_INTERSECTION",
            "contour[3]",
        ),
        (
            "tool too big for a pocket",
            with(
                json!({"contour": [[0, 0], [3, 0], [3, 3], [0, 3]], "side": "inside", "tool": {"kind": "flat", "radius": 2}}),
            ),
            "E_OFFSET_COLLAPSE",
            "contour[0]",
        ),
        ("bottom above top", with(json!({"depths": {"top": 0, "bottom": 5, "step": 1}})), "E_INPUT", "depths.bottom"),
        ("zero step", with(json!({"depths": {"top": 0, "bottom": -5, "step": 0}})), "E_INPUT", "depths.step"),
        ("negative step", with(json!({"depths": {"top": 0, "bottom": -5, "step": -1}})), "E_INPUT", "depths.step"),
        (
            "too many layers",
            with(json!({"depths": {"top": 0, "bottom": -100, "step": 0.001}})),
            "E_TOO_MANY_LAYERS",
            "depths.step",
        ),
        ("zero feed", with(json!({"feed": 0})), "E_INPUT", "feed"),
        ("negative loop feed", with(json!({"loop_feed": -5})), "E_INPUT", "loop_feed"),
        ("bad tool radius", with(json!({"tool": {"kind": "flat", "radius": -1}})), "E_INPUT", "tool.radius"),
        (
            "allowances growing inwards",
            with(json!({"passes": [{"allowance": 0.2}, {"allowance": 0.5}]})),
            "E_INPUT",
            "passes[1].allowance",
        ),
        ("no passes", with(json!({"passes": []})), "E_INPUT", "passes"),
        (
            "loop angle of 180°",
            with(json!({"corner_loop": {"style": "arc", "max_angle_deg": 180}})),
            "E_INPUT",
            "corner_loop.max_angle_deg",
        ),
        (
            "min leg above max leg",
            with(json!({"corner_loop": {"style": "triangle", "min_leg": 5, "max_leg": 1}})),
            "E_INPUT",
            "corner_loop.min_leg",
        ),
        (
            "override of a removed point",
            with(
                json!({"contour": [[0, 0], [20, 0], [40, 0], [40, 30], [0, 30]], "corner_overrides": [{"index": 1, "loop": true}]}),
            ),
            "E_INPUT",
            "corner_overrides[0].index",
        ),
        (
            "override out of range",
            with(json!({"corner_overrides": [{"index": 9}]})),
            "E_INPUT",
            "corner_overrides[0].index",
        ),
        ("tilt list of the wrong length", with(json!({"tilt_deg": [1, 2]})), "E_INPUT", "tilt_deg"),
        ("tilt too steep", with(json!({"tilt_deg": [0, 85, 0, 0]})), "E_INPUT", "tilt_deg[1]"),
        ("safe_z below the top", with(json!({"safe_z": -1})), "E_INPUT", "safe_z"),
        ("chord tolerance too fine", with(json!({"tolerance": 1e-9})), "E_INPUT", "tolerance"),
        ("start edge out of range", with(json!({"start_edge": 4})), "E_INPUT", "start_edge"),
        (
            "too many moves",
            with(
                json!({"depths": {"top": 0, "bottom": -100, "step": 0.01}, "corner_loop": {"radius": 50, "max_radius": 100, "max_leg": 100}, "tolerance": 1e-6}),
            ),
            "E_TOO_MANY_MOVES",
            "depths.step",
        ),
        (
            "stock below the first allowance",
            with(json!({"stock_allowance": 0.1, "passes": [{"allowance": 0.5}, {"allowance": 0}]})),
            "E_INPUT",
            "stock_allowance",
        ),
    ];
    for (name, body, code, field) in cases {
        eprintln!("{name}");
        assert_refused(name, body, code, field);
    }
}

#[test]
fn non_finite_numbers_name_their_field() {
    let mut request: ContourRequest = serde_json::from_value(base()).unwrap();
    request.contour[2] = [40.0, f64::NAN];
    let error = contour::solve(&request, &Tool::new(ToolKind::Flat, 1.0)).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("contour[2][1]")));
    let mut request: ContourRequest = serde_json::from_value(base()).unwrap();
    request.depths.top = f64::INFINITY;
    let error = contour::solve(&request, &Tool::new(ToolKind::Flat, 1.0)).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("depths.top")));
}

#[test]
fn too_many_points_are_refused_before_any_work() {
    let count = contour::request::MAX_POINTS + 1;
    let contour: Vec<[f64; 2]> = (0..count)
        .map(|i| {
            let angle = std::f64::consts::TAU * i as f64 / count as f64;
            [angle.cos() * 100.0, angle.sin() * 100.0]
        })
        .collect();
    assert_refused("too many points", with(json!({"contour": contour})), "E_TOO_MANY_POINTS", "contour");
}

#[test]
fn malformed_bodies_fail_to_parse() {
    for body in [
        with(json!({"unknown": 1})),
        with(json!({"side": "left"})),
        with(json!({"corner_loop": {"style": "spiral"}})),
        with(json!({"inside_corner_relief": "saw"})),
        with(json!({"depths": {"top": 0, "bottom": -1}})),
    ] {
        assert!(serde_json::from_value::<ContourRequest>(body).is_err());
    }
}

/// A pocket whose first pass (allowance 0.2, round joins) comes too near an edge between its
/// corners: refused by the global clearance check of the cuts against the edges near them, the
/// same distance and edge as when every nearby edge's exact distance was measured.
#[test]
fn a_cut_too_near_another_edge_is_found_by_the_clearance_check() {
    let request: ContourRequest = serde_json::from_value(json!({
        "block_time_ms": 2.3565128841951193,
        "contour": [[-7.184573213903681, 6.156619420489011], [-3.3481220819619044, 1.1157147824317797],
            [-3.465881213158125, -1.1161552770525018], [-2.3196213609975116, -2.8765021366723724],
            [-1.096309154864816, -2.1284283902725956], [0.8783137984975954, -9.259809547495236],
            [4.67369423262394, -5.179057371577678], [8.722046338593803, -2.7355083943464216],
            [4.944435817524319, 1.319884422071827], [1.8170280927709404, 2.783238814402929],
            [0.3107937018648377, 3.6785623666229292], [-0.20021936935860704, 5.463578280906071],
            [-0.33856266236322713, 4.185829235949789], [-1.7870167398077712, 8.574957898185115]],
        "corner_loop": {"max_angle_deg": 118.55027800319954, "style": "triangle"},
        "depths": {"bottom": -4.176015467076267, "step": 1.1160465154640435, "top": 0.0},
        "direction": "conventional", "feed": 600, "loop_feed": 2000,
        "passes": [{"allowance": 0.2, "join": "round"}, {"allowance": 0.0}],
        "ramp_angle_deg": 9.470834850335324, "side": "inside", "tolerance": 0.005,
        "tool": {"centre_cutting": false, "kind": "flat", "radius": 0.26719959095108076}
    }))
    .unwrap();
    let tool = Tool { centre_cutting: Some(false), ..Tool::new(ToolKind::Flat, 0.26719959095108076) };
    let error = contour::solve(&request, &tool).unwrap_err();
    assert_eq!(error.code().as_str(), "E_OFFSET_SELF_INTERSECTION");
    assert_eq!(error.field(), Some("contour[10]"));
    assert_eq!(
        error.message(),
        "the tool (radius 0.267199590951 mm + allowance 0.2 mm) does not fit: near (-0.1732 mm, 3.7487 mm) the path \
         comes within 0.446032 mm of the edge from contour[10] (a neck narrower than twice that)"
    );
}
