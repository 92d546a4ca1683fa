//! Ball and bull-nose ends with the engagement of every height (docs/spec/engagement.md §11 item 5):
//! each height band of the end takes the engaged arcs of its own section (radius
//! r(z)) against the stock its height has left, and the forces are summed over the bands. A flat
//! end is unchanged; a full slot deeper than the ball matches an independent quadrature over z;
//! beside a wall the ball's small sections near the tip do not reach it, so the torque falls
//! below the full-radius figure, and it never exceeds it where the stock's edges lie outside the
//! tool centre; at a slot's exit it does (the tip's sections still cut wide horns). Also a_p
//! from the stock's top and the path's Z (`stock_top_z`, `cut_z`, a G-code path's Z).

use std::f64::consts::{PI, TAU};

use kerf_solver::engagement::{self, EngagementRequest, EngagementSample, EngagementSolution, PathEngagement, Physics};
use kerf_solver::error::SolverError;
use kerf_solver::gcode::{Dialect, Post, Reference, ToolCall};
use kerf_solver::machine::SpindleLimits;
use kerf_solver::tool::{Tool, ToolKind};
use proptest::prelude::*;
use serde_json::{Value, json};

const RADIUS: f64 = 5.0;
const KC11: f64 = 1800.0;
const FZ: f64 = 0.05;

/// Flat-end requests whose answers were recorded on main before the height bands.
fn flat_scenarios() -> Vec<(&'static str, Tool, Value, Physics)> {
    let mut helical = Tool::new(ToolKind::Flat, 5.0);
    helical.flutes = 4;
    helical.helix_deg = Some(30.0);
    let mut straight = Tool::new(ToolKind::Flat, 5.0);
    straight.flutes = 3;
    let limits = Physics {
        material: None,
        spindle: SpindleLimits { spindle_power_kw: Some(0.8), spindle_torque_nm: Some(3.0) },
    };
    vec![
        (
            "corner, helix, cw",
            helical.clone(),
            json!({
                "tool": 1, "stock": {"polygon": [[0, -20], [50, -20], [50, 20], [0, 20]]},
                "path": [[-10, 17], [30, 17], [30, -30]], "spindle_rpm": 4000, "feed_per_tooth": 0.06,
                "flute_counts": [2, 3, 4], "step": 0.2, "axial_depth": 3,
                "kienzle": {"kc11": 2100, "mc": 0.23, "radial_ratio": 0.35},
            }),
            Physics::default(),
        ),
        (
            "arc path, arc feed, ccw",
            straight.clone(),
            json!({
                "tool": 1, "stock": {"polygon": [[-30, -30], [30, -30], [30, 30], [-30, 30]], "holes": [[[-12, -12], [12, -12], [12, 12], [-12, 12]]]},
                "path": {"start": [0, -14], "segments": [{"type": "arc", "to": [14, 0], "center": [0, 0], "dir": "ccw"}, {"type": "line", "to": [14, 20]}]},
                "spindle_rpm": 6000, "feed": 900, "flute_counts": [1, 3, 5], "step": 0.1, "axial_depth": 1.5,
                "spindle_direction": "ccw", "arc_feed_correction": true,
                "kienzle": {"kc11": 800, "mc": 0.3},
            }),
            Physics::default(),
        ),
        (
            "feed plan under limits",
            helical,
            json!({
                "tool": 1, "stock": {"polygon": [[0, -20], [50, -20], [50, 20], [0, 20]]},
                "path": [[-10, 0], [45, 0]], "spindle_rpm": 2000, "feed_per_tooth": 0.08,
                "flute_counts": [4], "step": 0.25, "axial_depth": 4,
                "kienzle": {"kc11": 1800, "mc": 0.25},
                "feed_plan": {"target_thickness": 0.1, "max_feed": 5000, "flute_count": 4},
            }),
            limits,
        ),
    ]
}

/// The force figures of an answer, in a fixed order.
fn fingerprint(result: &PathEngagement) -> Vec<f64> {
    let mut numbers = Vec::new();
    for flute in &result.flutes {
        numbers.extend([
            flute.mean_torque_nm.unwrap(),
            flute.peak_torque_nm.unwrap(),
            flute.mean_power_kw.unwrap(),
            flute.peak_power_kw.unwrap(),
            flute.peak_force_n.unwrap(),
        ]);
    }
    let sum = |f: &dyn Fn(&kerf_solver::engagement::EngagementSample) -> f64| result.samples.iter().map(f).sum::<f64>();
    numbers.push(sum(&|s| s.torque_nm.iter().sum()));
    numbers.push(sum(&|s| s.peak_torque_nm.iter().sum()));
    numbers.push(sum(&|s| s.peak_force_n.iter().sum()));
    numbers.push(sum(&|s| s.power_kw.iter().map(|p| p * s.s).sum()));
    if let Some(plan) = &result.feed_plan {
        numbers.push(plan.time_s);
        numbers.push(plan.blocks.len() as f64);
    }
    numbers
}

fn solve_with(body: Value, tool: &Tool, physics: &Physics) -> Result<EngagementSolution, SolverError> {
    let request: EngagementRequest = serde_json::from_value(body).unwrap();
    engagement::solve_in(&request, tool, None, physics, kerf_solver::capability::Control::default())
}

fn solve_body(body: Value, tool: &Tool) -> Result<PathEngagement, SolverError> {
    solve_with(body, tool, &Physics::default()).map(|answer| match answer {
        EngagementSolution::Single(result) => *result,
        EngagementSolution::Comparison(_) => panic!("single path expected"),
    })
}

fn end(kind: ToolKind, corner: Option<f64>, helix: Option<f64>) -> Tool {
    let mut tool = Tool::new(kind, RADIUS);
    tool.flutes = 4;
    tool.corner_radius = corner;
    tool.helix_deg = helix;
    tool
}

fn close_rel(what: &str, got: f64, expected: f64, relative: f64) {
    assert!((got - expected).abs() <= relative * expected.abs(), "{what}: got {got}, expected {expected}");
}

/// Radius of the end's section at height z above the tip, and sin κ there (corner radius r_c, R
/// for a ball).
fn section(corner: f64, z: f64) -> (f64, f64) {
    if z < corner {
        let s = (corner * corner - (corner - z) * (corner - z)).max(0.0).sqrt() / corner;
        (RADIUS - corner + corner * s, s)
    } else {
        (RADIUS, 1.0)
    }
}

/// ∫₀^a_p w(z)·r(z)·sin^(−m_c)κ(z) dz directly in z after z = a_p·u² (the integrand has a
/// z^(−m_c/2) singularity at a ball's tip): independent of the solver's κ substitution, tables
/// and bands.
fn over_height(corner: f64, depth: f64, mc: f64, w: impl Fn(f64, f64) -> f64) -> f64 {
    let n = 200_000;
    (0..n)
        .map(|i| {
            let u = (f64::from(i) + 0.5) / f64::from(n);
            let z = depth * u * u;
            let (r, sin_kappa) = section(corner, z);
            w(z, r) * r * sin_kappa.powf(-mc) * 2.0 * depth * u / f64::from(n)
        })
        .sum()
}

/// ∫₀^φ sin^a by the midpoint rule, for a table of φ.
struct Inner {
    step: f64,
    cumulative: Vec<f64>,
}

impl Inner {
    fn new(a: f64) -> Self {
        let n = 100_000;
        let step = PI / f64::from(n);
        let mut cumulative = vec![0.0];
        let mut total = 0.0;
        for i in 0..n {
            total += ((f64::from(i) + 0.5) * step).sin().powf(a) * step;
            cumulative.push(total);
        }
        Self { step, cumulative }
    }

    fn up_to(&self, phi: f64) -> f64 {
        let position = (phi / self.step).clamp(0.0, (self.cumulative.len() - 1) as f64);
        let index = (position.floor() as usize).min(self.cumulative.len() - 2);
        let t = position - index as f64;
        self.cumulative[index] * (1.0 - t) + self.cumulative[index + 1] * t
    }
}

/// The block [0, 50] × [−20, 20].
fn block() -> Value {
    json!({"polygon": [[0, -20], [50, -20], [50, 20], [0, 20]]})
}

fn request(path: Value, depth: f64, mc: f64, flutes: &[u32]) -> Value {
    json!({
        "tool": 1, "stock": block(), "path": path, "spindle_rpm": 3000, "feed_per_tooth": FZ,
        "flute_counts": flutes, "step": 0.25, "axial_depth": depth, "kienzle": {"kc11": KC11, "mc": mc},
    })
}

#[test]
fn a_flat_end_gives_what_it_gave_before() {
    // The numbers of main before the height bands (same scenarios, same fingerprint), to 1e-12.
    let before: [&[f64]; 3] = [
        &[
            2.0479992064843997e0,
            3.5959407984428986e0,
            8.578639015532155e-1,
            1.5062641593509365e0,
            7.581738205409596e2,
            3.0719988097265847e0,
            4.205994426805887e0,
            1.2867958523298169e0,
            1.7618028256390648e0,
            7.581738205409592e2,
            4.095998412968799e0,
            5.502450415253016e0,
            1.715727803106431e0,
            2.3048610401734635e0,
            8.267086269952143e2,
            3.308542718075562e3,
            4.416384511062183e3,
            8.055660124601483e5,
            5.766163191430779e4,
        ],
        &[
            4.3340757556192194e-1,
            1.706886173664973e0,
            2.7231801107909936e-1,
            1.0724682127399743e0,
            3.564082965776769e2,
            6.026051993941705e-1,
            9.072756435996661e-1,
            3.786280134863476e-1,
            5.700580993427324e-1,
            1.651820785907809e2,
            7.024048463910486e-1,
            9.684481419009316e-1,
            4.413339810535971e-1,
            6.084939135957305e-1,
            1.5559154801406942e2,
            7.33427985929529e2,
            1.4155580938428286e3,
            2.756205599871588e5,
            1.0571559947411992e4,
        ],
        &[
            7.327489097787763e0,
            8.28168407726311e0,
            1.534665727924622e0,
            1.7345118570987568e0,
            1.228369350975021e3,
            1.4654978195575525e3,
            1.6348931493136936e3,
            2.4471038754688294e5,
            9.408776919571112e3,
            1.6893725322200485e1,
            5e0,
        ],
    ];
    for ((name, tool, body, physics), expected) in flat_scenarios().into_iter().zip(before) {
        let answer = solve_with(body, &tool, &physics).unwrap();
        let result = &answer.candidates()[0];
        assert!(result.forces.as_ref().unwrap().height_sections.is_none(), "{name}: a flat end has no sections");
        let got = fingerprint(result);
        assert_eq!(got.len(), expected.len(), "{name}");
        for (index, (g, e)) in got.iter().zip(expected).enumerate() {
            assert!((g - e).abs() <= 1e-12 * e.abs().max(1e-300), "{name} [{index}]: {g:e} vs {e:e}");
        }
    }
}

#[test]
fn a_ball_in_a_full_slot_deeper_than_its_radius_matches_a_quadrature_over_the_height() {
    // Every section's front half is in the stock behind the entry: the sin^a integral over
    // [0°, 180°] at every height, so M = k·k_c·f_z^a·∫ r·sin^(−m_c)κ dz·I(a)/(2π) for the ball
    // and its shank flank, with or without a helix.
    for (label, tool, corner) in [
        ("ball", end(ToolKind::Ball, None, None), RADIUS),
        ("ball, helix", end(ToolKind::Ball, None, Some(30.0)), RADIUS),
        ("bull", end(ToolKind::Bull, Some(2.0), Some(40.0)), 2.0),
    ] {
        for mc in [0.0, 0.25] {
            let a = 1.0 - mc;
            let depth = 8.0;
            let integral = Inner::new(a).up_to(PI);
            let width = over_height(corner, depth, mc, |_, _| 1.0);
            let result = solve_body(request(json!([[0, 0], [45, 0]]), depth, mc, &[1, 2, 4]), &tool).unwrap();
            assert!(!result.warnings.iter().any(|w| w.code == "W_FORCE_MODEL"), "{label}: exact, no warning");
            assert_eq!(result.forces.as_ref().unwrap().height_sections, Some(10), "{label}: 9 corner edges + flank");
            for flute in &result.flutes {
                let k = f64::from(flute.flute_count);
                let expected = k * KC11 * width * FZ.powf(a) * integral / TAU / 1000.0;
                close_rel(&format!("{label} mc {mc} k {k} mean"), flute.mean_torque_nm.unwrap(), expected, 1e-4);
                if flute.flute_count == 1 && label != "ball, helix" && !label.starts_with("bull") {
                    // One straight tooth: every band at θ = 90° at once.
                    let peak = KC11 * width * FZ.powf(a) / 1000.0;
                    close_rel(&format!("{label} mc {mc} one tooth peak"), flute.peak_torque_nm.unwrap(), peak, 1e-4);
                }
            }
        }
    }
}

/// The full-radius figure for a rounded end: a flat end of the same radius whose a_p gives the
/// end's torque width (∫ r·sin^(−m_c)κ dz = R·a_p) sees the full radius's arcs at every height,
/// which is what the model took before the bands.
fn full_radius(body: &Value, corner: f64, depth: f64, mc: f64) -> PathEngagement {
    let width = over_height(corner, depth, mc, |_, _| 1.0);
    let mut flat = body.clone();
    flat["axial_depth"] = json!(width / RADIUS);
    let mut tool = end(ToolKind::Flat, None, None);
    tool.helix_deg = None;
    solve_body(flat, &tool).unwrap()
}

#[test]
fn beside_a_wall_the_tip_misses_it_and_the_torque_falls_below_the_full_radius_figure() {
    // Down milling a_e along the block's top edge: the section of radius r reaches the wall
    // R − a_e from the path only where r > R − a_e, over [0°, acos((R − a_e)/r)]; the quadrature
    // integrates exactly that over the height.
    for (label, tool, corner, radial, cases) in [
        (
            "ball",
            end(ToolKind::Ball, None, None),
            RADIUS,
            1.0,
            &[(0.0, RADIUS), (0.25, RADIUS), (0.25, 3.0), (0.25, 1.0)][..],
        ),
        (
            "bull",
            end(ToolKind::Bull, Some(2.0), None),
            2.0,
            1.0,
            &[(0.0, RADIUS), (0.25, RADIUS), (0.25, 3.0), (0.25, 1.0)],
        ),
        // Thin cuts, where only the top few per cent of the height reach the wall.
        ("ball, thin", end(ToolKind::Ball, None, None), RADIUS, 0.5, &[(0.25, 3.0)]),
        ("ball, thinner", end(ToolKind::Ball, None, None), RADIUS, 0.2, &[(0.25, RADIUS), (0.25, 4.0)]),
    ] {
        let wall = RADIUS - radial;
        let y = 20.0 + wall;
        for &(mc, depth) in cases {
            let a = 1.0 - mc;
            let inner = Inner::new(a);
            let body = request(json!([[-10, y], [60, y]]), depth, mc, &[1, 3]);
            let result = solve_body(body.clone(), &tool).unwrap();
            let bound = full_radius(&body, corner, depth, mc);
            let per_height =
                over_height(corner, depth, mc, |_, r| if r > wall { inner.up_to((wall / r).acos()) } else { 0.0 });
            let steady = |s: &EngagementSample| s.position[0] > 10.0 && s.position[0] < 40.0;
            let mut checked = 0;
            for (sample, full) in result.samples.iter().zip(&bound.samples).filter(|(s, _)| steady(s)) {
                for (column, k) in [1.0, 3.0].into_iter().enumerate() {
                    let expected = k * KC11 * FZ.powf(a) * per_height / TAU / 1000.0;
                    // The trapezoid over the sections, halved where the wall comes into reach.
                    close_rel(&format!("{label} mc {mc} a_p {depth} k {k}"), sample.torque_nm[column], expected, 1e-3);
                    assert!(
                        sample.torque_nm[column] < 0.95 * full.torque_nm[column],
                        "{label} a_p {depth}: {} not below the full-radius {}",
                        sample.torque_nm[column],
                        full.torque_nm[column]
                    );
                    assert!(sample.peak_torque_nm[column] < full.peak_torque_nm[column]);
                }
                checked += 1;
            }
            assert!(checked > 100);
            if corner == RADIUS && depth <= 1.0 {
                // A ball 1 mm deep: its largest section (r = 3) never reaches the wall.
                assert!(result.samples.iter().all(|s| s.torque_nm.iter().all(|t| *t == 0.0)), "{label}");
            }
        }
    }
}

#[test]
fn at_a_slots_exit_the_tip_cuts_more_than_the_full_radius_figure() {
    // Leaving the block at x = 50 the full section keeps two thin horns [0, T] ∪ [180 − T, 180]
    // with sin T = (50 − X)/R, but a section of radius r keeps sin T = (50 − X)/r, wider: the
    // full-radius arcs are no upper bound in general, which is why the bands are computed.
    let body = request(json!([[-10, 0], [60, 0]]), RADIUS, 0.25, &[2]);
    let result = solve_body(body.clone(), &end(ToolKind::Ball, None, None)).unwrap();
    let bound = full_radius(&body, RADIUS, RADIUS, 0.25);
    let exit = result
        .samples
        .iter()
        .zip(&bound.samples)
        .filter(|(s, _)| s.position[0] > 46.0 && s.position[0] < 49.5)
        .collect::<Vec<_>>();
    assert!(!exit.is_empty());
    assert!(exit.iter().all(|(s, full)| s.torque_nm[0] > full.torque_nm[0]), "the horns of the tip");
}

#[test]
fn engine_dots_keeps_the_full_radius_arcs_and_says_so() {
    let mut body = request(json!([[-10, 24], [60, 24]]), 3.0, 0.25, &[2]);
    body["engine"] = json!("dots");
    body["grid"] = json!(0.05);
    body["step"] = json!(0.5);
    let result = solve_body(body, &end(ToolKind::Ball, None, None)).unwrap();
    assert!(result.warnings.iter().any(|w| w.code == "W_FORCE_MODEL"));
    assert!(result.forces.unwrap().height_sections.is_none());
}

#[test]
fn arc_feed_and_the_feed_plan_use_the_bands() {
    // On an arc of the path each band corrects its chip at its own radius; the capped plan
    // holds the spindle with the bands' torque.
    let mut body = request(
        json!({"start": [-10, 24], "segments": [
            {"type": "line", "to": [20, 24]},
            {"type": "arc", "to": [40, 24], "center": [30, 24], "dir": "ccw"}]}),
        3.0,
        0.25,
        &[3],
    );
    body["arc_feed_correction"] = json!(true);
    body["feed_plan"] = json!({"target_thickness": 1.0, "max_feed": 50_000, "flute_count": 3});
    let physics = Physics {
        material: None,
        spindle: SpindleLimits { spindle_power_kw: Some(0.05), spindle_torque_nm: Some(0.3) },
    };
    let answer = solve_with(body, &end(ToolKind::Ball, None, None), &physics).unwrap();
    let result = &answer.candidates()[0];
    let plan = result.feed_plan.as_ref().unwrap();
    let nominal = result.flutes[0].feed;
    let mut limited = 0;
    for block in &plan.blocks {
        let feed = block.feed.unwrap();
        for sample in result.samples.iter().filter(|s| s.s >= block.from_s - 1e-9 && s.s <= block.to_s + 1e-9) {
            let torque = sample.torque_nm[0] * (feed / nominal).powf(0.75);
            assert!(torque <= 0.3 * (1.0 + 1e-9), "s {}: {torque}", sample.s);
            assert!(TAU * 3000.0 * torque / 60_000.0 <= 0.05 * (1.0 + 1e-9), "s {}: power", sample.s);
            limited += usize::from(torque > 0.0);
        }
    }
    assert!(limited > 10);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// Where every edge of the stock lies outside the tool centre or at least R from it (a wall
    /// beside a straight path, a slot, before the exit), each section's engaged arcs lie within
    /// the full radius's, so the bands never give more than the full-radius figure: mean and
    /// peak torque at every sample, any end, depth, exponent, flute count and direction.
    #[test]
    fn the_bands_never_exceed_the_full_radius_figure_where_the_stock_lies_outside_the_centre(
        mode in 0_u8..3,
        offset in 0.05_f64..4.95,
        ball in any::<bool>(),
        corner in 0.3_f64..5.0,
        depth in 0.2_f64..9.0,
        mc in 0.0_f64..0.4,
        flutes in 1_u32..6,
        ccw in any::<bool>(),
    ) {
        // Material right of travel below y = −offset, left above y = offset, or a wide slot.
        let stock = match mode {
            0 => json!({"polygon": [[0, -40], [60, -40], [60, -offset], [0, -offset]]}),
            1 => json!({"polygon": [[0, offset], [60, offset], [60, 40], [0, 40]]}),
            _ => json!({"polygon": [[0, -40], [60, -40], [60, 40], [0, 40]]}),
        };
        let corner = if ball { RADIUS } else { corner };
        let tool = if ball { end(ToolKind::Ball, None, None) } else { end(ToolKind::Bull, Some(corner), None) };
        let mut body = request(json!([[-10, 0], [60.0 - RADIUS, 0]]), depth, mc, &[flutes]);
        body["stock"] = stock;
        body["step"] = json!(0.7);
        if ccw {
            body["spindle_direction"] = json!("ccw");
        }
        let result = solve_body(body.clone(), &tool).unwrap();
        let bound = full_radius(&body, corner, depth, mc);
        for (sample, full) in result.samples.iter().zip(&bound.samples) {
            // The quadrature of the width is good to about 1e-7.
            prop_assert!(sample.torque_nm[0] <= full.torque_nm[0] * (1.0 + 1e-6) + 1e-12,
                "s {}: mean {} > {}", sample.s, sample.torque_nm[0], full.torque_nm[0]);
            prop_assert!(sample.peak_torque_nm[0] <= full.peak_torque_nm[0] * (1.0 + 1e-6) + 1e-12,
                "s {}: peak {} > {}", sample.s, sample.peak_torque_nm[0], full.peak_torque_nm[0]);
        }
    }
}

// a_p from the stock's top and the path's Z.

fn slot_at(extra: Value) -> Value {
    let mut body = json!({
        "tool": 1, "stock": block(), "path": [[0, 0], [45, 0]], "spindle_rpm": 3000,
        "feed_per_tooth": FZ, "flute_counts": [2, 4], "step": 0.5, "kienzle": {"kc11": KC11, "mc": 0.25},
    });
    for (key, value) in extra.as_object().unwrap() {
        body[key] = value.clone();
    }
    body
}

fn flat() -> Tool {
    let mut tool = end(ToolKind::Flat, None, None);
    tool.flute_length = Some(12.0);
    tool
}

fn codes(result: &PathEngagement) -> Vec<&str> {
    result.warnings.iter().map(|w| w.code).collect()
}

#[test]
fn a_path_below_the_stock_top_cuts_the_difference() {
    let given = solve_body(slot_at(json!({"axial_depth": 3})), &flat()).unwrap();
    let derived = solve_body(slot_at(json!({"stock_top_z": 10, "cut_z": 7})), &flat()).unwrap();
    assert_eq!(derived.forces.as_ref().unwrap().axial_depth, 3.0);
    assert_eq!(given.samples, derived.samples, "a_p = 10 − 7 cuts as axial_depth 3");
    assert!(!codes(&derived).contains(&"W_AXIAL_DEPTH"));
    // The top defaults to 0, as for the program.
    let below_zero = solve_body(slot_at(json!({"cut_z": -3})), &flat()).unwrap();
    assert_eq!(below_zero.samples, given.samples);
    // An explicit axial_depth wins, and says so where the heights disagree.
    let both = solve_body(slot_at(json!({"axial_depth": 2, "stock_top_z": 10, "cut_z": 7})), &flat()).unwrap();
    assert_eq!(both.forces.as_ref().unwrap().axial_depth, 2.0);
    assert!(both.warnings.iter().any(|w| w.code == "W_AXIAL_DEPTH" && w.message.contains("axial_depth = 2")));
    let agree = solve_body(slot_at(json!({"axial_depth": 3, "stock_top_z": 10, "cut_z": 7})), &flat()).unwrap();
    assert!(!codes(&agree).contains(&"W_AXIAL_DEPTH"));
    // At or above the top: a_p 0, nothing cut, said.
    let above = solve_body(slot_at(json!({"stock_top_z": 10, "cut_z": 10.5})), &flat()).unwrap();
    assert_eq!(above.forces.as_ref().unwrap().axial_depth, 0.0);
    assert!(above.samples.iter().all(|s| s.torque_nm.iter().all(|t| *t == 0.0)));
    assert!(codes(&above).contains(&"W_AXIAL_DEPTH"));
    // The removal rate follows a_p too, without kienzle.
    let mut plain = slot_at(json!({"stock_top_z": 10, "cut_z": 7}));
    plain.as_object_mut().unwrap().remove("kienzle");
    let plain = solve_body(plain, &flat()).unwrap();
    let mut three = slot_at(json!({"axial_depth": 3}));
    three.as_object_mut().unwrap().remove("kienzle");
    assert_eq!(plain.max_mrr, solve_body(three, &flat()).unwrap().max_mrr);
}

#[test]
fn deeper_than_the_flutes_is_refused_at_the_field_that_set_it() {
    let error = solve_body(slot_at(json!({"stock_top_z": 10, "cut_z": -5})), &flat()).unwrap_err();
    assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some("cut_z")));
    assert!(error.message().contains("flute_length 12"), "{}", error.message());
    let error = solve_body(slot_at(json!({"axial_depth": 13})), &flat()).unwrap_err();
    assert_eq!(error.field(), Some("axial_depth"));
    // Within the flutes, or a tool without a flute length: cut.
    assert!(solve_body(slot_at(json!({"stock_top_z": 10, "cut_z": -2})), &flat()).is_ok());
    assert!(solve_body(slot_at(json!({"axial_depth": 13})), &end(ToolKind::Flat, None, None)).is_ok());
    for (extra, field) in [
        (json!({"cut_z": 1e9}), "cut_z"),
        (json!({"stock_top_z": -1e9, "cut_z": 0}), "stock_top_z"),
        (json!({"axial_depth": -1}), "axial_depth"),
    ] {
        let error = solve_body(slot_at(extra.clone()), &flat()).unwrap_err();
        assert_eq!((error.code().as_str(), error.field()), ("E_INPUT", Some(field)), "{extra}");
    }
    let mut tool = flat();
    tool.flute_length = Some(-1.0);
    let error = solve_body(slot_at(json!({"axial_depth": 1})), &tool).unwrap_err();
    assert_eq!(error.field(), Some("tool.flute_length"));
}

#[test]
fn each_path_may_run_at_its_own_z() {
    let mut body = slot_at(json!({"stock_top_z": 5, "cut_z": 3}));
    let path = body.as_object_mut().unwrap().remove("path").unwrap();
    body["paths"] = json!([
        {"name": "request's Z", "path": path},
        {"name": "own Z", "path": path, "cut_z": 1},
        {"name": "own a_p", "path": path, "cut_z": 1, "axial_depth": 0.5},
    ]);
    let answer = solve_with(body.clone(), &flat(), &Physics::default()).unwrap();
    let depths: Vec<f64> = answer.candidates().iter().map(|c| c.forces.as_ref().unwrap().axial_depth).collect();
    assert_eq!(depths, [2.0, 4.0, 0.5]);
    body["paths"][1]["cut_z"] = json!(f64::MAX);
    let error = solve_with(body, &flat(), &Physics::default()).unwrap_err();
    assert_eq!(error.field(), Some("paths[1].cut_z"));
}

#[test]
fn a_gcode_path_brings_its_z_when_the_top_is_given() {
    let program = "G21 G90\nG0 X-10 Y0 Z5\nG1 Z-2.5 F200\nG1 X45 F600\nG0 Z5\n";
    let gcode = json!({"gcode": program});
    let with_top = solve_body(slot_at(json!({"path": gcode, "stock_top_z": 0})), &flat()).unwrap();
    assert_eq!(with_top.forces.as_ref().unwrap().axial_depth, 2.5);
    // Without an explicit top the program's Z is not taken (its Z0 may be anywhere).
    let error = solve_body(slot_at(json!({"path": gcode})), &flat()).unwrap_err();
    assert_eq!(error.field(), Some("axial_depth"));
    // cut_z wins over the program's Z; axial_depth over both.
    let cut = solve_body(slot_at(json!({"path": gcode, "stock_top_z": 0, "cut_z": -1})), &flat()).unwrap();
    assert_eq!(cut.forces.as_ref().unwrap().axial_depth, 1.0);
    // Feed moves at two levels: no a_p from the height, said; with axial_depth fine.
    let levels = json!({"gcode": "G21 G90\nG0 X-10 Y0 Z5\nG1 Z-1 F200\nG1 X20 F600\nG1 Z-2\nG1 X45\n"});
    let error = solve_body(slot_at(json!({"path": levels, "stock_top_z": 0})), &flat()).unwrap_err();
    assert_eq!(error.field(), Some("axial_depth"));
    let mut plain = slot_at(json!({"path": levels, "stock_top_z": 0}));
    plain.as_object_mut().unwrap().remove("kienzle");
    let plain = solve_body(plain, &flat()).unwrap();
    assert!(plain.warnings.iter().any(|w| w.code == "W_AXIAL_DEPTH" && w.message.contains("line 4")));
    assert!(plain.max_mrr.is_none());
}

#[test]
fn the_program_cuts_at_the_paths_z() {
    let post = Post {
        dialect: Dialect::Linuxcnc,
        reference: Reference::Tip,
        tool: ToolCall::Table(4),
        arcs: kerf_solver::gcode::Arcs::Chords,
        plunge_feed: None,
        units: kerf_solver::units::Units::Mm,
    };
    let mut body = slot_at(json!({"stock_top_z": 10, "cut_z": 7.25}));
    body.as_object_mut().unwrap().remove("kienzle");
    let request: EngagementRequest = serde_json::from_value(body).unwrap();
    let answer = engagement::solve(&request, &flat()).unwrap();
    let text = engagement::program(&answer, 0, &post).unwrap();
    assert!(text.contains("Z7.2500") && text.contains("Z15.0000"), "{text}");
}
